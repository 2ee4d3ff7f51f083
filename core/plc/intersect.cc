#include "core/plc/intersect.h"

#include <algorithm>
#include <cmath>

#include "core/plc/exact.h"

namespace svrc::plc {

using geom::Vec3;

namespace {

// Closed 2D segment test in the projection dropping `d`.
bool Segments2d(const Vec3& p, const Vec3& q, const Vec3& r, const Vec3& s, int d) {
  const int o1 = Orient2dSign(p, q, r, d), o2 = Orient2dSign(p, q, s, d);
  const int o3 = Orient2dSign(r, s, p, d), o4 = Orient2dSign(r, s, q, d);
  if (o1 * o2 < 0 && o3 * o4 < 0) return true;
  const int i = (d + 1) % 3, j = (d + 2) % 3;
  auto on = [&](const Vec3& a, const Vec3& b, const Vec3& x) {
    return std::min(a[i], b[i]) <= x[i] && x[i] <= std::max(a[i], b[i]) &&
           std::min(a[j], b[j]) <= x[j] && x[j] <= std::max(a[j], b[j]);
  };
  return (o1 == 0 && on(p, q, r)) || (o2 == 0 && on(p, q, s)) || (o3 == 0 && on(r, s, p)) ||
         (o4 == 0 && on(r, s, q));
}

bool InTriangle2d(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, int d) {
  const int s = Orient2dSign(a, b, c, d);
  return s * Orient2dSign(a, b, p, d) >= 0 && s * Orient2dSign(b, c, p, d) >= 0 &&
         s * Orient2dSign(c, a, p, d) >= 0;
}

int LongestAxis(const Vec3& a, const Vec3& b) {
  const Vec3 e = b - a;
  const double x = std::fabs(e.x), y = std::fabs(e.y), z = std::fabs(e.z);
  return x >= y && x >= z ? 0 : (y >= z ? 1 : 2);
}

}  // namespace

int FaithfulDrop(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = geom::Cross(b - a, c - a);
  const double x = std::fabs(n.x), y = std::fabs(n.y), z = std::fabs(n.z);
  int order[3] = {2, 1, 0};
  if (x >= y && x >= z) order[0] = 0, order[1] = 1, order[2] = 2;
  else if (y >= x && y >= z) order[0] = 1, order[1] = 2, order[2] = 0;
  for (int d : order) {
    if (Orient2dSign(a, b, c, d) != 0) return d;
  }
  return -1;
}

bool Collinear(const Vec3& a, const Vec3& b, const Vec3& c) {
  return Orient2dSign(a, b, c, 0) == 0 && Orient2dSign(a, b, c, 1) == 0 &&
         Orient2dSign(a, b, c, 2) == 0;
}

bool StrictlyInsideSegment(const Vec3& p, const Vec3& a, const Vec3& b) {
  if (p == a || p == b || a == b || !Collinear(a, b, p)) return false;
  const int k = LongestAxis(a, b);
  return std::min(a[k], b[k]) < p[k] && p[k] < std::max(a[k], b[k]);
}

bool PointInTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  if (Orient3dSign(a, b, c, p) != 0) return false;
  const int d = FaithfulDrop(a, b, c);
  if (d < 0) return false;
  return InTriangle2d(p, a, b, c, d);
}

bool SegmentMeetsTriangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b,
                          const Vec3& c) {
  const int op = Orient3dSign(a, b, c, p), oq = Orient3dSign(a, b, c, q);
  if (op * oq > 0) return false;
  if (op == 0 && oq == 0) {
    const int d = FaithfulDrop(a, b, c);
    if (d < 0) return false;
    return InTriangle2d(p, a, b, c, d) || InTriangle2d(q, a, b, c, d) ||
           Segments2d(p, q, a, b, d) || Segments2d(p, q, b, c, d) || Segments2d(p, q, c, a, d);
  }
  const int s1 = Orient3dSign(p, q, a, b), s2 = Orient3dSign(p, q, b, c),
            s3 = Orient3dSign(p, q, c, a);
  return (s1 >= 0 && s2 >= 0 && s3 >= 0) || (s1 <= 0 && s2 <= 0 && s3 <= 0);
}

