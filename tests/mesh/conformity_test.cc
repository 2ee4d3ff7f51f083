#include "core/mesh/conformity.h"

#include <algorithm>
#include <chrono>

#include "core/geometry/predicates.h"
#include "gtest/gtest.h"
#include "tests/mesh/mesh_test_util.h"

namespace svrc::mesh {
namespace {

using testing::BoxPlc;
using testing::KuhnBoxMesh;
using testing::TotalVolume;

const Vec3 kLo(0, 0, 0), kHi(1, 1, 1);

void FixOrientation(TetMesh* m) {
  for (auto& t : m->tets) {
    const Vec3 a = m->positions[t[0]];
    const double det = geom::Dot(m->positions[t[1]] - a,
                                 geom::Cross(m->positions[t[2]] - a, m->positions[t[3]] - a));
    if (det < 0) std::swap(t[2], t[3]);
  }
  m->tet_region.assign(m->tets.size(), 0);
  m->regions.resize(1);
}

TEST(Conformity, AcceptsKuhnBoxes) {
  for (int n : {1, 2, 3}) {
    const plc::Plc p = BoxPlc(kLo, kHi);
    const TetMesh m = KuhnBoxMesh(p, n);
    const ConformityReport r = CheckConformity(p, m);
    EXPECT_TRUE(r.ok()) << "n=" << n << "\n" << r.Summary();
    EXPECT_TRUE(r.enclosed_volume_known);
    EXPECT_NEAR(r.enclosed_volume, 1.0, 1e-12);
    EXPECT_NEAR(r.mesh_volume, 1.0, 1e-12);
    EXPECT_EQ(r.num_facets_checked, 6u);
    EXPECT_EQ(r.num_segments_checked, 12u);
  }
}

TEST(Conformity, AcceptsInternalFacetAndFarOffset) {
  const plc::Plc split = BoxPlc(kLo, kHi, /*split=*/true);
  const ConformityReport r = CheckConformity(split, KuhnBoxMesh(split, 2));
  EXPECT_TRUE(r.ok()) << r.Summary();
  // BoxPlc's internal facet ends inside the box's side facets, whose inner
  // sides split into two pieces each (docs/conformity.md "Pieces").
  EXPECT_TRUE(r.cells_known) << r.cells_unknown_reason;
  EXPECT_EQ(r.num_cells, 2u);
  EXPECT_NEAR(r.enclosed_volume, 1.0, 1e-12);
  const plc::Plc far = BoxPlc(Vec3(1e6, 1e6, 1e6), Vec3(1e6 + 1000, 1e6 + 1000, 1e6 + 1000));
  const ConformityReport r2 = CheckConformity(far, KuhnBoxMesh(far, 4));
  EXPECT_TRUE(r2.ok()) << r2.Summary();
  EXPECT_NEAR(r2.enclosed_volume, 1e9, 1e-3);
}

TEST(Conformity, KeepBoundingBox) {
  // Only the internal facet is an input facet; the mesh fills the box.
  plc::Plc p = BoxPlc(kLo, kHi, /*split=*/true);
  TetMesh m = KuhnBoxMesh(p, 2);
  p.facets.erase(p.facets.begin(), p.facets.begin() + 6);
  std::vector<std::array<uint32_t, 3>> tris;
  std::vector<int32_t> markers;
  for (size_t i = 0; i < m.triangles.size(); ++i) {
    if (m.triangle_marker[i] == 7) {
      tris.push_back(m.triangles[i]);
      markers.push_back(7);
    }
  }
  m.triangles = tris;
  m.triangle_marker = markers;
  ConformityOptions opt;
  opt.keep_bounding_box = true;
  const ConformityReport r = CheckConformity(p, m, opt);
  EXPECT_TRUE(r.ok()) << r.Summary();
  EXPECT_TRUE(r.enclosed_volume_known);
  EXPECT_NEAR(r.enclosed_volume, 1.0, 1e-15);
  // Without the flag the box faces are open faces.
  const ConformityReport r2 = CheckConformity(p, m);
  EXPECT_GT(r2.Count(ViolationKind::kOpenFace), 0u);
  // ... and a lone facet encloses nothing: every tet is in the unbounded cell.
  EXPECT_TRUE(r2.cells_known) << r2.cells_unknown_reason;
  EXPECT_EQ(r2.num_cells, 0u);
  EXPECT_EQ(r2.Count(ViolationKind::kVolumeMismatch), 1u) << r2.Summary();
  EXPECT_EQ(r2.Count(ConformityCategory::kCoverage),
            r2.Count(ViolationKind::kOpenFace) + r2.Count(ViolationKind::kVolumeMismatch));
}

// The corner tetrahedron o,a,b,c with Steiner points that doubles cannot put
// exactly on the slanted facet and the slanted edge ab.
struct SlantedCase {
  plc::Plc plc;
  TetMesh mesh;
};
SlantedCase Slanted() {
  SlantedCase c;
  c.plc.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  auto tri = [&](uint32_t a, uint32_t b, uint32_t d, int32_t marker) {
    plc::Facet f;
    f.polygons.push_back({{a, b, d}});
    f.marker = marker;
    c.plc.facets.push_back(f);
  };
  tri(0, 1, 2, 1);  // z = 0
  tri(0, 2, 3, 2);  // x = 0
  tri(0, 3, 1, 3);  // y = 0
  tri(1, 2, 3, 4);  // x + y + z = 1
  TetMesh& m = c.mesh;
  m.positions = c.plc.vertices;
  m.num_input_vertices = 4;
  m.positions.push_back(Vec3(2.0 / 3, 1.0 / 3, 0));          // 4: m on ab
  m.positions.push_back(Vec3(1.0 / 3, 1.0 / 3, 1.0 / 3));    // 5: s on abc
  m.tets = {{0, 1, 4, 5}, {0, 4, 2, 5}, {0, 2, 3, 5}, {0, 3, 1, 5}};
  FixOrientation(&m);
  m.triangles = {{0, 1, 4}, {0, 4, 2}, {0, 2, 3}, {0, 3, 1},
                 {1, 4, 5}, {4, 2, 5}, {2, 3, 5}, {3, 1, 5}};
  m.triangle_marker = {1, 1, 2, 3, 4, 4, 4, 4};
  return c;
}

TEST(Conformity, SlantedSteinerPointsNeedTheTolerance) {
  const SlantedCase c = Slanted();
  // s is not exactly on the plane x+y+z=1 and m not exactly on the line ab.
  EXPECT_NE(geom::Orient3d(c.plc.vertices[1], c.plc.vertices[2], c.plc.vertices[3],
                           c.mesh.positions[5]),
            0);
  const ConformityReport r = CheckConformity(c.plc, c.mesh);
  EXPECT_TRUE(r.ok()) << r.Summary();
  EXPECT_NEAR(r.enclosed_volume, 1.0 / 6, 1e-15);
  ConformityOptions exact;
  exact.tolerance_ulps = 0;
  const ConformityReport r0 = CheckConformity(c.plc, c.mesh, exact);
  EXPECT_GT(r0.Count(ConformityCategory::kConformity), 0u) << r0.Summary();
}

TEST(Conformity, RejectsFlippedTet) {
  const plc::Plc p = BoxPlc(kLo, kHi);
  TetMesh m = KuhnBoxMesh(p, 2);
  std::swap(m.tets[5][2], m.tets[5][3]);
  const ConformityReport r = CheckConformity(p, m);
  EXPECT_EQ(r.Count(ViolationKind::kFlippedTet), 1u) << r.Summary();
  EXPECT_GE(r.Count(ConformityCategory::kValidity), 1u);
  ASSERT_FALSE(r.violations.empty());
  const auto it = std::find_if(r.violations.begin(), r.violations.end(), [](const Violation& v) {
    return v.kind == ViolationKind::kFlippedTet;
  });
  ASSERT_NE(it, r.violations.end());
  EXPECT_EQ(it->ids, (std::vector<int64_t>{5}));
}

// Index of the first Kuhn tet of cell (i, j, k) of KuhnBoxMesh(p, n).
size_t CellTet(int n, int i, int j, int k) { return static_cast<size_t>(((k * n + j) * n + i) * 6); }

TEST(Conformity, RejectsDeletedTet) {
  const plc::Plc p = BoxPlc(kLo, kHi);
  TetMesh m = KuhnBoxMesh(p, 3);
  // A tet of the centre cell: all its faces are interior faces.
  m.tets.erase(m.tets.begin() + CellTet(3, 1, 1, 1) + 2);
  m.tet_region.pop_back();
  const ConformityReport r = CheckConformity(p, m);
  EXPECT_EQ(r.Count(ConformityCategory::kValidity), 0u) << r.Summary();
  EXPECT_EQ(r.Count(ViolationKind::kOpenFace), 4u) << r.Summary();
  EXPECT_EQ(r.Count(ViolationKind::kVolumeMismatch), 1u) << r.Summary();
  EXPECT_EQ(r.Count(ConformityCategory::kConformity), 0u) << r.Summary();
}

TEST(Conformity, RejectsDeletedOnlyTet) {
  // The corner tetrahedron as one tet: all faces lie on facets, so only the
  // volume (and the triangles that lost their tet) show the loss.
  SlantedCase c = Slanted();
  plc::Plc& p = c.plc;
  TetMesh m;
  m.positions = p.vertices;
  m.tets = {{0, 1, 2, 3}};
  FixOrientation(&m);
  m.triangles = {{0, 1, 2}, {0, 2, 3}, {0, 3, 1}, {1, 2, 3}};
  m.triangle_marker = {1, 2, 3, 4};
  ASSERT_TRUE(CheckConformity(p, m).ok()) << CheckConformity(p, m).Summary();
  m.tets.clear();
  m.tet_region.clear();
  const ConformityReport r = CheckConformity(p, m);
  EXPECT_EQ(r.Count(ViolationKind::kVolumeMismatch), 1u) << r.Summary();
}

// Validation accepts a facet planar to 1e-8 of its diameter (docs/plc.md); the
// checker took such a facet as not planar beyond 8 ulps, and refused the
// mesher's output for a unit cube with a corner 9e-9 above its top face
// (session 39). A facet's points now count as on it within 4x its flatness;
// a Steiner point off it by more, or a facet bent beyond what validation
// accepts, is still refused.
TEST(Conformity, FacetPlanarToTheValidationToleranceUsesItsFlatness) {
  const double bend = 9e-9;
  plc::Plc p = BoxPlc(kLo, kHi);
  TetMesh m = KuhnBoxMesh(p, 2);
  auto corner = std::find(p.vertices.begin(), p.vertices.end(), Vec3(1, 1, 1));
  ASSERT_NE(corner, p.vertices.end());
  auto mcorner = std::find(m.positions.begin(), m.positions.end(), Vec3(1, 1, 1));
  ASSERT_NE(mcorner, m.positions.end());
  auto centre = std::find(m.positions.begin(), m.positions.end(), Vec3(0.5, 0.5, 1));
  ASSERT_NE(centre, m.positions.end());
  corner->z += bend;
  mcorner->z += bend;
  // The midpoints of the two top edges at that corner follow their edges.
  for (const Vec3& mid : {Vec3(1, 0.5, 1), Vec3(0.5, 1, 1)}) {
    auto it = std::find(m.positions.begin(), m.positions.end(), mid);
    ASSERT_NE(it, m.positions.end());
    it->z += bend / 2;
  }
  const ConformityReport ok = CheckConformity(p, m);
  EXPECT_TRUE(ok.ok()) << ok.Summary();
  // The top face's centre 1e-7 off its plane: beyond 4 x 9e-9.
  TetMesh off = m;
  off.positions[centre - m.positions.begin()].z -= 1e-7;
  const ConformityReport r = CheckConformity(p, off);
  EXPECT_GT(r.Count(ViolationKind::kTriangleOffFacet), 0u) << r.Summary();
  // A corner 1e-6 off: the facet is not planar (validation refuses it too).
  plc::Plc bent = p;
  TetMesh mbent = m;
  bent.vertices[corner - p.vertices.begin()].z += 1e-6;
  mbent.positions[mcorner - m.positions.begin()].z += 1e-6;
  EXPECT_FALSE(CheckConformity(bent, mbent).ok());
}

TEST(Conformity, RejectsVertexMovedOffItsFacet) {
  const plc::Plc p = BoxPlc(kLo, kHi);
  for (double delta : {1e-3, 1e-12}) {
    TetMesh m = KuhnBoxMesh(p, 2);
    // The Steiner point in the middle of the top facet.
    auto it = std::find(m.positions.begin(), m.positions.end(), Vec3(0.5, 0.5, 1));
    ASSERT_NE(it, m.positions.end());
    it->z -= delta;
    const ConformityReport r = CheckConformity(p, m);
    EXPECT_EQ(r.Count(ConformityCategory::kValidity), 0u) << r.Summary();
    EXPECT_GT(r.Count(ViolationKind::kTriangleOffFacet), 0u) << delta << "\n" << r.Summary();
    EXPECT_EQ(r.Count(ViolationKind::kFacetNotCovered), 1u) << delta << "\n" << r.Summary();
  }
}

TEST(Conformity, RejectsBrokenSegmentChain) {
  // A cube with a free segment along the main diagonal 0-7: the Kuhn meshes
  // contain it (through the centre for n = 2); the 5-tet cube does not.
  plc::Plc p = BoxPlc(kLo, kHi);
  p.segments.push_back({0, 7, 9});
  for (int n : {1, 2}) {
    const ConformityReport r = CheckConformity(p, KuhnBoxMesh(p, n));
    EXPECT_TRUE(r.ok()) << n << "\n" << r.Summary();
    EXPECT_EQ(r.num_segments_checked, 13u);
  }
  TetMesh five;
  five.positions = p.vertices;
  five.num_input_vertices = 8;
  five.tets = {{1, 2, 4, 7}, {0, 1, 2, 4}, {3, 1, 2, 7}, {5, 1, 4, 7}, {6, 2, 4, 7}};
  FixOrientation(&five);
  // Boundary triangles of the 5-tet cube: each face split along the other diagonal.
  testing::AssignBoxTriangles(p, &five);
  ASSERT_EQ(five.triangles.size(), 12u);
  const ConformityReport r = CheckConformity(p, five);
  EXPECT_EQ(r.Count(ViolationKind::kBrokenSegment), 1u) << r.Summary();
  EXPECT_EQ(r.Count(ConformityCategory::kConformity), 1u) << r.Summary();
  EXPECT_EQ(r.Count(ConformityCategory::kValidity) + r.Count(ConformityCategory::kCoverage), 0u)
      << r.Summary();
  ASSERT_EQ(r.violations.size(), 1u);
  EXPECT_EQ(r.violations[0].ids[0], 0);  // free segments come first
}

// The unit box whose corner (1,1,1) is given twice: vertex 8 is an exact
// copy of vertex 7. Facet x = 1 and a free segment use the copy. The PLC
// readers/validator merge 8 into 7; the mesh keeps both positions at their
// input ids and its tets use only 7 (docs/conformity.md "Duplicate input
// vertices").
plc::Plc BoxWithDuplicateCorner() {
  plc::Plc p = BoxPlc(kLo, kHi);
  p.vertices.push_back(p.vertices[7]);
  p.facets[1].polygons[0].vertices = {1, 3, 8, 5};  // x = 1
  p.segments.push_back({0, 8, 9});                  // the main diagonal, through the copy
  return p;
}

TEST(Conformity, DuplicateInputVertexMapsToItsFirstOccurrence) {
  const plc::Plc p = BoxWithDuplicateCorner();
  const TetMesh m = KuhnBoxMesh(p, 2);
  ASSERT_EQ(m.positions[8], m.positions[7]);
  for (const auto& t : m.tets) ASSERT_EQ(std::count(t.begin(), t.end(), 8u), 0);
  const ConformityReport r = CheckConformity(p, m);
  EXPECT_TRUE(r.ok()) << r.Summary();
  EXPECT_TRUE(r.cells_known) << r.cells_unknown_reason;
  EXPECT_EQ(r.num_cells, 1u);
  EXPECT_NEAR(r.enclosed_volume, 1.0, 1e-12);
  // (0,8) = (0,7); facet x = 1's edges (3,8), (8,5) = (3,7), (7,5).
  EXPECT_EQ(r.num_segments_checked, 13u);
  ConformityOptions by_coordinates;
  by_coordinates.input_vertices_first = false;
  const ConformityReport rc = CheckConformity(p, m, by_coordinates);
  EXPECT_TRUE(rc.ok()) << rc.Summary();

  // The segment through the copy is still required: the 5-tet cube has no
  // edge 0-7.
  TetMesh five;
  five.positions = p.vertices;
  five.num_input_vertices = 9;
  five.tets = {{1, 2, 4, 7}, {0, 1, 2, 4}, {3, 1, 2, 7}, {5, 1, 4, 7}, {6, 2, 4, 7}};
  FixOrientation(&five);
  testing::AssignBoxTriangles(p, &five);
  const ConformityReport r5 = CheckConformity(p, five);
  EXPECT_EQ(r5.Count(ViolationKind::kBrokenSegment), 1u) << r5.Summary();
  EXPECT_EQ(r5.Count(ConformityCategory::kConformity), 1u) << r5.Summary();
  EXPECT_EQ(r5.Count(ConformityCategory::kValidity) + r5.Count(ConformityCategory::kCoverage), 0u)
      << r5.Summary();
}

TEST(Conformity, ConformitySegmentsMergeDuplicates) {
  const plc::Plc p = BoxWithDuplicateCorner();
  const auto segs = ConformitySegments(p);
  ASSERT_EQ(segs.size(), 13u);
  EXPECT_EQ(segs[0], (std::array<uint32_t, 2>{0, 7}));  // the free segment, mapped
  for (const auto& s : segs) {
    EXPECT_NE(s[0], 8u);
    EXPECT_NE(s[1], 8u);
  }
}

TEST(Conformity, RejectsOverlappingTetsWithUnchangedVolume) {
  const plc::Plc p = BoxPlc(kLo, kHi);
  TetMesh m = KuhnBoxMesh(p, 3);
  const double before = TotalVolume(m);
  // In the centre cell, replace a Kuhn tet (volume 1/6 of the cell) by the
  // cell's corner tet at its low corner (also 1/6), which overlaps the
  // cell's remaining Kuhn tets.
  const size_t t = CellTet(3, 1, 1, 1);
  const uint32_t o = m.tets[t][0];  // every Kuhn tet of the cell starts at its low corner
  auto vertex_at = [&](Vec3 q) {
    return static_cast<uint32_t>(std::find(m.positions.begin(), m.positions.end(), q) -
                                 m.positions.begin());
  };
  const Vec3 c = m.positions[o];
  const double h = 1.0 / 3;
  m.tets[t + 1] = {o, vertex_at(Vec3(c.x + h, c.y, c.z)), vertex_at(Vec3(c.x, c.y + h, c.z)),
                   vertex_at(Vec3(c.x, c.y, c.z + h))};
  FixOrientation(&m);
  EXPECT_NEAR(TotalVolume(m), before, 1e-15);
  const ConformityReport r = CheckConformity(p, m);
  EXPECT_EQ(r.Count(ViolationKind::kVolumeMismatch), 0u) << r.Summary();
  EXPECT_EQ(r.Count(ConformityCategory::kConformity), 0u) << r.Summary();
  EXPECT_GT(r.Count(ViolationKind::kOpenFace), 0u) << r.Summary();
}

TEST(Conformity, RejectsDroppedFacetTriangle) {
  const plc::Plc p = BoxPlc(kLo, kHi);
  TetMesh m = KuhnBoxMesh(p, 2);
  const int32_t marker = m.triangle_marker[3];
  m.triangles.erase(m.triangles.begin() + 3);
  m.triangle_marker.erase(m.triangle_marker.begin() + 3);
  const ConformityReport r = CheckConformity(p, m);
  EXPECT_EQ(r.Count(ViolationKind::kFacetNotCovered), 1u) << r.Summary();
  EXPECT_EQ(r.violations.size(), 1u) << r.Summary();
  EXPECT_EQ(r.violations[0].ids[0], marker - 1);  // facet index = marker - 1
}

TEST(Conformity, RejectsTetsCrossingAFacetAndMissingVertices) {
  const plc::Plc split = BoxPlc(kLo, kHi, /*split=*/true);
  const plc::Plc whole = BoxPlc(kLo, kHi);
  TetMesh m = KuhnBoxMesh(whole, 1);  // knows nothing of the facet x = 0.5
  ConformityOptions opt;
  const ConformityReport r = CheckConformity(split, m, opt);
  EXPECT_GT(r.Count(ViolationKind::kTetCrossesFacet), 0u) << r.Summary();
  EXPECT_EQ(r.Count(ViolationKind::kMissingInputVertex), 4u) << r.Summary();
  EXPECT_EQ(r.Count(ViolationKind::kFacetNotCovered), 1u) << r.Summary();
  // A Kuhn mesh with n = 3 has vertices at x = 1/3, 2/3 only: also crossing.
  const ConformityReport r3 = CheckConformity(split, KuhnBoxMesh(whole, 3), opt);
  EXPECT_GT(r3.Count(ViolationKind::kTetCrossesFacet), 0u) << r3.Summary();
}

// One tet (a, b, c, d) (reoriented if needed) over the PLC's vertices, which
// it does not use: for crossing tests only.
TetMesh OneTet(const plc::Plc& p, Vec3 a, Vec3 b, Vec3 c, Vec3 d) {
  TetMesh m;
  m.positions = p.vertices;
  m.num_input_vertices = static_cast<uint32_t>(p.vertices.size());
  const uint32_t n = static_cast<uint32_t>(m.positions.size());
  m.positions.insert(m.positions.end(), {a, b, c, d});
  m.tets = {{n, n + 1, n + 2, n + 3}};
  FixOrientation(&m);
  return m;
}

plc::Plc Square(Vec3 o, double side) {
  plc::Plc p;
  p.vertices = {o, o + Vec3(side, 0, 0), o + Vec3(side, side, 0), o + Vec3(0, side, 0)};
  plc::Facet f;
  f.polygons.push_back({{0, 1, 2, 3}});
  f.marker = 1;
  p.facets.push_back(f);
  return p;
}

TEST(Conformity, TetCrossingIsExactForASmallFacetInsideABigTet) {
  // The facet's area is 1e-14 of the tet's cross-section: the float test
  // (overlap > 1e-9 x section) missed it.
  const plc::Plc p = Square(Vec3(0, 0, 0), 1e-4);
  const TetMesh m = OneTet(p, Vec3(-1000, -1000, -1000), Vec3(1000, -1000, -1000),
                           Vec3(0, 1000, -1000), Vec3(0, 0, 1000));
  const ConformityReport r = CheckConformity(p, m);
  EXPECT_EQ(r.Count(ViolationKind::kTetCrossesFacet), 1u) << r.Summary();
  // Moved off the facet (the section no longer reaches it): not crossing.
  const TetMesh far = OneTet(p, Vec3(-1000, -1000, -1000), Vec3(-1e-3, -1000, -1000),
                             Vec3(-1e-3, 1000, -1000), Vec3(-1e-3, 0, 1000));
  EXPECT_EQ(CheckConformity(p, far).Count(ViolationKind::kTetCrossesFacet), 0u);
}

TEST(Conformity, TetCrossingIsExactForTetsTouchingAFacetEdgeFarFromTheOrigin) {
  // The square [1e6, 1e6+1] x [0, 1] at z = 0. Each tet has an edge on the
  // square's edge x = 1e6+1 and its other two vertices on either side of the
  // plane; the crossing point of their edge lies at x > 1e6+1 (exact: it is
  // decided by Orient3d below), so the cross-section only touches the facet.
  // The float test reported these as crossing (found by random search).
  const double x1 = 1e6 + 1;
  const plc::Plc p = Square(Vec3(1e6, 0, 0), 1);
  struct Case {
    double y0, y1;
    Vec3 w, z;
  };
  const Case cases[] = {
      {0.12373789188038692, 0.33994527787274942,
       Vec3(1000001.005222292, 0.60081977052630275, 0.78628347109737573),
       Vec3(1000001.0034015017, 0.70379206035348096, -0.96753020972015202)},
      {0.85948142104889147, 0.33516369279978936,
       Vec3(1000001.0001890856, 0.20181101345942198, 0.37713127437915916),
       Vec3(1000000.9999880089, 0.32360006139835928, -1.0724562971835945)},
      {0.12521831815411577, 0.31512640528734193,
       Vec3(1000001.0047847524, 0.38102520355882774, 0.9954904121005469),
       Vec3(1000000.9994138217, 0.57845029928409597, -0.16258456150024861)},
  };
  // Orient3d(e0, e1, w, z) has the sign of this reference when segment wz
  // crosses z = 0 on the far side (x > x1) of the line e0 e1.
  const Vec3 e0(x1, 0, 0), e1(x1, 1, 0);
  const int outside = geom::Orient3d(e0, e1, Vec3(x1 + 1, 0.5, 1), Vec3(x1 + 1, 0.5, -1));
  for (const Case& c : cases) {
    ASSERT_EQ(geom::Orient3d(e0, e1, c.w, c.z), outside);
    const TetMesh m = OneTet(p, Vec3(x1, c.y0, 0), Vec3(x1, c.y1, 0), c.w, c.z);
    const ConformityReport r = CheckConformity(p, m);
    EXPECT_EQ(r.Count(ViolationKind::kTetCrossesFacet), 0u) << r.Summary();
    // Mirrored to the facet's side (x -> 2 x1 - x, exact here): crossing.
    auto mirror = [&](Vec3 v) { return Vec3(x1 - (v.x - x1), v.y, v.z); };
    const TetMesh mm = OneTet(p, Vec3(x1, c.y0, 0), Vec3(x1, c.y1, 0), mirror(c.w), mirror(c.z));
    EXPECT_EQ(CheckConformity(p, mm).Count(ViolationKind::kTetCrossesFacet), 1u);
  }
}

TEST(Conformity, TetCrossingKeepsTheSlantedTolerance) {
  // The slanted triangle (1,0,0), (0,1,0), (0,0,1) and a tet with an edge on
  // its boundary edge z = 0 between Steiner points that doubles cannot put on
  // that edge, its other vertices on either side of the plane x+y+z = 1 and
  // their edge crossing it beyond the boundary (z < 0): it touches the facet
  // along the edge only.
  plc::Plc p;
  p.vertices = {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  plc::Facet f;
  f.polygons.push_back({{0, 1, 2}});
  p.facets.push_back(f);
  const Vec3 u(2.0 / 3, 1.0 / 3, 0), v(1.0 / 3, 2.0 / 3, 0);
  ASSERT_NE(geom::Orient3d(p.vertices[0], p.vertices[1], p.vertices[2], u), 0);
  // x+y+z = 1.3 and 0.5; their edge meets the plane at (0.55, 0.55, -0.1).
  const TetMesh m = OneTet(p, u, v, Vec3(0.7, 0.7, -0.1), Vec3(0.3, 0.3, -0.1));
  const ConformityReport r = CheckConformity(p, m);
  EXPECT_EQ(r.Count(ViolationKind::kTetCrossesFacet), 0u) << r.Summary();
  // The same tet pushed across the edge into the facet (crossing point
  // (0.45, 0.45, 0.1)) crosses it.
  const TetMesh in = OneTet(p, u, v, Vec3(0.6, 0.6, 0.1), Vec3(0.2, 0.2, 0.1));
  EXPECT_EQ(CheckConformity(p, in).Count(ViolationKind::kTetCrossesFacet), 1u);
}

TEST(Conformity, RejectsWrongMarkerDuplicatesAndBadIds) {
  const plc::Plc p = BoxPlc(kLo, kHi);
  {
    TetMesh m = KuhnBoxMesh(p, 2);
    m.triangle_marker[0] = 42;
    const ConformityReport r = CheckConformity(p, m);
    EXPECT_EQ(r.Count(ViolationKind::kWrongMarker), 1u) << r.Summary();
    EXPECT_EQ(r.violations.size(), 1u);
  }
  {
    TetMesh m = KuhnBoxMesh(p, 2);
    m.tets.push_back({m.tets[7][1], m.tets[7][0], m.tets[7][3], m.tets[7][2]});
    m.tet_region.push_back(0);
    const ConformityReport r = CheckValidity(m);
    EXPECT_EQ(r.Count(ViolationKind::kDuplicateTet), 1u) << r.Summary();
    EXPECT_GT(r.Count(ViolationKind::kFaceInMoreThanTwoTets), 0u);
  }
  {
    TetMesh m = KuhnBoxMesh(p, 2);
    m.tets[2][1] = static_cast<uint32_t>(m.positions.size());
    m.triangles.push_back({0, 1, 99});
    m.triangle_marker.push_back(1);
    m.tet_region.pop_back();
    const ConformityReport r = CheckConformity(p, m);
    EXPECT_EQ(r.Count(ViolationKind::kIdOutOfRange), 2u) << r.Summary();
    EXPECT_EQ(r.Count(ViolationKind::kTagCountMismatch), 1u) << r.Summary();
  }
  {
    TetMesh m = KuhnBoxMesh(p, 2);
    m.triangles.push_back({0, 1, 99 % 8});
    m.triangle_marker.push_back(5);
    const ConformityReport r = CheckValidity(m);
    EXPECT_GE(r.Count(ViolationKind::kTriangleNotAFace), 1u) << r.Summary();
  }
}

// A positively oriented tet whose vertex lies within the on-plane
// tolerance of its opposite face is flat_tet. The input that showed the
// need: the star armadillo.off's stitch produced (session 34), Orient3d +1
// by rounding; its four faces all lay on one facet, which the facet count
// then covered twice over the tet, and fandisk.off's output held a tet of
// radius-edge 6.85e13 that the checker passed.
TEST(Conformity, RejectsTetsFlatWithinTheTolerance) {
  TetMesh m;
  m.positions = {Vec3(-5.6970999999999998, -0.020401800000000001, 40.214799999999997),
                 Vec3(-5.7364019911771518, -0.27833771839876031, 40.519769688800025),
                 Vec3(-5.8058945718646475, -0.53122204016648034, 40.388316931337513),
                 Vec3(-5.7935405589433611, -0.3998141619699821, 40.12632642330879)};
  m.tets = {{0, 1, 2, 3}};
  ASSERT_GT(geom::Orient3d(m.positions[0], m.positions[1], m.positions[2], m.positions[3]), 0);
  m.tet_region.assign(1, 0);
  m.regions.resize(1);
  ConformityReport r = CheckValidity(m);
  EXPECT_EQ(r.Count(ViolationKind::kFlatTet), 1u) << r.Summary();
  EXPECT_EQ(r.Count(ViolationKind::kDegenerateTet), 0u);
  ASSERT_EQ(r.violations.size(), 1u);
  EXPECT_EQ(r.violations[0].ids[0], 0);
  // Unit scale: the tolerance is 8 ulps of 1. An apex 4 ulps above the base
  // is flat; 1e-12 above it (a thin but real sliver) is not.
  m.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0.3, 0.3, 4 * 0x1p-52)};
  ASSERT_GT(geom::Orient3d(m.positions[0], m.positions[1], m.positions[2], m.positions[3]), 0);
  r = CheckValidity(m);
  EXPECT_EQ(r.Count(ViolationKind::kFlatTet), 1u) << r.Summary();
  ASSERT_EQ(r.violations.size(), 1u);
  EXPECT_EQ(r.violations[0].ids[1], 3);
  m.positions[3].z = 1e-12;
  r = CheckValidity(m);
  EXPECT_TRUE(r.ok()) << r.Summary();
  // Looser tolerance_ulps makes the sliver flat too.
  ConformityOptions loose;
  loose.tolerance_ulps = 1e5;
  EXPECT_EQ(CheckValidity(m, loose).Count(ViolationKind::kFlatTet), 1u);
}

TEST(Conformity, RejectsSameSideNeighbours) {
  // Two tets on the same side of their shared face: a positive tet and a
  // smaller positive tet inside it sharing the face.
  TetMesh m;
  m.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1),
                 Vec3(0.1, 0.1, 0.1)};
  m.tets = {{0, 1, 2, 3}, {0, 1, 2, 4}};
  FixOrientation(&m);
  const ConformityReport r = CheckValidity(m);
  EXPECT_EQ(r.Count(ViolationKind::kNeighborsSameSide), 1u) << r.Summary();
}

