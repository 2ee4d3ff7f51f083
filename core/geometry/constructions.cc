// Constructions; formulas from Shewchuk, "Lecture Notes on Geometric
// Robustness" (circumcentres relative to a vertex) and Ericson, "Real-Time
// Collision Detection" §5.1 (closest points), derived independently here.
#include "core/geometry/constructions.h"

#include <cmath>

#include "core/geometry/expansion.h"

namespace svrc::geom {
namespace {

// det[t, u, v] in doubles; when it is small compared with its terms (so that
// cancellation may have destroyed its relative accuracy), evaluate it exactly
// and round once. Inputs are already differences, so "exact" here means exact
// for those rounded differences: the remaining error is that of the
// differences themselves (≤ u relative each).
double Det3Accurate(const Vec3& t, const Vec3& u, const Vec3& v) {
  const double det = t.x * (u.y * v.z - u.z * v.y) + t.y * (u.z * v.x - u.x * v.z) +
                     t.z * (u.x * v.y - u.y * v.x);
  const double perm = std::fabs(t.x) * (std::fabs(u.y * v.z) + std::fabs(u.z * v.y)) +
                      std::fabs(t.y) * (std::fabs(u.z * v.x) + std::fabs(u.x * v.z)) +
                      std::fabs(t.z) * (std::fabs(u.x * v.y) + std::fabs(u.y * v.x));
  if (std::fabs(det) > 1e-3 * perm) return det;
  const Expansion e = Expansion(t.x) * (Expansion::Product(u.y, v.z) - Expansion::Product(u.z, v.y)) +
                      Expansion(t.y) * (Expansion::Product(u.z, v.x) - Expansion::Product(u.x, v.z)) +
                      Expansion(t.z) * (Expansion::Product(u.x, v.y) - Expansion::Product(u.y, v.x));
  return e.Estimate();
}

double Det2Accurate(Vec2 u, Vec2 v) {
  const double det = u.x * v.y - u.y * v.x;
  const double perm = std::fabs(u.x * v.y) + std::fabs(u.y * v.x);
  if (std::fabs(det) > 1e-3 * perm) return det;
  return (Expansion::Product(u.x, v.y) - Expansion::Product(u.y, v.x)).Estimate();
}

// The three components of u×v, each accurate (exact-then-rounded when small).
Vec3 CrossAccurate(const Vec3& u, const Vec3& v) {
  return {Det2Accurate({u.y, u.z}, {v.y, v.z}), Det2Accurate({u.z, u.x}, {v.z, v.x}),
          Det2Accurate({u.x, u.y}, {v.x, v.y})};
}

// One component of the tet-circumcentre numerator,
//   |t|²(u×v)_i + |u|²(v×t)_i + |v|²(t×u)_i,
// re-evaluated exactly when cancellation is severe. That happens for slivers
// (near-flat AND near-cocircular tets, the ones Delaunay meshes are full of),
// where the centre's height above the plane is this small numerator over a
// small denominator.
double TetNumeratorComponent(const Vec3& t, const Vec3& u, const Vec3& v, int i) {
  const int j = (i + 1) % 3, k = (i + 2) % 3;
  auto cross_i = [&](const Vec3& p, const Vec3& q) { return p[j] * q[k] - p[k] * q[j]; };
  auto cross_perm = [&](const Vec3& p, const Vec3& q) {
    return std::fabs(p[j] * q[k]) + std::fabs(p[k] * q[j]);
  };
  const double tt = Norm2(t), uu = Norm2(u), vv = Norm2(v);
  const double num = tt * cross_i(u, v) + uu * cross_i(v, t) + vv * cross_i(t, u);
  const double perm = tt * cross_perm(u, v) + uu * cross_perm(v, t) + vv * cross_perm(t, u);
  if (std::fabs(num) > 1e-3 * perm) return num;
  auto norm2 = [](const Vec3& p) {
    return Expansion::Product(p.x, p.x) + Expansion::Product(p.y, p.y) + Expansion::Product(p.z, p.z);
  };
  auto cross = [&](const Vec3& p, const Vec3& q) {
    return Expansion::Product(p[j], q[k]) - Expansion::Product(p[k], q[j]);
  };
  return (norm2(t) * cross(u, v) + norm2(u) * cross(v, t) + norm2(v) * cross(t, u)).Estimate();
}

Vec3 TetOffset(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const Vec3 t = b - a, u = c - a, v = d - a;
  const double denom = 2 * Det3Accurate(t, u, v);
  const Vec3 num{TetNumeratorComponent(t, u, v, 0), TetNumeratorComponent(t, u, v, 1),
                 TetNumeratorComponent(t, u, v, 2)};
  return num / denom;
}

Vec3 TriangleOffset3d(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 u = b - a, v = c - a;
  const Vec3 n = CrossAccurate(u, v);
  const double denom = 2 * Norm2(n);
  return Cross(Norm2(u) * v - Norm2(v) * u, n) / denom;
}

Vec2 TriangleOffset2d(Vec2 a, Vec2 b, Vec2 c) {
  const Vec2 u = b - a, v = c - a;
  const double denom = 2 * Det2Accurate(u, v);
  const double uu = Norm2(u), vv = Norm2(v);
  return {(v.y * uu - u.y * vv) / denom, (u.x * vv - v.x * uu) / denom};
}

}  // namespace

Vec3 TetCircumcenter(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return a + TetOffset(a, b, c, d);
}

Ball3 TetCircumball(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const Vec3 off = TetOffset(a, b, c, d);
  return {a + off, Norm(off)};
}

Vec3 TriangleCircumcenter3d(const Vec3& a, const Vec3& b, const Vec3& c) {
  return a + TriangleOffset3d(a, b, c);
}

Ball3 TriangleCircumball3d(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 off = TriangleOffset3d(a, b, c);
  return {a + off, Norm(off)};
}

Vec2 TriangleCircumcenter2d(Vec2 a, Vec2 b, Vec2 c) { return a + TriangleOffset2d(a, b, c); }

Circle2 TriangleCircumcircle2d(Vec2 a, Vec2 b, Vec2 c) {
  const Vec2 off = TriangleOffset2d(a, b, c);
  return {a + off, std::sqrt(Norm2(off))};
}

Ball3 SegmentDiametralBall(const Vec3& a, const Vec3& b) {
  const Vec3 half = 0.5 * (b - a);
  return {a + half, Norm(half)};
}

Circle2 SegmentDiametralCircle(Vec2 a, Vec2 b) {
  const Vec2 half = 0.5 * (b - a);
  return {a + half, std::sqrt(Norm2(half))};
}

Vec3 ClosestPointOnSegment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double len2 = Norm2(ab);
  if (len2 == 0) return a;
  const double t = Dot(p - a, ab) / len2;
  if (t <= 0) return a;
  if (t >= 1) return b;
  return a + t * ab;
}

