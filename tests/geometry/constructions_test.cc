// Constructions against exact rational results (GMP), with relative error bounds.
#include "core/geometry/constructions.h"

#include <gmpxx.h>

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace svrc::geom {
namespace {

using Q = mpq_class;
struct QV {
  Q x, y, z;
};
QV ToQ(const Vec3& p) { return {Q(p.x), Q(p.y), Q(p.z)}; }
QV operator-(const QV& a, const QV& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
QV operator+(const QV& a, const QV& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
QV operator*(const Q& s, const QV& a) { return {s * a.x, s * a.y, s * a.z}; }
Q Dot(const QV& a, const QV& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
QV Cross(const QV& a, const QV& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
double DistTo(const Vec3& p, const QV& q) {
  const QV d = ToQ(p) - q;
  return std::sqrt(Dot(d, d).get_d());
}

// Exact circumcentre by solving the 3×3 system 2(o−a)·t = |t|², ... (Cramer).
QV ExactTetCenter(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const QV A = ToQ(a), t = ToQ(b) - A, u = ToQ(c) - A, v = ToQ(d) - A;
  const Q det = Dot(t, Cross(u, v));
  const QV num = Dot(t, t) * Cross(u, v) + Dot(u, u) * Cross(v, t) + Dot(v, v) * Cross(t, u);
  return A + Q(1, 2) / det * num;
}
QV ExactTriangleCenter(const Vec3& a, const Vec3& b, const Vec3& c) {
  const QV A = ToQ(a), u = ToQ(b) - A, v = ToQ(c) - A;
  const Q uu = Dot(u, u), uv = Dot(u, v), vv = Dot(v, v);
  const Q det = uu * vv - uv * uv;
  const Q s = (uu / 2 * vv - vv / 2 * uv) / det;
  const Q t = (vv / 2 * uu - uu / 2 * uv) / det;
  return A + (s * u + t * v);
}

class Rng {
 public:
  explicit Rng(uint64_t s) : g_(s) {}
  double U(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(g_); }
  Vec3 P(double s = 1) { return {U(-s, s), U(-s, s), U(-s, s)}; }

 private:
  std::mt19937_64 g_;
};

TEST(ConstructionsTest, TetCircumcenterRandomAndFarFromOrigin) {
  Rng r(1);
  double worst = 0;
  for (int i = 0; i < 1000; ++i) {
    const Vec3 o = i % 2 ? Vec3{1e6, -1e6, 1e6} : Vec3{};
    const double s = i % 2 ? 1e-3 : 1;
    const Vec3 a = o + r.P(s), b = o + r.P(s), c = o + r.P(s), d = o + r.P(s);
    const QV want = ExactTetCenter(a, b, c, d);
    const Ball3 got = TetCircumball(a, b, c, d);
    const double err = DistTo(got.center, want);
    // Error: rounding of differences and of the final a + offset.
    const double bound = 1e-12 * got.radius + 8e-16 * (Norm(a) + got.radius);
    worst = std::max(worst, err / bound);
    ASSERT_LE(err, bound) << i;
    ASSERT_NEAR(got.radius, DistTo(a, want), bound);
  }
  RecordProperty("worst_ratio", std::to_string(worst));
}

// Near-flat tets whose coordinate differences are exact (dyadic grid), so the
// only error source is the evaluation: the accurate denominator keeps the
// centre within a small relative error of R even as h → 0.
TEST(ConstructionsTest, TetCircumcenterNearFlat) {
  Rng r(2);
  for (int k = 5; k <= 40; k += 5) {
    const double h = std::ldexp(1.0, -k);
    for (int i = 0; i < 200; ++i) {
      auto grid = [&](double v) { return std::round(v * 1024) / 1024; };
      const Vec3 a{grid(r.U(0, 1)), grid(r.U(0, 1)), 0}, b{grid(r.U(0, 1)), grid(r.U(0, 1)), 0},
          c{grid(r.U(0, 1)), grid(r.U(0, 1)), 0}, d{grid(r.U(0, 1)), grid(r.U(0, 1)), h};
      const QV want = ExactTetCenter(a, b, c, d);
      if (!std::isfinite(Dot(want, want).get_d())) continue;
      const Ball3 got = TetCircumball(a, b, c, d);
      const double err = DistTo(got.center, want);
      ASSERT_LE(err, 1e-12 * got.radius) << "h=2^-" << k << " i=" << i;
    }
  }
}

TEST(ConstructionsTest, TriangleCircumcenter3dAnd2d) {
  Rng r(3);
  for (int i = 0; i < 1000; ++i) {
    const Vec3 o = i % 2 ? Vec3{-1e6, 1e6, 1e6} : Vec3{};
    const double s = i % 2 ? 1e-3 : 1;
    const Vec3 a = o + r.P(s), b = o + r.P(s), c = o + r.P(s);
    const QV want = ExactTriangleCenter(a, b, c);
    const Ball3 got = TriangleCircumball3d(a, b, c);
    const double bound = 1e-12 * got.radius + 8e-16 * (Norm(a) + got.radius);
    ASSERT_LE(DistTo(got.center, want), bound) << i;
    // Equidistant from the three vertices.
    EXPECT_NEAR(Dist(got.center, b), got.radius, 4 * bound);
    EXPECT_NEAR(Dist(got.center, c), got.radius, 4 * bound);
    // 2D: the same triangle flattened.
    const Vec2 a2{a.x, a.y}, b2{b.x, b.y}, c2{c.x, c.y};
    const QV want2 = ExactTriangleCenter({a.x, a.y, 0}, {b.x, b.y, 0}, {c.x, c.y, 0});
    const Circle2 got2 = TriangleCircumcircle2d(a2, b2, c2);
    const double bound2 = 1e-12 * got2.radius + 8e-16 * (Norm(a) + got2.radius);
    ASSERT_LE(DistTo({got2.center.x, got2.center.y, 0}, want2), bound2) << i;
  }
}

TEST(ConstructionsTest, DiametralBall) {
  const Ball3 b = SegmentDiametralBall({1, 2, 3}, {3, 2, 3});
  EXPECT_EQ(b.center, (Vec3{2, 2, 3}));
  EXPECT_EQ(b.radius, 1);
  const Circle2 c = SegmentDiametralCircle({0, 0}, {0, 4});
  EXPECT_EQ(c.center, (Vec2{0, 2}));
  EXPECT_EQ(c.radius, 2);
}

TEST(ConstructionsTest, PointSegmentAndTriangleDistances) {
  Rng r(4);
  for (int i = 0; i < 1000; ++i) {
    const Vec3 p = r.P(2), a = r.P(), b = r.P(), c = r.P();
    // Segment: exact rational clamp.
    {
      const QV A = ToQ(a), AB = ToQ(b) - A, AP = ToQ(p) - A;
      Q t = Dot(AP, AB) / Dot(AB, AB);
      if (t < 0) t = 0;
      if (t > 1) t = 1;
      const QV q = A + t * AB;
      EXPECT_NEAR(DistancePointSegment(p, a, b), DistTo(p, q), 1e-14);
    }
    // Triangle: exact projection; inside → plane distance, else min over edges.
    {
      const QV A = ToQ(a), u = ToQ(b) - A, v = ToQ(c) - A, w = ToQ(p) - A;
      const Q uu = Dot(u, u), uv = Dot(u, v), vv = Dot(v, v), wu = Dot(w, u), wv = Dot(w, v);
      const Q det = uu * vv - uv * uv;
      const Q s = (wu * vv - wv * uv) / det, t = (wv * uu - wu * uv) / det;
      double want;
      if (s >= 0 && t >= 0 && s + t <= 1) {
        want = DistTo(p, A + (s * u + t * v));
      } else {
        want = std::min({DistancePointSegment(p, a, b), DistancePointSegment(p, b, c),
                         DistancePointSegment(p, c, a)});
      }
      EXPECT_NEAR(DistancePointTriangle(p, a, b, c), want, 1e-13) << i;
    }
  }
  // Degenerate inputs.
  EXPECT_EQ(DistancePointSegment({1, 1, 0}, {0, 0, 0}, {0, 0, 0}), std::sqrt(2.0));
  EXPECT_NEAR(DistancePointTriangle({0, 1, 0}, {0, 0, 0}, {1, 0, 0}, {2, 0, 0}), 1, 1e-15);
}

TEST(ConstructionsTest, PlaneFrames) {
  Rng r(5);
  for (int i = 0; i < 1000; ++i) {
    const Vec3 a = r.P() + Vec3{1e3, 0, -1e3}, b = r.P() + Vec3{1e3, 0, -1e3},
               c = r.P() + Vec3{1e3, 0, -1e3};
    for (const PlaneFrame& f :
         {PlaneFrame::FromTriangle(a, b, c), PlaneFrame::FromNormal(a, Cross(b - a, c - a)),
          PlaneFrame::FromPolygon(std::vector<Vec3>{a, b, c})}) {
      EXPECT_NEAR(Norm(f.u), 1, 1e-15);
      EXPECT_NEAR(Norm(f.v), 1, 1e-15);
      EXPECT_NEAR(Norm(f.n), 1, 1e-15);
      EXPECT_NEAR(Dot(f.u, f.v), 0, 1e-15);
      EXPECT_NEAR(Dot(f.u, f.n), 0, 1e-15);
      EXPECT_GT(Dot(Cross(f.u, f.v), f.n), 0.999999);
      // Right-handed relative to the triangle's orientation.
      EXPECT_GT(Dot(f.n, Cross(b - a, c - a)), 0);
      for (const Vec3& p : {a, b, c}) {
        EXPECT_LE(Dist(f.To3d(f.To2d(p)), p), 1e-11);
        EXPECT_LE(std::fabs(f.Height(p)), 1e-11);
      }
    }
  }
  const Vec3 square[4] = {{0, 0, 5}, {2, 0, 5}, {2, 2, 5}, {0, 2, 5}};
  EXPECT_EQ(NewellNormal(square), (Vec3{0, 0, 8}));
}

}  // namespace
}  // namespace svrc::geom
