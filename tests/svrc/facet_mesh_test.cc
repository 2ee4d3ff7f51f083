// Facet meshes M_F (stage (c), increment 1): the facet region in its frame,
// "triangle in F" (guide §5 item 4), Delaunay validity of M_F inside Ω_F, and
// clipped cell sizes. The in-facet triangles must cover F exactly (area) when
// F's segments are edges of M_F, and cover it (area ≥) in any case.
#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <utility>
#include <vector>

#include "core/geometry/predicates.h"
#include "core/plc/features.h"
#include "core/plc/readers.h"
#include "core/svrc/facet_mesh.h"
#include "core/svrc/normalize.h"
#include "gtest/gtest.h"
#include "tests/test_support.h"

namespace svrc::refine {
namespace {

using geom::Vec2;
using geom::Vec3;
using Where = FacetRegion::Where;

double Area(Vec2 a, Vec2 b, Vec2 c) {
  return 0.5 * ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
}

// A square loop [lo, hi]² with `k` points per side (counter-clockwise).
std::vector<Vec2> SquareLoop(double lo, double hi, int k) {
  std::vector<Vec2> out;
  const double step = (hi - lo) / k;
  for (int i = 0; i < k; ++i) out.push_back({lo + i * step, lo});
  for (int i = 0; i < k; ++i) out.push_back({hi, lo + i * step});
  for (int i = 0; i < k; ++i) out.push_back({hi - i * step, hi});
  for (int i = 0; i < k; ++i) out.push_back({lo, hi - i * step});
  return out;
}

// Adds a loop with fresh ids and its edges as segments.
void AddLoopWithSegments(FacetRegion* r, const std::vector<Vec2>& uv, bool hole, uint32_t* next) {
  std::vector<PointId> ids;
  for (size_t i = 0; i < uv.size(); ++i) ids.push_back(PointId((*next)++));
  for (size_t i = 0; i < uv.size(); ++i) {
    r->segments.push_back({uv[i], uv[(i + 1) % uv.size()]});
    r->segment_points.push_back({ids[i], ids[(i + 1) % uv.size()]});
  }
  r->AddLoop(uv, ids, hole);
}

// Outer square [0,4]² (8 points per side) with a square hole [1.5,2.5]² (2 per side).
FacetRegion HoledSquare(uint32_t* next) {
  FacetRegion r;
  AddLoopWithSegments(&r, SquareLoop(0, 4, 8), false, next);
  AddLoopWithSegments(&r, SquareLoop(1.5, 2.5, 2), true, next);
  r.CollectPoints();
  return r;
}

TEST(FacetRegionTest, LocateHonoursHolesAndBoundary) {
  uint32_t next = 0;
  const FacetRegion r = HoledSquare(&next);
  EXPECT_EQ(r.Locate({0.5, 0.5}), Where::kInside);
  EXPECT_EQ(r.Locate({3.9, 2.0}), Where::kInside);
  EXPECT_EQ(r.Locate({2.0, 2.0}), Where::kOutside);  // in the hole
  EXPECT_EQ(r.Locate({5.0, 2.0}), Where::kOutside);
  EXPECT_EQ(r.Locate({-1e-300, 2.0}), Where::kOutside);
  EXPECT_EQ(r.Locate({0.0, 2.0}), Where::kOnBoundary);
  EXPECT_EQ(r.Locate({1.5, 2.0}), Where::kOnBoundary);
  // Ray through loop vertices (y = 2 hits vertices at x = 0 and 4 of the outer
  // loop, and the hole's midpoints): the half-open rule counts each once.
  EXPECT_EQ(r.Locate({1.0, 2.0}), Where::kInside);
  EXPECT_EQ(r.Locate({3.0, 1.5}), Where::kInside);
}

TEST(FacetRegionTest, IslandInsideAHoleIsInside) {
  uint32_t next = 0;
  FacetRegion r = HoledSquare(&next);
  AddLoopWithSegments(&r, SquareLoop(1.8, 2.2, 1), false, &next);
  EXPECT_EQ(r.Locate({2.0, 2.0}), Where::kInside);
  EXPECT_EQ(r.Locate({1.6, 2.0}), Where::kOutside);
}

TEST(FacetRegionTest, StraddlingTrianglesAreInFacet) {
  FacetRegion r;
  uint32_t next = 0;
  AddLoopWithSegments(&r, SquareLoop(0, 1, 1), false, &next);
  // Centroid outside, but the triangle pokes through the bottom edge.
  EXPECT_TRUE(r.CrossesSegment({-1, -1}, {2, -1}, {0.5, 0.1}));
  EXPECT_TRUE(r.TriangleInFacet({-1, -1}, {2, -1}, {0.5, 0.1}));
  // Touching the bottom edge from outside along a whole side: not in F.
  EXPECT_FALSE(r.CrossesSegment({0, 0}, {0.5, -1}, {1, 0}));
  EXPECT_FALSE(r.TriangleInFacet({0, 0}, {0.5, -1}, {1, 0}));
  // Touching a corner only.
  EXPECT_FALSE(r.TriangleInFacet({1, 1}, {2, 1}, {2, 2}));
  // A segment ending exactly on an edge of the triangle, entering its interior.
  FacetRegion s;
  s.segments.push_back({Vec2{0, 0}, Vec2{0.5, 0.5}});
  EXPECT_TRUE(s.CrossesSegment({0, 0}, {1, 0}, {0, 1}));
  // A triangle containing a whole hole-free facet is in F.
  EXPECT_TRUE(r.TriangleInFacet({-5, -5}, {5, -5}, {0, 5}));
}

// Inserts every point of the region into M_F; checks Delaunay validity and
// that in-facet triangles cover F (exactly when F's segments are M_F edges).
// Checks that exactly the live in-facet triangles own a live ConfBall, whose
// dual triangle is theirs and whose centre is equidistant (radius) from the
// triangle's vertices mapped to 3D through the frame.
void CheckTriangleBalls(const FacetMesh& mesh, const BallStore& balls,
                        const plc::FacetFrame& frame) {
  const auto& dt = mesh.dt();
  uint32_t in_facet = 0;
  for (auto t : dt.Triangles()) {
    const BallId b = mesh.TriBall(t);
    ASSERT_EQ(b.valid(), mesh.InFacet(t));
    if (!b.valid()) continue;
    ++in_facet;
    ASSERT_TRUE(balls.IsAlive(b));
    ASSERT_EQ(balls.NumVertices(b), 3);
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(balls.Vertex(b, i), mesh.PointOf(dt.TriVertex(t, i)));
      const Vec3 x = frame.ToSpace(dt.Point(dt.TriVertex(t, i)));
      EXPECT_NEAR(geom::Dist(x, balls.Center(b)), balls.Radius(b), 1e-12 * (1 + balls.Radius(b)));
    }
    EXPECT_NEAR(geom::Dot(balls.Center(b) - frame.origin, frame.normal), 0,
                1e-14 * (1 + balls.Radius(b)));
  }
  EXPECT_EQ(balls.NumAlive(), in_facet);
}

// Returns whether F's segments were all M_F edges (the exact-area case).
bool CheckFacetMesh(const FacetRegion& region, uint32_t corner_base, double facet_area,
                    const plc::FacetFrame& frame = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0),
                                                    Vec3(0, 0, 1)}) {
  FacetMesh mesh(region, {PointId(corner_base), PointId(corner_base + 1), PointId(corner_base + 2),
                          PointId(corner_base + 3)});
  BallStore balls;
  const FeatureId feature(7);
  const MeshId mesh_id(1);
  // The seed triangles contain F, so they are in F (they meet its segments).
  mesh.CreateAllTriangleBalls(frame, feature, mesh_id, &balls);
  EXPECT_EQ(balls.NumAlive(), 2u);
  // Every loop point, segment endpoint and interior point is in all_points.
  std::set<uint32_t> all;
  for (PointId p : region.all_points) all.insert(p.value());
  EXPECT_EQ(all.size(), region.all_points.size());
  for (const auto& loop : region.loops) {
    for (PointId p : loop.points) EXPECT_TRUE(all.count(p.value()));
  }
  for (const auto& s : region.segment_points) {
    EXPECT_TRUE(all.count(s[0].value()) && all.count(s[1].value()));
  }
  for (PointId p : region.interior_points) EXPECT_TRUE(all.count(p.value()));
  for (size_t i = 0; i < region.all_points.size(); ++i) {
    const auto r = mesh.Insert(region.all_uv[i], region.all_points[i]);
    EXPECT_EQ(r.outcome, delaunay::Delaunay2::InsertOutcome::kInserted);
    mesh.SyncTriangleBalls(r, frame, feature, mesh_id, &balls);
  }
  CheckTriangleBalls(mesh, balls, frame);
  EXPECT_TRUE(mesh.dt().Validate().ok()) << mesh.dt().Validate();
  const auto& dt = mesh.dt();
  std::set<std::pair<uint32_t, uint32_t>> edges;
  double in_area = 0;
  int in_count = 0;
  int corner_touching = 0;
  std::vector<std::array<PointId, 3>> in_tris;  // InFacet over every live triangle, recomputed
  for (auto t : dt.Triangles()) {
    const Vec2 a = dt.Point(dt.TriVertex(t, 0)), b = dt.Point(dt.TriVertex(t, 1)),
               c = dt.Point(dt.TriVertex(t, 2));
    for (int e = 0; e < 3; ++e) {
      const uint32_t u = mesh.PointOf(dt.TriVertex(t, e)).value();
      const uint32_t w = mesh.PointOf(dt.TriVertex(t, (e + 1) % 3)).value();
      edges.insert({std::min(u, w), std::max(u, w)});
    }
    if (!mesh.InFacet(t)) continue;
    in_tris.push_back({mesh.PointOf(dt.TriVertex(t, 0)), mesh.PointOf(dt.TriVertex(t, 1)),
                       mesh.PointOf(dt.TriVertex(t, 2))});
    ++in_count;
    in_area += Area(a, b, c);
    for (int i = 0; i < 3; ++i) corner_touching += dt.IsCorner(dt.TriVertex(t, i));
  }
  // InFacetTriangles reads the flags SyncTriangleBalls recorded (session 41):
  // the same triangles, in the same order, as testing each one again.
  EXPECT_EQ(static_cast<size_t>(in_count), mesh.InFacetTriangles().size());
  EXPECT_EQ(mesh.InFacetTriangles(), in_tris);
  bool conforming = true;
  for (const auto& s : region.segment_points) {
    const uint32_t u = s[0].value(), w = s[1].value();
    conforming = conforming && edges.count({std::min(u, w), std::max(u, w)});
  }
  const double tol = 1e-12 * (1 + facet_area);
  if (conforming) {
    // Then no in-facet triangle reaches Ω_F's corners, and they tile F.
    EXPECT_EQ(corner_touching, 0);
    EXPECT_NEAR(in_area, facet_area, tol);
  } else {
    EXPECT_GE(in_area, facet_area - tol);
  }
  // Cell sizes: finite, clipped to Ω_F, r_v ≤ R_v, corners' cells clipped.
  const Vec2 lo = mesh.SquareLo(), hi = mesh.SquareHi();
  for (uint32_t v = 0; v < dt.NumVertices(); ++v) {
    const auto vid = delaunay::Delaunay2::VertexId(v);
    const CellSize2 s = mesh.Size(vid);
    EXPECT_EQ(s.inradius, dt.InRadius(vid));  // from the star: the same double
    EXPECT_TRUE(std::isfinite(s.outradius));
    if (dt.IsCorner(vid) && s.outradius == 0) {
      // A quadrilateral corner whose cell no longer meets Ω_F.
      EXPECT_TRUE(s.clipped);
      continue;
    }
    EXPECT_LE(s.inradius, s.outradius + 1e-15);
    EXPECT_GE(s.corner.x, lo.x);
    EXPECT_LE(s.corner.x, hi.x);
    EXPECT_GE(s.corner.y, lo.y);
    EXPECT_LE(s.corner.y, hi.y);
    if (dt.IsCorner(vid)) {
      EXPECT_TRUE(s.clipped);
    }
    // Unclipped interior cells: R_v is the largest incident circumradius.
    if (!s.clipped) {
      EXPECT_NEAR(s.outradius, dt.OutRadius(vid), 1e-12 * s.outradius);
    }
  }
  return conforming;
}