double DistancePointSegment(const Vec3& p, const Vec3& a, const Vec3& b) {
  return Dist(p, ClosestPointOnSegment(p, a, b));
}

// Voronoi regions of the triangle's features, tested in barycentric terms.
Vec3 ClosestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = Dot(ab, ap), d2 = Dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const double d3 = Dot(ab, bp), d4 = Dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double den = d1 - d3;
    return den > 0 ? a + (d1 / den) * ab : a;
  }
  const Vec3 cp = p - c;
  const double d5 = Dot(ab, cp), d6 = Dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double den = d2 - d6;
    return den > 0 ? a + (d2 / den) * ac : a;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double den = (d4 - d3) + (d5 - d6);
    return den > 0 ? b + ((d4 - d3) / den) * (c - b) : b;
  }
  const double sum = va + vb + vc;
  if (!(sum > 0)) {
    // Degenerate (collinear) triangle: the closest of the three edges.
    const Vec3 q[3] = {ClosestPointOnSegment(p, a, b), ClosestPointOnSegment(p, b, c),
                       ClosestPointOnSegment(p, c, a)};
    int best = 0;
    for (int i = 1; i < 3; ++i) {
      if (Dist2(p, q[i]) < Dist2(p, q[best])) best = i;
    }
    return q[best];
  }
  const double v = vb / sum, w = vc / sum;
  return a + v * ab + w * ac;
}

double DistancePointTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  return Dist(p, ClosestPointOnTriangle(p, a, b, c));
}

Vec3 NewellNormal(std::span<const Vec3> loop) {
  Vec3 n;
  const size_t k = loop.size();
  if (k < 3) return n;
  // Relative to the first vertex for accuracy far from the origin.
  const Vec3 o = loop[0];
  for (size_t i = 0; i < k; ++i) {
    const Vec3 p = loop[i] - o, q = loop[(i + 1) % k] - o;
    n += Cross(p, q);
  }
  return n;
}

PlaneFrame PlaneFrame::FromNormal(const Vec3& origin, const Vec3& normal) {
  PlaneFrame f;
  f.origin = origin;
  f.n = normal / Norm(normal);
  // Axis least aligned with n, crossed with n, gives a well-conditioned u.
  const double ax = std::fabs(f.n.x), ay = std::fabs(f.n.y), az = std::fabs(f.n.z);
  Vec3 axis = (ax <= ay && ax <= az) ? Vec3{1, 0, 0} : (ay <= az ? Vec3{0, 1, 0} : Vec3{0, 0, 1});
  Vec3 u = Cross(axis, f.n);
  f.u = u / Norm(u);
  f.v = Cross(f.n, f.u);
  return f;
}

PlaneFrame PlaneFrame::FromTriangle(const Vec3& a, const Vec3& b, const Vec3& c) {
  PlaneFrame f;
  f.origin = a;
  const Vec3 ab = b - a;
  const Vec3 n = CrossAccurate(ab, c - a);
  f.n = n / Norm(n);
  f.u = ab / Norm(ab);
  // Re-orthogonalise u against n (n is exact-ish, u exact direction): v = n×u.
  f.u = f.u - Dot(f.u, f.n) * f.n;
  f.u = f.u / Norm(f.u);
  f.v = Cross(f.n, f.u);
  return f;
}

PlaneFrame PlaneFrame::FromPolygon(std::span<const Vec3> loop) {
  return FromNormal(loop.empty() ? Vec3{} : loop[0], NewellNormal(loop));
}

}  // namespace svrc::geom
