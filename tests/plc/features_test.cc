// Feature complex: points/segments/facets, splitting, creases (thesis
// Definitions 4-5) on hand-built PLCs and corpus files, and the spread Δ.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "core/plc/features.h"
#include "core/plc/readers.h"
#include "core/plc/validate.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/test_support.h"

namespace svrc::plc {
namespace {

using ::testing::ElementsAre;
using svrc::testing::CorpusPath;

constexpr double kDeg = std::numbers::pi / 180;

FeatureComplex MustBuild(const Plc& plc) {
  absl::StatusOr<FeatureComplex> fc = BuildFeatureComplex(plc);
  EXPECT_TRUE(fc.ok()) << fc.status();
  return fc.ok() ? *std::move(fc) : FeatureComplex{};
}

FeatureComplex MustBuildFile(const std::string& rel) {
  absl::StatusOr<Plc> plc = ReadPlcFile(CorpusPath(rel));
  EXPECT_TRUE(plc.ok()) << plc.status();
  return plc.ok() ? MustBuild(*plc) : FeatureComplex{};
}

Facet Quad(uint32_t a, uint32_t b, uint32_t c, uint32_t d, int32_t m = 0) {
  Facet f;
  f.polygons.push_back(Polygon{{a, b, c, d}});
  f.marker = m;
  return f;
}
Facet Tri(uint32_t a, uint32_t b, uint32_t c) {
  Facet f;
  f.polygons.push_back(Polygon{{a, b, c}});
  return f;
}

// A closed triangular prism whose two slanted faces meet along the edge at
// (0, y, 0) with the given opening angle; y in [0, 1].
Plc Wedge(double angle_deg) {
  const double a = angle_deg * kDeg;
  Plc plc;
  plc.vertices = {{0, 0, 0}, {1, 0, 0}, {std::cos(a), 0, std::sin(a)},
                  {0, 1, 0}, {1, 1, 0}, {std::cos(a), 1, std::sin(a)}};
  plc.facets = {Tri(0, 1, 2), Tri(3, 4, 5), Quad(0, 1, 4, 3), Quad(0, 2, 5, 3), Quad(1, 2, 5, 4)};
  return plc;
}

TEST(Features, CubeHasNoCreases) {
  for (const char* rel : {"a_convex/cube.poly", "a_convex/cube_binary.stl"}) {
    SCOPED_TRACE(rel);
    const FeatureComplex fc = MustBuildFile(rel);
    EXPECT_EQ(fc.points.size(), 8u);
    EXPECT_EQ(fc.segments.size(), 12u);
    EXPECT_EQ(fc.facets.size(), 6u);
    EXPECT_EQ(fc.NumCreasePoints(), 0u);
    EXPECT_EQ(fc.NumCreaseSegments(), 0u);
    for (const FeatureSegment& s : fc.segments) {
      EXPECT_EQ(s.facets.size(), 2u);
      EXPECT_NEAR(s.min_angle, 90 * kDeg, 1e-12);
    }
    for (const FeatureFacet& f : fc.facets) {
      EXPECT_EQ(f.triangles.size(), 2u);
      EXPECT_NEAR(std::fabs(f.frame.normal.x) + std::fabs(f.frame.normal.y) + std::fabs(f.frame.normal.z), 1, 1e-15);
      EXPECT_NEAR(geom::Dot(f.frame.u, f.frame.v), 0, 1e-15);
    }
    EXPECT_NEAR(fc.spread, std::sqrt(3.0), 1e-12);
  }
}

TEST(Features, WedgeAt30DegreesIsACrease) {
  const FeatureComplex fc = MustBuild(Wedge(30));
  const SegmentId edge = fc.FindSegment(0, 3);
  ASSERT_NE(edge, kNoId);
  EXPECT_TRUE(fc.segments[edge].crease);
  EXPECT_NEAR(fc.segments[edge].min_angle, 30 * kDeg, 1e-12);
  EXPECT_TRUE(fc.points[0].crease);
  EXPECT_TRUE(fc.points[3].crease);
  // The 90° edges (bottom face against the end triangles) are not creases...
  EXPECT_FALSE(fc.segments[fc.FindSegment(0, 1)].crease);
  // ...but the 75° edge at the top of the wedge is.
  EXPECT_TRUE(fc.segments[fc.FindSegment(2, 5)].crease);
  // A 100° wedge: the ridge is no crease.
  const FeatureComplex wide = MustBuild(Wedge(100));
  EXPECT_FALSE(wide.segments[wide.FindSegment(0, 3)].crease);
  EXPECT_NEAR(wide.segments[wide.FindSegment(0, 3)].min_angle, 100 * kDeg, 1e-12);
}

TEST(Features, ThreeFacetsAt120DegreesAroundAnEdge) {
  // Three rectangles sharing the edge from (0,0,0) to (0,1,0), 120° apart.
  Plc plc;
  plc.vertices = {{0, 0, 0}, {0, 1, 0}};
  for (int k = 0; k < 3; ++k) {
    const double a = k * 120 * kDeg;
    plc.vertices.push_back({std::cos(a), 0, std::sin(a)});
    plc.vertices.push_back({std::cos(a), 1, std::sin(a)});
    plc.facets.push_back(Quad(0, 2 + 2 * k, 3 + 2 * k, 1));
  }
  ValidationOptions vo;
  FeatureOptions fo;
  ValidationReport report;
  absl::StatusOr<FeatureComplex> fc = PreparePlc(plc, vo, fo, &report);
  // Three fins alone enclose nothing: rejected by the closedness rule.
  EXPECT_FALSE(fc.ok());
  ASSERT_NE(report.Find(ProblemKind::kOpenBoundary), nullptr);
  // Close them into three 120° prisms around the shared edge (outer faces and
  // end-cap triangles); the edge then lies on three facets.
  for (int k = 0; k < 3; ++k) {
    const int j = (k + 1) % 3;
    plc.facets.push_back(Quad(2 + 2 * k, 2 + 2 * j, 3 + 2 * j, 3 + 2 * k));
    plc.facets.push_back(Tri(0, 2 + 2 * k, 2 + 2 * j));
    plc.facets.push_back(Tri(1, 3 + 2 * k, 3 + 2 * j));
  }
  fc = PreparePlc(plc, vo, fo, &report);
  ASSERT_TRUE(fc.ok()) << fc.status();
  const SegmentId axis = fc->FindSegment(0, 1);
  ASSERT_NE(axis, kNoId);
  EXPECT_EQ(fc->segments[axis].facets.size(), 3u);
  EXPECT_NEAR(fc->segments[axis].min_angle, 120 * kDeg, 1e-12);
  EXPECT_FALSE(fc->segments[axis].crease);
}

TEST(Features, Wedge1SmeshAndKnifeEdge) {
  const FeatureComplex w = MustBuildFile("c_creases/wedge-1.smesh");
  const SegmentId ridge = w.FindSegment(0, 1);
  ASSERT_NE(ridge, kNoId);
  EXPECT_TRUE(w.segments[ridge].crease);
  // The file lifts the edge by sin(1°) over a run of 1: atan(sin 1°) = 0.99985°.
  EXPECT_NEAR(w.segments[ridge].min_angle, std::atan(std::sin(1 * kDeg)), 1e-12);
  EXPECT_TRUE(w.points[0].crease && w.points[1].crease);
  // The 89° edge between the slanted top and the end face is a crease too;
  // the 90° ones are not.
  EXPECT_TRUE(w.segments[w.FindSegment(4, 5)].crease);
  EXPECT_FALSE(w.segments[w.FindSegment(2, 3)].crease);

  const FeatureComplex k = MustBuildFile("c_creases/knife_edge.poly");
  const SegmentId blade = k.FindSegment(12, 13);
  ASSERT_NE(blade, kNoId);
  EXPECT_TRUE(k.segments[blade].crease);
  EXPECT_NEAR(k.segments[blade].min_angle, 5 * kDeg, 1e-9);
  EXPECT_EQ(k.NumCreaseSegments(), 1u);
  EXPECT_EQ(k.NumCreasePoints(), 2u);
}

TEST(Features, SegmentsSplitAtPointsOnThemAndFreeSegments) {
  const FeatureComplex fan = MustBuildFile("d_small_angles/segment_fan.poly");
  // In-facet segments of the top facet from corner 5 (0-based 4) fan out at
  // 0.5..8 degrees: crease points; their pieces lie in the top facet only.
  EXPECT_TRUE(fan.points[4].crease);
  const SegmentId s = fan.FindSegment(4, 8);
  ASSERT_NE(s, kNoId);
  EXPECT_THAT(fan.segments[s].facets, ElementsAre(1));
  // 5 fan segments + the 3 edges of the in-facet triangle have the top facet
  // on both sides.
  EXPECT_EQ(fan.facets[1].interior_segments.size(), 8u);
  EXPECT_TRUE(std::binary_search(fan.facets[1].interior_segments.begin(),
                                 fan.facets[1].interior_segments.end(), s));
  // The two free segments meet at 1 degree at point 17 (0-based 16).
  EXPECT_TRUE(fan.points[16].crease);
  ASSERT_EQ(fan.pieces_of_free_segment.size(), 2u);
  EXPECT_TRUE(fan.segments[fan.pieces_of_free_segment[0][0]].is_free);

  // A vertical free segment standing on the midpoint of a square's edge
  // splits that edge; its other end is an interior point of nothing.
  Plc plc;
  plc.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0, 0}, {0.5, 0, 1},
                  {0.5, 0.5, 0}};
  plc.facets = {Quad(0, 1, 2, 3)};
  plc.segments = {{4, 5, 7}};
  ValidationReport report;
  absl::StatusOr<FeatureComplex> fc = PreparePlc(plc, {}, {}, &report);
  // Not closed (a lone square): the complex is still checked via validation.
  EXPECT_FALSE(fc.ok());
  ASSERT_NE(report.Find(ProblemKind::kOpenBoundary), nullptr);
  EXPECT_EQ(report.errors.size(), 1u);
}