TEST(FacetMeshTest, HoledSquareCoversFacetMinusHole) {
  uint32_t next = 0;
  const FacetRegion r = HoledSquare(&next);
  EXPECT_TRUE(CheckFacetMesh(r, next, 16.0 - 1.0));
}

// An in-facet segment (not a loop: only its pieces and endpoints are given)
// and an isolated interior point: both sides of the segment are in F, and
// its endpoints and the point become M_F vertices.
TEST(FacetMeshTest, InFacetSegmentAndIsolatedPoint) {
  FacetRegion r;
  uint32_t next = 0;
  AddLoopWithSegments(&r, SquareLoop(0, 4, 8), false, &next);
  uint32_t prev = next++;
  for (int i = 1; i <= 4; ++i) {
    const uint32_t cur = next++;
    r.segments.push_back({Vec2{1 + 0.5 * (i - 1), 2}, Vec2{1 + 0.5 * i, 2}});
    r.segment_points.push_back({PointId(prev), PointId(cur)});
    prev = cur;
  }
  r.interior_uv.push_back({2, 3.25});
  r.interior_points.push_back(PointId(next++));
  r.CollectPoints();
  EXPECT_EQ(r.all_points.size(), 32u + 5u + 1u);
  EXPECT_EQ(r.Locate({2, 1.9}), FacetRegion::Where::kInside);
  EXPECT_EQ(r.Locate({2, 2.1}), FacetRegion::Where::kInside);
  EXPECT_TRUE(CheckFacetMesh(r, next, 16.0));
}

