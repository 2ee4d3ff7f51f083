// The conformity checker against meshes written by an independent mesher:
// tetgen 1.5.0 (Debian) on corpus inputs must pass every check; the same
// meshes, broken on purpose, must fail in the right category.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "absl/strings/str_cat.h"
#include "core/mesh/conformity.h"
#include "core/mesh/read_tetgen.h"
#include "core/plc/readers.h"
#include "gtest/gtest.h"
#include "tests/mesh/mesh_test_util.h"
#include "tests/test_support.h"

namespace svrc::mesh {
namespace {

namespace fs = std::filesystem;
using testing::HaveTool;

// Runs `tetgen -<switches>` on a copy of the file `src` in a fresh folder and
// returns the path of the .1.node it wrote ("" after a failed expectation).
std::string RunTetgenOn(const fs::path& src, const std::string& switches) {
  if (!HaveTool("tetgen")) {
    ADD_FAILURE() << "tetgen not installed (scripts/setup.sh installs it)";
    return "";
  }
  const fs::path dir = svrc::testing::MakeTempDir("tetgen");
  const fs::path copy = dir / src.filename();
  fs::copy_file(src, copy);
  const int rc = testing::RunIn(dir.string(),
                                absl::StrCat("stdbuf -o0 tetgen -", switches, " '",
                                             copy.filename().string(), "'"),
                                "tetgen.log");
  EXPECT_EQ(rc, 0) << "tetgen -" << switches << "\n"
                   << svrc::testing::ReadFileOrFail((dir / "tetgen.log").string());
  fs::path node = copy;
  node.replace_extension(".1.node");
  EXPECT_TRUE(fs::exists(node)) << node;
  return node.string();
}

std::string RunTetgen(const std::string& corpus_file, const std::string& switches) {
  return RunTetgenOn(svrc::testing::CorpusPath(corpus_file), switches);
}

struct Case {
  std::string file;
  std::string switches;
};

class TetgenCorpus : public ::testing::TestWithParam<Case> {};

TEST_P(TetgenCorpus, CheckerAcceptsTetgenMesh) {
  const Case& c = GetParam();
  auto plc = plc::ReadPlcFile(svrc::testing::CorpusPath(c.file));
  ASSERT_TRUE(plc.ok()) << plc.status();
  const std::string node = RunTetgen(c.file, c.switches);
  ASSERT_FALSE(node.empty());
  auto mesh = ReadTetgenMesh(node);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  ASSERT_GT(mesh->tets.size(), 0u);
  ConformityOptions opt;
  opt.input_vertices_first = false;  // tetgen keeps input order, but need not
  // tetgen writes marker 1 on boundary faces of unmarked (surface) inputs.
  opt.check_markers = !plc->is_surface;
  const ConformityReport r = CheckConformity(*plc, *mesh, opt);
  EXPECT_TRUE(r.ok()) << c.file << " -" << c.switches << "\n" << r.Summary();
  EXPECT_GT(r.num_facets_checked, 0u);
  // example.poly: facet #20 separates a volume hole from the exterior; every
  // other facet of these inputs bounds the domain.
  EXPECT_EQ(r.num_facets_outside, c.file == "b_internal/example.poly" ? 1u : 0u);
  // Every input's cells are built (internal facets included) and each
  // cell's coverage is checked (docs/conformity.md).
  EXPECT_TRUE(r.cells_known) << r.cells_unknown_reason;
  EXPECT_TRUE(r.enclosed_volume_known);
  EXPECT_NEAR(r.mesh_volume, r.enclosed_volume, 1e-9 * r.enclosed_volume);
  if (c.file == "b_internal/box_internal_facet.poly") {
    EXPECT_EQ(r.num_cells, 2u);
  }
  if (c.file == "b_internal/box_in_box.poly") {
    EXPECT_EQ(r.num_cells, 2u);
  }
  std::printf("%s -%s: %zu vertices, %zu tets, %zu triangles, volume %.17g (enclosed %s)\n",
              c.file.c_str(), c.switches.c_str(), mesh->positions.size(), mesh->tets.size(),
              mesh->triangles.size(), r.mesh_volume,
              r.enclosed_volume_known ? absl::StrCat(r.enclosed_volume).c_str() : "unknown");
}

std::vector<Case> Cases() {
  std::vector<Case> out;
  for (const char* f : {"a_convex/cube.poly", "a_convex/tetra.poly",
                        "b_internal/box_internal_facet.poly", "b_internal/example.poly",
                        "b_internal/box_in_box.poly", "e_spread/tiny_cube_in_box.poly",
                        "c_creases/knife_edge.poly", "d_small_angles/segment_fan.poly",
                        "e_spread/far_offset_close_points.poly", "c_creases/wedge-1.smesh",
                        "c_creases/schonhardt.off", "a_convex/cube.off"}) {
    for (const char* s : {"pAQ", "pq2AQ"}) out.push_back({f, s});
  }
  return out;
}

INSTANTIATE_TEST_SUITE_P(Corpus, TetgenCorpus, ::testing::ValuesIn(Cases()),
                         [](const ::testing::TestParamInfo<Case>& info) {
                           std::string n = absl::StrCat(info.param.file, "_", info.param.switches);
                           for (char& ch : n) {
                             if (!isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           }
                           return n;
                         });

// The same real mesh, broken on purpose: each defect is reported in its own
// category.
class TetgenMutations : public ::testing::Test {
 protected:
  void SetUp() override {
    auto p = plc::ReadPlcFile(svrc::testing::CorpusPath("b_internal/example.poly"));
    ASSERT_TRUE(p.ok()) << p.status();
    plc_ = *p;
    const std::string node = RunTetgen("b_internal/example.poly", "pq2AQ");
    ASSERT_FALSE(node.empty());
    auto m = ReadTetgenMesh(node);
    ASSERT_TRUE(m.ok()) << m.status();
    mesh_ = *m;
    opt_.input_vertices_first = false;
    ASSERT_TRUE(CheckConformity(plc_, mesh_, opt_).ok());
  }
  plc::Plc plc_;
  TetMesh mesh_;
  ConformityOptions opt_;
};

TEST_F(TetgenMutations, FlippedTet) {
  std::swap(mesh_.tets[10][0], mesh_.tets[10][1]);
  const ConformityReport r = CheckConformity(plc_, mesh_, opt_);
  EXPECT_EQ(r.Count(ViolationKind::kFlippedTet), 1u) << r.Summary();
}

TEST_F(TetgenMutations, DeletedTet) {
  mesh_.tets.erase(mesh_.tets.begin() + 100);
  mesh_.tet_region.erase(mesh_.tet_region.begin() + 100);
  const ConformityReport r = CheckConformity(plc_, mesh_, opt_);
  EXPECT_GT(r.Count(ConformityCategory::kCoverage), 0u) << r.Summary();
}

TEST_F(TetgenMutations, DroppedFacetTriangle) {
  mesh_.triangles.erase(mesh_.triangles.begin() + 5);
  mesh_.triangle_marker.erase(mesh_.triangle_marker.begin() + 5);
  const ConformityReport r = CheckConformity(plc_, mesh_, opt_);
  EXPECT_EQ(r.Count(ViolationKind::kFacetNotCovered), 1u) << r.Summary();
  EXPECT_EQ(r.Count(ConformityCategory::kValidity) + r.Count(ConformityCategory::kCoverage), 0u);
}

TEST_F(TetgenMutations, VertexMovedOffItsFacet) {
  // Move the first vertex of the first triangle along the facet normal... any
  // direction off the plane works: try each axis until the triangle leaves
  // its facet plane.
  const uint32_t v = mesh_.triangles[0][0];
  mesh_.positions[v] = mesh_.positions[v] + Vec3(1e-6, 1e-6, 1e-6);
  const ConformityReport r = CheckConformity(plc_, mesh_, opt_);
  EXPECT_GT(r.Count(ConformityCategory::kConformity), 0u) << r.Summary();
}

// tetgen's mesh of box_internal_facet.poly (two regions split by z = ½), with
// a whole region deleted or meshed twice.
class TetgenRegions : public ::testing::Test {
 protected:
  void SetUp() override {
    auto p = plc::ReadPlcFile(svrc::testing::CorpusPath("b_internal/box_internal_facet.poly"));
    ASSERT_TRUE(p.ok()) << p.status();
    plc_ = *p;
    const std::string node = RunTetgen("b_internal/box_internal_facet.poly", "pq2AQ");
    ASSERT_FALSE(node.empty());
    auto m = ReadTetgenMesh(node);
    ASSERT_TRUE(m.ok()) << m.status();
    mesh_ = *m;
    opt_.input_vertices_first = false;
    const ConformityReport r = CheckConformity(plc_, mesh_, opt_);
    ASSERT_TRUE(r.ok()) << r.Summary();
    ASSERT_TRUE(r.cells_known) << r.cells_unknown_reason;
  }
  static double CentroidZ(const TetMesh& m, const std::array<uint32_t, 4>& t) {
    return (m.positions[t[0]].z + m.positions[t[1]].z + m.positions[t[2]].z +
            m.positions[t[3]].z) / 4;
  }
  plc::Plc plc_;
  TetMesh mesh_;
  ConformityOptions opt_;
};

TEST_F(TetgenRegions, DeletedRegionIsRejected) {
  TetMesh m = mesh_;
  m.tets.clear();
  m.tet_region.clear();
  for (size_t t = 0; t < mesh_.tets.size(); ++t) {
    if (CentroidZ(mesh_, mesh_.tets[t]) > 0.5) {
      m.tets.push_back(mesh_.tets[t]);
      m.tet_region.push_back(mesh_.tet_region[t]);
    }
  }
  ASSERT_LT(m.tets.size(), mesh_.tets.size());
  // Keep only the triangles that are still faces (the bottom region's
  // boundary triangles go with it), so that only the coverage can tell.
  std::set<std::array<uint32_t, 3>> faces;
  for (const auto& t : m.tets) {
    for (int k = 0; k < 4; ++k) {
      std::array<uint32_t, 3> f = {t[(k + 1) % 4], t[(k + 2) % 4], t[(k + 3) % 4]};
      std::sort(f.begin(), f.end());
      faces.insert(f);
    }
  }
  m.triangles.clear();
  m.triangle_marker.clear();
  for (size_t i = 0; i < mesh_.triangles.size(); ++i) {
    auto f = mesh_.triangles[i];
    std::sort(f.begin(), f.end());
    if (faces.count(f)) {
      m.triangles.push_back(mesh_.triangles[i]);
      m.triangle_marker.push_back(mesh_.triangle_marker[i]);
    }
  }
  const ConformityReport r = CheckConformity(plc_, m, opt_);
  EXPECT_EQ(r.Count(ViolationKind::kVolumeMismatch), 1u) << r.Summary();
  EXPECT_EQ(r.Count(ViolationKind::kOpenFace), 0u) << r.Summary();
  EXPECT_NE(r.Summary().find("region seed(s) 0"), std::string::npos) << r.Summary();
  EXPECT_NE(r.Summary().find("not filled"), std::string::npos) << r.Summary();
}

TEST_F(TetgenRegions, DuplicatedRegionIsRejected) {
  TetMesh m = mesh_;
  const uint32_t nv = static_cast<uint32_t>(m.positions.size());
  m.positions.insert(m.positions.end(), mesh_.positions.begin(), mesh_.positions.end());
  for (size_t t = 0; t < mesh_.tets.size(); ++t) {
    if (CentroidZ(mesh_, mesh_.tets[t]) > 0.5) {
      const auto& q = mesh_.tets[t];
      m.tets.push_back({q[0] + nv, q[1] + nv, q[2] + nv, q[3] + nv});
      m.tet_region.push_back(mesh_.tet_region[t]);
    }
  }
  const ConformityReport r = CheckConformity(plc_, m, opt_);
  EXPECT_EQ(r.Count(ViolationKind::kVolumeMismatch), 1u) << r.Summary();
  EXPECT_NE(r.Summary().find("region seed(s) 1"), std::string::npos) << r.Summary();
  EXPECT_NE(r.Summary().find("more than once"), std::string::npos) << r.Summary();
}

// The unit box split by an internal facet z = 1/2 and, in the upper half
// only, by an internal facet x = 1/2 whose bottom edge is an in-facet segment
// of the z = 1/2 facet and whose other edges are in-facet segments of the
// y = 0, y = 1 and z = 1 facets (polygon edges split at the T-junction
// vertices, which tetgen 1.5.0 needs). Every facet but x = 1/2 has a side
// split into pieces (docs/conformity.md "Pieces"); three cells.
constexpr char kTBoxPoly[] = R"(# T-box
16 3 0 0
1 0 0 0
2 1 0 0
3 0 1 0
4 1 1 0
5 0 0 1
6 1 0 1
7 0 1 1
8 1 1 1
9 0 0 0.5
10 1 0 0.5
11 1 1 0.5
12 0 1 0.5
13 0.5 0 0.5
14 0.5 1 0.5
15 0.5 1 1
16 0.5 0 1
8 1
2 0 1
6 1 3 12 7 5 9
2 9 12
2 0 2
6 2 4 11 8 6 10
2 10 11
4 0 3
7 1 2 10 6 16 5 9
2 9 13
2 13 10
2 13 16
4 0 4
7 3 4 11 8 15 7 12
2 12 14
2 14 11
2 14 15
1 0 5
4 1 2 4 3
2 0 6
6 5 16 6 8 15 7
2 15 16
2 0 7
6 9 13 10 11 14 12
2 13 14
1 0 8
4 13 14 15 16
0
3
1 0.5 0.5 0.25 1 -1
2 0.25 0.5 0.75 2 -1
3 0.75 0.5 0.75 3 -1
)";

TEST(TetgenPieces, CellsOfFacetsSplitIntoPieces) {
  const fs::path dir = svrc::testing::MakeTempDir("tbox");
  const fs::path poly = dir / "tbox.poly";
  {
    std::ofstream out(poly);
    out << kTBoxPoly;
  }
  auto plc = plc::ReadPlcFile(poly.string());
  ASSERT_TRUE(plc.ok()) << plc.status();
  ConformityOptions opt;
  opt.input_vertices_first = false;
  for (const char* sw : {"pAQ", "pq1.5a0.01AQ"}) {
    const std::string node = RunTetgenOn(poly, sw);
    ASSERT_FALSE(node.empty());
    auto mesh = ReadTetgenMesh(node);
    ASSERT_TRUE(mesh.ok()) << mesh.status();
    const ConformityReport r = CheckConformity(*plc, *mesh, opt);
    EXPECT_TRUE(r.ok()) << sw << "\n" << r.Summary();
    ASSERT_TRUE(r.cells_known) << sw << ": " << r.cells_unknown_reason;
    EXPECT_EQ(r.num_cells, 3u);
    EXPECT_NEAR(r.enclosed_volume, 1.0, 1e-12);
    EXPECT_NEAR(r.mesh_volume, 1.0, 1e-12);
    EXPECT_EQ(r.num_facets_outside, 0u);

    // The top right region deleted and the top left one meshed twice: the
    // same total volume, caught cell by cell.
    const TetMesh& m = *mesh;
    TetMesh bad = m;
    const uint32_t nv = static_cast<uint32_t>(m.positions.size());
    bad.positions.insert(bad.positions.end(), m.positions.begin(), m.positions.end());
    bad.tets.clear();
    bad.tet_region.clear();
    for (size_t t = 0; t < m.tets.size(); ++t) {
      const auto& q = m.tets[t];
      const Vec3 c = (m.positions[q[0]] + m.positions[q[1]] + m.positions[q[2]] +
                      m.positions[q[3]]) / 4.0;
      if (c.z > 0.5 && c.x > 0.5) continue;
      bad.tets.push_back(q);
      bad.tet_region.push_back(m.tet_region[t]);
      if (c.z > 0.5 && c.x < 0.5) {
        bad.tets.push_back({q[0] + nv, q[1] + nv, q[2] + nv, q[3] + nv});
        bad.tet_region.push_back(m.tet_region[t]);
      }
    }
    const ConformityReport rb = CheckConformity(*plc, bad, opt);
    EXPECT_NEAR(rb.mesh_volume, 1.0, 1e-12);
    EXPECT_EQ(rb.Count(ViolationKind::kVolumeMismatch), 2u) << sw << "\n" << rb.Summary();
    const std::string sum = rb.Summary();
    EXPECT_NE(sum.find("region seed(s) 1: tets in it have volume"), std::string::npos) << sum;
    EXPECT_NE(sum.find("region seed(s) 2: tets in it have volume"), std::string::npos) << sum;
    EXPECT_NE(sum.find("more than once"), std::string::npos) << sum;
    EXPECT_NE(sum.find("not filled"), std::string::npos) << sum;
  }
}

}  // namespace
}  // namespace svrc::mesh