TEST(Features, SplitAndInteriorPointsInAClosedBox) {
  Plc plc;
  plc.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                  {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1},
                  {0.5, 0, 0}, {0.5, 0.5, 0.5}, {0.3, 0.4, 0}};
  plc.facets = {Quad(0, 3, 2, 1), Quad(4, 5, 6, 7), Quad(0, 1, 5, 4),
                Quad(1, 2, 6, 5), Quad(2, 3, 7, 6), Quad(3, 0, 4, 7)};
  plc.segments = {{8, 9, 4}, {10, 9, 5}};  // one on the bottom edge midpoint, one from a bottom interior point
  const FeatureComplex fc = MustBuild(plc);
  EXPECT_EQ(fc.points.size(), 11u);
  // Edge 0-1 split at 8 on both the bottom and the front face.
  EXPECT_EQ(fc.FindSegment(0, 1), kNoId);
  const SegmentId a = fc.FindSegment(0, 8), b = fc.FindSegment(1, 8);
  ASSERT_NE(a, kNoId);
  ASSERT_NE(b, kNoId);
  EXPECT_THAT(fc.segments[a].facets, ElementsAre(0, 2));
  EXPECT_EQ(fc.facets[0].loops[0].size(), 5u);
  // Point 10 lies inside the bottom facet.
  EXPECT_THAT(fc.points[10].interior_of, ElementsAre(0));
  EXPECT_THAT(fc.facets[0].interior_points, ElementsAre(10));
  EXPECT_FALSE(fc.points[10].isolated);
  const SegmentId free = fc.FindSegment(9, 10);
  ASSERT_NE(free, kNoId);
  EXPECT_TRUE(fc.segments[free].is_free);
  EXPECT_EQ(fc.segments[free].marker, 5);
  EXPECT_TRUE(fc.segments[free].facets.empty());
  // Point 9 is where two free segments meet at an acute angle.
  EXPECT_TRUE(fc.points[9].crease);
}

