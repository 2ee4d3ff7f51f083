// Every predicate against an exact rational oracle (GMP; doubles convert to
// mpq_class exactly). The oracle uses the *definitions* (lifted determinants
// with absolute coordinates), not the translated formulas of the code.
#include "core/geometry/predicates.h"

#include <gmpxx.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <numeric>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace svrc::geom {
namespace {

using Q = mpq_class;

// Sanitizer builds (CI runs the `core` suites under ASan+UBSan) use a quarter
// of the cases; release builds run them all.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_UNDEFINED__)
constexpr int kCaseDivisor = 4;
#else
constexpr int kCaseDivisor = 1;
#endif
constexpr int N(int n) { return n / kCaseDivisor; }

// ---------------------------------------------------------------- oracle

// Determinant of an n×n rational matrix by Gaussian elimination.
Q Det(std::vector<std::vector<Q>> m) {
  const size_t n = m.size();
  Q det = 1;
  for (size_t col = 0; col < n; ++col) {
    size_t pivot = col;
    while (pivot < n && sgn(m[pivot][col]) == 0) ++pivot;
    if (pivot == n) return 0;
    if (pivot != col) {
      std::swap(m[pivot], m[col]);
      det = -det;
    }
    det *= m[col][col];
    for (size_t r = col + 1; r < n; ++r) {
      if (sgn(m[r][col]) == 0) continue;
      const Q f = m[r][col] / m[col][col];
      for (size_t c = col; c < n; ++c) m[r][c] -= f * m[col][c];
    }
  }
  return det;
}

// Laplace expansion: better than elimination for the SoS oracle, whose
// entries carry huge powers of ε (no divisions).
Q DetLaplace(const std::vector<std::vector<Q>>& m) {
  const size_t n = m.size();
  if (n == 1) return m[0][0];
  Q det = 0;
  for (size_t r = 0; r < n; ++r) {
    if (sgn(m[r][0]) == 0) continue;
    std::vector<std::vector<Q>> minor;
    for (size_t i = 0; i < n; ++i) {
      if (i != r) minor.emplace_back(m[i].begin() + 1, m[i].end());
    }
    const Q sub = m[r][0] * DetLaplace(minor);
    if (r % 2 == 0) {
      det += sub;
    } else {
      det -= sub;
    }
  }
  return det;
}

std::vector<Q> Row(Vec2 p) { return {Q(1), Q(p.x), Q(p.y)}; }
std::vector<Q> Row(const Vec3& p) { return {Q(1), Q(p.x), Q(p.y), Q(p.z)}; }
std::vector<Q> LiftedRow(Vec2 p) {
  auto r = Row(p);
  r.push_back(r[1] * r[1] + r[2] * r[2]);
  return r;
}
std::vector<Q> LiftedRow(const Vec3& p) {
  auto r = Row(p);
  r.push_back(r[1] * r[1] + r[2] * r[2] + r[3] * r[3]);
  return r;
}

int OracleOrient2d(Vec2 a, Vec2 b, Vec2 c) { return sgn(Det({Row(a), Row(b), Row(c)})); }
int OracleOrient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return sgn(Det({Row(a), Row(b), Row(c), Row(d)}));
}
int OracleInCircle(Vec2 a, Vec2 b, Vec2 c, Vec2 d) {
  return -sgn(Det({LiftedRow(a), LiftedRow(b), LiftedRow(c), LiftedRow(d)}));
}
int OracleInSphere(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const Vec3& e) {
  return -sgn(Det({LiftedRow(a), LiftedRow(b), LiftedRow(c), LiftedRow(d), LiftedRow(e)}));
}

