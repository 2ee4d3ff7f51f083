// Exact fallbacks, simulation of simplicity and the extra predicates of
// core/geometry/predicates.h (conventions and derivations are there).
#include "core/geometry/predicates.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <initializer_list>

#include <gmpxx.h>

#include "core/geometry/expansion.h"

namespace svrc::geom {

namespace {

using internal::SignOf;

void CountExact(Pred p) { ++internal::tls_predicate_stats.exact[static_cast<int>(p)]; }
void CountSos(Pred p) { ++internal::tls_predicate_stats.sos[static_cast<int>(p)]; }

// ---------------------------------------------------------- number types
// The exact polynomials are written once as templates over the number type:
// Expansion (fast, the normal exact path) and mpq_class (GMP; only when the
// input's exponent range is too wide for expansions, see PlanScaling).

template <class T>
T Cv(double x);
template <>
Expansion Cv<Expansion>(double x) {
  return Expansion(x);
}
template <>
mpq_class Cv<mpq_class>(double x) {
  return mpq_class(x);
}
template <>
double Cv<double>(double x) {
  return x;
}
int SignOfT(double x) { return SignOf(x); }
int SignOfT(const Expansion& e) { return e.Sign(); }
int SignOfT(const mpq_class& q) { return sgn(q); }

// Exact a − b.
template <class T>
T Diff(double a, double b) {
  return Cv<T>(a) - Cv<T>(b);
}
template <>
Expansion Diff<Expansion>(double a, double b) {
  return Expansion::Diff(a, b);
}

// ------------------------------------------------------------- scaling plan
// Every predicate is a homogeneous polynomial of some degree d in the input
// coordinates (or their differences), so scaling all inputs by 2^k (exact)
// keeps its sign. Expansion arithmetic is exact when nothing overflows or
// underflows. All inputs are integer multiples of 2^g (g = the lowest set bit
// over all coordinates), hence so is every difference and every word of every
// intermediate expansion of degree ≤ d a multiple of 2^(d·g): with d·(g+k) ≥
// −1074 nothing can underflow inexactly (Dekker's halves keep the granularity
// too). Overflow: keep the largest coordinate below 2^(960/d − 8), so that
// sums of a few dozen products of d differences stay below 2^996, where the
// split would overflow. We take k as large as allowed; if the lowest bit then
// still falls below −1074/d (coordinates spanning more than ~2000/d binary
// orders of magnitude, e.g. 1e120 next to a denormal), we fall back to GMP.
struct ScalePlan {
  int k = 0;
  bool use_gmp = false;
};

// x ≠ 0 finite: the exponent of its lowest set bit (x = odd·2^result).
int LowestSetBitExponent(double x) {
  uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  const int biased = static_cast<int>((bits >> 52) & 0x7ff);
  uint64_t mant = bits & ((uint64_t{1} << 52) - 1);
  if (biased == 0) return -1074 + __builtin_ctzll(mant);  // subnormal: mant·2^-1074
  mant |= uint64_t{1} << 52;                               // normal: mant·2^(biased−1075)
  return biased - 1075 + __builtin_ctzll(mant);
}

ScalePlan PlanScaling(const double* v, int n, int degree) {
  double m = 0;
  int g = 1 << 20;
  for (int i = 0; i < n; ++i) {
    if (v[i] == 0) continue;
    if (!std::isfinite(v[i])) return {};  // garbage in: no guarantee
    m = std::max(m, std::fabs(v[i]));
    g = std::min(g, LowestSetBitExponent(v[i]));
  }
  if (m == 0) return {};
  ScalePlan plan;
  plan.k = (960 / degree - 8) - std::ilogb(m);
  if (degree * (g + plan.k) < -1074) plan.use_gmp = true;
  return plan;
}

// Runs eval<T>(scaled coordinates) with T = Expansion, or with T = mpq_class
// on the unscaled coordinates when the plan says so. `coords` holds n values.
template <class Eval>
int ExactSign(const double* coords, int n, int degree, Eval eval) {
  const ScalePlan plan = PlanScaling(coords, n, degree);
  if (plan.use_gmp) return eval(static_cast<mpq_class*>(nullptr), coords);
  double scaled[32];
  for (int i = 0; i < n; ++i) scaled[i] = plan.k == 0 ? coords[i] : std::ldexp(coords[i], plan.k);
  return eval(static_cast<Expansion*>(nullptr), scaled);
}

// -------------------------------------------- small-integer exact fast path
// Grids and other "nice" inputs make the filter fail on exactly degenerate
// configurations all the time. When every coordinate difference the formula
// uses is exact in doubles and equal to n·2^g for one g with |n| < 2^bits,
// every product/sum of the degree-d formula is an integer multiple of 2^(d·g)
// below 2^53 of them, so plain double evaluation is exact. `bits` per formula:
// orient2d 26, orient3d 16, incircle 12, insphere 9 (2^(5·9+6.2) < 2^53: the
// bound on |lift·3×3 minor| summed over four terms). Differences are taken
// against point `ref` (as in the formulas).
bool SmallDyadicDiffs(const double* c, int npts, int dim, int ref, int bits, int degree) {
  int g = 1 << 20, top = -(1 << 20);
  for (int i = 0; i < npts; ++i) {
    if (i == ref) continue;
    for (int j = 0; j < dim; ++j) {
      double d, tail;
      TwoDiff(c[i * dim + j], c[ref * dim + j], d, tail);
      if (tail != 0 || !std::isfinite(d)) return false;
      if (d == 0) continue;
      g = std::min(g, LowestSetBitExponent(d));
      top = std::max(top, std::ilogb(d));
    }
  }
  if (top < g) return true;  // all differences zero
  return top - g < bits && degree * g >= -1000 && degree * (top + 2) <= 1000;
}

// ------------------------------------------------------ exact core predicates
// The same formulas as the inline filters, on exact differences. Coordinates
// arrive flattened: point i at c[D*i ...].

template <class T>
int Orient2dPoly(const double* c) {
  const T bax = Diff<T>(c[2], c[0]), bay = Diff<T>(c[3], c[1]);
  const T cax = Diff<T>(c[4], c[0]), cay = Diff<T>(c[5], c[1]);
  return SignOfT(bax * cay - bay * cax);
}

template <class T>
int Orient3dPoly(const double* c) {
  const T bax = Diff<T>(c[3], c[0]), bay = Diff<T>(c[4], c[1]), baz = Diff<T>(c[5], c[2]);
  const T cax = Diff<T>(c[6], c[0]), cay = Diff<T>(c[7], c[1]), caz = Diff<T>(c[8], c[2]);
  const T dax = Diff<T>(c[9], c[0]), day = Diff<T>(c[10], c[1]), daz = Diff<T>(c[11], c[2]);
  return SignOfT(bax * (cay * daz - caz * day) + bay * (caz * dax - cax * daz) +
                 baz * (cax * day - cay * dax));
}

template <class T>
int InCirclePoly(const double* c) {
  const T adx = Diff<T>(c[0], c[6]), ady = Diff<T>(c[1], c[7]);
  const T bdx = Diff<T>(c[2], c[6]), bdy = Diff<T>(c[3], c[7]);
  const T cdx = Diff<T>(c[4], c[6]), cdy = Diff<T>(c[5], c[7]);
  const T alift = adx * adx + ady * ady;
  const T blift = bdx * bdx + bdy * bdy;
  const T clift = cdx * cdx + cdy * cdy;
  return SignOfT(alift * (bdx * cdy - cdx * bdy) + blift * (cdx * ady - adx * cdy) +
                 clift * (adx * bdy - bdx * ady));
}

template <class T>
int InSpherePoly(const double* c) {
  const T aex = Diff<T>(c[0], c[12]), aey = Diff<T>(c[1], c[13]), aez = Diff<T>(c[2], c[14]);
  const T bex = Diff<T>(c[3], c[12]), bey = Diff<T>(c[4], c[13]), bez = Diff<T>(c[5], c[14]);
  const T cex = Diff<T>(c[6], c[12]), cey = Diff<T>(c[7], c[13]), cez = Diff<T>(c[8], c[14]);
  const T dex = Diff<T>(c[9], c[12]), dey = Diff<T>(c[10], c[13]), dez = Diff<T>(c[11], c[14]);
  const T ab = aex * bey - bex * aey;
  const T bc = bex * cey - cex * bey;
  const T cd = cex * dey - dex * cey;
  const T da = dex * aey - aex * dey;
  const T ac = aex * cey - cex * aey;
  const T bd = bex * dey - dex * bey;
  const T abc = aez * bc - bez * ac + cez * ab;
  const T bcd = bez * cd - cez * bd + dez * bc;
  const T cda = cez * da + dez * ac + aez * cd;
  const T dab = dez * ab + aez * bd + bez * da;
  const T alift = aex * aex + aey * aey + aez * aez;
  const T blift = bex * bex + bey * bey + bez * bez;
  const T clift = cex * cex + cey * cey + cez * cez;
  const T dlift = dex * dex + dey * dey + dez * dez;
  return SignOfT((clift * dab - dlift * abc) + (alift * bcd - blift * cda));
}

int Orient2dExactImpl(Vec2 a, Vec2 b, Vec2 c) {
  const double v[6] = {a.x, a.y, b.x, b.y, c.x, c.y};
  if (SmallDyadicDiffs(v, 3, 2, 0, 26, 2)) return Orient2dPoly<double>(v);
  return ExactSign(v, 6, 2, [](auto* tag, const double* q) {
    return Orient2dPoly<std::remove_pointer_t<decltype(tag)>>(q);
  });
}

int Orient3dExactImpl(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const double v[12] = {a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z, d.x, d.y, d.z};
  if (SmallDyadicDiffs(v, 4, 3, 0, 16, 3)) return Orient3dPoly<double>(v);
  return ExactSign(v, 12, 3, [](auto* tag, const double* q) {
    return Orient3dPoly<std::remove_pointer_t<decltype(tag)>>(q);
  });
}

int InCircleExactImpl(Vec2 a, Vec2 b, Vec2 c, Vec2 d) {
  const double v[8] = {a.x, a.y, b.x, b.y, c.x, c.y, d.x, d.y};
  if (SmallDyadicDiffs(v, 4, 2, 3, 12, 4)) return InCirclePoly<double>(v);
  return ExactSign(v, 8, 4, [](auto* tag, const double* q) {
    return InCirclePoly<std::remove_pointer_t<decltype(tag)>>(q);
  });
}

int InSphereExactImpl(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const Vec3& e) {
  const double v[15] = {a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z,
                        d.x, d.y, d.z, e.x, e.y, e.z};
  if (SmallDyadicDiffs(v, 5, 3, 4, 9, 5)) return InSpherePoly<double>(v);
  return ExactSign(v, 15, 5, [](auto* tag, const double* q) {
    return InSpherePoly<std::remove_pointer_t<decltype(tag)>>(q);
  });
}

// -------------------------------------------------- simulation of simplicity

// Exact determinant of an n×n matrix (n ≤ 4) of doubles, row-major, by
// Laplace expansion along the first column (zero entries skipped).
template <class T>
T DetT(const double* m, int n, int stride) {
  if (n == 1) return Cv<T>(m[0]);
  if (n == 2) return Cv<T>(m[0]) * Cv<T>(m[stride + 1]) - Cv<T>(m[1]) * Cv<T>(m[stride]);
  T det = Cv<T>(0);
  double minor[16];
  for (int r = 0; r < n; ++r) {
    if (m[r * stride] == 0) continue;
    int k = 0;
    for (int i = 0; i < n; ++i) {
      if (i == r) continue;
      for (int j = 1; j < n; ++j) minor[k * (n - 1) + (j - 1)] = m[i * stride + j];
      ++k;
    }
    const T sub = Cv<T>(m[r * stride]) * DetT<T>(minor, n - 1, n - 1);
    if (r % 2 == 0) {
      det += sub;
    } else {
      det -= sub;
    }
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
    // The coefficient is a homogeneous polynomial of degree N in the matrix
    // entries (the 1s included), so scaling the whole matrix keeps its sign.
    const int s = ExactSign(m, N * N, N, [](auto* tag, const double* q) {
      return SignOfT(DetT<std::remove_pointer_t<decltype(tag)>>(q, N, N));
    });
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
    case Pred::kInBall: return "in_ball";
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
  const double coords[6] = {a.x, a.y, b.x, b.y, c.x, c.y};
  const uint32_t ids[3] = {ia, ib, ic};
  return OrientSoS<2>(coords, ids);
}

int Orient3dSoSTail(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, uint32_t ia,
                    uint32_t ib, uint32_t ic, uint32_t id) {
  CountSos(Pred::kOrient3d);
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
      const int o = Orient2dUncounted(q[0], q[1], q[2]);
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
      const int o = Orient3dUncounted(q[0], q[1], q[2], q[3]);
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
template <class T>
T CvX(double x) {
  if constexpr (std::is_same_v<T, Fp>) {
    return Fp{x, 0};
  } else {
    return Cv<T>(x);
  }
}

template <class T>
struct V3 {
  T x, y, z;
};
template <class T>
V3<T> Sub(const Vec3& a, const Vec3& b) {
  return {CvX<T>(a.x) - CvX<T>(b.x), CvX<T>(a.y) - CvX<T>(b.y), CvX<T>(a.z) - CvX<T>(b.z)};
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
  const T bai = CvX<T>(b[i]) - CvX<T>(a[i]), baj = CvX<T>(b[j]) - CvX<T>(a[j]);
  const T cai = CvX<T>(c[i]) - CvX<T>(a[i]), caj = CvX<T>(c[j]) - CvX<T>(a[j]);
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
  double coords[18];
  int n = 0;
  for (const Vec3& p : pts) {
    coords[n++] = p.x;
    coords[n++] = p.y;
    coords[n++] = p.z;
  }
  return ExactSign(coords, n, degree, [&eval, n](auto* tag, const double* q) {
    Vec3 scaled[6];
    for (int i = 0; i < n / 3; ++i) scaled[i] = {q[3 * i], q[3 * i + 1], q[3 * i + 2]};
    return SignOfT(eval(tag, scaled));
  });
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

// Exact sign of |p−a|² − |p−b|² on (already scaled) coordinates whose six
// differences p_i − a_i, p_i − b_i are exact in doubles: then the value is
// Σ d_i² − Σ e_i², each square exactly x + y (TwoProduct), and the sign of
// these 12 doubles' sum is that of their expansion (Grow-Expansion, Shewchuk
// 1997 Theorem 10, with zero elimination). Scaled as for ExactSign (degree
// 2), nothing under- or overflows. ~25 TwoSums on average instead of a dozen
// generic Expansion operations (~4.6k instructions per call).
int CompareDistanceTailFree(const double* d, const double* e) {
  double terms[12];
  for (int i = 0; i < 3; ++i) {
    TwoProduct(d[i], d[i], terms[4 * i + 1], terms[4 * i]);
    double x, y;
    TwoProduct(e[i], e[i], x, y);
    terms[4 * i + 2] = -y;
    terms[4 * i + 3] = -x;
  }
  double h[13];
  int n = 0;
  for (double b : terms) {
    if (b == 0) continue;
    double q = b;
    int m = 0;
    for (int j = 0; j < n; ++j) {
      double s, t;
      TwoSum(q, h[j], s, t);
      if (t != 0) h[m++] = t;
      q = s;
    }
    if (q != 0) h[m++] = q;
    n = m;
  }
  return n == 0 ? 0 : (h[n - 1] > 0 ? 1 : -1);
}

int CompareDistance(const Vec3& p, const Vec3& a, const Vec3& b) {
  // Decide()'s steps (filter, counters, scaling, GMP fallback), with an exact
  // stage of its own for the common case of exact coordinate differences
  // (~90% of the calls that reach it on volume-bound corpus runs).
  internal::CountCall(Pred::kCompareDistance);
  // Static pre-filter: with x_i = fl(p_i − a_i), y_i = fl(p_i − b_i),
  // A = Σ fl(x_i²), B = Σ fl(y_i²), each computed square is within
  // (3u + O(u²))·fl(x_i²) of the exact (p_i − a_i)², the two 3-term sums add
  // at most 2u·A and 2u·B, the final difference u·|A − B|: |fl(A − B) − exact|
  // <= 6u·(A + B) (1 + O(u)) < 1e-15·(A + B) (u = 2^-53). 1e-300 covers
  // underflow (as Fp's kTiny); NaN/Inf never pass. A certain sign here is the
  // exact sign, so the result is the same; what it leaves goes through the
  // running-error filter (Fp) and the exact stages below as before (the
  // exact-call counter is unchanged).
  {
    const double x0 = p.x - a.x, x1 = p.y - a.y, x2 = p.z - a.z;
    const double y0 = p.x - b.x, y1 = p.y - b.y, y2 = p.z - b.z;
    const double sa = x0 * x0 + x1 * x1 + x2 * x2, sb = y0 * y0 + y1 * y1 + y2 * y2;
    const double v = sa - sb;
    if (std::fabs(v) > 1e-15 * (sa + sb) + 1e-300) return v > 0 ? 1 : -1;
  }
  bool certain = false;
  const int s = FilteredSign(CompareDistancePoly<Fp>(p, a, b), &certain);
  if (certain) return s;
  CountExact(Pred::kCompareDistance);
  const double coords[9] = {p.x, p.y, p.z, a.x, a.y, a.z, b.x, b.y, b.z};
  const ScalePlan plan = PlanScaling(coords, 9, 2);
  if (!plan.use_gmp) {
    double q[9];
    for (int i = 0; i < 9; ++i) q[i] = plan.k == 0 ? coords[i] : std::ldexp(coords[i], plan.k);
    double d[3], e[3];
    bool tail_free = true;
    for (int i = 0; i < 3; ++i) {
      double t;
      TwoDiff(q[i], q[3 + i], d[i], t);
      tail_free = tail_free && t == 0;
      TwoDiff(q[i], q[6 + i], e[i], t);
      tail_free = tail_free && t == 0;
    }
    if (tail_free) return CompareDistanceTailFree(d, e);
  }
  return ExactSign(coords, 9, 2, [](auto* tag, const double* q) {
    using T = std::remove_pointer_t<decltype(tag)>;
    const Vec3 v[3] = {{q[0], q[1], q[2]}, {q[3], q[4], q[5]}, {q[6], q[7], q[8]}};
    return SignOfT(CompareDistancePoly<T>(v[0], v[1], v[2]));
  });
}

int CompareDistance(Vec2 p, Vec2 a, Vec2 b) { return CompareDistance(To3(p), To3(a), To3(b)); }

int DotSign(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return Decide(Pred::kDotSign, 2, {a, b, c, d}, [](auto* tag, const Vec3* q) {
    using T = std::remove_pointer_t<decltype(tag)>;
    return DotSignPoly<T>(q[0], q[1], q[2], q[3]);
  });
}

int InBall(const Vec3& p, const Vec3& c, double r) {
  // Static pre-filter, as CompareDistance's: with x_i = fl(p_i − c_i) and
  // S = Σ fl(x_i²), S is within (5u + O(u²))·S of the exact Σ (p_i − c_i)²
  // (3u per square, 2u for the two additions), R = fl(r²) within u·R, and the
  // difference adds u·|R − S|: |fl(R − S) − exact| <= 6u·(R + S)(1 + O(u))
  // < 1e-15·(R + S) (u = 2^-53); 1e-300 covers underflow, NaN/Inf never
  // pass. A certain sign here is the exact sign. The collar path calls this
  // tens of millions of times (wedge-1.smesh: 10% of its CPU went to the
  // running-error filter below).
  {
    const double x0 = p.x - c.x, x1 = p.y - c.y, x2 = p.z - c.z;
    const double sq = x0 * x0 + x1 * x1 + x2 * x2, rr = r * r;
    const double v = rr - sq;
    if (std::fabs(v) > 1e-15 * (rr + sq) + 1e-300) {
      internal::CountCall(Pred::kInBall);
      return v > 0 ? 1 : -1;
    }
  }
  // r rides as the x coordinate of a third point so that the exact path's
  // common scaling applies to it too (the expression is homogeneous of degree 2).
  return Decide(Pred::kInBall, 2, {p, c, Vec3(r, 0, 0)}, [](auto* tag, const Vec3* q) {
    using T = std::remove_pointer_t<decltype(tag)>;
    const V3<T> pc = Sub<T>(q[0], q[1]);
    const T rr = CvX<T>(q[2].x);
    return T(rr * rr - DotT(pc, pc));  // T(): no mpq expression template over locals
  });
}

int Orient2dProjected(const Vec3& a, const Vec3& b, const Vec3& c, int axis) {
  return Decide(Pred::kOrient2dProjected, 2, {a, b, c}, [axis](auto* tag, const Vec3* q) {
    using T = std::remove_pointer_t<decltype(tag)>;
    return Orient2dProjectedPoly<T>(q[0], q[1], q[2], axis);
  });
}

}  // namespace svrc::geom
