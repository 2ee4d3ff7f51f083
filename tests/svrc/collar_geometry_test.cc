// Collar geometry primitives against brute force / long double references.
#include "core/svrc/collar_geometry.h"

#include <cmath>
#include <numbers>
#include <random>

#include "core/geometry/predicates.h"
#include "core/svrc/ball_grid.h"
#include "gtest/gtest.h"

namespace svrc::refine {
namespace {

Vec3 RandomUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0, 1);
  for (;;) {
    Vec3 v(n(rng), n(rng), n(rng));
    const double l = geom::Norm(v);
    if (l > 1e-6) return v / l;
  }
}

TEST(InBallTest, ExactSignsIncludingOnSphere) {
  EXPECT_GT(geom::InBall({0, 0, 0}, {0, 0, 0}, 1.0), 0);
  EXPECT_EQ(geom::InBall({1, 0, 0}, {0, 0, 0}, 1.0), 0);  // exactly on the sphere
  EXPECT_LT(geom::InBall({1, 1e-300, 0}, {0, 0, 0}, 1.0), 0);
  // Dyadic values: 0.75² + 0.5² = 0.8125 exactly; r = 0.9013878... rounded.
  EXPECT_GT(geom::InBall({0.75, 0.5, 0}, {0, 0, 0}, 0.9014), 0);
  EXPECT_LT(geom::InBall({0.75, 0.5, 0}, {0, 0, 0}, 0.9013), 0);
  // Exactly on: r = 1.25, p = (0.75, 1) (3-4-5 scaled by 1/4).
  EXPECT_EQ(geom::InBall({0.75, 1, 0}, {0, 0, 0}, 1.25), 0);
  EXPECT_GT(geom::InBall({1 - 1e-16, 0, 0}, {0, 0, 0}, 1.0), 0);
}

TEST(SphereSphereCircleTest, PointsOnBothSpheresRandom) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.2, 2.0);
  int made = 0;
  for (int it = 0; it < 2000; ++it) {
    const CollarBall b1{Vec3(0.1, 0.2, 0.3), u(rng)};
    const CollarBall b2{b1.center + u(rng) * RandomUnit(rng), u(rng)};
    const double d = geom::Dist(b1.center, b2.center);
    Circle3 c;
    const bool ok = SphereSphereCircle(b1, b2, &c);
    EXPECT_EQ(ok, d < b1.radius + b2.radius && d > std::fabs(b1.radius - b2.radius));
    if (!ok) continue;
    ++made;
    for (double t = 0; t < 6.28; t += 0.7) {
      const Vec3 p = CirclePoint(c, t);
      EXPECT_NEAR(geom::Dist(p, b1.center), b1.radius, 1e-12 * 4);
      EXPECT_NEAR(geom::Dist(p, b2.center), b2.radius, 1e-12 * 4);
    }
  }
  EXPECT_GT(made, 500);
}

TEST(SphereSphereCircleTest, NearTangentIsAccurate) {
  // Two unit spheres 2 − 1e-10 apart: circle radius² = 1 − (1 − 5e-11)² ≈ 1e-10.
  const CollarBall b1{{0, 0, 0}, 1}, b2{{2 - 1e-10, 0, 0}, 1};
  Circle3 c;
  ASSERT_TRUE(SphereSphereCircle(b1, b2, &c));
  const long double h = (2.0L - 1e-10L) / 2;
  const long double ref = std::sqrt((1 - h) * (1 + h));
  EXPECT_NEAR(c.radius, static_cast<double>(ref), 1e-6 * static_cast<double>(ref));
}