TEST(Features, Spread) {
  const FeatureComplex far = MustBuildFile("e_spread/far_offset_close_points.poly");
  // Two isolated points 1e-3 apart and 1e-3 above the bottom facet.
  EXPECT_NEAR(far.min_feature_distance, 1e-3, 1e-9);
  EXPECT_NEAR(far.diameter, 1000 * std::sqrt(3.0), 1e-6);
  EXPECT_NEAR(far.spread, std::sqrt(3.0) * 1e6, 10);
  EXPECT_EQ(far.points[8].isolated, true);
  const FeatureComplex tiny = MustBuildFile("e_spread/tiny_cube_in_box.poly");
  EXPECT_NEAR(tiny.min_feature_distance, 1e-4, 1e-12);
  EXPECT_NEAR(tiny.spread, std::sqrt(3.0) * 1e4, 1e-3);
  // box_in_box: isolated point (0.1, 0.1, 0.1) is 0.1 from three faces.
  const FeatureComplex bb = MustBuildFile("b_internal/box_in_box.poly");
  EXPECT_NEAR(bb.min_feature_distance, 0.1, 1e-12);
}

// The pair the smallest gap is measured between, as messages name it
// (input numbering from 0, a segment by its end points).
Plc UnitCubePlc() {
  Plc plc;
  plc.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  plc.facets = {Quad(0, 1, 2, 3), Quad(4, 5, 6, 7), Quad(0, 1, 5, 4),
                Quad(1, 2, 6, 5), Quad(2, 3, 7, 6), Quad(3, 0, 4, 7)};
  return plc;
}

