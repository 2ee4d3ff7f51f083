// Generated PLC families (core/plc/families.h): every family passes
// validation with the intended counts, the crease families carry the crease
// at the intended angle (thesis Definitions 4-5, docs/plc.md §6) to 1e-9 rad,
// and PolyText round-trips through the .poly reader.
#include "core/plc/families.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "core/plc/features.h"
#include "core/plc/readers.h"
#include "core/plc/validate.h"
#include "gtest/gtest.h"

namespace svrc::plc::families {
namespace {

constexpr double kDeg = std::numbers::pi / 180;

struct Prepared {
  bool ok = false;
  FeatureComplex fc;
  ValidationReport report;
};

Prepared Prepare(const Plc& plc, double crease_angle_deg = 90) {
  Prepared p;
  FeatureOptions fo;
  fo.crease_angle_deg = crease_angle_deg;
  absl::StatusOr<FeatureComplex> fc = PreparePlc(plc, ValidationOptions{}, fo, &p.report);
  EXPECT_TRUE(fc.ok()) << plc.source_name << ": " << fc.status();
  EXPECT_TRUE(p.report.errors.empty()) << plc.source_name;
  if (fc.ok()) {
    p.ok = true;
    p.fc = *std::move(fc);
  }
  return p;
}

// Input vertex id with exactly these coordinates (the families build the
// vertices they talk about from exact constants).
uint32_t VertexAt(const Plc& plc, Vec3 p) {
  for (uint32_t i = 0; i < plc.vertices.size(); ++i) {
    if (plc.vertices[i] == p) return i;
  }
  ADD_FAILURE() << "no vertex at " << p.x << " " << p.y << " " << p.z << " in " << plc.source_name;
  return 0;
}

const FeatureSegment* Piece(const Prepared& p, const Plc& plc, Vec3 a, Vec3 b) {
  const SegmentId s = p.fc.FindSegment(p.fc.point_of_vertex[VertexAt(plc, a)],
                                       p.fc.point_of_vertex[VertexAt(plc, b)]);
  EXPECT_NE(s, kNoId);
  return s == kNoId ? nullptr : &p.fc.segments[s];
}

size_t CountIsolated(const FeatureComplex& fc) {
  return std::count_if(fc.points.begin(), fc.points.end(),
                       [](const FeaturePoint& p) { return p.isolated; });
}

bool HasWarning(const ValidationReport& r, ProblemKind kind) {
  return std::any_of(r.warnings.begin(), r.warnings.end(),
                     [&](const Problem& p) { return p.kind == kind; });
}

TEST(Families, BoxWithInternalFacets) {
  for (int k : {1, 3}) {
    const Plc plc = BoxWithInternalFacets(k);
    EXPECT_EQ(plc.vertices.size(), size_t(4 * (k + 2)));
    EXPECT_EQ(plc.facets.size(), size_t(2 + 4 * (k + 1) + k));
    ASSERT_EQ(plc.regions.size(), size_t(k + 1));
    EXPECT_EQ(plc.regions.back().attribute, k + 1);
    const Prepared p = Prepare(plc);
    ASSERT_TRUE(p.ok);
    EXPECT_TRUE(p.report.warnings.empty());
    EXPECT_EQ(p.fc.NumCreaseSegments(), 0u);
    EXPECT_EQ(p.fc.NumCreasePoints(), 0u);
    // An internal facet's edge carries the internal facet and two wall pieces.
    const double x = 1.0 / (k + 1);
    const FeatureSegment* e = Piece(p, plc, {x, 0, 0}, {x, 1, 0});
    ASSERT_NE(e, nullptr);
    EXPECT_EQ(e->facets.size(), 3u);
    EXPECT_NEAR(e->min_angle, 90 * kDeg, 1e-9);
  }
}

TEST(Families, HoleCavityTunnel) {
  const Plc hole = BoxWithCubicalHole(0.4);
  EXPECT_EQ(hole.vertices.size(), 16u);
  EXPECT_EQ(hole.facets.size(), 12u);
  ASSERT_EQ(hole.holes.size(), 1u);
  EXPECT_EQ(hole.holes[0], Vec3(0.5, 0.5, 0.5));
  const Prepared ph = Prepare(hole);
  ASSERT_TRUE(ph.ok);
  EXPECT_EQ(ph.fc.holes.size(), 1u);
  EXPECT_EQ(ph.fc.NumCreasePoints(), 0u);
  // The void is 0.3 away from the walls: the closest disjoint features.
  EXPECT_NEAR(ph.fc.min_feature_distance, 0.3, 1e-12);

  const Plc cavity = BoxWithCavity(0.4);
  EXPECT_TRUE(cavity.holes.empty());
  ASSERT_EQ(cavity.regions.size(), 2u);
  EXPECT_EQ(cavity.regions[1].point, Vec3(0.5, 0.5, 0.5));
  EXPECT_EQ(cavity.regions[1].attribute, 2);
  ASSERT_TRUE(Prepare(cavity).ok);

  const Plc tunnel = BoxWithTunnel(0.4);
  EXPECT_EQ(tunnel.vertices.size(), 16u);
  EXPECT_EQ(tunnel.facets.size(), 10u);
  const Prepared pt = Prepare(tunnel);
  ASSERT_TRUE(pt.ok);
  EXPECT_TRUE(pt.report.warnings.empty());
  EXPECT_EQ(pt.fc.NumCreasePoints(), 0u);
  for (int f : {0, 1}) {  // bottom and top: the outer square and the tunnel's hole
    ASSERT_EQ(pt.fc.facets[f].loops.size(), 2u);
    EXPECT_FALSE(pt.fc.facets[f].loop_is_hole[0]);
    EXPECT_TRUE(pt.fc.facets[f].loop_is_hole[1]);
    // A square annulus triangulates into 8 triangles.
    EXPECT_EQ(pt.fc.facets[f].triangles.size(), 8u);
  }
}

TEST(Families, InternalFacetWithHole) {
  for (int sides : {4, 7}) {
    const Plc plc = InternalFacetWithHole(sides, 0.25);
    EXPECT_EQ(plc.vertices.size(), size_t(12 + sides));
    ASSERT_EQ(plc.facets.size(), 11u);
    const Facet& mid = plc.facets.back();
    ASSERT_EQ(mid.polygons.size(), 2u);
    EXPECT_EQ(mid.polygons[1].vertices.size(), size_t(sides));
    ASSERT_EQ(mid.holes.size(), 1u);
    const Prepared p = Prepare(plc);
    ASSERT_TRUE(p.ok);
    // The hole's edges have the facet on one side only: the validator peels
    // the facet off as an internal fin (a warning); the box stays closed.
    ASSERT_EQ(p.report.warnings.size(), 1u);
    EXPECT_EQ(p.report.warnings[0].kind, ProblemKind::kDanglingFacet);
    EXPECT_EQ(p.report.warnings[0].ids, std::vector<uint32_t>{10});
    const FeatureFacet& ff = p.fc.facets.back();
    ASSERT_EQ(ff.loops.size(), 2u);
    EXPECT_TRUE(ff.loop_is_hole[1]);
    // Annulus of a square and a k-gon: 4 + k triangles (Euler, no interior points).
    EXPECT_EQ(ff.triangles.size(), size_t(4 + sides));
    EXPECT_EQ(p.fc.NumCreaseSegments(), 0u);
  }
}

TEST(Families, FreeSegmentsAndPoints) {
  const Plc plc = FreeSegmentsAndPoints(4, 20, 1);
  EXPECT_EQ(plc.vertices.size(), 8u + 8u + 20u);
  ASSERT_EQ(plc.segments.size(), 4u);
  for (const Vec3& v : plc.vertices) {
    EXPECT_TRUE(v.x >= 0 && v.x <= 1 && v.y >= 0 && v.y <= 1 && v.z >= 0 && v.z <= 1);
  }
  const Prepared p = Prepare(plc);
  ASSERT_TRUE(p.ok);
  EXPECT_EQ(CountIsolated(p.fc), 20u);
  EXPECT_EQ(p.fc.pieces_of_free_segment.size(), 4u);
  EXPECT_EQ(p.fc.segments.size(), 12u + 4u);
  // Deterministic, and the seed matters.
  EXPECT_EQ(PolyText(plc), PolyText(FreeSegmentsAndPoints(4, 20, 1)));
  EXPECT_NE(PolyText(plc), PolyText(FreeSegmentsAndPoints(4, 20, 2)));
}

TEST(Families, NestedBoxesAndVolumeCube) {
  const Plc plc = NestedBoxes(3, 1e-2, 0.125);
  EXPECT_EQ(plc.vertices.size(), 24u);
  EXPECT_EQ(plc.facets.size(), 18u);
  ASSERT_EQ(plc.regions.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(plc.regions[i].attribute, i + 1);
    EXPECT_DOUBLE_EQ(plc.regions[i].max_volume, 1e-2 * std::pow(0.125, i));
  }
  // Seeds strictly between consecutive shells (cube i has half-side 2^-(i+1)).
  EXPECT_EQ(plc.regions[0].point, Vec3(0.5 - 0.375, 0.5, 0.5));
  EXPECT_EQ(plc.regions[1].point, Vec3(0.5 - 0.1875, 0.5, 0.5));
  EXPECT_EQ(plc.regions[2].point, Vec3(0.5, 0.5, 0.5));
  const Prepared p = Prepare(plc);
  ASSERT_TRUE(p.ok);
  EXPECT_EQ(p.fc.regions.size(), 3u);
  EXPECT_NEAR(p.fc.min_feature_distance, 0.125, 1e-12);

  const Plc cube = VolumeConstrainedCube(2, 1e-3);
  ASSERT_EQ(cube.regions.size(), 1u);
  EXPECT_EQ(cube.regions[0].max_volume, 1e-3);
  EXPECT_EQ(cube.regions[0].point, Vec3(1, 1, 1));
  const Prepared pc = Prepare(cube);
  ASSERT_TRUE(pc.ok);
  EXPECT_EQ(pc.fc.points.size(), 8u);
  EXPECT_EQ(pc.fc.segments.size(), 12u);
}

TEST(Families, SkewLines) {
  const Plc plc = SkewLines(50);
  EXPECT_EQ(plc.vertices.size(), 108u);
  ASSERT_EQ(plc.segments.size(), 98u);  // two chains of 49
  const Prepared p = Prepare(plc);
  ASSERT_TRUE(p.ok);
  ASSERT_EQ(p.fc.pieces_of_free_segment.size(), 98u);
  EXPECT_EQ(p.fc.segments.size(), 98u + 12u);
  size_t free_pieces = 0;
  for (const FeatureSegment& s : p.fc.segments) free_pieces += s.is_free;
  EXPECT_EQ(free_pieces, 98u);
  EXPECT_EQ(CountIsolated(p.fc), 0u);
  // Consecutive points on a line are disjoint features 0.75/49 apart (the
  // lines are 1/2 apart, 1/4 from the floor and the ceiling).
  EXPECT_NEAR(p.fc.min_feature_distance, 0.75 / 49, 1e-12);

  const Plc pts = SkewLines(200, {.segments = false, .bounding_box = false});
  EXPECT_TRUE(pts.IsPointSet());
  EXPECT_EQ(pts.vertices.size(), 400u);
  const Prepared pp = Prepare(pts);
  ASSERT_TRUE(pp.ok);
  EXPECT_EQ(CountIsolated(pp.fc), 400u);
  EXPECT_NEAR(pp.fc.min_feature_distance, 0.75 / 199, 1e-12);
}

TEST(Families, CreaseFacetPairAngles) {
  for (double deg : {30.0, 10.0, 5.0, 1.0, 0.1}) {
    SCOPED_TRACE(deg);
    const Plc plc = CreaseFacetPair(deg);
    EXPECT_EQ(plc.vertices.size(), 14u);
    EXPECT_EQ(plc.facets.size(), 8u);
    const Prepared p = Prepare(plc);
    ASSERT_TRUE(p.ok);
    // The quads' far edges are free: internal fins, a warning, not an error.
    EXPECT_TRUE(HasWarning(p.report, ProblemKind::kDanglingFacet));
    const FeatureSegment* hinge = Piece(p, plc, {0.25, 0, 0.5}, {0.25, 1, 0.5});
    ASSERT_NE(hinge, nullptr);
    EXPECT_EQ(hinge->facets.size(), 2u);
    EXPECT_NEAR(hinge->min_angle, deg * kDeg, 1e-9);
    EXPECT_TRUE(hinge->crease);
    EXPECT_TRUE(p.fc.points[hinge->a].crease);
    EXPECT_TRUE(p.fc.points[hinge->b].crease);
    // The hinge is the only crease segment: quads meet the walls at 90°.
    EXPECT_EQ(p.fc.NumCreaseSegments(), 1u);
    // Where the hinge meets the front wall, the wall's two in-facet segments
    // open at the same angle (segment-segment pair).
    const Prepared below = Prepare(plc, deg * (1 - 1e-6));
    EXPECT_EQ(below.fc.NumCreaseSegments(), 0u);
    EXPECT_EQ(below.fc.NumCreasePoints(), 0u);
  }
  // Above 90°: no crease.
  const Prepared wide = Prepare(CreaseFacetPair(120));
  EXPECT_EQ(wide.fc.NumCreaseSegments(), 0u);
}

TEST(Families, SegmentFacetAngles) {
  for (double deg : {10.0, 1.0, 0.1}) {
    SCOPED_TRACE(deg);
    const Plc plc = SegmentFacetAngle(deg);
    ASSERT_EQ(plc.segments.size(), 1u);
    const Prepared p = Prepare(plc);
    ASSERT_TRUE(p.ok);
    const PointId foot = p.fc.point_of_vertex[plc.segments[0].a];
    const PointId tip = p.fc.point_of_vertex[plc.segments[0].b];
    // The foot ends an in-facet segment of the floor (facet 0).
    const FeatureSegment* in_floor = Piece(p, plc, {0.25, 0.5, 0}, {0.125, 0.5, 0});
    ASSERT_NE(in_floor, nullptr);
    EXPECT_EQ(in_floor->facets, std::vector<FacetId>{0});
    EXPECT_FALSE(in_floor->is_free);
    EXPECT_TRUE(p.fc.points[foot].crease);
    EXPECT_FALSE(p.fc.points[tip].crease);
    EXPECT_EQ(p.fc.NumCreasePoints(), 1u);
    EXPECT_EQ(p.fc.NumCreaseSegments(), 0u);
    // The segment-facet angle is the smallest pair at the foot (the in-facet
    // segment makes 180° - angle with the free one): a crease iff the
    // threshold (alpha - 1e-9 rad, creases.cc) exceeds it. Bracketing with
    // alpha = angle + 2e-9 rad and alpha = angle puts it within 1e-9 rad.
    const double rad = deg * kDeg;
    EXPECT_TRUE(Prepare(plc, (rad + 2e-9) / kDeg).fc.points[foot].crease);
    EXPECT_FALSE(Prepare(plc, rad / kDeg).fc.points[foot].crease);
  }
}

TEST(Families, FacetFanAngles) {
  struct Case {
    int k;
    double spacing, smallest;
  };
  for (const Case& c : {Case{6, 60, 60}, Case{8, 5, 5}, Case{3, 100, 100}, Case{4, 20, 20}}) {
    SCOPED_TRACE(c.k);
    const Plc plc = FacetFan(c.k, c.spacing);
    EXPECT_EQ(plc.vertices.size(), size_t(8 + 2 + 2 * c.k));
    EXPECT_EQ(plc.facets.size(), size_t(6 + c.k));
    const Prepared p = Prepare(plc);
    ASSERT_TRUE(p.ok);
    const FeatureSegment* hinge = Piece(p, plc, {0.5, 0, 0.5}, {0.5, 1, 0.5});
    ASSERT_NE(hinge, nullptr);
    EXPECT_EQ(hinge->facets.size(), size_t(c.k));
    EXPECT_NEAR(hinge->min_angle, c.smallest * kDeg, 1e-9);
    EXPECT_EQ(hinge->crease, c.smallest < 90);
  }
}

TEST(Families, StandardInputsValidateAndRoundTrip) {
  const std::vector<GeneratedInput> inputs = StandardInputs();
  ASSERT_GE(inputs.size(), 20u);
  const std::vector<GeneratedInput> again = StandardInputs();
  ASSERT_EQ(again.size(), inputs.size());
  std::vector<std::string> names;
  for (size_t i = 0; i < inputs.size(); ++i) {
    const GeneratedInput& in = inputs[i];
    SCOPED_TRACE(in.name);
    names.push_back(in.name);
    EXPECT_EQ(in.plc.source_name, in.name);
    const Prepared p = Prepare(in.plc);
    ASSERT_TRUE(p.ok);
    if (in.crease_angle_deg > 0 && in.crease_angle_deg < 90) {
      EXPECT_GT(p.fc.NumCreasePoints(), 0u);
    }
    // Deterministic text.
    const std::string text =
        in.plc.IsPointSet() ? NodeText(in.plc) : PolyText(in.plc);
    EXPECT_EQ(text, in.plc.IsPointSet() ? NodeText(again[i].plc) : PolyText(again[i].plc));
    // The text reads back to the same PLC.
    absl::StatusOr<Plc> back = ReadPlcBytes(
        text, in.plc.IsPointSet() ? InputFormat::kNode : InputFormat::kPoly, in.name);
    ASSERT_TRUE(back.ok()) << back.status();
    ASSERT_EQ(back->vertices.size(), in.plc.vertices.size());
    for (size_t v = 0; v < in.plc.vertices.size(); ++v) {
      EXPECT_EQ(back->vertices[v], in.plc.vertices[v]);
    }
    ASSERT_EQ(back->facets.size(), in.plc.facets.size());
    for (size_t f = 0; f < in.plc.facets.size(); ++f) {
      const Facet& a = back->facets[f];
      const Facet& b = in.plc.facets[f];
      EXPECT_EQ(a.marker, b.marker);
      ASSERT_EQ(a.polygons.size(), b.polygons.size());
      for (size_t k = 0; k < a.polygons.size(); ++k) {
        EXPECT_EQ(a.polygons[k].vertices, b.polygons[k].vertices);
      }
      ASSERT_EQ(a.holes.size(), b.holes.size());
      for (size_t h = 0; h < a.holes.size(); ++h) EXPECT_EQ(a.holes[h], b.holes[h]);
    }
    ASSERT_EQ(back->segments.size(), in.plc.segments.size());
    for (size_t s = 0; s < in.plc.segments.size(); ++s) {
      EXPECT_EQ(back->segments[s].a, in.plc.segments[s].a);
      EXPECT_EQ(back->segments[s].b, in.plc.segments[s].b);
      EXPECT_EQ(back->segments[s].marker, in.plc.segments[s].marker);
    }
    ASSERT_EQ(back->holes.size(), in.plc.holes.size());
    ASSERT_EQ(back->regions.size(), in.plc.regions.size());
    for (size_t r = 0; r < in.plc.regions.size(); ++r) {
      EXPECT_EQ(back->regions[r].point, in.plc.regions[r].point);
      EXPECT_EQ(back->regions[r].attribute, in.plc.regions[r].attribute);
      EXPECT_EQ(back->regions[r].max_volume > 0 ? back->regions[r].max_volume : 0,
                in.plc.regions[r].max_volume);
    }
  }
  std::sort(names.begin(), names.end());
  EXPECT_EQ(std::unique(names.begin(), names.end()), names.end()) << "duplicate names";
}

}  // namespace
}  // namespace svrc::plc::families