TEST(FacetMeshTest, CornerCellOfSquareWithOnePoint) {
  FacetRegion r;
  uint32_t next = 0;
  AddLoopWithSegments(&r, SquareLoop(0, 1, 1), false, &next);
  FacetMesh mesh(r, {PointId(10), PointId(11), PointId(12), PointId(13)});
  // Ω_F: side 3·√2 centred on (0.5, 0.5).
  const double half = 1.5 * std::sqrt(2.0);
  EXPECT_DOUBLE_EQ(mesh.SquareLo().x, 0.5 - half);
  EXPECT_DOUBLE_EQ(mesh.SquareHi().y, 0.5 + half);
  // The Delaunay quadrilateral is the square of 3× Ω_F's side around it.
  EXPECT_DOUBLE_EQ(mesh.QuadCorner(0).x, 0.5 - 3 * half);
  EXPECT_DOUBLE_EQ(mesh.QuadCorner(2).y, 0.5 + 3 * half);
  mesh.Insert({0.5, 0.5}, PointId(20));
  // The centre point's cell is the diamond of the quadrilateral corners'
  // bisectors (at 1.5·√2·half along the diagonals), which contains Ω_F: its
  // farthest corner is a corner of Ω_F, at √2·half; r_v is half the distance
  // to a quadrilateral corner.
  const CellSize2 s = mesh.Size(delaunay::Delaunay2::VertexId(4));
  EXPECT_TRUE(s.clipped);
  EXPECT_NEAR(s.outradius, std::sqrt(2.0) * half, 1e-12);
  EXPECT_NEAR(s.inradius, 1.5 * std::sqrt(2.0) * half, 1e-12);
  // A quadrilateral corner's cell does not meet Ω_F: R = 0, never skinny.
  const CellSize2 c = mesh.Size(delaunay::Delaunay2::VertexId(0));
  EXPECT_TRUE(c.clipped);
  EXPECT_EQ(c.outradius, 0.0);
}

