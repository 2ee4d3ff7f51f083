// Output assembly (core/svrc/assemble.h): vertex order and bit-exact input
// vertices, regions, triangle markers and orientation, volumes, determinism,
// and the conformity checker on assembled meshes (grids and corpus PLCs whose
// vertex Delaunay already conforms).
#include "core/svrc/assemble.h"

#include <algorithm>
#include <cstring>
#include <numeric>
#include <random>

#include "core/delaunay/point_set.h"
#include "core/geometry/predicates.h"
#include "core/mesh/canonical.h"
#include "core/mesh/conformity.h"
#include "core/plc/readers.h"
#include "gtest/gtest.h"
#include "tests/svrc/output_test_util.h"
#include "tests/test_support.h"

namespace svrc::refine {
namespace {

using geom::Vec3;
using testing::Grid;

bool Inside(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  return p.x > lo.x && p.x < hi.x && p.y > lo.y && p.y < hi.y && p.z > lo.z && p.z < hi.z;
}

bool SameBits(const Vec3& a, const Vec3& b) { return std::memcmp(&a, &b, sizeof(Vec3)) == 0; }

double MeshVolume(const mesh::TetMesh& m) {
  double v = 0;
  for (size_t t = 0; t < m.tets.size(); ++t) v += testing::TetVolume(m, t);
  return v;
}

// Nested boxes [1,7] ⊃ [2,6] ⊃ [3,5] (grid units) in an 8^3 Kuhn grid, the
// PLC in input coordinates x = grid·2^-3 + (1e6, -2e6, 3.5): the back map is
// exact on the grid, so expected values are exact too.
struct NestedCase {
  CoordinateMap map{{1e6, -2e6, 3.5}, -3};
  Grid grid = testing::KuhnGrid(8);
  plc::Plc plc;
  std::vector<ConstrainedFace> faces;
  std::vector<uint32_t> input_vertex;
  NestedCase() {
    auto in = [&](double a) { return map.ToInput({a, a, a}); };
    testing::AddBox(&plc, in(1), in(7), 1);
    testing::AddBox(&plc, in(2), in(6), 2);
    testing::AddBox(&plc, in(3), in(5), 3);
    plc.regions = {{map.ToInput({1.5, 1.5, 1.5}), 10, 0}, {map.ToInput({2.5, 2.6, 2.7}), 20, 0.25}};
    plc.holes = {map.ToInput({4.1, 4.2, 4.3})};
    faces = testing::FacesOnConvexFacets(grid.positions, grid.tets, testing::ConvexFacetsOf(plc, map));
    input_vertex = testing::GridVertexOf(plc, grid, map);
  }
  absl::StatusOr<OutputStageResult> Run(bool keep = false) const {
    return BuildOutputMesh(plc, grid.positions, grid.tets, input_vertex, faces, map, keep);
  }
};

TEST(AssembleTest, NestedBoxesRegionsMarkersOrientation) {
  NestedCase nc;
  mesh::MeshStats stats;
  stats.Set("svrc.vertices", 729);
  auto r = BuildOutputMesh(nc.plc, nc.grid.positions, nc.grid.tets, nc.input_vertex, nc.faces, nc.map,
                           false, &stats);
  ASSERT_TRUE(r.ok()) << r.status();
  const mesh::TetMesh& m = r->mesh;
  EXPECT_TRUE(r->issues.empty());
  // Vertices: input first, bit-exact; Steiner points = grid points used by kept tets.
  ASSERT_EQ(m.num_input_vertices, 24u);
  for (uint32_t i = 0; i < 24; ++i) EXPECT_TRUE(SameBits(m.positions[i], nc.plc.vertices[i])) << i;
  EXPECT_EQ(r->report.num_steiner_vertices, 7u * 7u * 7u - 1u - 24u);  // all of [1,7]^3 but (4,4,4)
  EXPECT_EQ(m.positions.size(), 24u + r->report.num_steiner_vertices);
  EXPECT_EQ(r->report.num_dropped_vertices, 729u - 343u + 1u);
  EXPECT_EQ(r->report.num_unused_input_vertices, 0u);
  EXPECT_EQ(r->report.num_nonpositive_tets, 0u);
  // Steiner points are in SpatialOrder.
  std::vector<Vec3> steiner(m.positions.begin() + 24, m.positions.end());
  const auto order = mesh::SpatialOrder(steiner);
  for (size_t k = 0; k < order.size(); ++k) ASSERT_EQ(order[k], k);
  EXPECT_TRUE(mesh::IsCanonical(m));
  // Regions: seed order.
  ASSERT_EQ(m.regions.size(), 2u);
  EXPECT_EQ(m.regions[0].attribute, 10);
  EXPECT_EQ(m.regions[1].attribute, 20);
  EXPECT_EQ(m.regions[1].max_volume, 0.25);
  ASSERT_EQ(m.tets.size(), (216u - 8u) * 6u);
  ASSERT_EQ(m.tet_region.size(), m.tets.size());
  const Vec3 lo2 = nc.map.ToInput({2, 2, 2}), hi2 = nc.map.ToInput({6, 6, 6});
  double vol[2] = {0, 0};
  for (size_t t = 0; t < m.tets.size(); ++t) {
    const int32_t want = Inside(testing::TetCentroid(m, t), lo2, hi2) ? 1 : 0;
    EXPECT_EQ(m.tet_region[t], want) << t;
    EXPECT_GT(geom::Orient3d(m.positions[m.tets[t][0]], m.positions[m.tets[t][1]],
                             m.positions[m.tets[t][2]], m.positions[m.tets[t][3]]), 0);
    vol[m.tet_region[t]] += testing::TetVolume(m, t);
  }
  EXPECT_NEAR(vol[0], (216.0 - 64.0) / 512.0, 1e-12);
  EXPECT_NEAR(vol[1], (64.0 - 8.0) / 512.0, 1e-12);
  // Triangles: each box's faces with its marker; normals point into the
  // kept side of the lower region: outer box inwards, middle box outwards
  // (into region 0), inner box outwards (into the kept middle shell).
  ASSERT_EQ(m.triangles.size(), 6u * (36u + 16u + 4u) * 2u);
  const Vec3 centre = nc.map.ToInput({4, 4, 4});
  int count[4] = {0, 0, 0, 0};
  for (size_t i = 0; i < m.triangles.size(); ++i) {
    const auto& t = m.triangles[i];
    const int32_t mk = m.triangle_marker[i];
    ASSERT_GE(mk, 1);
    ASSERT_LE(mk, 3);
    ++count[mk];
    const int s = geom::Orient3d(m.positions[t[0]], m.positions[t[1]], m.positions[t[2]], centre);
    EXPECT_EQ(s, mk == 1 ? 1 : -1) << "triangle " << i << " marker " << mk;
  }
  EXPECT_EQ(count[1], 6 * 36 * 2);
  EXPECT_EQ(count[2], 6 * 16 * 2);
  EXPECT_EQ(count[3], 6 * 4 * 2);
  // Stats: passed through, then output counters.
  EXPECT_EQ(m.stats.counters[0].first, "svrc.vertices");
  EXPECT_EQ(m.stats.Get("output.tets"), m.tets.size());
  // The conformity checker: nested shells with a hole seed.
  const mesh::ConformityReport rep = mesh::CheckConformity(nc.plc, m);
  EXPECT_TRUE(rep.ok()) << rep.Summary();
  EXPECT_TRUE(rep.enclosed_volume_known);
  EXPECT_NEAR(rep.mesh_volume, 208.0 / 512.0, 1e-12);
}

TEST(AssembleTest, KeepBoundingBox) {
  NestedCase nc;
  auto r = nc.Run(/*keep=*/true);
  ASSERT_TRUE(r.ok()) << r.status();
  const mesh::TetMesh& m = r->mesh;
  EXPECT_EQ(m.tets.size(), nc.grid.tets.size());
  EXPECT_EQ(m.positions.size(), 729u);
  // Seeded shells first (seed order), then the unseeded exterior and hole.
  ASSERT_EQ(m.regions.size(), 4u);
  EXPECT_EQ(m.regions[0].attribute, 10);
  EXPECT_EQ(m.regions[1].attribute, 20);
  EXPECT_EQ(m.regions[2].attribute, 0);
  EXPECT_EQ(m.regions[3].attribute, 0);
  EXPECT_NEAR(MeshVolume(m), 1.0, 1e-12);
  mesh::ConformityOptions opt;
  opt.keep_bounding_box = true;
  const mesh::ConformityReport rep = mesh::CheckConformity(nc.plc, m, opt);
  EXPECT_TRUE(rep.ok()) << rep.Summary();
}

// The output does not depend on the order of the tet list, on the rotation of
// each tet's vertices, nor on the mesher's numbering of its vertices.
TEST(AssembleTest, DeterministicUnderPermutations) {
  NestedCase nc;
  auto a = nc.Run();
  auto b = nc.Run();
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_TRUE(testing::SameMesh(a->mesh, b->mesh));

  std::mt19937 rng(12345);
  const size_t nv = nc.grid.positions.size();
  std::vector<uint32_t> relabel(nv);  // old -> new
  std::iota(relabel.begin(), relabel.end(), 0u);
  std::shuffle(relabel.begin(), relabel.end(), rng);
  std::vector<Vec3> pos(nv);
  for (size_t v = 0; v < nv; ++v) pos[relabel[v]] = nc.grid.positions[v];
  std::vector<std::array<uint32_t, 4>> tets;
  for (const auto& t : nc.grid.tets) {
    std::array<uint32_t, 4> u{relabel[t[0]], relabel[t[1]], relabel[t[2]], relabel[t[3]]};
    // An even permutation keeps the orientation.
    const int rot = static_cast<int>(rng() % 3);
    for (int k = 0; k < rot; ++k) u = {u[0], u[2], u[3], u[1]};
    if (rng() % 2) u = {u[1], u[0], u[3], u[2]};
    tets.push_back(u);
  }
  std::shuffle(tets.begin(), tets.end(), rng);
  std::vector<uint32_t> iv;
  for (uint32_t v : nc.input_vertex) iv.push_back(relabel[v]);
  std::vector<ConstrainedFace> faces = nc.faces;
  for (auto& f : faces) f.v = {relabel[f.v[2]], relabel[f.v[0]], relabel[f.v[1]]};
  std::shuffle(faces.begin(), faces.end(), rng);
  auto c = BuildOutputMesh(nc.plc, pos, tets, iv, faces, nc.map, false);
  ASSERT_TRUE(c.ok()) << c.status();
  EXPECT_TRUE(testing::SameMesh(a->mesh, c->mesh));
}

// An internal facet inside one region (it splits nothing): its triangles are
// kept with its marker (TetGen -p keeps such faces), oriented towards the apex
// with the smaller output vertex id.
TEST(AssembleTest, InternalFacetInsideOneRegion) {
  const Grid g = testing::KuhnGrid(6);
  plc::Plc plc;
  testing::AddBox(&plc, {1, 1, 1}, {5, 5, 5}, 1);
  const uint32_t b = static_cast<uint32_t>(plc.vertices.size());
  plc.vertices.insert(plc.vertices.end(), {{3, 2, 2}, {3, 4, 2}, {3, 4, 4}, {3, 2, 4}});
  plc::Facet f;
  f.polygons.push_back({{b, b + 1, b + 2, b + 3}});
  f.marker = 9;
  plc.facets.push_back(f);
  plc.regions = {{{1.5, 1.7, 1.9}, 3, 0}};
  const CoordinateMap id;
  const auto faces = testing::FacesOnConvexFacets(g.positions, g.tets, testing::ConvexFacetsOf(plc, id));
  auto r = BuildOutputMesh(plc, g.positions, g.tets, testing::GridVertexOf(plc, g, id), faces, id, false);
  ASSERT_TRUE(r.ok()) << r.status();
  const mesh::TetMesh& m = r->mesh;
  ASSERT_EQ(m.regions.size(), 1u);
  EXPECT_EQ(m.regions[0].attribute, 3);
  EXPECT_NEAR(MeshVolume(m), 64.0, 1e-12);
  ASSERT_EQ(m.triangles.size(), 6u * 16u * 2u + 8u);
  int internal = 0;
  for (size_t i = 0; i < m.triangles.size(); ++i) {
    if (m.triangle_marker[i] != 9) continue;
    ++internal;
    const auto& t = m.triangles[i];
    // The two apexes: the tets containing the triangle.
    std::vector<uint32_t> apex;
    for (const auto& tet : m.tets) {
      int shared = 0;
      uint32_t other = 0;
      for (uint32_t v : tet) {
        if (v == t[0] || v == t[1] || v == t[2]) {
          ++shared;
        } else {
          other = v;
        }
      }
      if (shared == 3) apex.push_back(other);
    }
    ASSERT_EQ(apex.size(), 2u);
    const uint32_t lower = std::min(apex[0], apex[1]);
    EXPECT_GT(geom::Orient3d(m.positions[t[0]], m.positions[t[1]], m.positions[t[2]], m.positions[lower]), 0);
  }
  EXPECT_EQ(internal, 8);
  const mesh::ConformityReport rep = mesh::CheckConformity(plc, m);
  EXPECT_TRUE(rep.ok()) << rep.Summary();
}

TEST(AssembleTest, DuplicateInputVertexKeepsItsSlot) {
  const Grid g = testing::KuhnGrid(4);
  plc::Plc plc;
  testing::AddBox(&plc, {1, 1, 1}, {3, 3, 3}, 1);
  plc.vertices.push_back(plc.vertices[0]);  // vertex 8 duplicates vertex 0
  const CoordinateMap id;
  const auto faces = testing::FacesOnConvexFacets(g.positions, g.tets, testing::ConvexFacetsOf(plc, id));
  const auto iv = testing::GridVertexOf(plc, g, id);
  ASSERT_EQ(iv[8], iv[0]);
  auto r = BuildOutputMesh(plc, g.positions, g.tets, iv, faces, id, false);
  ASSERT_TRUE(r.ok()) << r.status();
  const mesh::TetMesh& m = r->mesh;
  EXPECT_EQ(m.num_input_vertices, 9u);
  EXPECT_TRUE(SameBits(m.positions[8], plc.vertices[8]));
  EXPECT_EQ(r->report.num_unused_input_vertices, 1u);
  bool uses0 = false;
  for (const auto& t : m.tets) {
    for (uint32_t v : t) {
      EXPECT_NE(v, 8u);
      uses0 |= v == 0;
    }
  }
  EXPECT_TRUE(uses0);
}

TEST(AssembleTest, Errors) {
  NestedCase nc;
  // An input vertex mapped to the wrong mesher vertex.
  std::vector<uint32_t> iv = nc.input_vertex;
  std::swap(iv[0], iv[1]);
  auto r = BuildOutputMesh(nc.plc, nc.grid.positions, nc.grid.tets, iv, nc.faces, nc.map, false);
  EXPECT_EQ(r.status().code(), absl::StatusCode::kInternal);
  iv.pop_back();
  r = BuildOutputMesh(nc.plc, nc.grid.positions, nc.grid.tets, iv, nc.faces, nc.map, false);
  EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
  AssembleInput ai;
  EXPECT_EQ(AssembleMesh(ai).status().code(), absl::StatusCode::kInvalidArgument);
}

// Convex corpus PLCs whose vertices' Delaunay tetrahedralization already
// conforms: the assembled mesh passes the conformity checker.
struct CorpusRun {
  plc::Plc plc;
  OutputStageResult out;
};

CorpusRun RunCorpus(const std::string& rel) {
  CorpusRun run;
  auto plc = plc::ReadPlcFile(svrc::testing::CorpusPath(rel));
  EXPECT_TRUE(plc.ok()) << plc.status();
  if (!plc.ok()) return run;
  run.plc = *plc;
  auto del = delaunay::TetrahedralizePointSet(run.plc.vertices);
  EXPECT_TRUE(del.ok()) << del.status();
  if (!del.ok()) return run;
  const CoordinateMap id;
  const auto faces = testing::FacesOnConvexFacets(run.plc.vertices, del->tets,
                                                  testing::ConvexFacetsOf(run.plc, id));
  auto r = BuildOutputMesh(run.plc, run.plc.vertices, del->tets, del->representative, faces, id, false);
  EXPECT_TRUE(r.ok()) << r.status();
  if (r.ok()) run.out = std::move(*r);
  return run;
}

TEST(AssembleCorpusTest, ConvexInputsConform) {
  for (const char* rel : {"a_convex/cube.poly", "a_convex/tetra.poly", "b_internal/box_internal_facet.poly"}) {
    SCOPED_TRACE(rel);
    CorpusRun run = RunCorpus(rel);
    const mesh::TetMesh& m = run.out.mesh;
    ASSERT_FALSE(m.tets.empty());
    EXPECT_TRUE(run.out.issues.empty());
    EXPECT_EQ(m.positions.size(), run.plc.vertices.size());  // no Steiner points
    for (size_t i = 0; i < run.plc.vertices.size(); ++i) EXPECT_TRUE(SameBits(m.positions[i], run.plc.vertices[i]));
    const mesh::ConformityReport rep = mesh::CheckConformity(run.plc, m);
    EXPECT_TRUE(rep.ok()) << rep.Summary();
    EXPECT_TRUE(rep.enclosed_volume_known || std::string(rel).find("internal") != std::string::npos);
  }
}

// The refiner's layout: input vertices, then the 8 corners of a bounding cube
// Ω (side 3× the input's, as docs/svrc-design.md §3), Delaunay of all of them.
// The exterior touches ∂Ω and is dropped with Ω's corners; the rest conforms.
TEST(AssembleCorpusTest, ConvexInputInBoundingCube) {
  for (const char* rel : {"a_convex/cube.poly", "b_internal/box_internal_facet.poly"}) {
    SCOPED_TRACE(rel);
    auto plc = plc::ReadPlcFile(svrc::testing::CorpusPath(rel));
    ASSERT_TRUE(plc.ok()) << plc.status();
    std::vector<Vec3> pts = plc->vertices;
    for (int c = 0; c < 8; ++c) pts.push_back({(c & 1) ? 2.0 : -1.0, (c & 2) ? 2.0 : -1.0, (c & 4) ? 2.0 : -1.0});
    auto del = delaunay::TetrahedralizePointSet(pts);
    ASSERT_TRUE(del.ok()) << del.status();
    const CoordinateMap id;
    const auto faces = testing::FacesOnConvexFacets(pts, del->tets, testing::ConvexFacetsOf(*plc, id));
    std::vector<uint32_t> iv(del->representative.begin(), del->representative.begin() + plc->vertices.size());
    auto r = BuildOutputMesh(*plc, pts, del->tets, iv, faces, id, false);
    ASSERT_TRUE(r.ok()) << r.status();
    EXPECT_TRUE(r->issues.empty());
    EXPECT_EQ(r->report.num_dropped_vertices, 8u);
    EXPECT_EQ(r->mesh.positions.size(), plc->vertices.size());
    EXPECT_GT(r->report.num_dropped_tets, 0u);
    const mesh::ConformityReport rep = mesh::CheckConformity(*plc, r->mesh);
    EXPECT_TRUE(rep.ok()) << rep.Summary();
    EXPECT_NEAR(MeshVolume(r->mesh), 1.0, 1e-12);
    // With keep_bounding_box: the whole Ω, volume 27, one unseeded region more.
    auto k = BuildOutputMesh(*plc, pts, del->tets, iv, faces, id, true);
    ASSERT_TRUE(k.ok()) << k.status();
    EXPECT_EQ(k->mesh.tets.size(), del->tets.size());
    EXPECT_EQ(k->mesh.regions.size(), r->mesh.regions.size() + 1);
    EXPECT_EQ(k->mesh.regions.back().attribute, 0);
    EXPECT_NEAR(MeshVolume(k->mesh), 27.0, 1e-12);
    mesh::ConformityOptions opt;
    opt.keep_bounding_box = true;
    const mesh::ConformityReport krep = mesh::CheckConformity(*plc, k->mesh, opt);
    EXPECT_TRUE(krep.ok()) << krep.Summary();
  }
}

// box_internal_facet.poly: the unit cube split at z = 0.5 (marker 7), regions
// 1 (below) and 2 (above). TetGen -pA writes 12 tets and 22 faces, the 2
// internal ones with marker 7 and normals pointing down (into region 1).
TEST(AssembleCorpusTest, BoxInternalFacetMatchesTetgen) {
  CorpusRun run = RunCorpus("b_internal/box_internal_facet.poly");
  const mesh::TetMesh& m = run.out.mesh;
  ASSERT_EQ(m.tets.size(), 12u);
  ASSERT_EQ(m.regions.size(), 2u);
  EXPECT_EQ(m.regions[0].attribute, 1);
  EXPECT_EQ(m.regions[1].attribute, 2);
  double vol[2] = {0, 0};
  for (size_t t = 0; t < m.tets.size(); ++t) {
    EXPECT_EQ(m.tet_region[t], testing::TetCentroid(m, t).z < 0.5 ? 0 : 1);
    vol[m.tet_region[t]] += testing::TetVolume(m, t);
  }
  EXPECT_DOUBLE_EQ(vol[0], 0.5);
  EXPECT_DOUBLE_EQ(vol[1], 0.5);
  ASSERT_EQ(m.triangles.size(), 22u);
  int internal = 0;
  const Vec3 inside{0.5, 0.5, 0.5};
  for (size_t i = 0; i < m.triangles.size(); ++i) {
    const auto& t = m.triangles[i];
    const Vec3 &a = m.positions[t[0]], &b = m.positions[t[1]], &c = m.positions[t[2]];
    if (m.triangle_marker[i] == 7) {
      ++internal;
      EXPECT_EQ(geom::Orient3d(a, b, c, {0.5, 0.5, 0.25}), 1);
    } else {
      // Boundary faces: normals into the mesh (TetGen's .face convention too).
      EXPECT_EQ(geom::Orient3d(a, b, c, inside), 1);
      const bool top = a.z == 1 && b.z == 1 && c.z == 1, bottom = a.z == 0 && b.z == 0 && c.z == 0;
      EXPECT_EQ(m.triangle_marker[i], top ? 2 : (bottom ? 1 : 3));
    }
  }
  EXPECT_EQ(internal, 2);
}

}  // namespace
}  // namespace svrc::refine