struct QV {
  Q x, y, z;
};
QV ToQ(const Vec3& p) { return {Q(p.x), Q(p.y), Q(p.z)}; }
QV operator-(const QV& a, const QV& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Q Dot(const QV& a, const QV& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
QV Cross(const QV& a, const QV& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

int OracleInDiametral(const Vec3& a, const Vec3& b, const Vec3& p) {
  return -sgn(Dot(ToQ(a) - ToQ(p), ToQ(b) - ToQ(p)));
}
// Circumcentre of a triangle in 3D computed as the solution of the linear
// system (independent of the code's closed form): o = a + s·u + t·v with
// (o−a)·u = |u|²/2, (o−a)·v = |v|²/2.
int OracleInTriangleBall(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p) {
  const QV A = ToQ(a), u = ToQ(b) - A, v = ToQ(c) - A, q = ToQ(p) - A;
  const Q uu = Dot(u, u), uv = Dot(u, v), vv = Dot(v, v);
  const Q det = uu * vv - uv * uv;
  if (sgn(det) == 0) return 0;
  const Q s = (uu / 2 * vv - vv / 2 * uv) / det;
  const Q t = (vv / 2 * uu - uu / 2 * uv) / det;
  const QV w{s * u.x + t * v.x, s * u.y + t * v.y, s * u.z + t * v.z};
  const QV qw = q - w;
  return sgn(Dot(w, w) - Dot(qw, qw));
}
int OracleCompareDistance(const Vec3& p, const Vec3& a, const Vec3& b) {
  const QV pa = ToQ(p) - ToQ(a), pb = ToQ(p) - ToQ(b);
  return sgn(Dot(pa, pa) - Dot(pb, pb));
}
int OracleInBall(const Vec3& p, const Vec3& c, double r) {
  const QV pc = ToQ(p) - ToQ(c);
  const Q rr = Q(r) * Q(r);
  return sgn(rr - Dot(pc, pc));
}
int OracleDotSign(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return sgn(Dot(ToQ(b) - ToQ(a), ToQ(d) - ToQ(c)));
}
int OracleOrientProjected(const Vec3& a, const Vec3& b, const Vec3& c, int axis) {
  const QV n = Cross(ToQ(b) - ToQ(a), ToQ(c) - ToQ(a));
  return sgn(axis == 0 ? n.x : axis == 1 ? n.y : n.z);
}

// ---------------------------------------------------------- input families

class Gen {
 public:
  explicit Gen(uint64_t seed) : rng_(seed) {}
  double Uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng_); }
  int Int(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }
  Vec3 Point3(double s = 1) { return {Uniform(-s, s), Uniform(-s, s), Uniform(-s, s)}; }
  Vec2 Point2(double s = 1) { return {Uniform(-s, s), Uniform(-s, s)}; }
  Vec3 IntPoint3(int r) { return {double(Int(-r, r)), double(Int(-r, r)), double(Int(-r, r))}; }
  Vec2 IntPoint2(int r) { return {double(Int(-r, r)), double(Int(-r, r))}; }
  // Move one random coordinate of one random point by ±1 ulp.
  template <class P, size_t N>
  void NudgeOneUlp(std::array<P, N>& pts) {
    P& p = pts[Int(0, int(N) - 1)];
    double* c = const_cast<double*>(p.data()) + Int(0, int(sizeof(P) / sizeof(double)) - 1);
    *c = std::nextafter(*c, Int(0, 1) ? HUGE_VAL : -HUGE_VAL);
  }
  std::mt19937_64& rng() { return rng_; }

 private:
  std::mt19937_64 rng_;
};

// Integer points on the sphere x²+y²+z² = r².
std::vector<Vec3> SpherePoints(int r) {
  std::vector<Vec3> out;
  for (int x = -r; x <= r; ++x)
    for (int y = -r; y <= r; ++y)
      for (int z = -r; z <= r; ++z)
        if (x * x + y * y + z * z == r * r) out.push_back({double(x), double(y), double(z)});
  return out;
}
std::vector<Vec2> CirclePoints(int r) {
  std::vector<Vec2> out;
  for (int x = -r; x <= r; ++x)
    for (int y = -r; y <= r; ++y)
      if (x * x + y * y == r * r) out.push_back({double(x), double(y)});
  return out;
}

// Exact affine maps that keep degeneracy: scale by 2^k, translate by a
// multiple of the scale that keeps every coordinate representable.
struct Frame {
  int k;          // scale 2^k
  double offset;  // added after scaling
};
constexpr Frame kFrames[] = {
    {0, 0},           {-10, 0},         {200, 0},   {-200, 0},         {-500, 0},
    {400, 0},         {-10, 1048576.0}, {-20, 1e6}, {-30, -3.5e3},     {-3, 0.125},
};
Vec3 Apply(const Frame& f, const Vec3& p) {
  return {std::ldexp(p.x, f.k) + f.offset, std::ldexp(p.y, f.k) - f.offset,
          std::ldexp(p.z, f.k) + 0.5 * f.offset};
}
Vec2 Apply(const Frame& f, Vec2 p) { return {std::ldexp(p.x, f.k) + f.offset, std::ldexp(p.y, f.k) - f.offset}; }

template <class P, size_t N>
std::string Show(const std::array<P, N>& pts) {
  std::ostringstream os;
  os.precision(17);
  for (const P& p : pts) {
    os << "(";
    for (size_t i = 0; i < sizeof(P) / sizeof(double); ++i) os << (i ? ", " : "") << p.data()[i];
    os << ") ";
  }
  return os.str();
}

// ------------------------------------------------------ core predicate tests

// Each family: random, integer (many exact zeros), degenerate sets under
// exact frames, and the same nudged by one ulp.
TEST(PredicatesTest, Orient2dMatchesOracle) {
  Gen g(11);
  int cases = 0, zeros = 0;
  auto check = [&](std::array<Vec2, 3> p) {
    const int want = OracleOrient2d(p[0], p[1], p[2]);
    ASSERT_EQ(Orient2d(p[0], p[1], p[2]), want) << p[0].x << " " << p[0].y << " " << p[1].x;
    ++cases;
    zeros += want == 0;
  };
  for (int i = 0; i < N(4000); ++i) check({g.Point2(), g.Point2(), g.Point2()});
  for (const Frame& f : kFrames) {
    for (int i = 0; i < N(600); ++i) {
      // Collinear: a + s·(b−a) with small integers.
      const Vec2 a = g.IntPoint2(8), d = g.IntPoint2(3);
      const int s = g.Int(-3, 3), t = g.Int(-3, 3);
      std::array<Vec2, 3> p = {Apply(f, a), Apply(f, a + double(s) * d), Apply(f, a + double(t) * d)};
      check(p);
      g.NudgeOneUlp(p);
      check(p);
      check({Apply(f, g.IntPoint2(2)), Apply(f, g.IntPoint2(2)), Apply(f, g.IntPoint2(2))});
    }
  }
  // Far from the origin with 1e-3 separations (not exactly representable).
  for (int i = 0; i < N(2000); ++i) {
    const Vec2 o{1e6, -1e6};
    check({o + 1e-3 * g.IntPoint2(3), o + 1e-3 * g.IntPoint2(3), o + 1e-3 * g.IntPoint2(3)});
  }
  EXPECT_GT(zeros, N(1000));
  EXPECT_GT(cases, N(20000));
}

TEST(PredicatesTest, Orient3dMatchesOracle) {
  Gen g(12);
  int cases = 0, zeros = 0;
  auto check = [&](std::array<Vec3, 4> p) {
    const int want = OracleOrient3d(p[0], p[1], p[2], p[3]);
    ASSERT_EQ(Orient3d(p[0], p[1], p[2], p[3]), want) << Show(p);
    ++cases;
    zeros += want == 0;
  };
  for (int i = 0; i < N(4000); ++i) check({g.Point3(), g.Point3(), g.Point3(), g.Point3()});
  for (const Frame& f : kFrames) {
    for (int i = 0; i < N(500); ++i) {
      // Coplanar: a + s·u + t·v.
      const Vec3 a = g.IntPoint3(8), u = g.IntPoint3(3), v = g.IntPoint3(3);
      std::array<Vec3, 4> p;
      for (auto& q : p) q = Apply(f, a + double(g.Int(-3, 3)) * u + double(g.Int(-3, 3)) * v);
      check(p);
      g.NudgeOneUlp(p);
      check(p);
      check({Apply(f, g.IntPoint3(1)), Apply(f, g.IntPoint3(1)), Apply(f, g.IntPoint3(1)),
             Apply(f, g.IntPoint3(1))});
    }
  }
  for (int i = 0; i < N(2000); ++i) {
    const Vec3 o{1e6, 1e6, -1e6};
    check({o + 1e-3 * g.IntPoint3(2), o + 1e-3 * g.IntPoint3(2), o + 1e-3 * g.IntPoint3(2),
           o + 1e-3 * g.IntPoint3(2)});
  }
  EXPECT_GT(zeros, N(1000));
  EXPECT_GT(cases, N(20000));
}

TEST(PredicatesTest, InCircleMatchesOracle) {
  Gen g(13);
  int cases = 0, zeros = 0;
  auto check = [&](std::array<Vec2, 4> p) {
    const int want = OracleInCircle(p[0], p[1], p[2], p[3]);
    ASSERT_EQ(InCircle(p[0], p[1], p[2], p[3]), want);
    ++cases;
    zeros += want == 0;
  };
  for (int i = 0; i < N(4000); ++i) check({g.Point2(), g.Point2(), g.Point2(), g.Point2()});
  const std::vector<Vec2> circle = CirclePoints(25);  // 12 lattice points... and more
  ASSERT_GE(circle.size(), 12u);
  for (const Frame& f : kFrames) {
    for (int i = 0; i < N(500); ++i) {
      std::array<Vec2, 4> p;
      for (auto& q : p) q = Apply(f, circle[g.Int(0, int(circle.size()) - 1)] + Vec2{3, -7});
      check(p);
      g.NudgeOneUlp(p);
      check(p);
      check({Apply(f, g.IntPoint2(2)), Apply(f, g.IntPoint2(2)), Apply(f, g.IntPoint2(2)),
             Apply(f, g.IntPoint2(2))});
    }
  }
  for (int i = 0; i < N(2000); ++i) {
    const Vec2 o{-1e6, 1e6};
    check({o + 1e-3 * g.IntPoint2(3), o + 1e-3 * g.IntPoint2(3), o + 1e-3 * g.IntPoint2(3),
           o + 1e-3 * g.IntPoint2(3)});
  }
  EXPECT_GT(zeros, N(1000));
  EXPECT_GT(cases, N(20000));
}

TEST(PredicatesTest, InSphereMatchesOracle) {
  Gen g(14);
  int cases = 0, zeros = 0;
  auto check = [&](std::array<Vec3, 5> p) {
    const int want = OracleInSphere(p[0], p[1], p[2], p[3], p[4]);
    ASSERT_EQ(InSphere(p[0], p[1], p[2], p[3], p[4]), want)
        << p[0].x << "," << p[0].y << "," << p[0].z << " " << p[4].x;
    ++cases;
    zeros += want == 0;
  };
  for (int i = 0; i < N(4000); ++i) check({g.Point3(), g.Point3(), g.Point3(), g.Point3(), g.Point3()});
  const std::vector<Vec3> sphere = SpherePoints(9);  // many lattice points on r = 9
  ASSERT_GE(sphere.size(), 30u);
  const Vec3 cube[8] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0},
                        {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
  for (const Frame& f : kFrames) {
    for (int i = 0; i < N(400); ++i) {
      std::array<Vec3, 5> p;
      for (auto& q : p) q = Apply(f, sphere[g.Int(0, int(sphere.size()) - 1)] + Vec3{2, -5, 1});
      check(p);
      g.NudgeOneUlp(p);
      check(p);
      for (auto& q : p) q = Apply(f, cube[g.Int(0, 7)]);
      check(p);
      g.NudgeOneUlp(p);
      check(p);
      check({Apply(f, g.IntPoint3(1)), Apply(f, g.IntPoint3(1)), Apply(f, g.IntPoint3(1)),
             Apply(f, g.IntPoint3(1)), Apply(f, g.IntPoint3(1))});
    }
  }
  for (int i = 0; i < N(2000); ++i) {
    const Vec3 o{1e6, -1e6, 1e6};
    check({o + 1e-3 * g.IntPoint3(2), o + 1e-3 * g.IntPoint3(2), o + 1e-3 * g.IntPoint3(2),
           o + 1e-3 * g.IntPoint3(2), o + 1e-3 * g.IntPoint3(2)});
  }
  EXPECT_GT(zeros, N(1000));
  EXPECT_GT(cases, N(20000));
}

// Around the bit limits of the small-integer exact path: integer points whose
// differences straddle 2^9 (insphere), 2^12 (incircle), 2^16 (orient3d),
// exactly degenerate and nudged by one unit.
TEST(PredicatesTest, SmallIntegerPathBoundaries) {
  Gen g(16);
  // Lattice points on spheres/circles of radius ~ 200..300.
  std::vector<Vec3> sphere;
  for (int r : {221, 255, 289}) {
    for (int x = -r; x <= r; x += 3) {
      for (int y = -r; y <= r; y += 5) {
        const long z2 = long(r) * r - long(x) * x - long(y) * y;
        if (z2 < 0) continue;
        const long z = std::lround(std::sqrt(double(z2)));
        if (z * z == z2 && sphere.size() < 400) sphere.push_back({double(x), double(y), double(z)});
      }
    }
  }
  ASSERT_GE(sphere.size(), 20u);
  for (int i = 0; i < N(3000); ++i) {
    std::array<Vec3, 5> p;
    for (auto& q : p) q = sphere[g.Int(0, int(sphere.size()) - 1)];
    if (i % 2) {
      double* c = const_cast<double*>(p[g.Int(0, 4)].data()) + g.Int(0, 2);
      *c += g.Int(0, 1) ? 1 : -1;
    }
    ASSERT_EQ(InSphere(p[0], p[1], p[2], p[3], p[4]), OracleInSphere(p[0], p[1], p[2], p[3], p[4]))
        << Show(p);
  }
  for (int i = 0; i < N(3000); ++i) {
    const int s = 1 << g.Int(8, 14);
    const Vec2 a{double(g.Int(-s, s)), double(g.Int(-s, s))}, d{double(g.Int(-s, s)), double(g.Int(-s, s))};
    std::array<Vec2, 4> p = {a, Vec2{-a.y, a.x}, Vec2{-a.x, -a.y}, Vec2{a.y, -a.x}};  // cocircular
    if (i % 3 == 1) p[3] = d;
    if (i % 3 == 2) p[g.Int(0, 3)].x += 1;
    ASSERT_EQ(InCircle(p[0], p[1], p[2], p[3]), OracleInCircle(p[0], p[1], p[2], p[3])) << Show(p);
  }
  for (int i = 0; i < N(3000); ++i) {
    const int s = 1 << g.Int(12, 18);
    const Vec3 o = g.IntPoint3(s), u = g.IntPoint3(s / 64), v = g.IntPoint3(s / 64);
    std::array<Vec3, 4> p = {o, o + u, o + v, o + 3.0 * u - 2.0 * v};  // coplanar
    if (i % 2) p[g.Int(0, 3)].z += 1;
    ASSERT_EQ(Orient3d(p[0], p[1], p[2], p[3]), OracleOrient3d(p[0], p[1], p[2], p[3])) << Show(p);
  }
}

TEST(PredicatesTest, ConventionsOnSimpleCases) {
  EXPECT_EQ(Orient2d({0, 0}, {1, 0}, {0, 1}), 1);
  EXPECT_EQ(Orient3d({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}), 1);
  EXPECT_EQ(InCircle({0, 0}, {1, 0}, {0, 1}, {0.25, 0.25}), 1);
  EXPECT_EQ(InCircle({0, 0}, {1, 0}, {0, 1}, {2, 2}), -1);
  EXPECT_EQ(InCircle({0, 0}, {1, 0}, {0, 1}, {1, 1}), 0);
  const Vec3 a{0, 0, 0}, b{1, 0, 0}, c{0, 1, 0}, d{0, 0, 1};
  EXPECT_EQ(InSphere(a, b, c, d, {0.1, 0.1, 0.1}), 1);
  EXPECT_EQ(InSphere(a, b, c, d, {2, 2, 2}), -1);
  EXPECT_EQ(InSphere(a, b, c, d, {1, 1, 1}), 0);
  EXPECT_EQ(InSphere(b, a, c, d, {0.1, 0.1, 0.1}), -1);  // negative tet flips
  EXPECT_EQ(Orient1d(1, 2), 1);
  EXPECT_EQ(Orient1d(2, 2), 0);
  EXPECT_EQ(InDiametralSphere(a, b, {0.5, 0.4, 0}), 1);
  EXPECT_EQ(InDiametralSphere(a, b, {0.5, 0.5, 0}), 0);
  EXPECT_EQ(InDiametralSphere(a, b, {0.5, 0.6, 0}), -1);
  EXPECT_EQ(InTriangleCircumball3d(b, c, d, {0.3, 0.3, 0.3}), 1);
  EXPECT_EQ(InTriangleCircumball3d(b, c, d, a), 1);  // |o|² = 1/3 < R² = 2/3
  EXPECT_EQ(InTriangleCircumball3d(b, c, d, {-1, -1, -1}), -1);
  EXPECT_EQ(CompareDistance(a, b, {0.5, 0, 0}), 1);
  EXPECT_EQ(Orient2dProjected(a, b, c, 2), 1);
  EXPECT_EQ(Orient2dProjected(a, c, b, 2), -1);
  EXPECT_EQ(Orient2dProjected(a, c, d, 0), 1);
  EXPECT_EQ(Orient2dProjected(a, d, b, 1), 1);
  EXPECT_EQ(DominantAxis({0.1, -3, 2}), 1);
}

// ------------------------------------------------------ extra predicates

// InBall's static pre-filter (session 15) must only ever return the exact
// sign: points on the sphere (lattice points of radius 9, exact zeros, in
// every frame), a radius rounded from the distance (the hardest case: the
// sign hangs on the last bits of r), nudged by one ulp either way, random
// points, and extreme scales.
TEST(PredicatesTest, InBallMatchesOracle) {
  Gen g(16);
  const std::vector<Vec3> sphere = SpherePoints(9);
  int cases = 0, zeros = 0;
  auto check = [&](const Vec3& p, const Vec3& c, double r) {
    const int want = OracleInBall(p, c, r);
    ASSERT_EQ(InBall(p, c, r), want) << "p " << p.x << " " << p.y << " " << p.z << " c " << c.x << " " << c.y << " "
                                     << c.z << " r " << r;
    zeros += want == 0;
    ++cases;
  };
  for (const Frame& f : kFrames) {
    const double r = std::ldexp(9.0, f.k);
    const Vec3 c = Apply(f, Vec3{0, 0, 0});
    for (const Vec3& s : sphere) {
      const Vec3 p = Apply(f, s);
      check(p, c, r);
      check(p, c, std::nextafter(r, HUGE_VAL));
      check(p, c, std::nextafter(r, 0.0));
      std::array<Vec3, 1> q = {p};
      g.NudgeOneUlp(q);
      check(q[0], c, r);
    }
  }
  for (int i = 0; i < N(20000); ++i) {
    const double scale = std::ldexp(1.0, g.Int(-300, 300));
    const Vec3 c = g.Point3(scale), p = g.Point3(scale);
    const double d = Norm(p - c);
    check(p, c, d);
    check(p, c, std::nextafter(d, HUGE_VAL));
    check(p, c, std::nextafter(d, 0.0));
    check(p, c, g.Uniform(0, 2 * scale));
  }
  EXPECT_GT(zeros, 100);
  EXPECT_GT(cases, N(80000));
}

TEST(PredicatesTest, ExtraPredicatesMatchOracle) {
  Gen g(15);
  const Vec3 cube[8] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0},
                        {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
  const std::vector<Vec3> sphere = SpherePoints(9);
  int cases = 0, zeros = 0;
  auto check_all = [&](std::array<Vec3, 4> p) {
    int want = OracleInDiametral(p[0], p[1], p[2]);
    ASSERT_EQ(InDiametralSphere(p[0], p[1], p[2]), want);
    zeros += want == 0;
    want = OracleInTriangleBall(p[0], p[1], p[2], p[3]);
    ASSERT_EQ(InTriangleCircumball3d(p[0], p[1], p[2], p[3]), want);
    zeros += want == 0;
    want = OracleCompareDistance(p[0], p[1], p[2]);
    ASSERT_EQ(CompareDistance(p[0], p[1], p[2]), want);
    zeros += want == 0;
    want = OracleDotSign(p[0], p[1], p[2], p[3]);
    ASSERT_EQ(DotSign(p[0], p[1], p[2], p[3]), want);
    for (int axis = 0; axis < 3; ++axis) {
      ASSERT_EQ(Orient2dProjected(p[0], p[1], p[2], axis),
                OracleOrientProjected(p[0], p[1], p[2], axis));
    }
    cases += 7;
  };
  for (int i = 0; i < N(2000); ++i) check_all({g.Point3(), g.Point3(), g.Point3(), g.Point3()});
  for (const Frame& f : kFrames) {
    for (int i = 0; i < N(300); ++i) {
      std::array<Vec3, 4> p;
      // Cospherical with a sphere centred at the origin: a, b antipodal on the
      // lattice sphere make p on the diametral sphere; the circumball of a
      // great-circle triangle is the sphere itself.
      const Vec3 s = sphere[g.Int(0, int(sphere.size()) - 1)];
      p = {Apply(f, s), Apply(f, -1.0 * s), Apply(f, sphere[g.Int(0, int(sphere.size()) - 1)]),
           Apply(f, sphere[g.Int(0, int(sphere.size()) - 1)])};
      check_all(p);
      g.NudgeOneUlp(p);
      check_all(p);
      for (auto& q : p) q = Apply(f, cube[g.Int(0, 7)]);
      check_all(p);
      g.NudgeOneUlp(p);
      check_all(p);
    }
  }
  EXPECT_GT(zeros, N(500));
  EXPECT_GT(cases, N(20000));
}

// CompareDistance's own exact stage (exact coordinate differences: squares as
// TwoProducts, Grow-Expansion) and its generic fallback (inexact
// differences), against the rational oracle on exact ties and 1-ulp nudges:
// b = p + a permutation / sign flip of a − p (equal distances), at every
// frame's scale and offset, with random and with wide-mantissa differences.
TEST(PredicatesTest, CompareDistanceTiesMatchOracle) {
  Gen g(20261121);
  int zeros = 0, cases = 0;
  for (const Frame& f : kFrames) {
    for (int i = 0; i < N(3000); ++i) {
      const Vec3 p = g.Point3(i % 2 ? 1 : 1e-3);
      Vec3 d = g.Point3();
      if (i % 3 == 0) d = {std::ldexp(std::round(std::ldexp(d.x, 20)), -20), d.y, d.z};
      const double c[3] = {d.x, d.y, d.z};
      const int perm = g.Int(0, 5), flips = g.Int(0, 7);
      static constexpr int kPerm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
      Vec3 e{c[kPerm[perm][0]], c[kPerm[perm][1]], c[kPerm[perm][2]]};
      if (flips & 1) e.x = -e.x;
      if (flips & 2) e.y = -e.y;
      if (flips & 4) e.z = -e.z;
      std::array<Vec3, 3> q = {Apply(f, p), Apply(f, p + d), Apply(f, p + e)};
      for (int nudge = 0; nudge < 3; ++nudge) {
        const int want = OracleCompareDistance(q[0], q[1], q[2]);
        ASSERT_EQ(CompareDistance(q[0], q[1], q[2]), want) << "frame " << f.k << " case " << i;
        ASSERT_EQ(CompareDistance(q[0], q[2], q[1]), -want);
        zeros += want == 0;
        ++cases;
        g.NudgeOneUlp(q);
      }
    }
  }
  EXPECT_GT(zeros, cases / 20);  // the ties are really exercised
}

// ------------------------------------------------------ SoS

// Oracle for the SoS orientation: the perturbed determinant evaluated exactly
// at a tiny rational ε, p_{r,j} += ε^(2^(d·r−j)) (rank r by id).
template <int D>
int OracleOrientSoS(const std::array<std::array<double, D>, D + 1>& pts,
                    const std::array<uint32_t, D + 1>& ids, const Q& eps) {
  std::vector<std::vector<Q>> m;
  for (int i = 0; i <= D; ++i) {
    int rank = 1;
    for (int j = 0; j <= D; ++j) rank += ids[j] < ids[i];
    std::vector<Q> row{Q(1)};
    for (int j = 1; j <= D; ++j) {
      Q e = 1;
      const int exponent = 1 << (D * rank - j);
      mpz_class num = 1, den = 1;
      mpz_pow_ui(num.get_mpz_t(), eps.get_num_mpz_t(), exponent);
      mpz_pow_ui(den.get_mpz_t(), eps.get_den_mpz_t(), exponent);
      e = Q(num, den);
      row.push_back(Q(pts[i][j - 1]) + e);
    }
    m.push_back(row);
  }
  return sgn(DetLaplace(m));
}

// Oracle for the lifting perturbation: |p|² + ε^rank.
int OracleInSphereSoS(const std::array<Vec3, 5>& p, const std::array<uint32_t, 5>& ids,
                      const Q& eps) {
  std::vector<std::vector<Q>> m;
  for (int i = 0; i < 5; ++i) {
    int rank = 1;
    for (int j = 0; j < 5; ++j) rank += ids[j] < ids[i];
    auto row = LiftedRow(p[i]);
    Q e = 1;
    for (int k = 0; k < rank; ++k) e *= eps;
    row.back() += e;
    m.push_back(row);
  }
  return -sgn(Det(m));
}
int OracleInCircleSoS(const std::array<Vec2, 4>& p, const std::array<uint32_t, 4>& ids,
                      const Q& eps) {
  std::vector<std::vector<Q>> m;
  for (int i = 0; i < 4; ++i) {
    int rank = 1;
    for (int j = 0; j < 4; ++j) rank += ids[j] < ids[i];
    auto row = LiftedRow(p[i]);
    Q e = 1;
    for (int k = 0; k < rank; ++k) e *= eps;
    row.back() += e;
    m.push_back(row);
  }
  return -sgn(Det(m));
}

template <size_t N>
int Parity(const std::array<int, N>& perm) {
  int inv = 0;
  for (size_t i = 0; i < N; ++i)
    for (size_t j = i + 1; j < N; ++j) inv += perm[i] > perm[j];
  return inv % 2 ? -1 : 1;
}

TEST(PredicatesSoSTest, Orient2dSoS) {
  Gen g(21);
  const Q eps(mpz_class(1), mpz_class(1) << 40);
  for (int i = 0; i < N(3000); ++i) {
    // Small grid: many collinear (and some coincident) triples.
    std::array<Vec2, 3> p = {g.IntPoint2(2), g.IntPoint2(2), g.IntPoint2(2)};
    std::array<uint32_t, 3> ids = {uint32_t(g.Int(0, 1000)), 0, 0};
    ids[1] = ids[0] + 1 + g.Int(0, 5);
    ids[2] = ids[1] + 1 + g.Int(0, 5);
    std::shuffle(ids.begin(), ids.end(), g.rng());
    const int s = Orient2dSoS(p[0], p[1], p[2], ids[0], ids[1], ids[2]);
    ASSERT_NE(s, 0);
    const int exact = OracleOrient2d(p[0], p[1], p[2]);
    if (exact != 0) {
      ASSERT_EQ(s, exact);
    }
    ASSERT_EQ(s, (OracleOrientSoS<2>({{{p[0].x, p[0].y}, {p[1].x, p[1].y}, {p[2].x, p[2].y}}}, ids, eps)));
    std::array<int, 3> perm = {0, 1, 2};
    while (std::next_permutation(perm.begin(), perm.end())) {
      ASSERT_EQ(Orient2dSoS(p[perm[0]], p[perm[1]], p[perm[2]], ids[perm[0]], ids[perm[1]],
                            ids[perm[2]]),
                Parity(perm) * s);
    }
  }
}

TEST(PredicatesSoSTest, Orient3dSoS) {
  Gen g(22);
  const Q eps(mpz_class(1), mpz_class(1) << 24);
  for (int i = 0; i < N(1500); ++i) {
    std::array<Vec3, 4> p = {g.IntPoint3(1), g.IntPoint3(1), g.IntPoint3(1), g.IntPoint3(1)};
    std::array<uint32_t, 4> ids;
    for (int k = 0; k < 4; ++k) ids[k] = k * 7 + g.Int(0, 6);
    std::shuffle(ids.begin(), ids.end(), g.rng());
    const int s = Orient3dSoS(p[0], p[1], p[2], p[3], ids[0], ids[1], ids[2], ids[3]);
    ASSERT_NE(s, 0);
    const int exact = OracleOrient3d(p[0], p[1], p[2], p[3]);
    if (exact != 0) {
      ASSERT_EQ(s, exact);
    }
    if (i < N(300)) {
      std::array<std::array<double, 3>, 4> pts;
      for (int k = 0; k < 4; ++k) pts[k] = {p[k].x, p[k].y, p[k].z};
      ASSERT_EQ(s, OracleOrientSoS<3>(pts, ids, eps)) << i;
    }
    std::array<int, 4> perm = {0, 1, 2, 3};
    while (std::next_permutation(perm.begin(), perm.end())) {
      ASSERT_EQ(Orient3dSoS(p[perm[0]], p[perm[1]], p[perm[2]], p[perm[3]], ids[perm[0]],
                            ids[perm[1]], ids[perm[2]], ids[perm[3]]),
                Parity(perm) * s);
    }
  }
}

TEST(PredicatesSoSTest, InCircleSoS) {
  Gen g(23);
  const std::vector<Vec2> circle = CirclePoints(5);  // 12 points
  const Q eps(mpz_class(1), mpz_class(1) << 60);
  int decided_by_sos = 0;
  for (int i = 0; i < N(3000); ++i) {
    std::array<Vec2, 4> p;
    if (i % 2) {
      std::vector<Vec2> pool = circle;
      std::shuffle(pool.begin(), pool.end(), g.rng());
      std::copy_n(pool.begin(), 4, p.begin());
    } else {
      for (auto& q : p) q = g.IntPoint2(2);
    }
    if (OracleOrient2d(p[0], p[1], p[2]) == 0) continue;  // precondition: abc a triangle
    std::array<uint32_t, 4> ids;
    for (int k = 0; k < 4; ++k) ids[k] = k * 5 + g.Int(0, 4);
    std::shuffle(ids.begin(), ids.end(), g.rng());
    const int s = InCircleSoS(p[0], p[1], p[2], p[3], ids[0], ids[1], ids[2], ids[3]);
    const bool distinct = !(p[3] == p[0] || p[3] == p[1] || p[3] == p[2]);
    if (distinct) {
      ASSERT_NE(s, 0);
    }
    const int exact = OracleInCircle(p[0], p[1], p[2], p[3]);
    if (exact != 0) {
      ASSERT_EQ(s, exact);
    }
    decided_by_sos += exact == 0;
    ASSERT_EQ(s, OracleInCircleSoS(p, ids, eps));
    std::array<int, 4> perm = {0, 1, 2, 3};
    while (std::next_permutation(perm.begin(), perm.end())) {
      ASSERT_EQ(InCircleSoS(p[perm[0]], p[perm[1]], p[perm[2]], p[perm[3]], ids[perm[0]],
                            ids[perm[1]], ids[perm[2]], ids[perm[3]]),
                Parity(perm) * s);
    }
  }
  EXPECT_GT(decided_by_sos, N(500));
}

TEST(PredicatesSoSTest, InSphereSoS) {
  Gen g(24);
  const std::vector<Vec3> sphere = SpherePoints(3);  // 30 points on r = 3
  const Q eps(mpz_class(1), mpz_class(1) << 60);
  int decided_by_sos = 0;
  for (int i = 0; i < N(1500); ++i) {
    std::array<Vec3, 5> p;
    if (i % 2) {
      std::vector<Vec3> pool = sphere;
      std::shuffle(pool.begin(), pool.end(), g.rng());
      std::copy_n(pool.begin(), 5, p.begin());
    } else {
      for (auto& q : p) q = g.IntPoint3(1);
    }
    if (OracleOrient3d(p[0], p[1], p[2], p[3]) == 0) continue;
    std::array<uint32_t, 5> ids;
    for (int k = 0; k < 5; ++k) ids[k] = k * 5 + g.Int(0, 4);
    std::shuffle(ids.begin(), ids.end(), g.rng());
    const int s = InSphereSoS(p[0], p[1], p[2], p[3], p[4], ids[0], ids[1], ids[2], ids[3], ids[4]);
    ASSERT_NE(s, 0);
    const int exact = OracleInSphere(p[0], p[1], p[2], p[3], p[4]);
    if (exact != 0) {
      ASSERT_EQ(s, exact);
    }
    decided_by_sos += exact == 0;
    ASSERT_EQ(s, OracleInSphereSoS(p, ids, eps));
    if (i < N(200)) {
      std::array<int, 5> perm = {0, 1, 2, 3, 4};
      while (std::next_permutation(perm.begin(), perm.end())) {
        ASSERT_EQ(InSphereSoS(p[perm[0]], p[perm[1]], p[perm[2]], p[perm[3]], p[perm[4]],
                              ids[perm[0]], ids[perm[1]], ids[perm[2]], ids[perm[3]], ids[perm[4]]),
                  Parity(perm) * s);
      }
    }
  }
  EXPECT_GT(decided_by_sos, N(300));
}

// Brute-force Delaunay of the 8 cube corners (all cospherical) under SoS: the
// tets that are positively oriented and empty under InSphereSoS must tile the
// cube: total volume 1, every interior triangle shared by exactly two tets.
// Checked for several id assignments.
TEST(PredicatesSoSTest, CubeCornersTriangulateUnderSoS) {
  const Vec3 cube[8] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0},
                        {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
  std::array<uint32_t, 8> ids = {0, 1, 2, 3, 4, 5, 6, 7};
  std::mt19937_64 rng(5);
  for (int trial = 0; trial < 40; ++trial) {
    std::shuffle(ids.begin(), ids.end(), rng);
    Q volume = 0;
    int tets = 0;
    std::map<std::array<int, 3>, int> faces;
    for (int a = 0; a < 8; ++a)
      for (int b = a + 1; b < 8; ++b)
        for (int c = b + 1; c < 8; ++c)
          for (int d = c + 1; d < 8; ++d) {
            std::array<int, 4> t = {a, b, c, d};
            const int o = Orient3d(cube[a], cube[b], cube[c], cube[d]);
            if (o == 0) continue;
            if (o < 0) std::swap(t[0], t[1]);
            bool empty = true;
            for (int e = 0; e < 8 && empty; ++e) {
              if (e == a || e == b || e == c || e == d) continue;
              empty = InSphereSoS(cube[t[0]], cube[t[1]], cube[t[2]], cube[t[3]], cube[e], ids[t[0]],
                                  ids[t[1]], ids[t[2]], ids[t[3]], ids[e]) < 0;
            }
            if (!empty) continue;
            ++tets;
            volume += Q(std::fabs(
                          Dot(ToQ(cube[b]) - ToQ(cube[a]),
                              Cross(ToQ(cube[c]) - ToQ(cube[a]), ToQ(cube[d]) - ToQ(cube[a])))
                              .get_d())) /
                      6;
            for (int f = 0; f < 4; ++f) {
              std::array<int, 3> face;
              for (int k = 0, m = 0; k < 4; ++k)
                if (k != f) face[m++] = t[k];
              std::sort(face.begin(), face.end());
              ++faces[face];
            }
          }
    EXPECT_EQ(volume, Q(1)) << "trial " << trial << " tets " << tets;
    for (const auto& [face, count] : faces) {
      // Boundary faces lie on a cube facet (one coordinate constant).
      bool boundary = false;
      for (int axis = 0; axis < 3; ++axis) {
        boundary |= cube[face[0]][axis] == cube[face[1]][axis] &&
                    cube[face[1]][axis] == cube[face[2]][axis];
      }
      EXPECT_EQ(count, boundary ? 1 : 2);
    }
  }
}

// Two equal points make the orientation determinant exactly 0: answered
// without the expansion arithmetic (example.poly's facet triangles tested
// against the facet segments they share endpoints with: 43,241 → 32,489
// exact calls in a run), while a near-degenerate triple without a repeated
// point still goes exact and gets its true sign.
TEST(PredicatesStatsTest, RepeatedPointsAreZeroWithoutExactArithmetic) {
  ResetPredicateStats();
  const Vec2 a{0.1, 0.7}, b{0.3, 2.9}, c{-1.7, 0.2};
  for (const auto& [p, q, r] : {std::array<Vec2, 3>{a, b, a}, {a, b, b}, {a, a, c}, {c, a, c}}) {
    EXPECT_EQ(Orient2d(p, q, r), 0);
  }
  const Vec3 d{0.1, 0.2, 0.3}, e{1.3, -0.7, 0.9}, f{-0.4, 2.2, 0.5}, g{0.7, 0.1, -1.9};
  for (const auto& [p, q, r, t] :
       {std::array<Vec3, 4>{d, e, f, d}, {d, e, f, e}, {d, e, f, f}, {d, d, f, g}, {d, e, d, g}, {d, e, e, g}}) {
    EXPECT_EQ(Orient3d(p, q, r, t), 0);
  }
  EXPECT_EQ(GetPredicateStats().exact[int(Pred::kOrient2d)], 0u);
  EXPECT_EQ(GetPredicateStats().exact[int(Pred::kOrient3d)], 0u);
  // Nearly collinear, no two points equal: exact, and positive
  // (0.1 + 2^-55 is not on the line y = x through (0, 0) and (0.2, 0.2)).
  EXPECT_EQ(Orient2d({0, 0}, {0.2, 0.2}, {0.1, 0.1 + 0x1p-55}), 1);
  EXPECT_EQ(GetPredicateStats().exact[int(Pred::kOrient2d)], 1u);
  ResetPredicateStats();
}

TEST(PredicatesStatsTest, CountsCallsExactAndSos) {
  ResetPredicateStats();
  Orient3d({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1});
  Orient3d({0, 0, 0}, {1, 1, 1}, {2, 2, 2.0000000000000004}, {3, 3, 3});
  Orient3dSoS({0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}, 0, 1, 2, 3);
  const PredicateStats& s = GetPredicateStats();
  EXPECT_EQ(s.calls[int(Pred::kOrient3d)], 3u);
  EXPECT_EQ(s.exact[int(Pred::kOrient3d)], 2u);
  EXPECT_EQ(s.sos[int(Pred::kOrient3d)], 1u);
  EXPECT_STREQ(PredicateName(Pred::kInSphere), "insphere");
  ResetPredicateStats();
  EXPECT_EQ(GetPredicateStats().TotalCalls(), 0u);
}

}  // namespace
}  // namespace svrc::geom