TEST(Features, SpreadNamesTheClosestFeatures) {
  Plc point = UnitCubePlc();
  point.vertices.push_back({0.5, 0.5, 1e-6});  // an isolated point just above the bottom facet
  const FeatureComplex fp = MustBuild(point);
  EXPECT_NEAR(fp.min_feature_distance, 1e-6, 1e-18);
  EXPECT_EQ(fp.closest_features, "point 8 (0.5, 0.5, 1e-06) and facet 0");

  Plc segs = UnitCubePlc();  // two free skew segments 2e-5 apart
  segs.vertices.insert(segs.vertices.end(), {{0.2, 0.5, 0.5}, {0.8, 0.5, 0.5}, {0.5, 0.2, 0.50002}, {0.5, 0.8, 0.50002}});
  segs.segments = {{8, 9, 0}, {10, 11, 0}};
  const FeatureComplex fs = MustBuild(segs);
  EXPECT_NEAR(fs.min_feature_distance, 2e-5, 1e-15);
  EXPECT_EQ(fs.closest_features, "segment (8, 9) and segment (10, 11)");

  Plc near_seg = UnitCubePlc();  // an isolated point 3e-4 from a free segment
  near_seg.vertices.insert(near_seg.vertices.end(), {{0.2, 0.5, 0.5}, {0.8, 0.5, 0.5}, {0.4, 0.5003, 0.5}});
  near_seg.segments = {{8, 9, 0}};
  const FeatureComplex fn = MustBuild(near_seg);
  EXPECT_NEAR(fn.min_feature_distance, 3e-4, 1e-12);
  EXPECT_EQ(fn.closest_features, "point 10 (0.4, 0.5003, 0.5) and segment (8, 9)");

  const FeatureComplex cube = MustBuild(UnitCubePlc());  // no two disjoint features closer than the side
  EXPECT_NEAR(cube.min_feature_distance, 1, 1e-15);
  EXPECT_FALSE(cube.closest_features.empty());
}

// A point crease off every crease segment: two edges of two coplanar facets
// meeting at 0.5°. Session 51: random_plcs.py hull+rot 65 has 0.42° at its
// point 4, and `svrc validate` said only "8 vertices (angle < 90 deg)". The
// point keeps its angle and the complex names its sharpest feature.
TEST(Features, PointCreaseKeepsItsAngle) {
  // The unit cube with its bottom face cut into a sliver triangle (0, 1, 8)
  // and the rest, vertex 8 = (1, tan 0.5°, 0) on the edge from 1 to 2.
  Plc plc = UnitCubePlc();
  plc.vertices.push_back({1, std::tan(0.5 * kDeg), 0});
  plc.facets[0] = Tri(0, 1, 8);
  plc.facets.push_back(Quad(0, 8, 2, 3));
  const FeatureComplex fc = MustBuild(plc);
  EXPECT_EQ(fc.NumCreaseSegments(), 0u);
  EXPECT_TRUE(fc.points[0].crease);
  EXPECT_NEAR(fc.points[0].min_angle, 0.5 * kDeg, 1e-12);
  std::string where;
  EXPECT_NEAR(fc.SharpestAngleDeg(&where), 0.5, 1e-9);
  EXPECT_EQ(where, "point 0 (0, 0, 0)");

  const FeatureComplex cube = MustBuild(UnitCubePlc());  // every angle 90°: no crease, the sharpest is 90°
  for (const FeaturePoint& q : cube.points) EXPECT_NEAR(q.min_angle, 90 * kDeg, 1e-9);
  EXPECT_NEAR(cube.SharpestAngleDeg(&where), 90, 1e-6);
  EXPECT_FALSE(where.empty());
  const FeatureComplex wedge = MustBuild(Wedge(30));  // the ridge's dihedral (its end points see 30° too)
  EXPECT_NEAR(wedge.SharpestAngleDeg(&where), 30, 1e-6);
  EXPECT_FALSE(where.empty());
}