TEST(Conformity, CanonicalIndexRequirement) {
  const plc::Plc p = BoxPlc(kLo, kHi);
  TetMesh m = KuhnBoxMesh(p, 2);
  // Swap vertices 0 and 20 (ids in tets and triangles follow).
  std::swap(m.positions[0], m.positions[20]);
  for (auto& t : m.tets) {
    for (auto& v : t) v = v == 0 ? 20 : (v == 20 ? 0 : v);
  }
  for (auto& t : m.triangles) {
    for (auto& v : t) v = v == 0 ? 20 : (v == 20 ? 0 : v);
  }
  const ConformityReport r = CheckConformity(p, m);
  EXPECT_EQ(r.Count(ViolationKind::kInputVertexIndex), 1u) << r.Summary();
  EXPECT_EQ(r.violations.size(), 1u) << r.Summary();
  ConformityOptions by_coordinates;
  by_coordinates.input_vertices_first = false;
  EXPECT_TRUE(CheckConformity(p, m, by_coordinates).ok());
}

// The unit box with a box [0.25, 0.75]^3 inside (facet markers 11..16),
// meshed by a Kuhn grid with n = 4 (conforms to both).
struct Nested {
  plc::Plc plc;
  TetMesh mesh;
};
Nested BoxInBox(bool hole) {
  Nested c;
  c.plc = BoxPlc(kLo, kHi);
  const plc::Plc inner = BoxPlc(Vec3(0.25, 0.25, 0.25), Vec3(0.75, 0.75, 0.75));
  for (const Vec3& v : inner.vertices) c.plc.vertices.push_back(v);
  for (plc::Facet f : inner.facets) {
    for (auto& poly : f.polygons) {
      for (auto& v : poly.vertices) v += 8;
    }
    f.marker += 10;
    c.plc.facets.push_back(f);
  }
  c.mesh = KuhnBoxMesh(c.plc, 4);
  if (hole) {
    c.plc.holes.push_back(Vec3(0.5, 0.5, 0.5));
    TetMesh& m = c.mesh;
    std::vector<std::array<uint32_t, 4>> kept;
    for (const auto& t : m.tets) {
      const Vec3 g = (m.positions[t[0]] + m.positions[t[1]] + m.positions[t[2]] + m.positions[t[3]]) / 4.0;
      const bool in = g.x > 0.25 && g.x < 0.75 && g.y > 0.25 && g.y < 0.75 && g.z > 0.25 && g.z < 0.75;
      if (!in) kept.push_back(t);
    }
    m.tets = kept;
    m.tet_region.assign(kept.size(), 0);
  }
  testing::AssignAxisAlignedTriangles(c.plc, &c.mesh);
  return c;
}

