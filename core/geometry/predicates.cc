// Exact fallbacks, simulation of simplicity and the extra predicates of
// core/geometry/predicates.h (conventions and derivations are there).
#include "core/geometry/predicates.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <initializer_list>

#include "core/geometry/expansion.h"

namespace svrc::geom {

namespace internal {
thread_local constinit PredicateStats tls_predicate_stats;
}  // namespace internal

namespace {

using internal::SignOf;

void CountExact(Pred p) { ++internal::tls_predicate_stats.exact[static_cast<int>(p)]; }
void CountSos(Pred p) { ++internal::tls_predicate_stats.sos[static_cast<int>(p)]; }

// ---------------------------------------------------------------- rescaling
// Every predicate is a homogeneous polynomial in the coordinates (or in their
// differences), so multiplying all inputs by 2^k (exact, barring underflow of
// the scaled values) keeps its sign. Before exact evaluation we scale so that
// the largest |coordinate| is about 2^(960/degree): products of `degree`
// factors (and the sums of a few dozen of them) stay below 2^996, where
// Dekker's split would overflow, while tiny differences (down to denormal
// nudges of a zero coordinate) are lifted as far from the underflow threshold
// as possible. Exact as long as no product of nonzero differences falls below
// ~2^-969 after scaling, i.e. unless the input's nonzero coordinate differences
// span more than ~2^(1900/degree) (pathological; documented in predicates.h).
int TargetExponent(int degree) { return 960 / degree - 8; }

class Scaler {
 public:
  Scaler(std::initializer_list<double> values, int degree) {
    double m = 0;
    for (double v : values) m = std::max(m, std::fabs(v));
    if (m != 0 && std::isfinite(m)) k_ = TargetExponent(degree) - std::ilogb(m);
  }
  double operator()(double x) const { return k_ == 0 ? x : std::ldexp(x, k_); }
  Vec2 operator()(Vec2 p) const { return {(*this)(p.x), (*this)(p.y)}; }
  Vec3 operator()(const Vec3& p) const { return {(*this)(p.x), (*this)(p.y), (*this)(p.z)}; }