TEST(SegmentSphereTest, AgreesWithLongDoubleRoots) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-2, 2);
  int counts[3] = {0, 0, 0};
  for (int it = 0; it < 20000; ++it) {
    const Vec3 a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng));
    const CollarBall ball{Vec3(0.05, -0.1, 0.2), 1.0 + 0.1 * u(rng)};
    double s[2];
    const int n = SegmentSphere(a, b, ball, s);
    ++counts[n];
    // Reference: long double quadratic, roots in [0,1].
    long double d[3], f[3];
    for (int k = 0; k < 3; ++k) {
      d[k] = static_cast<long double>(b[k]) - a[k];
      f[k] = static_cast<long double>(a[k]) - ball.center[k];
    }
    const long double A = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    const long double B = f[0] * d[0] + f[1] * d[1] + f[2] * d[2];
    const long double C = f[0] * f[0] + f[1] * f[1] + f[2] * f[2] -
                          static_cast<long double>(ball.radius) * ball.radius;
    const long double disc = B * B - A * C;
    std::vector<long double> ref;
    if (disc >= 0) {
      for (long double r : {(-B - std::sqrt(disc)) / A, (-B + std::sqrt(disc)) / A}) {
        if (r >= 0 && r <= 1) ref.push_back(r);
      }
    }
    ASSERT_EQ(n, static_cast<int>(ref.size())) << it;
    for (int k = 0; k < n; ++k) {
      EXPECT_NEAR(s[k], static_cast<double>(ref[k]), 1e-12);
      const Vec3 x = a + s[k] * (b - a);
      EXPECT_NEAR(geom::Dist(x, ball.center), ball.radius, 1e-12);
    }
  }
  EXPECT_GT(counts[0], 100);
  EXPECT_GT(counts[1], 100);
  EXPECT_GT(counts[2], 100);
}

TEST(SegmentSphereTest, NoCancellationForLongSegmentNearlyTangent) {
  // A segment of length 2e6 passing 1e-3 inside a unit sphere's tangent point.
  const CollarBall ball{{0, 0, 0}, 1};
  const Vec3 a(-1e6, 1 - 1e-3, 0), b(1e6, 1 - 1e-3, 0);
  double s[2];
  ASSERT_EQ(SegmentSphere(a, b, ball, s), 2);
  for (int k = 0; k < 2; ++k) {
    const Vec3 x = a + s[k] * (b - a);
    // Half-chord = sqrt(1 − (1−1e-3)²) ≈ 0.0447; x must be on the sphere to ~1e-9
    // (the parameter is quantised by 2e6·2^-53 ≈ 2e-10 in absolute position).
    EXPECT_NEAR(geom::Dist(x, ball.center), 1.0, 1e-9);
  }
  const double half = std::sqrt(1 - (1 - 1e-3) * (1 - 1e-3));
  EXPECT_NEAR((a + s[0] * (b - a)).x, -half, 1e-9);
  EXPECT_NEAR((a + s[1] * (b - a)).x, half, 1e-9);
}

TEST(PlaneSphereTest, CircleOnBoth) {
  const CollarBall ball{{1, 2, 3}, 2};
  Circle3 c;
  ASSERT_TRUE(PlaneSphereCircle({0, 0, 3.5}, {0, 0, 7}, ball, &c));
  EXPECT_NEAR(c.radius, std::sqrt(4 - 0.25), 1e-15);
  EXPECT_EQ(c.center.z, 3.5);
  for (double t = 0; t < 6.28; t += 0.5) {
    const Vec3 p = CirclePoint(c, t);
    EXPECT_NEAR(p.z, 3.5, 1e-15);
    EXPECT_NEAR(geom::Dist(p, ball.center), 2, 1e-14);
  }
  EXPECT_FALSE(PlaneSphereCircle({0, 0, 5.5}, {0, 0, 1}, ball, &c));
}

TEST(SegmentCircleInPlaneTest, ChordOfCircle) {
  const Circle3 c{{0, 0, 0}, {0, 0, 1}, 1};
  double s[2];
  ASSERT_EQ(SegmentCircleInPlane({-2, 0.5, 0}, {2, 0.5, 0}, c, s), 2);
  EXPECT_NEAR(-2 + 4 * s[0], -std::sqrt(0.75), 1e-15);
  EXPECT_NEAR(-2 + 4 * s[1], std::sqrt(0.75), 1e-15);
  EXPECT_EQ(SegmentCircleInPlane({0, 0, 0}, {0.5, 0, 0}, c, s), 0);
  ASSERT_EQ(SegmentCircleInPlane({0, 0, 0}, {2, 0, 0}, c, s), 1);
  EXPECT_NEAR(s[0], 0.5, 1e-15);
}