TEST(Conformity, NestedShellsAndVolumeHoles) {
  const Nested solid = BoxInBox(/*hole=*/false);
  const ConformityReport r = CheckConformity(solid.plc, solid.mesh);
  EXPECT_TRUE(r.ok()) << r.Summary();
  ASSERT_TRUE(r.enclosed_volume_known);
  EXPECT_NEAR(r.enclosed_volume, 1.0, 1e-12);  // the inner box is a region, not a hole
  const Nested holed = BoxInBox(/*hole=*/true);
  const ConformityReport rh = CheckConformity(holed.plc, holed.mesh);
  EXPECT_TRUE(rh.ok()) << rh.Summary();
  ASSERT_TRUE(rh.enclosed_volume_known);
  EXPECT_NEAR(rh.enclosed_volume, 0.875, 1e-12);
  // The same hollow mesh without the hole seed: a whole region is missing,
  // and only the volume shows it (its faces all lie on facets).
  plc::Plc no_seed = holed.plc;
  no_seed.holes.clear();
  const ConformityReport rm = CheckConformity(no_seed, holed.mesh);
  EXPECT_EQ(rm.Count(ViolationKind::kVolumeMismatch), 1u) << rm.Summary();
  EXPECT_EQ(rm.violations.size(), 1u) << rm.Summary();
}

