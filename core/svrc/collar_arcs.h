// The 2D collar system of a facet plane — "arcs and points" (thesis §2.4.1,
// Definition 26 restricted to a plane; §3.1.2 Definition 37: CD (2,1) and (2,2))
// and the restricted Delaunay of a facet mesh to it (Definitions 28–30, 34 and
// 38 in 2D; guide "Restricted Delaunay of S", "Facet mesh (2D)"; stage (e)).
//
// Everything is computed in the plane's (u, v) coordinates, as the facet mesh
// M_F decides (docs/svrc-design.md §2): ball ∩ plane is a disk (centre, radius
// constructed once); every in/out decision is the exact predicate InBall on the
// disk lifted to z = 0 (an exact 2D in-disk test against the constructed disk).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/delaunay/delaunay2.h"
#include "core/geometry/vec3.h"
#include "core/plc/features.h"
#include "core/svrc/collar_geometry.h"

namespace svrc::refine {

using geom::Vec2;

inline constexpr uint32_t kNoArcIndex = 0xFFFFFFFFu;

// Ball ∩ plane in plane coordinates: a disk of the ball `ball` whose sphere
// crosses the plane (PlaneSphereCircle; the centre is the projection of the
// ball's centre, radius² = (ρ − h)(ρ + h), h the centre's height).
struct PlaneCircle {
  uint32_t ball = 0;  // index into the balls span given to FacetCollars
  Vec2 center;
  double radius = 0;
};

// One arc of the 2D collar description (Definition 26 in a plane): the points
// center + r(cos θ, sin θ) of circle `circle`, θ ∈ [t0, t0 + length], that are
// not strictly inside another ball. `full`: the whole circle (length 2π, no
// ends). Otherwise both ends are (2,1) points (end[0] at t0, end[1] at
// t0 + length; kNoArcIndex only if an end could not be matched, see
// FacetCollarSystem::unmatched_ends). θ is counter-clockwise in (u, v).
struct CollarArc {
  uint32_t circle = 0;  // index into FacetCollarSystem::circles
  uint32_t ball = 0;    // the circle's ball
  double t0 = 0;
  double length = 0;    // in (0, 2π]
  bool full = false;
  uint32_t end[2] = {kNoArcIndex, kNoArcIndex};  // indices into points21
};

// A (2,1) point (Definition 37: "points where collar circles intersect input
// facets"): the circles of balls a < b cross here and no other ball contains it
// strictly. It ends one arc of each of the two circles. Its RepBall has radius
// 0 (Definition 38, 2D item 2): it must be a vertex of the facet mesh.
struct Point21 {
  Vec2 x;
  uint32_t a = 0, b = 0;            // balls
  uint32_t circle_a = 0, circle_b = 0;  // indices into circles
};

// The collar description of one plane: circles (ascending ball), arcs (by
// circle, then counter-clockwise from angle −π), (2,1) points (by ball pair,
// then the two intersection points in a fixed order). Deterministic.
struct FacetCollarSystem {
  std::vector<PlaneCircle> circles;
  std::vector<CollarArc> arcs;
  std::vector<Point21> points21;
  // Arc ends from ClipCircleByBalls not within 1e-6 rad of a (2,1) point of
  // their circle (only near tangencies or triple points, which the thesis
  // excludes by perturbing collar radii, §2.4.2). 0 in the generic case.
  int unmatched_ends = 0;