TEST(ClipCircleTest, ArcsMatchDenseSampling) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int it = 0; it < 200; ++it) {
    const Circle3 c{{0, 0, 0}, RandomUnit(rng), 1};
    std::vector<CollarBall> others;
    const int k = 1 + static_cast<int>(rng() % 3);
    for (int j = 0; j < k; ++j) {
      others.push_back({Vec3(u(rng), u(rng), u(rng)) * 1.5, 0.3 + 0.7 * (u(rng) + 1) / 2});
    }
    const std::vector<Arc> arcs = ClipCircleByBalls(c, others);
    // Brute force: sample angles away from arc ends; membership must agree.
    for (int i = 0; i < 720; ++i) {
      const double t = (i + 0.5) * 2 * std::numbers::pi / 720;
      bool near_end = false, in_arc = false;
      for (const Arc& a : arcs) {
        if (t >= a.t0 && t <= a.t1) in_arc = true;
        if (std::fabs(t - a.t0) < 1e-9 || std::fabs(t - a.t1) < 1e-9) near_end = true;
      }
      if (near_end) continue;
      const bool covered = InsideAnyBall(CirclePoint(c, t), others);
      EXPECT_EQ(in_arc, !covered) << "it " << it << " t " << t;
    }
  }
}

TEST(OnCollarSurfaceTest, OtherBallsExclude) {
  const std::vector<CollarBall> balls = {{{0, 0, 0}, 1}, {{1.5, 0, 0}, 1}};
  EXPECT_TRUE(OnCollarSurface({-1, 0, 0}, 0, balls));
  EXPECT_FALSE(OnCollarSurface({1, 0, 0}, 0, balls));  // inside ball 1
  Circle3 c;
  ASSERT_TRUE(SphereSphereCircle(balls[0], balls[1], &c));
  EXPECT_NEAR(c.center.x, 0.75, 1e-15);
  EXPECT_NEAR(c.radius, std::sqrt(1 - 0.75 * 0.75), 1e-15);
  const CollarDescription d = BuildCollarDescription(balls);
  ASSERT_EQ(d.circles.size(), 1u);
  EXPECT_EQ(d.circles_of_ball[0].size(), 1u);
  EXPECT_EQ(d.circles_of_ball[1].size(), 1u);
}

// BallGrid answers as the scans do, bit for bit: balls of radii over
// five orders of magnitude (some far from the origin, where the box test's
// rounding matters), queried at random points, at points constructed on
// their spheres and on the spheres of other balls, and at points on the
// widened box faces and cell boundaries; skipping none, one or two balls.
TEST(BallGridTest, AnswersAsTheScans) {
  std::mt19937_64 rng(16);
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_real_distribution<double> lr(-5, 0);
  std::vector<CollarBall> balls;
  for (int i = 0; i < 300; ++i) {
    const double off = i % 7 == 0 ? 1e3 : 0;  // a cluster far out
    balls.push_back({{off + u(rng), u(rng), u(rng)}, 0.2 * std::pow(10.0, lr(rng))});
  }
  // Tangent and touching pairs: a ball whose sphere passes through another's centre.
  balls.push_back({balls[3].center + Vec3(balls[3].radius, 0, 0), balls[3].radius});
  balls.push_back({balls[5].center + Vec3(0, 2 * balls[5].radius, 0), balls[5].radius});
  const BallGrid grid(balls);
  std::vector<CollarBall> others;
  auto check = [&](const Vec3& x, uint32_t self, uint32_t other) {
    others.clear();
    for (uint32_t j = 0; j < balls.size(); ++j) {
      if (j != self && j != other) others.push_back(balls[j]);
    }
    ASSERT_EQ(grid.StrictlyInside(x, self, other), InsideAnyBall(x, others)) << x.x << " " << x.y << " " << x.z;
    if (other == BallGrid::kNone && self != BallGrid::kNone) {
      ASSERT_EQ(!grid.StrictlyInside(x, self), OnCollarSurface(x, self, balls));
    }
  };
  const uint32_t n = static_cast<uint32_t>(balls.size());
  int inside = 0, total = 0;
  for (int q = 0; q < 20000; ++q) {
    const uint32_t i = static_cast<uint32_t>(rng() % n), j = static_cast<uint32_t>(rng() % n);
    const CollarBall& b = balls[i];
    Vec3 x;
    switch (q % 5) {
      case 0: x = Vec3((i % 7 == 0 ? 1e3 : 0) + u(rng), u(rng), u(rng)); break;
      case 1: x = b.center + b.radius * RandomUnit(rng); break;  // on sphere i, rounded
      case 2: {  // on the circle where spheres i and j meet, when they do
        Circle3 c;
        if (i == j || !SphereSphereCircle(b, balls[j], &c)) continue;
        Vec3 e = geom::Cross(c.normal, RandomUnit(rng));
        if (!(geom::Norm(e) > 1e-6)) continue;
        x = c.center + (c.radius / geom::Norm(e)) * e;
        break;
      }
      case 3: x = b.center + Vec3(b.radius * (1 + 1e-9), 0, 0); break;  // OutsideBox's own bound
      default: x = Vec3(std::ldexp(std::round(std::ldexp(b.center.x, 6)), -6), b.center.y, b.center.z);  // a cell face
    }
    check(x, BallGrid::kNone, BallGrid::kNone);
    check(x, i, BallGrid::kNone);
    check(x, i, j);
    inside += InsideAnyBall(x, balls);
    ++total;
  }
  // Both answers occur often enough to mean something.
  EXPECT_GT(inside, total / 10);
  EXPECT_LT(inside, total - total / 10);
}

