// The feature complex the mesher works on: the validated PLC as points,
// segments (every 1D feature, split at points lying on it) and facets with a
// plane frame, plus crease flags (thesis Definitions 4-5) and the spread Δ
// (Definition 3). Built by BuildFeatureComplex after validation (validate.h).
// Decisions (tolerances, crease rule, Δ) are in docs/plc.md.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/geometry/vec3.h"
#include "core/plc/plc.h"

namespace svrc::plc {

using geom::Vec2;
using geom::Vec3;

using PointId = uint32_t;
using SegmentId = uint32_t;
using FacetId = uint32_t;
inline constexpr uint32_t kNoId = std::numeric_limits<uint32_t>::max();

// A point of the complex: every distinct input vertex (exact duplicates
// merged; the first occurrence keeps its position in input order).
struct FeaturePoint {
  Vec3 p;
  int32_t marker = 0;       // input vertex marker of the first occurrence (0 if none)
  bool crease = false;      // a crease (Def. 5), or an endpoint of a crease segment
  bool isolated = false;    // on no segment and no facet (a lone input vertex)
  // Smallest angle (radians) between two features meeting at the point that
  // share no segment there (segment–segment, segment–facet, facet–facet; the
  // point test of Def. 5); +inf if there are no two. A crease segment's
  // dihedral is FeatureSegment::min_angle, not counted here.
  double min_angle = std::numeric_limits<double>::infinity();
  // Facets whose interior contains this point (it is on no segment of the facet):
  // isolated interior points of a facet (TetGen inserts them; so do we).
  std::vector<FacetId> interior_of;
};

// A segment of the complex between two points, with no point of the complex
// strictly inside it. Every free input segment and every facet polygon edge is
// split at the points lying exactly on it; equal pieces are merged.
struct FeatureSegment {
  PointId a = kNoId, b = kNoId;     // a < b
  std::vector<FacetId> facets;      // facets containing it (boundary or in-facet), sorted
  bool is_free = false;             // (part of) a free input segment (Plc::segments)
  int32_t marker = 0;               // marker of the free input segment (0 otherwise)
  bool crease = false;              // Def. 5 (two features containing it meet below 90°)
  // Smallest angle (radians) between two features containing it, measured
  // orthogonally to it (dihedral for two facets); +inf if fewer than two.
  double min_angle = std::numeric_limits<double>::infinity();
};

// Orthonormal frame of a facet's plane: x = origin + s*u + t*v (+ h*normal).
// origin is the first point of the facet's first loop; normal is the
// normalised Newell normal of that loop (right-handed: u x v = normal).
struct FacetFrame {
  Vec3 origin, u, v, normal;
  Vec2 ToPlane(Vec3 x) const {
    const Vec3 d = x - origin;
    return {geom::Dot(d, u), geom::Dot(d, v)};
  }
  Vec3 ToSpace(Vec2 st) const { return origin + st.x * u + st.y * v; }
};

struct FeatureFacet {
  FacetFrame frame;
  // Closed polygons (>= 3 points) as point-id loops in input order, with the
  // points lying exactly on their edges inserted (collinear points kept).
  // loop_is_hole[i]: loop i bounds a hole of the facet (a hole seed lies inside
  // it and in no loop nested in it); the other loops bound pieces of the facet
  // or are in-facet polygons.
  std::vector<std::vector<PointId>> loops;
  std::vector<bool> loop_is_hole;
  std::vector<SegmentId> segments;     // every segment lying in the facet, sorted
  // The subset with the facet on both sides: in-facet segments (2-vertex
  // polygons) and edges of in-facet polygons; the others bound the facet.
  std::vector<SegmentId> interior_segments;
  std::vector<PointId> interior_points;  // points in the facet on none of its segments
  std::vector<Vec3> holes;             // facet hole seeds (input)
  // A triangulation of the facet region (loops minus holes), point-id triples,
  // used by validation and crease angles; not a quality mesh.
  std::vector<std::array<PointId, 3>> triangles;
  int32_t marker = 0;
  uint32_t input_facet = kNoId;        // index in Plc::facets
};

struct FeatureComplex {
  std::vector<FeaturePoint> points;
  std::vector<FeatureSegment> segments;  // sorted by (a, b)
  std::vector<FeatureFacet> facets;      // one per input facet, same order
  // input vertex id -> point id (exact duplicates map to the same point).
  std::vector<PointId> point_of_vertex;
  // Free input segment i -> its pieces (in order from a to b).
  std::vector<std::vector<SegmentId>> pieces_of_free_segment;
  std::vector<Vec3> holes;               // volume hole seeds
  std::vector<RegionSeed> regions;

  // Spread Δ = diameter / smallest distance between two disjoint features
  // (docs/plc.md gives the exact definition); 0 if there are no two disjoint
  // features. `diameter` is the bounding-box diagonal of the points.
  double diameter = 0;
  double min_feature_distance = 0;
  double spread = 0;
  // The two features min_feature_distance is measured between, for messages:
  // "point 8 (x, y, z) and facet 7" (points numbered as in Plc::points from
  // 0, facets as in Plc::facets, a segment piece by its end points); empty
  // when spread is 0.
  std::string closest_features;

  size_t NumCreasePoints() const;
  // How messages name features: "point 3 (x, y, z)", "segment (a, b)"
  // (points numbered from 0, a segment by its end points).
  std::string PointName(PointId p) const;
  std::string SegmentName(SegmentId s) const;
  // The sharpest angle of the complex in degrees (the smallest point or
  // segment min_angle; +inf if none) and where, as PointName / SegmentName
  // give it (empty if none), for `svrc validate`.
  double SharpestAngleDeg(std::string* where) const;
  size_t NumCreaseSegments() const;
  // Segment id of the piece between a and b (either order), or kNoId.
  SegmentId FindSegment(PointId a, PointId b) const;
};

struct FeatureOptions {
  // Angle (degrees) below which two features meeting make a crease (Def. 5's α).
  double crease_angle_deg = 90.0;
  bool compute_spread = true;
};

// Builds the complex from a PLC that passed ValidatePlc (validate.h). Returns
// INVALID_ARGUMENT if the PLC is not valid (runs the validation itself when
// called on an unchecked PLC: dangling ids, non-finite coordinates, ...).
absl::StatusOr<FeatureComplex> BuildFeatureComplex(const Plc& plc,
                                                   const FeatureOptions& options = {});

}  // namespace svrc::plc