// Corpus facets: cube (convex quads), box_internal_facet (an internal facet),
// example (a facet with a hole).
// Returns the number of facets whose segments were all M_F edges.
int CheckCorpusFacets(const char* file) {
  int conforming = 0;
  auto plc = plc::ReadPlcFile(svrc::testing::CorpusPath(file));
  EXPECT_TRUE(plc.ok()) << plc.status();
  if (!plc.ok()) return -1;
  auto complex = plc::BuildFeatureComplex(*plc);
  EXPECT_TRUE(complex.ok()) << complex.status();
  if (!complex.ok()) return -1;
  std::vector<Vec3> pts;
  for (const auto& p : complex->points) pts.push_back(p.p);
  auto norm = ChooseNormalization(pts);
  EXPECT_TRUE(norm.ok());
  if (!norm.ok()) return -1;
  std::vector<PointId> ids;
  for (uint32_t i = 0; i < pts.size(); ++i) ids.push_back(PointId(i));
  for (uint32_t f = 0; f < complex->facets.size(); ++f) {
    SCOPED_TRACE(::testing::Message() << file << " facet " << f);
    plc::FacetFrame frame;
    const FacetRegion r = BuildFacetRegion(*complex, f, *norm, ids, &frame);
    // F's area from the complex's own triangulation, in the normalised frame.
    double area = 0;
    for (const auto& t : complex->facets[f].triangles) {
      area += std::fabs(Area(frame.ToPlane(norm->Forward(pts[t[0]])),
                             frame.ToPlane(norm->Forward(pts[t[1]])),
                             frame.ToPlane(norm->Forward(pts[t[2]]))));
    }
    EXPECT_GT(area, 0);
    // Loop points project onto the frame plane (normalised) within rounding,
    // and their uv maps back to their xyz within rounding.
    for (const auto& loop : r.loops) {
      for (size_t i = 0; i < loop.points.size(); ++i) {
        const Vec3 x = norm->Forward(pts[loop.points[i].value()]);
        EXPECT_NEAR(geom::Dot(x - frame.origin, frame.normal), 0, 1e-14);
        EXPECT_LE(geom::Dist(frame.ToSpace(loop.uv[i]), x), 1e-14);
      }
    }
    conforming += CheckFacetMesh(r, static_cast<uint32_t>(pts.size()) + 4 * f, area, frame);
  }
  return conforming;
}