// The split box with the four side facets cut along the internal facet's
// edges (as in the corpus's box_internal_facet.poly): two cells, x < 1/2
// (region seed 0) and x > 1/2 (region seed 1).
struct SplitBox {
  plc::Plc plc;
  TetMesh mesh;
};
SplitBox ProperSplitBox(int n) {
  SplitBox b;
  b.plc = BoxPlc(kLo, kHi, /*split=*/true);
  b.mesh = KuhnBoxMesh(b.plc, n);
  auto quad = [&](std::vector<uint32_t> v, int32_t marker) {
    plc::Facet f;
    f.polygons.push_back({std::move(v)});
    f.marker = marker;
    return f;
  };
  // Corners: i + 2j + 4k; 8..11 = (½,0,0), (½,1,0), (½,1,1), (½,0,1).
  b.plc.facets = {quad({0, 2, 6, 4}, 1),   quad({1, 3, 7, 5}, 2),   quad({8, 9, 10, 11}, 7),
                  quad({0, 8, 11, 4}, 3),  quad({8, 1, 5, 11}, 3),  quad({2, 9, 10, 6}, 4),
                  quad({9, 3, 7, 10}, 4),  quad({0, 8, 9, 2}, 5),   quad({8, 1, 3, 9}, 5),
                  quad({4, 11, 10, 6}, 6), quad({11, 5, 7, 10}, 6)};
  b.plc.regions = {{Vec3(0.25, 0.5, 0.5), 1, 0}, {Vec3(0.75, 0.5, 0.5), 2, 0}};
  testing::AssignAxisAlignedTriangles(b.plc, &b.mesh);
  return b;
}

