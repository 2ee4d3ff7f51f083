// Generated PLC families for tests and benchmarks (issues #5 and #6): boxes
// with internal facets, holes, cavities and tunnels, nested regions, free
// segments and isolated points, two skew lines of points (Delaunay complexity
// Ω(N²), thesis §1.5.1) and crease inputs (facets and segments
// meeting at small angles, thesis Definitions 4-5). Every family is
// deterministic and passes PreparePlc (validate.h); coordinates are chosen so
// that planarity and incidences hold exactly in doubles (docs/plc.md §2, §4).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "core/plc/plc.h"

namespace svrc::plc::families {

// Facet markers used by the families (so that a mesh's triangle markers tell
// which feature a boundary triangle came from).
inline constexpr int32_t kWallMarker = 1;      // the bounding box's walls
inline constexpr int32_t kInternalMarker = 2;  // internal facets / inner surfaces
inline constexpr int32_t kCreaseMarker = 3;    // the facets meeting at a crease

// Unit box [0,1]^3 split by k >= 1 internal facets x = i/(k+1), i = 1..k.
// The walls are split into k+1 rectangles each so that every internal facet's
// edges are wall edges. One region seed per slab, attribute = slab index + 1.
Plc BoxWithInternalFacets(int k);

// Unit box with a closed cubical void of side `side` (0 < side < 1) centred in
// it, removed by a volume hole seed at its centre.
Plc BoxWithCubicalHole(double side);

// Unit box with a closed cubical cavity of side `side` centred in it, kept as
// a second region: region seeds outside (attribute 1) and inside (2).
Plc BoxWithCavity(double side);

// Unit box pierced along z by a square tunnel [0.5±side/2]^2 (genus 1): the
// top and bottom facets each have a square hole (second polygon + facet hole
// seed) and four quads line the tunnel.
Plc BoxWithTunnel(double side);

// Unit box split at z = 1/2 by an internal square facet (edges on the side
// walls, which are split into two rectangles each) that has a regular
// `hole_sides`-gon hole (>= 3) of circumradius `hole_radius` (< 0.5) centred
// at (1/2, 1/2, 1/2), removed by a facet hole seed. The two halves connect
// through the hole: one region, and validation reports the facet as an
// internal fin (a warning: its hole edges have it on one side only).
// BoxWithTunnel is the closed variant whose facets with holes bound the volume.
Plc InternalFacetWithHole(int hole_sides, double hole_radius);

// Unit box with `num_segments` free segments (segment i, marker 10+i, lies in
// the plane z = (i+1)/(num_segments+1), so no two meet) and `num_points` isolated
// points, uniform in [0.1, 0.9]^3 from std::mt19937_64(seed) (53-bit
// mantissas taken from the raw integers, so identical on every platform).
Plc FreeSegmentsAndPoints(int num_segments, int num_points, uint64_t seed);

// `levels` >= 1 nested cubes centred at (1/2,1/2,1/2), half-sides 2^-(i+1),
// i = 0..levels-1 (the outermost is the unit box). Region i (between cube i
// and cube i+1, the innermost cube's inside for the last) gets attribute i+1
// and max volume outer_max_volume * volume_ratio^i (no bound if
// outer_max_volume <= 0).
Plc NestedBoxes(int levels, double outer_max_volume, double volume_ratio);

// Cube [0, side]^3 with one region seed carrying `max_volume` (the
// volume-constrained cube of issue #5's output-sensitivity benchmark).
Plc VolumeConstrainedCube(double side, double max_volume);

struct SkewLinesOptions {
  bool segments = true;      // the two lines are input segments
  bool bounding_box = true;  // inside the unit box (else: only the lines)
};
// n >= 2 points on each of two orthogonal skew lines: (t, 1/2, 1/4) and
// (1/2, t, 3/4), t = 1/8 + (3/4)·i/(n-1); with `segments`, each line is a
// chain of n-1 free segments (markers 1 and 2). Without segments and box this
// is a point set whose Delaunay triangulation has Θ(n²) tetrahedra.
Plc SkewLines(int n, const SkewLinesOptions& options = {});

// Crease families (issue #6). Both inside the unit box.
//
// Two quads sharing the hinge line (1/4, y, 1/2), y in [0,1], at dihedral
// angle `angle_deg` (0 < angle < 180), symmetric about z = 1/2, length 1/2.
// Each quad spans the box in y: its edges at y = 0 and y = 1 are in-facet
// segments of the front and back walls (quads are y-extrusions, hence exactly
// planar). Their far edges are free (internal fins). The hinge is a crease
// segment with min_angle = angle_deg.
Plc CreaseFacetPair(double angle_deg);

// A free segment from (1/4, 1/2, 0) on the floor z = 0, rising at
// `angle_deg` to the floor in the x direction, length 1/2. Its foot ends an
// in-facet segment of the floor going to (1/8, 1/2, 0), away from it (the
// pair makes 180° - angle_deg), so the segment-facet angle is the only
// crease pair at the foot.
Plc SegmentFacetAngle(double angle_deg);

// k >= 2 quads around the hinge line (1/2, y, 1/2), y in [0,1], the i-th in
// direction (cos, 0, sin)(i * spacing_deg), length 0.4; edges on the front and
// back walls as in CreaseFacetPair. Needs (k-1)*spacing_deg < 360; the
// smallest dihedral at the hinge is min(spacing, 360 - (k-1)*spacing).
Plc FacetFan(int k, double spacing_deg);

// The tetrahedron (0,0,0), (1,0,0), (1/2,9/10,0), (1/2,3/10,3/20): its side
// facets meet the base at ~26.6°, so all three base edges are creases below
// 45° and its collar system needs neck splits (docs/svrc-collars.md,
// "Wiring status (session 5)"). Not in StandardInputs().
Plc FlatTetrahedron();

// A generated input with what a benchmark should do with it.
struct GeneratedInput {
  std::string name;         // file-name friendly, e.g. "crease_pair_5deg"
  std::string description;  // one line
  Plc plc;
  double max_volume = 0;    // global bound to pass the mesher (<= 0: none)
  // The smallest crease angle built in (degrees), 0 if the family has none
  // (informational; crease analysis decides).
  double crease_angle_deg = 0;
};

// The standard list used by bench/svrc/plc_bench.cc: every family above with
// small parameters (each meshes in well under a second with tetgen -pq2),
// then the crease families at 30, 10, 5, 1 and 0.1 degrees.
std::vector<GeneratedInput> StandardInputs();

// TetGen .poly text of `plc` (1-based, %.17g so doubles round-trip): nodes
// (with markers if present), facets (free segments become facets made of one
// 2-vertex polygon, as ReadPlcFile reads them back), volume holes, regions
// (max volume -1 when unbounded).
std::string PolyText(const Plc& plc);
// TetGen .node text of the vertices only (a point set).
std::string NodeText(const Plc& plc);
// Writes PolyText (or NodeText when `path` ends in ".node") to `path`.
absl::Status WritePoly(const Plc& plc, const std::string& path);

}  // namespace svrc::plc::families