// The six quads of the cube conform with their 4 corners alone: the exact
// area check runs on each.
TEST(FacetMeshTest, CorpusCube) { EXPECT_EQ(CheckCorpusFacets("a_convex/cube.poly"), 6); }
TEST(FacetMeshTest, CorpusBoxInternalFacet) {
  const int n = CheckCorpusFacets("b_internal/box_internal_facet.poly");
  EXPECT_GE(n, 0);
  ::testing::Test::RecordProperty("conforming_facets", n);
}
TEST(FacetMeshTest, CorpusExampleWithHole) {
  const int n = CheckCorpusFacets("b_internal/example.poly");
  EXPECT_GE(n, 0);
  ::testing::Test::RecordProperty("conforming_facets", n);
}

// TriangleMeetsSegment rejects disjoint bounding boxes before its side tests;
// the answer is the side tests' own on every pair: small integer coordinates
// (segments touching vertices and edges, collinear with edges, boxes sharing
// a side) and random ones.
TEST(FacetRegionTest, TriangleMeetsSegmentBoxRejectKeepsTheAnswer) {
  uint64_t z = 12345;
  auto next = [&](int k) {
    z = z * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<int>((z >> 33) % static_cast<uint64_t>(k));
  };
  int met = 0, rejected_by_box = 0;
  for (int i = 0; i < 200000; ++i) {
    const bool small = i % 2 == 0;
    auto pt = [&]() {
      return small ? Vec2{double(next(5)), double(next(5))}
                   : Vec2{next(1 << 20) / double(1 << 18), next(1 << 20) / double(1 << 18)};
    };
    Vec2 a = pt(), b = pt(), c = pt();
    const int o = geom::Orient2d(a, b, c);
    if (o == 0) continue;
    if (o < 0) std::swap(b, c);
    const Vec2 s0 = pt(), s1 = pt();
    const bool want = internal::TriangleMeetsSegmentBySides(a, b, c, s0, s1);
    ASSERT_EQ(TriangleMeetsSegment(a, b, c, s0, s1), want)
        << a.x << "," << a.y << " " << b.x << "," << b.y << " " << c.x << "," << c.y << " | " << s0.x << "," << s0.y
        << " " << s1.x << "," << s1.y;
    met += want;
    rejected_by_box += std::max({a.x, b.x, c.x}) < std::min(s0.x, s1.x) || std::min({a.y, b.y, c.y}) > std::max(s0.y, s1.y);
  }
  EXPECT_GT(met, 10000);
  EXPECT_GT(rejected_by_box, 10000);
}

}  // namespace
}  // namespace svrc::refine
