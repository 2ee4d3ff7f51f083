// Collar geometry primitives (thesis §2.4.1, Definition 26; guide "Collars",
// "Restricted Delaunay of S"): sphere–sphere circles, segment/plane ∩ sphere,
// circle arcs clipped by other balls, "point on S", representation angles.
// Constructions are in double; every inside/outside decision goes through
// core/geometry/predicates.h (InBall, CompareDistance).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/geometry/vec3.h"

namespace svrc::refine {

using geom::Vec3;

// A collar ball B(center, radius) (Definition 26). radius > 0.
struct CollarBall {
  Vec3 center;
  double radius = 0;
};

// Segment pa–pb crosses the plane through `origin` with unit `normal`: its
// ends strictly on opposite sides beyond tol, or beyond the rounding of a
// point of the plane (16 ulps of the coordinates) when that is larger;
// *x = the crossing. A segment's collar point and a facet's own points lie on
// the facet's plane only up to rounding: on a slanted facet next to a small
// collar ball (random_plcs.py near+rot 9, ρ = 4.9e-6) a (1,2) point
// 6.9e-18 = 1.4e-12ρ off the plane passed tol = 1e-12ρ, the T′ edges from it
// "crossed" the facet, and the arc points put there were chased down to the
// resolution of doubles.
bool SegmentCrossesPlane(const Vec3& origin, const Vec3& normal, const Vec3& pa, const Vec3& pb, double tol,
                         Vec3* x);

// A circle in 3D: centre, unit normal, radius.
struct Circle3 {
  Vec3 center;
  Vec3 normal;
  double radius = 0;
};

// One circle of the collar description: where spheres of balls `a` < `b` meet.
struct CollarCircle {
  uint32_t a = 0, b = 0;
  Circle3 circle;
};

// Definition 26's ⟨circles, partial spheres⟩. Partial sphere i is the sphere of
// balls[i] minus the other balls; it is bounded by the circles listing i
// (a circle may itself be partly inside a third ball: clip it with
// ClipCircleByBalls).
struct CollarDescription {
  std::vector<CollarBall> balls;
  std::vector<CollarCircle> circles;        // sorted by (a, b)
  std::vector<std::vector<uint32_t>> circles_of_ball;  // indices into `circles`
};

// --- Constructions ----------------------------------------------------------------

// The circle where the spheres of b1 and b2 meet; false if the spheres do not
// cross (|c1c2| ≥ r1 + r2, |c1c2| ≤ |r1 − r2|, or concentric). The normal points
// from b1's centre to b2's. Radical-plane distance h1 = (d² + r1² − r2²)/(2d),
// radius² = (r1 − h1)(r1 + h1) (factored: no cancellation near tangency).
// Whether the spheres cross is a double comparison on constructed radii (collar
// radii are perturbed anyway, guide §5 item 2), not an exact predicate.
bool SphereSphereCircle(const CollarBall& b1, const CollarBall& b2, Circle3* out);

// Plane (point p0, normal n, any length) ∩ sphere: false if they do not meet.
bool PlaneSphereCircle(const Vec3& p0, const Vec3& n, const CollarBall& ball, Circle3* out);

// Roots s ∈ [0,1] of |a + s(b−a) − o|² = ρ², ascending; returns their count
// (0, 1 or 2). The count is decided exactly where it can be: endpoints strictly
// inside/outside via InBall; one endpoint in and one out gives exactly one root.
// When both are outside, two roots exist iff the segment's closest point to o
// is strictly inside (decided on that constructed point). Roots use the
// cancellation-free form q = −(B + sign(B)√disc), s₁ = q/A, s₂ = C/q.
int SegmentSphere(const Vec3& a, const Vec3& b, const CollarBall& ball, double s[2]);

// Segment ab lying in the plane of `circle` ∩ the circle: the same quadratic
// with the circle's centre and radius (a, b are assumed in its plane).
int SegmentCircleInPlane(const Vec3& a, const Vec3& b, const Circle3& circle, double s[2]);

// Point on a circle at angle t: center + r(cos t·u + sin t·w), (u, w) =
// CircleFrame(circle) (deterministic orthonormal frame ⟂ normal).
void CircleFrame(const Circle3& c, Vec3* u, Vec3* w);
Vec3 CirclePoint(const Circle3& c, double t);

// The point of `c` nearest p: p's offset from the centre projected onto the
// circle's plane, scaled to the radius. False when that projection is zero
// (p on the axis: every point of the circle is nearest).
bool NearestCirclePoint(const Circle3& c, const Vec3& p, Vec3* x);

// An arc [t0, t1] of angles (t0 < t1 ≤ t0 + 2π) in the CircleFrame.
struct Arc {
  double t0 = 0, t1 = 0;
};

// The parts of `circle` not strictly inside any of `others` (thesis §2.4.1: in a
// facet plane the collar surface is arcs and points). Each ball cuts an open
// angular interval (solving A cos t + B sin t > D); the complement is returned
// as sorted arcs in [0, 2π) (an arc through angle 0 is split in two). The arc
// ends are constructions; decide membership of a point with InsideAnyBall. If no
// ball cuts the circle: one arc [0, 2π]. Empty if the circle is covered.
std::vector<Arc> ClipCircleByBalls(const Circle3& circle, std::span<const CollarBall> others);

// --- Decisions ----------------------------------------------------------------------

// "x is on S" for a point constructed on sphere `self` of `balls`: x is not
// strictly inside any other ball (InBall ≤ 0 for all j ≠ self). The caller
// guarantees x was constructed on sphere `self` (rounded).
bool OnCollarSurface(const Vec3& x, uint32_t self, std::span<const CollarBall> balls);

// True iff p is strictly inside some ball of `balls` (exact, InBall).
bool InsideAnyBall(const Vec3& p, std::span<const CollarBall> balls);

// Definition 26: builds circles for every pair of balls whose spheres cross.
// O(n²) pairs; the refiner builds the same incrementally from BLG neighbours.
CollarDescription BuildCollarDescription(std::span<const CollarBall> balls);

// Definition 34: angle in [0, π/2] between the line direction `dir` (a Voronoi
// edge, ∝ the normal of its triangle) and the sphere normal x − o. atan2 of
// |cross| and |dot| (accurate at 0 and π/2).
double RepresentationAngle(const Vec3& dir, const Vec3& x, const Vec3& o);

// Definition 34 for circles: angle in [0, π/2] between edge ab and the tangent
// of `circle` at x (the tangent is normal × (x − center)).
double CircleRepresentationAngle(const Vec3& a, const Vec3& b, const Circle3& circle,
                                 const Vec3& x);

// Angle in [0, π] between two vectors (atan2 form).
double AngleBetween(const Vec3& u, const Vec3& v);

// --- Dihedral angles of stitched tets (RipStitchCollar, Figure 3.12) -----------
// The bounds are derived in docs/svrc-collars.md §1; angles in radians.

// Interior dihedral angle of tet (p, q, r, s) at edge pq.
double DihedralAtEdge(const Vec3& p, const Vec3& q, const Vec3& r, const Vec3& s);

// Star tet (o, a, b, c): o the crease vertex (sphere centre), abc a restricted
// triangle. base = edges of abc, radial = edges oa, ob, oc.
struct StarDihedrals {
  double max_base = 0, max_radial = 0;
};
StarDihedrals MeasureStar(const Vec3& o, const Vec3& a, const Vec3& b, const Vec3& c);

// Book tet (v, w, a, b): vw the crease edge (axis of the circle), ab a
// restricted edge of the circle. side = edges va, vb, wa, wb.
struct BookDihedrals {
  double at_ab = 0, at_axis = 0, max_side = 0;
};
BookDihedrals MeasureBook(const Vec3& v, const Vec3& w, const Vec3& a, const Vec3& b);

// Star bound (doc Theorem 1) from the representation angle σ, ε = RepBall
// radius / sphere radius and γ = the triangle's largest plane angle:
//   base   ≤ π/2 + atan((sin σ + ε) / (cos σ − ε))
//   radial ≤ 2·atan(tan(γ/2) / cos(σ + asin ε))
// valid iff ε < cos σ and σ + asin ε < π/2 (otherwise the tet may be inverted).
struct StarBound {
  bool valid = false;
  double base = 0, radial = 0;
};
StarBound StarDihedralBound(double sigma, double eps, double gamma);

// Book bound (doc Theorem 2) from the circle representation angle σ,
// ε = max(|xa|, |xb|) / circle radius, and α = ∠ v m w at the midpoint m of ab
// (α → the angle between the two sphere normals at the circle, ≤ π/2 for a
// smooth collar system, Lemma 14):
//   at ab ≤ 2·atan(tan(α/2) / cos(σ + asin ε)),  side ≤ π/2 + σ + asin ε,
//   at vw ≤ 2·asin ε.   valid iff ε < 1 and σ + asin ε < π/2.
struct BookBound {
  bool valid = false;
  double at_ab = 0, side = 0, axis = 0;
};
BookBound BookDihedralBound(double sigma, double eps, double alpha);

// The shape of RipStitchCollar's stars and books (StitchResult::shape, the
// final stitch's in RefineStats::stitch): measured extremes (degrees) and the
// bounds above at the measured extremes σ_max, ε_max, γ_max / α_max; the
// bounds are monotone in each argument, so every tet's own bound is ≤ these.
// Per tet: a star/book whose own σ, ε (and γ / α) meet its theorem's
// premises is "bounded"; a bounded tet with a dihedral above its own bound
// (1e-9 rad slack) is a violation — the derivation would be wrong. The
// largest dihedral of the bounded and of the other tets, degrees.
struct StitchShape {
  double max_star_base_deg = 0, max_star_radial_deg = 0;
  double star_sigma_max_deg = 0, star_eps_max = 0, star_gamma_max_deg = 0;
  bool star_bound_valid = false;
  double star_bound_base_deg = 0, star_bound_radial_deg = 0;
  double max_book_ab_deg = 0, max_book_side_deg = 0, max_book_axis_deg = 0;
  double book_sigma_max_deg = 0, book_eps_max = 0, book_alpha_max_deg = 0;
  bool book_bound_valid = false;
  double book_bound_ab_deg = 0, book_bound_side_deg = 0, book_bound_axis_deg = 0;
  uint32_t stars_bounded = 0, star_violations = 0;
  uint32_t books_bounded = 0, book_violations = 0;
  double max_bounded_dihedral_deg = 0, max_unbounded_dihedral_deg = 0;

  uint32_t bounded() const { return stars_bounded + books_bounded; }
  uint32_t violations() const { return star_violations + book_violations; }
};

}  // namespace svrc::refine