// Keeps the tets whose centroid satisfies keep(centroid).
template <typename F>
void FilterTets(TetMesh* m, F keep) {
  std::vector<std::array<uint32_t, 4>> tets;
  for (const auto& t : m->tets) {
    const Vec3 c = (m->positions[t[0]] + m->positions[t[1]] + m->positions[t[2]] +
                    m->positions[t[3]]) / 4.0;
    if (keep(c)) tets.push_back(t);
  }
  m->tets = tets;
  m->tet_region.assign(tets.size(), 0);
}

TEST(Conformity, InternalFacetCellsRegionByRegion) {
  const SplitBox b = ProperSplitBox(4);
  const ConformityReport r = CheckConformity(b.plc, b.mesh);
  EXPECT_TRUE(r.ok()) << r.Summary();
  ASSERT_TRUE(r.cells_known) << r.cells_unknown_reason;
  EXPECT_EQ(r.num_cells, 2u);
  EXPECT_NEAR(r.enclosed_volume, 1.0, 1e-12);
  EXPECT_EQ(r.num_facets_outside, 0u);

  // A whole region deleted (every tet with x < ½): its faces on the internal
  // facet become boundary faces, which lie on a facet, so only the cell's
  // coverage shows it.
  SplitBox missing = b;
  FilterTets(&missing.mesh, [](const Vec3& c) { return c.x > 0.5; });
  testing::AssignAxisAlignedTriangles(missing.plc, &missing.mesh);
  const ConformityReport rm = CheckConformity(missing.plc, missing.mesh);
  EXPECT_EQ(rm.Count(ViolationKind::kVolumeMismatch), 1u) << rm.Summary();
  EXPECT_EQ(rm.Count(ViolationKind::kOpenFace), 0u) << rm.Summary();
  // The deleted region's own facets (x = 0 and the four x < ½ halves) bound a
  // meshed cell, so they must be covered although no tet touches them (the
  // rule before cells took them for facets outside the domain).
  EXPECT_EQ(rm.Count(ViolationKind::kFacetNotCovered), 5u) << rm.Summary();
  EXPECT_EQ(rm.num_facets_outside, 0u);
  ASSERT_FALSE(rm.violations.empty());
  bool named = false;
  for (const Violation& v : rm.violations) {
    if (v.kind == ViolationKind::kVolumeMismatch) {
      named = v.message.find("region seed(s) 0") != std::string::npos &&
              v.message.find("not filled") != std::string::npos;
    }
  }
  EXPECT_TRUE(named) << rm.Summary();

  // A region meshed twice (the x > ½ tets duplicated with shifted ids into a
  // copy of their vertices): the copy is a separate component in the same cell.
  SplitBox twice = b;
  const uint32_t nv = static_cast<uint32_t>(twice.mesh.positions.size());
  twice.mesh.positions.insert(twice.mesh.positions.end(), b.mesh.positions.begin(),
                              b.mesh.positions.end());
  for (const auto& t : b.mesh.tets) {
    const Vec3 c = (b.mesh.positions[t[0]] + b.mesh.positions[t[1]] + b.mesh.positions[t[2]] +
                    b.mesh.positions[t[3]]) / 4.0;
    if (c.x > 0.5) twice.mesh.tets.push_back({t[0] + nv, t[1] + nv, t[2] + nv, t[3] + nv});
  }
  twice.mesh.tet_region.assign(twice.mesh.tets.size(), 0);
  ConformityOptions opt;
  opt.input_vertices_first = false;  // the copies of input vertices come later
  const ConformityReport rt = CheckConformity(twice.plc, twice.mesh, opt);
  EXPECT_EQ(rt.Count(ViolationKind::kVolumeMismatch), 1u) << rt.Summary();
  bool more = false;
  for (const Violation& v : rt.violations) {
    more = more || (v.kind == ViolationKind::kVolumeMismatch &&
                    v.message.find("region seed(s) 1") != std::string::npos &&
                    v.message.find("more than once") != std::string::npos);
  }
  EXPECT_TRUE(more) << rt.Summary();
}