 private:
  int k_ = 0;
};

// ------------------------------------------------------ exact core predicates
// The same formulas as the inline filters, on exact differences.

int Orient2dExactImpl(Vec2 a, Vec2 b, Vec2 c) {
  const Scaler s({a.x, a.y, b.x, b.y, c.x, c.y}, 2);
  a = s(a), b = s(b), c = s(c);
  const Expansion bax = Expansion::Diff(b.x, a.x), bay = Expansion::Diff(b.y, a.y);
  const Expansion cax = Expansion::Diff(c.x, a.x), cay = Expansion::Diff(c.y, a.y);
  return (bax * cay - bay * cax).Sign();
}

int Orient3dExactImpl(Vec3 a, Vec3 b, Vec3 c, Vec3 d) {
  const Scaler s({a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z, d.x, d.y, d.z}, 3);
  a = s(a), b = s(b), c = s(c), d = s(d);
  const Expansion bax = Expansion::Diff(b.x, a.x), bay = Expansion::Diff(b.y, a.y),
                  baz = Expansion::Diff(b.z, a.z);
  const Expansion cax = Expansion::Diff(c.x, a.x), cay = Expansion::Diff(c.y, a.y),
                  caz = Expansion::Diff(c.z, a.z);
  const Expansion dax = Expansion::Diff(d.x, a.x), day = Expansion::Diff(d.y, a.y),
                  daz = Expansion::Diff(d.z, a.z);
  const Expansion det = bax * (cay * daz - caz * day) + bay * (caz * dax - cax * daz) +
                        baz * (cax * day - cay * dax);
  return det.Sign();
}

int InCircleExactImpl(Vec2 a, Vec2 b, Vec2 c, Vec2 d) {
  const Scaler s({a.x, a.y, b.x, b.y, c.x, c.y, d.x, d.y}, 4);
  a = s(a), b = s(b), c = s(c), d = s(d);
  const Expansion adx = Expansion::Diff(a.x, d.x), ady = Expansion::Diff(a.y, d.y);
  const Expansion bdx = Expansion::Diff(b.x, d.x), bdy = Expansion::Diff(b.y, d.y);
  const Expansion cdx = Expansion::Diff(c.x, d.x), cdy = Expansion::Diff(c.y, d.y);
  const Expansion alift = adx * adx + ady * ady;
  const Expansion blift = bdx * bdx + bdy * bdy;
  const Expansion clift = cdx * cdx + cdy * cdy;
  const Expansion det = alift * (bdx * cdy - cdx * bdy) + blift * (cdx * ady - adx * cdy) +
                        clift * (adx * bdy - bdx * ady);
  return det.Sign();
}

int InSphereExactImpl(Vec3 a, Vec3 b, Vec3 c, Vec3 d, Vec3 e) {
  const Scaler s({a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z, d.x, d.y, d.z, e.x, e.y, e.z}, 5);
  a = s(a), b = s(b), c = s(c), d = s(d), e = s(e);
  const Expansion aex = Expansion::Diff(a.x, e.x), aey = Expansion::Diff(a.y, e.y),
                  aez = Expansion::Diff(a.z, e.z);
  const Expansion bex = Expansion::Diff(b.x, e.x), bey = Expansion::Diff(b.y, e.y),
                  bez = Expansion::Diff(b.z, e.z);
  const Expansion cex = Expansion::Diff(c.x, e.x), cey = Expansion::Diff(c.y, e.y),
                  cez = Expansion::Diff(c.z, e.z);
  const Expansion dex = Expansion::Diff(d.x, e.x), dey = Expansion::Diff(d.y, e.y),
                  dez = Expansion::Diff(d.z, e.z);
  const Expansion ab = aex * bey - bex * aey;
  const Expansion bc = bex * cey - cex * bey;
  const Expansion cd = cex * dey - dex * cey;
  const Expansion da = dex * aey - aex * dey;
  const Expansion ac = aex * cey - cex * aey;
  const Expansion bd = bex * dey - dex * bey;
  const Expansion abc = aez * bc - bez * ac + cez * ab;
  const Expansion bcd = bez * cd - cez * bd + dez * bc;
  const Expansion cda = cez * da + dez * ac + aez * cd;
  const Expansion dab = dez * ab + aez * bd + bez * da;
  const Expansion alift = aex * aex + aey * aey + aez * aez;
  const Expansion blift = bex * bex + bey * bey + bez * bez;
  const Expansion clift = cex * cex + cey * cey + cez * cez;
  const Expansion dlift = dex * dex + dey * dey + dez * dez;
  const Expansion det = (clift * dab - dlift * abc) + (alift * bcd - blift * cda);
  return det.Sign();
}

// -------------------------------------------------- simulation of simplicity

// Exact determinant of an n×n matrix (n ≤ 4) of doubles, row-major, by
// Laplace expansion along the first column (zero entries skipped).
Expansion DetExact(const double* m, int n, int stride) {
  if (n == 1) return Expansion(m[0]);
  if (n == 2) {
    return Expansion::Product(m[0], m[stride + 1]) - Expansion::Product(m[1], m[stride]);
  }
  Expansion det;
  double minor[16];
  for (int r = 0; r < n; ++r) {
    if (m[r * stride] == 0) continue;
    int k = 0;
    for (int i = 0; i < n; ++i) {
      if (i == r) continue;
      for (int j = 1; j < n; ++j) minor[k * (n - 1) + (j - 1)] = m[i * stride + j];
      ++k;
    }
    const Expansion sub = DetExact(minor, n - 1, n - 1).Scale(m[r * stride]);
    det = (r % 2 == 0) ? det + sub : det - sub;
  }
  return det;
}

// Ranks of the ids: rank[i] = 1 + number of ids smaller than ids[i].
template <int N>
std::array<int, N> Ranks(const uint32_t (&ids)[N]) {
  std::array<int, N> rank;
  for (int i = 0; i < N; ++i) {
    rank[i] = 1;
    for (int j = 0; j < N; ++j) rank[i] += ids[j] < ids[i];
  }
  return rank;
}

// Edelsbrunner–Mücke coordinate perturbation for orientation in dimension D
// (N = D + 1 points). coords[i*D + j] is coordinate j of point i. Visits the
// ε-monomials in increasing exponent order; see predicates.h.
template <int D>
int OrientSoS(const double* coords, const uint32_t (&ids)[D + 1]) {
  constexpr int N = D + 1;
  const std::array<int, N> rank = Ranks<N>(ids);
  // Point and coordinate of each bit: bit = D·r − j with r = rank (1-based),
  // j = coordinate (1-based).
  int bit_point[D * N], bit_coord[D * N];
  for (int i = 0; i < N; ++i) {
    for (int j = 1; j <= D; ++j) {
      const int bit = D * rank[i] - j;
      bit_point[bit] = i;
      bit_coord[bit] = j;
    }
  }
  double m[N * N];
  for (uint32_t mask = 1; mask < (1u << (D * N)); ++mask) {
    unsigned points_used = 0, coords_used = 0;
    bool valid = true;
    for (int bit = 0; bit < D * N && valid; ++bit) {
      if (!(mask >> bit & 1)) continue;
      const unsigned pb = 1u << bit_point[bit], cb = 1u << bit_coord[bit];
      valid = !(points_used & pb) && !(coords_used & cb);
      points_used |= pb;
      coords_used |= cb;
    }
    if (!valid) continue;
    // Rows [1, p] for untouched points, unit vector e_j for perturbed ones.
    for (int i = 0; i < N; ++i) {
      m[i * N] = 1;
      for (int j = 0; j < D; ++j) m[i * N + 1 + j] = coords[i * D + j];
    }
    for (int bit = 0; bit < D * N; ++bit) {
      if (!(mask >> bit & 1)) continue;
      double* row = m + bit_point[bit] * N;
      for (int j = 0; j < N; ++j) row[j] = 0;
      row[bit_coord[bit]] = 1;
    }
    const int s = DetExact(m, N, N).Sign();
    if (s != 0) return s;
  }
  return 0;  // unreachable: a mask covering every coordinate gives ±1
}

}  // namespace

const char* PredicateName(Pred p) {
  switch (p) {
    case Pred::kOrient1d: return "orient1d";
    case Pred::kOrient2d: return "orient2d";
    case Pred::kOrient3d: return "orient3d";
    case Pred::kInCircle: return "incircle";
    case Pred::kInSphere: return "insphere";
    case Pred::kInDiametralSphere: return "in_diametral_sphere";
    case Pred::kInTriangleCircumball3d: return "in_triangle_circumball3d";
    case Pred::kCompareDistance: return "compare_distance";
    case Pred::kDotSign: return "dot_sign";
    case Pred::kOrient2dProjected: return "orient2d_projected";
    case Pred::kCount: break;
  }
  return "?";
}

uint64_t PredicateStats::TotalCalls() const {
  uint64_t s = 0;
  for (uint64_t v : calls) s += v;
  return s;
}
uint64_t PredicateStats::TotalExact() const {
  uint64_t s = 0;
  for (uint64_t v : exact) s += v;
  return s;
}
uint64_t PredicateStats::TotalSos() const {
  uint64_t s = 0;
  for (uint64_t v : sos) s += v;
  return s;
}

namespace internal {

int Orient2dExact(Vec2 a, Vec2 b, Vec2 c) {
  CountExact(Pred::kOrient2d);
  return Orient2dExactImpl(a, b, c);
}
int Orient3dExact(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  CountExact(Pred::kOrient3d);
  return Orient3dExactImpl(a, b, c, d);
}
int InCircleExact(Vec2 a, Vec2 b, Vec2 c, Vec2 d) {
  CountExact(Pred::kInCircle);
  return InCircleExactImpl(a, b, c, d);
}
int InSphereExact(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const Vec3& e) {
  CountExact(Pred::kInSphere);
  return InSphereExactImpl(a, b, c, d, e);
}

int Orient2dSoSTail(Vec2 a, Vec2 b, Vec2 c, uint32_t ia, uint32_t ib, uint32_t ic) {
  CountSos(Pred::kOrient2d);
  const Scaler s({a.x, a.y, b.x, b.y, c.x, c.y}, 2);
  a = s(a), b = s(b), c = s(c);
  const double coords[6] = {a.x, a.y, b.x, b.y, c.x, c.y};
  const uint32_t ids[3] = {ia, ib, ic};
  return OrientSoS<2>(coords, ids);
}

int Orient3dSoSTail(const Vec3& a0, const Vec3& b0, const Vec3& c0, const Vec3& d0, uint32_t ia,
                    uint32_t ib, uint32_t ic, uint32_t id) {
  CountSos(Pred::kOrient3d);
  const Scaler s({a0.x, a0.y, a0.z, b0.x, b0.y, b0.z, c0.x, c0.y, c0.z, d0.x, d0.y, d0.z}, 3);
  const Vec3 a = s(a0), b = s(b0), c = s(c0), d = s(d0);
  const double coords[12] = {a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z, d.x, d.y, d.z};
  const uint32_t ids[4] = {ia, ib, ic, id};
  return OrientSoS<3>(coords, ids);
}

int InCircleSoSTail(Vec2 a, Vec2 b, Vec2 c, Vec2 d, uint32_t ia, uint32_t ib, uint32_t ic,
                    uint32_t id) {
  CountSos(Pred::kInCircle);
  const Vec2 p[4] = {a, b, c, d};
  const uint32_t ids[4] = {ia, ib, ic, id};
  const std::array<int, 4> rank = Ranks<4>(ids);
  for (int r = 1; r <= 4; ++r) {
    for (int i = 0; i < 4; ++i) {
      if (rank[i] != r) continue;
      // Cofactor of the lifted entry of row i (0-based): (−1)^(i+1+4)·Orient2d(others).
      Vec2 q[3];
      for (int j = 0, k = 0; j < 4; ++j) {
        if (j != i) q[k++] = p[j];
      }
      const int o = Orient2dExactImpl(q[0], q[1], q[2]);
      if (o == 0) continue;
      const int cofactor = ((i + 1) % 2 == 0) ? o : -o;
      return -cofactor;
    }
  }
  return 0;  // all four points collinear
}

int InSphereSoSTail(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const Vec3& e,
                    uint32_t ia, uint32_t ib, uint32_t ic, uint32_t id, uint32_t ie) {
  CountSos(Pred::kInSphere);
  const Vec3 p[5] = {a, b, c, d, e};
  const uint32_t ids[5] = {ia, ib, ic, id, ie};
  const std::array<int, 5> rank = Ranks<5>(ids);
  for (int r = 1; r <= 5; ++r) {
    for (int i = 0; i < 5; ++i) {
      if (rank[i] != r) continue;
      // Cofactor of the lifted entry of row i (0-based): (−1)^(i+1+5)·Orient3d(others).
      Vec3 q[4];
      for (int j = 0, k = 0; j < 5; ++j) {
        if (j != i) q[k++] = p[j];
      }
      const int o = Orient3dExactImpl(q[0], q[1], q[2], q[3]);
      if (o == 0) continue;
      const int cofactor = ((i + 1 + 5) % 2 == 0) ? o : -o;
      return -cofactor;
    }
  }
  return 0;  // all five points coplanar
}

}  // namespace internal

// ------------------------------------------------------------ extra predicates
namespace {

// A double with a rigorous bound on its absolute error (forward running error
// analysis). Rounding to nearest: |fl(x) − x| ≤ u·|fl(x)|; kTiny covers
// underflow (absolute error ≤ 2^-1075 per operation).
struct Fp {
  double v = 0;
  double e = 0;
};
constexpr double kTiny = 1e-300;
inline Fp FromDouble(double x, Fp*) { return {x, 0}; }
inline Fp operator+(Fp a, Fp b) {
  const double v = a.v + b.v;
  return {v, a.e + b.e + internal::kU * std::fabs(v) + kTiny};
}
inline Fp operator-(Fp a, Fp b) {
  const double v = a.v - b.v;
  return {v, a.e + b.e + internal::kU * std::fabs(v) + kTiny};
}
inline Fp operator-(Fp a) { return {-a.v, a.e}; }
inline Fp operator*(Fp a, Fp b) {
  const double v = a.v * b.v;
  return {v, std::fabs(a.v) * b.e + std::fabs(b.v) * a.e + a.e * b.e + internal::kU * std::fabs(v) +
                 kTiny};
}
// The error bound itself was computed in floating point (each term with a
// relative error of a few u over at most ~100 operations): inflate it.
inline int FilteredSign(Fp x, bool* certain) {
  const double bound = x.e * (1 + 1e-10);
  *certain = std::fabs(x.v) > bound;  // false for NaN/Inf too
  return SignOf(x.v);
}
inline Expansion FromDouble(double x, Expansion*) { return Expansion(x); }

template <class T>
T Cv(double x) {
  return FromDouble(x, static_cast<T*>(nullptr));
}

template <class T>
struct V3 {
  T x, y, z;
};
template <class T>
V3<T> Sub(const Vec3& a, const Vec3& b) {
  return {Cv<T>(a.x) - Cv<T>(b.x), Cv<T>(a.y) - Cv<T>(b.y), Cv<T>(a.z) - Cv<T>(b.z)};
}
template <class T>
T DotT(const V3<T>& a, const V3<T>& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class T>
V3<T> CrossT(const V3<T>& a, const V3<T>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

// The polynomials; > 0 means the documented "true" outcome.
template <class T>
T InDiametralPoly(const Vec3& a, const Vec3& b, const Vec3& p) {
  return -DotT(Sub<T>(a, p), Sub<T>(b, p));
}
template <class T>
T InTriangleCircumballPoly(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p) {
  // q = p−a, u = b−a, v = c−a, n = u×v. Circumcentre o = a + w with
  // w = (|u|²(v×n) + |v|²(n×u)) / (2|n|²); p inside ⇔ |q−w|² < |w|²
  // ⇔ q·(|u|²(v×n) + |v|²(n×u)) − |q|²|n|² > 0.
  const V3<T> q = Sub<T>(p, a), u = Sub<T>(b, a), v = Sub<T>(c, a);
  const V3<T> n = CrossT(u, v);
  const T uu = DotT(u, u), vv = DotT(v, v);
  const V3<T> vn = CrossT(v, n), nu = CrossT(n, u);
  const V3<T> w{uu * vn.x + vv * nu.x, uu * vn.y + vv * nu.y, uu * vn.z + vv * nu.z};
  return DotT(q, w) - DotT(q, q) * DotT(n, n);
}
template <class T>
T CompareDistancePoly(const Vec3& p, const Vec3& a, const Vec3& b) {
  const V3<T> pa = Sub<T>(p, a), pb = Sub<T>(p, b);
  return DotT(pa, pa) - DotT(pb, pb);
}
template <class T>
T DotSignPoly(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return DotT(Sub<T>(b, a), Sub<T>(d, c));
}
template <class T>
T Orient2dProjectedPoly(const Vec3& a, const Vec3& b, const Vec3& c, int axis) {
  const int i = (axis + 1) % 3, j = (axis + 2) % 3;
  const T bai = Cv<T>(b[i]) - Cv<T>(a[i]), baj = Cv<T>(b[j]) - Cv<T>(a[j]);
  const T cai = Cv<T>(c[i]) - Cv<T>(a[i]), caj = Cv<T>(c[j]) - Cv<T>(a[j]);
  return bai * caj - baj * cai;
}

Vec3 To3(Vec2 p) { return {p.x, p.y, 0}; }

// Filter, then exact on rescaled inputs. `eval` is a generic lambda taking
// a type tag and the (possibly rescaled) points.
template <class Eval>
int Decide(Pred pred, int degree, std::initializer_list<Vec3> pts, Eval eval) {
  internal::CountCall(pred);
  bool certain = false;
  const int s = FilteredSign(eval(static_cast<Fp*>(nullptr), pts.begin()), &certain);
  if (certain) return s;
  CountExact(pred);
  double mags[18];
  int k = 0;
  for (const Vec3& p : pts) {
    mags[k++] = p.x;
    mags[k++] = p.y;
    mags[k++] = p.z;
  }
  double m = 0;
  for (int i = 0; i < k; ++i) m = std::max(m, std::fabs(mags[i]));
  Vec3 scaled[6];
  int e = 0;
  if (m != 0 && std::isfinite(m)) e = TargetExponent(degree) - std::ilogb(m);
  int n = 0;
  for (const Vec3& p : pts) {
    scaled[n++] = {std::ldexp(p.x, e), std::ldexp(p.y, e), std::ldexp(p.z, e)};
  }
  return eval(static_cast<Expansion*>(nullptr), scaled).Sign();
}

}  // namespace

int InDiametralSphere(const Vec3& a, const Vec3& b, const Vec3& p) {
  return Decide(Pred::kInDiametralSphere, 2, {a, b, p}, [](auto* tag, const Vec3* q) {
    using T = std::remove_pointer_t<decltype(tag)>;
    return InDiametralPoly<T>(q[0], q[1], q[2]);
  });
}

int InDiametralCircle(Vec2 a, Vec2 b, Vec2 p) { return InDiametralSphere(To3(a), To3(b), To3(p)); }

int InTriangleCircumball3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p) {
  return Decide(Pred::kInTriangleCircumball3d, 6, {a, b, c, p}, [](auto* tag, const Vec3* q) {
    using T = std::remove_pointer_t<decltype(tag)>;
    return InTriangleCircumballPoly<T>(q[0], q[1], q[2], q[3]);
  });
}

int CompareDistance(const Vec3& p, const Vec3& a, const Vec3& b) {
  return Decide(Pred::kCompareDistance, 2, {p, a, b}, [](auto* tag, const Vec3* q) {
    using T = std::remove_pointer_t<decltype(tag)>;
    return CompareDistancePoly<T>(q[0], q[1], q[2]);
  });
}

int CompareDistance(Vec2 p, Vec2 a, Vec2 b) { return CompareDistance(To3(p), To3(a), To3(b)); }

int DotSign(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return Decide(Pred::kDotSign, 2, {a, b, c, d}, [](auto* tag, const Vec3* q) {
    using T = std::remove_pointer_t<decltype(tag)>;
    return DotSignPoly<T>(q[0], q[1], q[2], q[3]);
  });
}

int Orient2dProjected(const Vec3& a, const Vec3& b, const Vec3& c, int axis) {
  return Decide(Pred::kOrient2dProjected, 2, {a, b, c}, [axis](auto* tag, const Vec3* q) {
    using T = std::remove_pointer_t<decltype(tag)>;
    return Orient2dProjectedPoly<T>(q[0], q[1], q[2], axis);
  });
}

}  // namespace svrc::geom