bool SegmentsMeetProjected(const Vec3& p, const Vec3& q, const Vec3& r, const Vec3& s, int drop) {
  return Segments2d(p, q, r, s, drop);
}

bool SegmentsMeet(const Vec3& p, const Vec3& q, const Vec3& r, const Vec3& s) {
  if (Orient3dSign(p, q, r, s) != 0) return false;
  for (int d = 0; d < 3; ++d) {
    if (Orient2dSign(p, q, r, d) != 0 || Orient2dSign(p, q, s, d) != 0 ||
        Orient2dSign(r, s, p, d) != 0 || Orient2dSign(r, s, q, d) != 0) {
      // Not all collinear in this projection. The points are coplanar; the
      // projection is faithful unless their plane contains the dropped axis,
      // in which case all four project onto one line (all signs 0): excluded.
      return Segments2d(p, q, r, s, d);
    }
  }
  // All four collinear in 3D: 1D overlap along the longest axis.
  const int k = p == q ? LongestAxis(r, s) : LongestAxis(p, q);
  return std::max(std::min(p[k], q[k]), std::min(r[k], s[k])) <=
         std::min(std::max(p[k], q[k]), std::max(r[k], s[k]));
}

bool SegmentFromCornerEntersTriangle(const Vec3& v, const Vec3& x, const Vec3& b, const Vec3& c) {
  if (Orient3dSign(v, b, c, x) != 0) return false;
  const int d = FaithfulDrop(v, b, c);
  if (d < 0) return false;
  const int s = Orient2dSign(v, b, c, d);
  return s * Orient2dSign(v, b, x, d) >= 0 && s * Orient2dSign(v, x, c, d) >= 0;
}

double PointSegmentDistance(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double l2 = geom::Norm2(ab);
  double t = l2 > 0 ? geom::Dot(p - a, ab) / l2 : 0;
  t = std::clamp(t, 0.0, 1.0);
  return geom::Dist(p, a + t * ab);
}

double PointTriangleDistance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  // Ericson, Real-Time Collision Detection, 5.1.5 (closest point on triangle).
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = geom::Dot(ab, ap), d2 = geom::Dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return geom::Dist(p, a);
  const Vec3 bp = p - b;
  const double d3 = geom::Dot(ab, bp), d4 = geom::Dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return geom::Dist(p, b);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return geom::Dist(p, a + (d1 / (d1 - d3)) * ab);
  const Vec3 cp = p - c;
  const double d5 = geom::Dot(ab, cp), d6 = geom::Dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return geom::Dist(p, c);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return geom::Dist(p, a + (d2 / (d2 - d6)) * ac);
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    return geom::Dist(p, b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b));
  }
  const double denom = 1.0 / (va + vb + vc);
  return geom::Dist(p, a + (vb * denom) * ab + (vc * denom) * ac);
}

double SegmentSegmentDistance(const Vec3& p, const Vec3& q, const Vec3& r, const Vec3& s) {
  // Ericson 5.1.9, clamped closest points of two segments.
  const Vec3 d1 = q - p, d2 = s - r, w = p - r;
  const double a = geom::Dot(d1, d1), e = geom::Dot(d2, d2), f = geom::Dot(d2, w);
  double t1 = 0, t2 = 0;
  if (a <= 0 && e <= 0) return geom::Dist(p, r);
  if (a <= 0) {
    t2 = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = geom::Dot(d1, w);
    if (e <= 0) {
      t1 = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = geom::Dot(d1, d2), den = a * e - b * b;
      t1 = den > 0 ? std::clamp((b * f - c * e) / den, 0.0, 1.0) : 0.0;
      t2 = (b * t1 + f) / e;
      if (t2 < 0) {
        t2 = 0;
        t1 = std::clamp(-c / a, 0.0, 1.0);
      } else if (t2 > 1) {
        t2 = 1;
        t1 = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  const double d = geom::Dist(p + t1 * d1, r + t2 * d2);
  // Endpoint distances guard against cancellation in nearly parallel cases.
  return std::min({d, PointSegmentDistance(p, r, s), PointSegmentDistance(q, r, s),
                   PointSegmentDistance(r, p, q), PointSegmentDistance(s, p, q)});
}

}  // namespace svrc::plc