TEST(Conformity, FacetOutsideTheDomainIsDecidedByItsCells) {
  // A square hanging outside the box (the unbounded cell on both sides) is
  // not required; the facets of a deleted region, which bound a meshed cell,
  // are (InternalFacetCellsRegionByRegion).
  SplitBox b = ProperSplitBox(2);
  const uint32_t base = static_cast<uint32_t>(b.plc.vertices.size());
  for (const Vec3& p : {Vec3(2, 0, 0), Vec3(3, 0, 0), Vec3(3, 1, 0), Vec3(2, 1, 0)}) {
    b.plc.vertices.push_back(p);
  }
  plc::Facet f;
  f.polygons.push_back({{base, base + 1, base + 2, base + 3}});
  f.marker = 9;
  b.plc.facets.push_back(f);
  b.mesh.positions.insert(b.mesh.positions.begin() + base, b.plc.vertices.begin() + base,
                          b.plc.vertices.end());
  for (auto& t : b.mesh.tets) {
    for (uint32_t& v : t) v += v >= base ? 4 : 0;
  }
  for (auto& t : b.mesh.triangles) {
    for (uint32_t& v : t) v += v >= base ? 4 : 0;
  }
  b.mesh.num_input_vertices = base + 4;
  const ConformityReport r = CheckConformity(b.plc, b.mesh);
  ASSERT_TRUE(r.cells_known) << r.cells_unknown_reason;
  EXPECT_EQ(r.num_cells, 2u);
  EXPECT_EQ(r.num_facets_outside, 1u);
  EXPECT_EQ(r.Count(ViolationKind::kFacetNotCovered), 0u) << r.Summary();
  EXPECT_EQ(r.Count(ConformityCategory::kCoverage), 0u) << r.Summary();
  // Its four edges are still segments the mesh must contain: segments are
  // not classified by cells (docs/conformity.md).
  EXPECT_EQ(r.Count(ViolationKind::kBrokenSegment), 4u) << r.Summary();
  EXPECT_EQ(r.Count(ConformityCategory::kConformity), 4u) << r.Summary();
}

