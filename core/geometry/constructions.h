// Geometric constructions in doubles: circumballs, diametral balls, distances,
// facet frames (thesis §3.1 primitives; implementer's guide §3, §7 "circumcentres
// of near-flat simplices"). These produce *values*; no decision may be taken on
// them — signs go through core/geometry/predicates.h.
//
// Accuracy: circumcentres are computed relative to a vertex (so translation
// far from the origin costs nothing). The denominator (6× the signed volume,
// 2× the signed area, |n|²) and, for tets, each numerator component are
// re-evaluated exactly (expansion arithmetic on the rounded differences,
// rounded once) when cancellation has eaten more than ~10 bits (value below
// 1e-3 × its permanent) — slivers are near-flat AND near-cocircular, and
// their centre's height is a small numerator over a small denominator.
// Measured (tests/geometry/constructions_test.cc, GMP reference): centre
// error ≤ 1e-12·R + 8e-16·|a| on random, far-from-origin and near-flat
// (h down to 2^-40) tets.
// A flat simplex (exact denominator 0) yields a non-finite centre (inf/NaN).
#pragma once

#include <span>

#include "core/geometry/vec3.h"

namespace svrc::geom {

struct Ball3 {
  Vec3 center;
  double radius = 0;
};
struct Circle2 {
  Vec2 center;
  double radius = 0;
};

// Circumcentre of tet abcd:
//   o = a + (|t|²(u×v) + |u|²(v×t) + |v|²(t×u)) / (2 t·(u×v)),  t,u,v = b−a, c−a, d−a.
Vec3 TetCircumcenter(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);
// Circumball (radius = |o − a|, computed from the offset, not from o).
Ball3 TetCircumball(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);
inline double TetCircumradius(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return TetCircumball(a, b, c, d).radius;
}

// Circumcentre of a 3D triangle in its own plane (= centre of its diametral
// ball, the smallest ball through a, b, c):
//   o = a + ((|u|² v − |v|² u) × (u×v)) / (2|u×v|²),  u,v = b−a, c−a.
Vec3 TriangleCircumcenter3d(const Vec3& a, const Vec3& b, const Vec3& c);
Ball3 TriangleCircumball3d(const Vec3& a, const Vec3& b, const Vec3& c);

// 2D circumcircle: o = a + (v_y|u|² − u_y|v|², u_x|v|² − v_x|u|²) / (2 det[u, v]).
Vec2 TriangleCircumcenter2d(Vec2 a, Vec2 b, Vec2 c);
Circle2 TriangleCircumcircle2d(Vec2 a, Vec2 b, Vec2 c);

// Diametral ball of a segment: midpoint, half length.
Ball3 SegmentDiametralBall(const Vec3& a, const Vec3& b);
Circle2 SegmentDiametralCircle(Vec2 a, Vec2 b);

// Closest points and distances. Degenerate segments/triangles are handled
// (a zero-length segment is a point; a collinear triangle falls back to its
// edges).
Vec3 ClosestPointOnSegment(const Vec3& p, const Vec3& a, const Vec3& b);
double DistancePointSegment(const Vec3& p, const Vec3& a, const Vec3& b);
Vec3 ClosestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);
double DistancePointTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

// An orthonormal frame of a plane: origin, in-plane axes u, v and unit normal
// n = u × v (right-handed). To2d projects orthogonally; To3d(To2d(p)) = p for
// points of the plane up to rounding (a few ulps of |p − origin|).
struct PlaneFrame {
  Vec3 origin;
  Vec3 u{1, 0, 0}, v{0, 1, 0}, n{0, 0, 1};

  Vec2 To2d(const Vec3& p) const {
    const Vec3 d = p - origin;
    return {Dot(d, u), Dot(d, v)};
  }
  Vec3 To3d(Vec2 q) const { return origin + q.x * u + q.y * v; }
  // Signed distance from the plane, along n.
  double Height(const Vec3& p) const { return Dot(p - origin, n); }

  // Frame with the given origin and normal direction (need not be unit; must
  // be non-zero). u is built from the coordinate axis least aligned with n, so
  // the frame depends only on (origin, normal).
  static PlaneFrame FromNormal(const Vec3& origin, const Vec3& normal);
  // Plane of triangle abc, origin a, n ∝ (b−a)×(c−a), u along b−a.
  static PlaneFrame FromTriangle(const Vec3& a, const Vec3& b, const Vec3& c);
  // Plane of a (near-)planar polygon: Newell's normal, origin = first vertex.
  static PlaneFrame FromPolygon(std::span<const Vec3> loop);
};

// Newell's normal of a closed polygon (twice the vector area).
Vec3 NewellNormal(std::span<const Vec3> loop);

}  // namespace svrc::geom