TEST(Features, ExampleHoleAndRegions) {
  const FeatureComplex ex = MustBuildFile("b_internal/example.poly");
  // Facet 3 has a hole loop (the inner box's face fills it with facet 20).
  const FeatureFacet& f3 = ex.facets[2];
  ASSERT_EQ(f3.loops.size(), 2u);
  EXPECT_FALSE(f3.loop_is_hole[0]);
  EXPECT_TRUE(f3.loop_is_hole[1]);
  EXPECT_EQ(f3.triangles.size(), 8u);  // quad with a quad hole
  EXPECT_EQ(ex.regions.size(), 2u);
  EXPECT_EQ(ex.holes.size(), 2u);
  // The slanted internal facet 2 meets the upper box walls at 63.4°.
  EXPECT_EQ(ex.NumCreaseSegments(), 2u);
  const SegmentId s = ex.FindSegment(6, 7);
  ASSERT_NE(s, kNoId);
  EXPECT_NEAR(ex.segments[s].min_angle, std::atan2(2, 1), 1e-12);
}

}  // namespace
}  // namespace svrc::plc

namespace svrc::plc {
namespace {

double TriArea(const FeatureComplex& fc, const std::array<PointId, 3>& t) {
  return 0.5 * geom::Norm(geom::Cross(fc.points[t[1]].p - fc.points[t[0]].p,
                                      fc.points[t[2]].p - fc.points[t[0]].p));
}

double LoopArea(const FeatureComplex& fc, const std::vector<PointId>& loop) {
  geom::Vec3 n;
  for (size_t i = 0; i < loop.size(); ++i) {
    n += geom::Cross(fc.points[loop[i]].p, fc.points[loop[(i + 1) % loop.size()]].p);
  }
  return 0.5 * geom::Norm(n);
}

// Each facet's triangulation covers exactly its pieces minus its holes.
TEST(Features, TriangulationsCoverFacetsMinusHoles) {
  for (const char* rel : {"f_real/hinge.stl", "b_internal/example.poly", "c_creases/knife_edge.poly",
                          "d_small_angles/segment_fan.poly"}) {
    SCOPED_TRACE(rel);
    const FeatureComplex fc = MustBuildFile(rel);
    size_t with_holes = 0;
    for (const FeatureFacet& f : fc.facets) {
      double tri = 0, expect = 0;
      for (const auto& t : f.triangles) tri += TriArea(fc, t);
      size_t holes = 0;
      for (size_t l = 0; l < f.loops.size(); ++l) {
        if (f.loop_is_hole[l]) {
          expect -= LoopArea(fc, f.loops[l]);
          ++holes;
        } else if (l == 0) {
          expect += LoopArea(fc, f.loops[l]);  // pieces here: the first loop only
        }
      }
      EXPECT_EQ(holes, f.holes.size());
      with_holes += holes;
      EXPECT_NEAR(tri, expect, 1e-9 * std::max(1.0, expect));
    }
    if (std::string(rel) == "f_real/hinge.stl") {
      // 10 merged-facet holes (7 when only exactly coplanar faces merged,
      // before session 39).
      EXPECT_EQ(with_holes, 10u);
    }
  }
}

}  // namespace
}  // namespace svrc::plc