// The unit box (six whole quads) split by an internal facet z = 1/2 and, in
// the upper half only, by an internal facet x = 1/2 whose bottom edge lies
// inside the z = 1/2 facet and whose other edges lie inside the y = 0, y = 1
// and z = 1 facets: every facet but x = 1/2 has a side split into pieces.
// Cells: bottom (seed 0), top left (seed 1), top right (seed 2).
plc::Plc TBoxPlc() {
  plc::Plc p = BoxPlc(kLo, kHi);
  const uint32_t b = static_cast<uint32_t>(p.vertices.size());
  for (const Vec3& v : {Vec3(0, 0, 0.5), Vec3(1, 0, 0.5), Vec3(1, 1, 0.5), Vec3(0, 1, 0.5),
                        Vec3(0.5, 0, 0.5), Vec3(0.5, 1, 0.5), Vec3(0.5, 1, 1), Vec3(0.5, 0, 1)}) {
    p.vertices.push_back(v);
  }
  auto quad = [&](std::vector<uint32_t> v, int32_t marker) {
    plc::Facet f;
    f.polygons.push_back({std::move(v)});
    f.marker = marker;
    p.facets.push_back(std::move(f));
  };
  quad({b, b + 1, b + 2, b + 3}, 7);
  quad({b + 4, b + 5, b + 6, b + 7}, 8);
  p.regions = {{Vec3(0.5, 0.5, 0.25), 1, 0}, {Vec3(0.25, 0.5, 0.75), 2, 0},
               {Vec3(0.75, 0.5, 0.75), 3, 0}};
  return p;
}

