// Exact orientation signs: a floating-point filter, then exact evaluation with
// Shewchuk's expansion arithmetic ("Adaptive Precision Floating-Point
// Arithmetic and Fast Robust Geometric Predicates", 1997: Two-Sum, Two-Product
// and zero-eliminating expansion sums). Interim implementation until
// core/geometry/predicates.h lands; then these forward to it.
#include "core/plc/exact.h"

#include <cmath>
#include <vector>

namespace svrc::plc {
namespace {

using Expansion = std::vector<double>;  // nonoverlapping, increasing magnitude

inline void TwoSum(double a, double b, double& x, double& y) {
  x = a + b;
  const double bv = x - a;
  const double av = x - bv;
  y = (a - av) + (b - bv);
}

inline void TwoProduct(double a, double b, double& x, double& y) {
  x = a * b;
  y = std::fma(a, b, -x);  // exact error term of the product
}

// Shewchuk's Linear-Expansion-Sum with zero elimination (simple Grow-based form).
Expansion Sum(const Expansion& e, const Expansion& f) {
  Expansion h = e;
  for (double b : f) {
    Expansion g;
    g.reserve(h.size() + 1);
    double q = b;
    for (double a : h) {
      double x, y;
      TwoSum(q, a, x, y);
      if (y != 0) g.push_back(y);
      q = x;
    }
    if (q != 0) g.push_back(q);
    h.swap(g);
  }
  return h;
}

Expansion Negate(Expansion e) {
  for (double& x : e) x = -x;
  return e;
}

// Scale-Expansion with zero elimination.
Expansion Scale(const Expansion& e, double b) {
  Expansion h;
  if (e.empty() || b == 0) return h;
  double q, hh;
  TwoProduct(e[0], b, q, hh);
  if (hh != 0) h.push_back(hh);
  for (size_t i = 1; i < e.size(); ++i) {
    double t1, t0;
    TwoProduct(e[i], b, t1, t0);
    double sum, err;
    TwoSum(q, t0, sum, err);
    if (err != 0) h.push_back(err);
    TwoSum(t1, sum, q, err);
    if (err != 0) h.push_back(err);
  }
  if (q != 0) h.push_back(q);
  return h;
}

Expansion Mul(const Expansion& e, const Expansion& f) {
  Expansion r;
  for (double b : f) r = Sum(r, Scale(e, b));
  return r;
}

Expansion Diff(double a, double b) {
  double x, y;
  TwoSum(a, -b, x, y);
  Expansion e;
  if (y != 0) e.push_back(y);
  if (x != 0) e.push_back(x);
  return e;
}

int SignOf(const Expansion& e) {
  for (size_t i = e.size(); i-- > 0;) {
    if (e[i] > 0) return 1;
    if (e[i] < 0) return -1;
  }
  return 0;
}

constexpr double kEps = 0x1p-53;
// Shewchuk's static error bounds (Predicates.c): o3derrboundA, ccwerrboundA.
constexpr double kO3dBound = (7.0 + 56.0 * kEps) * kEps;
constexpr double kO2dBound = (3.0 + 16.0 * kEps) * kEps;

}  // namespace

int Orient3dSign(const geom::Vec3& a, const geom::Vec3& b, const geom::Vec3& c,
                 const geom::Vec3& d) {
  // det[b-a, c-a, d-a] == Shewchuk's orient3d(b, c, d, a) up to sign convention;
  // we fix det of the rows (b-a, c-a, d-a).
  const double bx = b.x - a.x, by = b.y - a.y, bz = b.z - a.z;
  const double cx = c.x - a.x, cy = c.y - a.y, cz = c.z - a.z;
  const double dx = d.x - a.x, dy = d.y - a.y, dz = d.z - a.z;
  const double m1 = cy * dz, m2 = cz * dy, m3 = cz * dx, m4 = cx * dz, m5 = cx * dy, m6 = cy * dx;
  const double det = bx * (m1 - m2) + by * (m3 - m4) + bz * (m5 - m6);
  const double perm = std::fabs(bx) * (std::fabs(m1) + std::fabs(m2)) +
                      std::fabs(by) * (std::fabs(m3) + std::fabs(m4)) +
                      std::fabs(bz) * (std::fabs(m5) + std::fabs(m6));
  // The differences are rounded too: widen the bound (the exact path decides).
  const double bound = 4 * kO3dBound * perm;
  if (std::isfinite(det) && std::isfinite(perm)) {
    if (det > bound) return 1;
    if (det < -bound) return -1;
    if (perm == 0) return 0;
  }
  const Expansion ex = Diff(b.x, a.x), ey = Diff(b.y, a.y), ez = Diff(b.z, a.z);
  const Expansion fx = Diff(c.x, a.x), fy = Diff(c.y, a.y), fz = Diff(c.z, a.z);
  const Expansion gx = Diff(d.x, a.x), gy = Diff(d.y, a.y), gz = Diff(d.z, a.z);
  const Expansion t1 = Sum(Mul(fy, gz), Negate(Mul(fz, gy)));
  const Expansion t2 = Sum(Mul(fz, gx), Negate(Mul(fx, gz)));
  const Expansion t3 = Sum(Mul(fx, gy), Negate(Mul(fy, gx)));
  const Expansion r = Sum(Sum(Mul(ex, t1), Mul(ey, t2)), Mul(ez, t3));
  return SignOf(r);
}

int Orient2dSign(const geom::Vec3& a, const geom::Vec3& b, const geom::Vec3& c, int drop) {
  const int i = (drop + 1) % 3, j = (drop + 2) % 3;
  const double bx = b[i] - a[i], by = b[j] - a[j];
  const double cx = c[i] - a[i], cy = c[j] - a[j];
  const double l = bx * cy, r = by * cx;
  const double det = l - r;
  const double bound = 4 * kO2dBound * (std::fabs(l) + std::fabs(r));
  if (std::isfinite(det) && std::isfinite(bound)) {
    if (det > bound) return 1;
    if (det < -bound) return -1;
    if (l == 0 && r == 0) return 0;
  }
  const Expansion ex = Diff(b[i], a[i]), ey = Diff(b[j], a[j]);
  const Expansion fx = Diff(c[i], a[i]), fy = Diff(c[j], a[j]);
  return SignOf(Sum(Mul(ex, fy), Negate(Mul(ey, fx))));
}

}  // namespace svrc::plc