// SegmentCrossesPlane: points of a slanted plane, constructed in doubles
// (origin + u·e1 + v·e2, as a facet frame maps its points), are on the plane
// only up to rounding; a segment from one of them to a point off the plane
// does not cross it, even for a tolerance far below that rounding (1e-12 of a
// collar radius of 4.9e-6, random_plcs.py near+rot 9). Segments through the
// plane do cross, at the point.
TEST(SegmentCrossesPlaneTest, PointsOfASlantedPlaneUpToRoundingDoNotCross) {
  const Vec3 origin{0.2504879109722008, 0.2669290550898028, 0.33976598379197998};
  Vec3 n{0.31, -0.52, 0.79};
  n = (1 / geom::Norm(n)) * n;
  Vec3 e1 = geom::Cross(n, Vec3{1, 0, 0});
  e1 = (1 / geom::Norm(e1)) * e1;
  const Vec3 e2 = geom::Cross(n, e1);
  const double rho = 4.8623405968516022e-06;
  std::mt19937_64 rng(38);
  std::uniform_real_distribution<double> uni(-rho, rho);
  int off_plane = 0, crossings = 0;
  for (int i = 0; i < 2000; ++i) {
    const Vec3 p = origin + uni(rng) * e1 + uni(rng) * e2;
    if (geom::Dot(p - origin, n) != 0) ++off_plane;
    Vec3 x;
    for (double side : {0.7, -0.7}) {
      if (SegmentCrossesPlane(origin, n, p, p + (side * rho) * n, 1e-12 * rho, &x)) ++crossings;
      if (SegmentCrossesPlane(origin, n, p + (side * rho) * n, p, 1e-12 * rho, &x)) ++crossings;
    }
    ASSERT_TRUE(SegmentCrossesPlane(origin, n, p - (0.5 * rho) * n, p + (0.5 * rho) * n, 1e-12 * rho, &x));
    EXPECT_LT(geom::Dist(x, p), 1e-9 * rho);
  }
  EXPECT_GT(off_plane, 1000);  // the rounding this test is about
  EXPECT_EQ(crossings, 0);
}

TEST(RepresentationAngleTest, HandChecked) {
  const Vec3 o(0, 0, 0);
  EXPECT_NEAR(RepresentationAngle({0, 0, 1}, {0, 0, 2}, o), 0, 1e-16);
  EXPECT_NEAR(RepresentationAngle({0, 0, -3}, {0, 0, 2}, o), 0, 1e-16);  // unsigned line
  EXPECT_NEAR(RepresentationAngle({1, 0, 1}, {0, 0, 2}, o), std::numbers::pi / 4, 1e-15);
  EXPECT_NEAR(RepresentationAngle({1, 0, 0}, {0, 0, 2}, o), std::numbers::pi / 2, 1e-15);
  const double a30 = std::numbers::pi / 6;
  EXPECT_NEAR(RepresentationAngle({std::sin(a30), 0, std::cos(a30)}, {0, 0, 1}, o), a30, 1e-15);
  const Circle3 c{{0, 0, 0}, {0, 0, 1}, 1};
  // Tangent at (1,0,0) is ±y; a chord edge from (1,-1,0) to (1,1,0) has angle 0.
  EXPECT_NEAR(CircleRepresentationAngle({1, -1, 0}, {1, 1, 0}, c, {1, 0, 0}), 0, 1e-16);
  EXPECT_NEAR(CircleRepresentationAngle({1, 0, -1}, {1, 1, 0}, c, {1, 0, 0}),
              std::numbers::pi / 4, 1e-15);
}

}  // namespace
}  // namespace svrc::refine