TEST(Conformity, FacetSidesSplitIntoPieces) {
  const plc::Plc p = TBoxPlc();
  TetMesh m = KuhnBoxMesh(p, 4);
  testing::AssignAxisAlignedTriangles(p, &m);
  const ConformityReport r = CheckConformity(p, m);
  EXPECT_TRUE(r.ok()) << r.Summary();
  ASSERT_TRUE(r.cells_known) << r.cells_unknown_reason;
  EXPECT_EQ(r.num_cells, 3u);
  EXPECT_NEAR(r.enclosed_volume, 1.0, 1e-12);
  EXPECT_EQ(r.num_facets_outside, 0u);
  {
    // The same with the x = 1/2 facet's bottom edge and the z = 1/2 facet's
    // edge on y = 0 declared as in-facet segments (2-vertex polygons) of the
    // facets they lie in, as the PLC validator wants them.
    plc::Plc declared = p;
    declared.facets[6].polygons.push_back({{12, 13}});  // z = 1/2: (½,0,½)-(½,1,½)
    declared.facets[2].polygons.push_back({{8, 9}});    // y = 0: (0,0,½)-(1,0,½)
    const ConformityReport rd = CheckConformity(declared, m);
    EXPECT_TRUE(rd.ok()) << rd.Summary();
    EXPECT_TRUE(rd.cells_known) << rd.cells_unknown_reason;
    EXPECT_EQ(rd.num_cells, 3u);
  }

  // Top right region deleted and top left meshed twice (a shifted copy of its
  // tets over a copy of the vertices): the total volume is unchanged, so
  // only the cell-by-cell check sees it.
  auto centroid = [&](const std::array<uint32_t, 4>& t) {
    return (m.positions[t[0]] + m.positions[t[1]] + m.positions[t[2]] + m.positions[t[3]]) / 4.0;
  };
  TetMesh bad = m;
  const uint32_t nv = static_cast<uint32_t>(m.positions.size());
  bad.positions.insert(bad.positions.end(), m.positions.begin(), m.positions.end());
  bad.tets.clear();
  for (const auto& t : m.tets) {
    const Vec3 c = centroid(t);
    if (c.z > 0.5 && c.x > 0.5) continue;
    bad.tets.push_back(t);
    if (c.z > 0.5 && c.x < 0.5) bad.tets.push_back({t[0] + nv, t[1] + nv, t[2] + nv, t[3] + nv});
  }
  bad.tet_region.assign(bad.tets.size(), 0);
  EXPECT_NEAR(TotalVolume(bad), TotalVolume(m), 1e-12);
  ConformityOptions opt;
  opt.input_vertices_first = false;
  const ConformityReport rb = CheckConformity(p, bad, opt);
  ASSERT_TRUE(rb.cells_known) << rb.cells_unknown_reason;
  EXPECT_EQ(rb.Count(ViolationKind::kVolumeMismatch), 2u) << rb.Summary();
  const std::string sum = rb.Summary();
  EXPECT_NE(sum.find("region seed(s) 1: tets in it have volume"), std::string::npos) << sum;
  EXPECT_NE(sum.find("more than once"), std::string::npos) << sum;
  EXPECT_NE(sum.find("region seed(s) 2: tets in it have volume"), std::string::npos) << sum;
  EXPECT_NE(sum.find("not filled"), std::string::npos) << sum;
}

TEST(Conformity, FacetPartlyOutsideTheDomain) {
  // The unit box standing on the square [-1, 2]^2 x {0} (instead of its own
  // bottom facet): the box's side facets end inside the square, which splits
  // into the box's bottom (bounding the box's cell) and a ring with the
  // unbounded cell on both sides, which is outside the domain.
  plc::Plc p = BoxPlc(kLo, kHi);
  p.facets.erase(p.facets.begin() + 4);  // z = 0
  const uint32_t b = static_cast<uint32_t>(p.vertices.size());
  for (const Vec3& v : {Vec3(-1, -1, 0), Vec3(2, -1, 0), Vec3(2, 2, 0), Vec3(-1, 2, 0)}) {
    p.vertices.push_back(v);
  }
  plc::Facet f;
  f.polygons.push_back({{b, b + 1, b + 2, b + 3}});
  f.marker = 5;
  p.facets.push_back(f);
  TetMesh m = KuhnBoxMesh(p, 2);
  testing::AssignAxisAlignedTriangles(p, &m);
  const ConformityReport r = CheckConformity(p, m);
  ASSERT_TRUE(r.cells_known) << r.cells_unknown_reason;
  EXPECT_EQ(r.num_cells, 1u);
  EXPECT_NEAR(r.enclosed_volume, 1.0, 1e-12);
  EXPECT_EQ(r.num_facets_outside, 0u);
  EXPECT_EQ(r.num_facets_partly_outside, 1u);
  EXPECT_EQ(r.Count(ConformityCategory::kCoverage), 0u) << r.Summary();
  EXPECT_EQ(r.Count(ViolationKind::kFacetNotCovered), 0u) << r.Summary();
  // The square's own edges lie outside the domain and are still required
  // (segments are not classified by cells), as in FacetOutsideTheDomain...
  EXPECT_EQ(r.Count(ViolationKind::kBrokenSegment), 4u) << r.Summary();
  EXPECT_EQ(r.Count(ConformityCategory::kConformity), 4u) << r.Summary();
  // Without the box's bottom triangles the inside piece is not covered.
  TetMesh open = m;
  open.triangles.clear();
  open.triangle_marker.clear();
  for (size_t i = 0; i < m.triangles.size(); ++i) {
    if (m.triangle_marker[i] == 5) continue;
    open.triangles.push_back(m.triangles[i]);
    open.triangle_marker.push_back(m.triangle_marker[i]);
  }
  const ConformityReport ro = CheckConformity(p, open);
  EXPECT_EQ(ro.Count(ViolationKind::kFacetNotCovered), 1u) << ro.Summary();
}

TEST(Conformity, ScalesToHundredsOfThousandsOfTets) {
  const plc::Plc p = BoxPlc(kLo, kHi, /*split=*/true);
  const TetMesh m = KuhnBoxMesh(p, 24);  // 82,944 tets
  const auto t0 = std::chrono::steady_clock::now();
  const ConformityReport r = CheckConformity(p, m);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_TRUE(r.ok()) << r.Summary();
  EXPECT_EQ(m.tets.size(), 82944u);
  RecordProperty("seconds", std::to_string(s));
  std::printf("checked %zu tets in %.3f s\n", m.tets.size(), s);
}

}  // namespace
}  // namespace svrc::mesh