  // Point of arc `a` at arc parameter s ∈ [0, length] (angle t0 + s).
  Vec2 ArcPoint(uint32_t a, double s) const;
};

// The 2D collar description of `frame`'s plane (plc::FacetFrame: origin and
// orthonormal u, v; the normal used is u × v): for every ball whose sphere
// crosses the plane, its circle and the arcs of it not strictly inside any
// other ball (ClipCircleByBalls; an arc through the frame's angle 0 is joined
// back into one), and the (2,1) points where two circles meet outside every
// other ball. Arc ends are snapped to the (2,1) points (same coordinates, so a
// vertex inserted at one is exactly the end of both arcs).
FacetCollarSystem FacetCollars(const plc::FacetFrame& frame, std::span<const CollarBall> balls);

// Options for the classification of facet-mesh vertices as lying on an arc.
struct ArcOptions {
  // Snap (thesis §3.1.2): a vertex within snap·r of an arc's circle (and within
  // its angular range) counts as on the arc. The floor is the rounding of a
  // constructed point, 64·2⁻⁵³·(|centre|∞ + r).
  double snap = 0;
  // Repair restricted edges with a vertex off their arc (kOffArcVertex). With
  // it, every restricted path runs through on-arc vertices only, so every
  // restricted edge is a chord and its representation angle is 0 (Definition
  // 34: the bisector of two points of a circle passes through its centre) —
  // σ then binds only on the way. Off: the thesis' criteria alone
  // (consistency + σ), which do not give chords (docs/svrc-collars.md).
  bool require_on_arc = true;
  // Size test (guide "Restricted Delaunay of S", the simpler alternative of
  // Ch. 6): repair a restricted edge whose RepBall radius exceeds
  // eps·(its circle's radius) — the in-plane circle radius, which bounds the
  // angle a chord subtends at the circle's centre by 4·asin(eps/2). 0: off.
  // Default 1 (≤ 120°, the chords of an inscribed triangle): consistency
  // alone accepts one chord for a 263° arc, and the fan (crease point, chord)
  // of RipStitchCollar is on the wrong side of a chord subtending > 180°.
  double eps = 1;
};

// A restricted Delaunay edge of an arc (Definition 28 in 2D): the Voronoi edge
// of Delaunay edge (a, b) — the segment between the circumcentres of its two
// triangles, or the outward ray of a hull edge — meets the arc at x.
struct ArcEdge {
  delaunay::Delaunay2::VertexId a, b;  // a.value() < b.value()
  uint32_t arc = 0;
  Vec2 x;                 // representation point (on the circle, radially projected)
  double s = 0;           // arc parameter of x
  double rep_radius = 0;  // RepBall B(x, |x − a|) (Definition 38, 2D item 1)
  double angle = 0;       // representation angle (Definition 34 in 2D), radians
  uint32_t crossings = 0; // crossings of this Voronoi edge with all arcs; ≠ 1 violates (a)
};

// All restricted edges of all arcs of `system` in `dt`, sorted by (arc, s).
// Each finite Delaunay edge is visited once (triangle slot order); each root
// of its Voronoi edge with a circle (SegmentSphere on the lifted disk, then
// projected radially onto the circle) is kept iff it is not strictly inside
// another disk (exact InBall) and assigned to the arc of that circle containing
// its angle (the nearest one at rounding-level ends).
// `index_circles` = false tests every Voronoi edge against every circle (the
// reference the grid of circle boxes is checked against; same output).
std::vector<ArcEdge> RestrictedArcEdges(const delaunay::Delaunay2& dt,
                                        const FacetCollarSystem& system, bool index_circles = true);

// Why a repair point is wanted (guide (a)–(e) in 2D, plus the facet's need of
// vertices on the arc and the angle bound σ of §3.1.2).
enum class ArcRepairReason : uint8_t {
  kMissingPoint21,     // a (2,1) point is not a vertex (radius-0 RepBall)
  kMultipleCrossings,  // (a) a Voronoi edge crosses the arcs more than once
  kBrokenPath,         // (b)/(c) an arc's restricted edges are not one simple path
                       // (cycle) in arc order between its ends, or a vertex has
                       // more than 2 restricted edges on one arc
  kEmptyArc,           // (d) a non-empty arc without restricted edges
  kOffArcVertex,       // a restricted edge has a vertex not on its arc: the chord
                       // chain M_F needs (RipStitchCollar) would miss it
  kAngle,              // representation angle > σ
  kSize,               // RepBall radius > ArcOptions::eps · circle radius
};
const char* ArcRepairReasonName(ArcRepairReason r);

// A point of the collar system to insert into M_F: the centre of a RepBall
// to destroy (Definition 38). collar_dim 1: a (2,1) point; 2: a point on an arc
// (Definition 37, CD (2,1) / (2,2)). radius: the RepBall radius (0 for (2,1)
// points); insert the largest first. x lies on circle `ball` (to rounding) and
// not strictly inside any other ball; it is never an existing vertex.
struct ArcRepair {
  Vec2 x;
  uint32_t ball = 0;                  // the circle's ball (for (2,1): the smaller)
  uint32_t other_ball = kNoArcIndex;  // (2,1): the other ball
  uint32_t arc = kNoArcIndex;         // dim 2: the arc; dim 1: kNoArcIndex
  uint32_t point21 = kNoArcIndex;     // dim 1: index into points21
  int collar_dim = 2;
  double radius = 0;
  ArcRepairReason reason = ArcRepairReason::kAngle;
};

// What ArcRepairs saw (counts of violations, before deduplication).
struct ArcReport {
  int restricted_edges = 0;
  int missing_points21 = 0;
  int multi_crossings = 0;   // Voronoi edges crossing the arcs ≥ 2 times
  int broken_arcs = 0;       // arcs failing the path/cycle test
  int high_degree = 0;       // (vertex, arc) pairs with > 2 restricted edges
  int empty_arcs = 0;
  int off_arc_edges = 0;     // restricted edges with a vertex off their arc
  int bad_angles = 0;        // restricted edges with angle > σ
  int too_large = 0;         // restricted edges failing the size test
  double max_angle = 0;      // over all restricted edges, radians
  int skipped = 0;           // repair points equal to a vertex or outside dt's square
};

// The repairs that make `dt` a consistent sample of `system` with
// representation angles ≤ sigma (radians) and chords on the arcs. One repair
// per offending restricted edge (its representation point; for a broken
// arc, the crossing with the largest RepBall among the offending ones), per
// missing (2,1) point and per empty arc (the arc point farthest from the vertex
// whose cell holds the arc: the largest gap). Deterministic order:
// (2,1) points, then by (arc, s). An empty result means: all (2,1) points are
// vertices; each Voronoi edge crosses the arcs at most once; each arc's
// restricted edges form one simple path from end[0] to end[1] (a cycle for a
// full circle), its on-arc vertices in arc order; σ holds; and, per `opts`,
// every path vertex is on the arc (require_on_arc) and RepBalls are ≤ eps·r.
std::vector<ArcRepair> ArcRepairs(const delaunay::Delaunay2& dt, const FacetCollarSystem& system,
                                  double sigma, ArcReport* report = nullptr,
                                  const ArcOptions& opts = {});

// True iff vertex p lies on arc `a` (ArcOptions::snap; a (2,1) point given
// exactly is on both of its arcs).
bool OnArc(Vec2 p, const FacetCollarSystem& system, uint32_t a, const ArcOptions& opts = {});

// The chord chain of one arc in M_F: the vertices of dt on the arc in arc
// order (for a full circle from the smallest arc parameter). `complete` iff
// (non-full) the first/last are the (2,1) ends, or (full) there are ≥ 3; and
// every two consecutive vertices (and last → first for a full circle) are
// joined by a dt edge.
struct ArcChain {
  uint32_t arc = 0;
  bool closed = false;
  bool complete = false;
  std::vector<delaunay::Delaunay2::VertexId> vertices;
};
std::vector<ArcChain> ArcChains(const delaunay::Delaunay2& dt, const FacetCollarSystem& system,
                                const ArcOptions& opts = {});

// What RipStitchCollar needs of M_F (thesis Figure 3.12, Theorem 4's facet
// case): every arc is a complete chain of dt edges between vertices on it.
bool ArcChordsPresent(const delaunay::Delaunay2& dt, const FacetCollarSystem& system,
                      const ArcOptions& opts = {});

// --- Back to 3D through the facet frame (x = origin + s·u + t·v) ------------

struct ArcChain3 {
  uint32_t arc = 0, ball = 0;
  bool closed = false;
  std::vector<Vec3> points;
};
std::vector<ArcChain3> ArcChainsToSpace(const plc::FacetFrame& frame,
                                        const delaunay::Delaunay2& dt,
                                        const FacetCollarSystem& system,
                                        std::span<const ArcChain> chains);
// The 3D position of a repair (on the sphere of repair.ball and on the plane,
// to rounding).
Vec3 RepairToSpace(const plc::FacetFrame& frame, const ArcRepair& repair);

}  // namespace svrc::refine
