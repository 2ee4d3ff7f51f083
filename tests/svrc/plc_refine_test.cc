// End-to-end SVRC on PLCs without creases (issue #5 "Must show"): corpus files
// through core::MeshPlc, every output checked by the conformity checker of #3
// (valid, covers, conforms) and for radius-edge ≤ the bound on every tet.
#include <string>

#include "core/api.h"
#include "core/mesh/conformity.h"
#include "core/mesh/quality.h"
#include "core/plc/readers.h"
#include "gtest/gtest.h"
#include "tests/test_support.h"

namespace svrc {
namespace {

struct Meshed {
  plc::Plc plc;
  mesh::TetMesh mesh;
};

Meshed MeshCorpus(const std::string& rel, const core::MeshParams& params = {}) {
  Meshed out;
  absl::StatusOr<plc::Plc> plc = plc::ReadPlcFile(testing::CorpusPath(rel));
  EXPECT_TRUE(plc.ok()) << plc.status();
  if (!plc.ok()) return out;
  out.plc = *plc;
  absl::StatusOr<mesh::TetMesh> m = core::MeshPlc(*plc, params);
  EXPECT_TRUE(m.ok()) << rel << ": " << m.status();
  if (m.ok()) out.mesh = std::move(*m);
  return out;
}

void ExpectGoodMesh(const Meshed& m, double radius_edge, const std::string& what) {
  ASSERT_FALSE(m.mesh.tets.empty()) << what;
  const mesh::ConformityReport rep = mesh::CheckConformity(m.plc, m.mesh);
  EXPECT_TRUE(rep.ok()) << what << ": " << rep.Summary();
  const mesh::QualityReport q = mesh::ComputeQuality(m.mesh);
  EXPECT_LE(q.all.radius_edge.max, radius_edge * (1 + 1e-9)) << what;
}

TEST(PlcRefine, Cube) {
  for (const char* f : {"a_convex/cube.poly", "a_convex/cube.off", "a_convex/cube_ascii.stl", "a_convex/cube_binary.stl", "a_convex/cube.obj"}) {
    Meshed m = MeshCorpus(f);
    ExpectGoodMesh(m, 2.0, f);
  }
}

TEST(PlcRefine, BoxInternalFacet) {
  Meshed m = MeshCorpus("b_internal/box_internal_facet.poly");
  ExpectGoodMesh(m, 2.0, "box_internal_facet");
}

TEST(PlcRefine, BoxInBox) {
  Meshed m = MeshCorpus("b_internal/box_in_box.poly");
  ExpectGoodMesh(m, 2.0, "box_in_box");
}

TEST(PlcRefine, TinyCubeInBox) {
  Meshed m = MeshCorpus("e_spread/tiny_cube_in_box.poly");
  ExpectGoodMesh(m, 2.0, "tiny_cube_in_box");
}

TEST(PlcRefine, FarOffsetClosePoints) {
  Meshed m = MeshCorpus("e_spread/far_offset_close_points.poly");
  ExpectGoodMesh(m, 2.0, "far_offset_close_points");
}

}  // namespace
}  // namespace svrc
