// The dihedral bound of docs/svrc-collars.md §1 checked on synthetic stars
// (crease vertex + restricted triangle of its sphere) and books (crease edge +
// restricted edge of the circle), for σ ∈ {15°, 30°, 45°}.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include "core/delaunay/delaunay3.h"
#include "core/svrc/restricted_delaunay.h"
#include "gtest/gtest.h"

namespace svrc::refine {
namespace {

using delaunay::Delaunay3;
using delaunay::VertexId;

constexpr double kDeg = std::numbers::pi / 180;

Vec3 RandomUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0, 1);
  for (;;) {
    Vec3 v(n(rng), n(rng), n(rng));
    const double l = geom::Norm(v);
    if (l > 1e-6) return v / l;
  }
}

// Interior angle of triangle at a.
double PlaneAngle(const Vec3& a, const Vec3& b, const Vec3& c) { return AngleBetween(b - a, c - a); }

TEST(CollarDihedralTest, StarsRespectTheBound) {
  // Samples of the unit sphere with radial jitter up to 15% (so representation
  // angles spread over [0°, ~60°]), plus points inside and outside.
  std::mt19937_64 rng(2024);
  std::uniform_real_distribution<double> u(-1, 1);
  const CollarBall ball{Vec3(0, 0, 0), 1.0};
  Delaunay3 dt;
  uint32_t id = 0;
  for (int i = 0; i < 700; ++i) {
    const double jitter = (i % 3 == 0) ? 0.15 : 0.04;
    dt.Insert((1 + jitter * u(rng)) * RandomUnit(rng), id++);
  }
  for (int c = 0; c < 8; ++c) dt.Insert(Vec3(c & 1 ? 3 : -3, c & 2 ? 3 : -3, c & 4 ? 3 : -3), id++);
  const std::vector<CollarBall> balls = {ball};
  const std::vector<RestrictedTriangle> tris = RestrictedSphereTriangles(dt, balls, 0);
  ASSERT_GT(tris.size(), 500u);
  for (double sigma_deg : {15.0, 30.0, 45.0}) {
    const double sigma = sigma_deg * kDeg;
    int stars = 0;
    double max_base = 0, max_radial = 0, max_eps = 0, max_gamma = 0;
    for (const RestrictedTriangle& t : tris) {
      if (t.num_roots != 1 || t.angle > sigma) continue;
      const Vec3 a = dt.Point(t.v[0]), b = dt.Point(t.v[1]), c = dt.Point(t.v[2]);
      const double eps = t.rep_radius / ball.radius;
      const StarDihedrals d = MeasureStar(ball.center, a, b, c);
      const double gamma = std::max({PlaneAngle(a, b, c), PlaneAngle(b, c, a), PlaneAngle(c, a, b)});
      // Per-tet bound with the tet's own σ_T, ε_T, γ_T (Theorem in the doc).
      const StarBound bound = StarDihedralBound(t.angle, eps, gamma);
      ASSERT_TRUE(bound.valid) << "σ_T " << t.angle << " ε " << eps;
      EXPECT_LE(d.max_base, bound.base + 1e-12) << "σ_T " << t.angle / kDeg << " ε " << eps;
      EXPECT_LE(d.max_radial, bound.radial + 1e-12) << "γ " << gamma / kDeg;
      ++stars;
      max_base = std::max(max_base, d.max_base);
      max_radial = std::max(max_radial, d.max_radial);
      max_eps = std::max(max_eps, eps);
      max_gamma = std::max(max_gamma, gamma);
    }
    // The global statement: with σ and the sample's ε, γ_max.
    const StarBound global = StarDihedralBound(sigma, max_eps, max_gamma);
    EXPECT_LE(max_base, global.base);
    EXPECT_LE(max_radial, global.radial);
    std::printf(
        "stars σ=%2.0f°: %4d tets, max base dihedral %6.2f° (bound %6.2f°, π/2+σ = %6.2f°), "
        "max radial %6.2f° (bound %6.2f°, γmax %6.2f°), εmax %.3f\n",
        sigma_deg, stars, max_base / kDeg, global.base / kDeg, 90 + sigma_deg,
        max_radial / kDeg, global.radial / kDeg, max_gamma / kDeg, max_eps);
    EXPECT_GT(stars, 50);
  }
}

TEST(CollarDihedralTest, BooksRespectTheBound) {
  // Two collar balls on a crease along z; samples jittered around their circle
  // (so edge representation angles spread), plus samples of both partial spheres.
  const std::vector<CollarBall> balls = {{Vec3(0, 0, -0.5), 0.8}, {Vec3(0, 0, 0.6), 0.9}};
  Circle3 circle;
  ASSERT_TRUE(SphereSphereCircle(balls[0], balls[1], &circle));
  std::mt19937_64 rng(77);
  std::uniform_real_distribution<double> u(-1, 1);
  Delaunay3 dt;
  uint32_t id = 0;
  const int n = 40;
  for (int k = 0; k < n; ++k) {
    const double t = 2 * std::numbers::pi * (k + 0.3 * u(rng)) / n;
    const double j = circle.radius * 0.04;
    dt.Insert(CirclePoint(circle, t) + Vec3(j * u(rng), j * u(rng), j * u(rng)), id++);
  }
  for (int b = 0; b < 2; ++b) {
    int made = 0;
    while (made < 400) {
      const Vec3 p = balls[b].center + balls[b].radius * RandomUnit(rng);
      if (!OnCollarSurface(p, b, balls) || std::fabs(p.z - circle.center.z) < 0.05) continue;
      dt.Insert(p, id++);
      ++made;
    }
  }
  for (int c = 0; c < 8; ++c) dt.Insert(Vec3(c & 1 ? 3 : -3, c & 2 ? 3 : -3, c & 4 ? 3 : -3), id++);
  const std::vector<RestrictedEdge> edges = RestrictedCircleEdges(dt, circle, {});
  ASSERT_GE(edges.size(), 30u);
  const Vec3 v = balls[0].center, w = balls[1].center;
  for (double sigma_deg : {15.0, 30.0, 45.0}) {
    const double sigma = sigma_deg * kDeg;
    int books = 0;
    double max_ab = 0, max_side = 0, max_axis = 0, max_eps = 0, max_alpha = 0;
    for (const RestrictedEdge& e : edges) {
      if (e.angle > sigma) continue;
      const Vec3 a = dt.Point(e.v[0]), b = dt.Point(e.v[1]);
      const double eps = std::max(geom::Dist(e.x, a), geom::Dist(e.x, b)) / circle.radius;
      const BookDihedrals d = MeasureBook(v, w, a, b);
      const double alpha = AngleBetween(v - 0.5 * (a + b), w - 0.5 * (a + b));
      const BookBound bound = BookDihedralBound(e.angle, eps, alpha);
      ASSERT_TRUE(bound.valid);
      EXPECT_LE(d.at_ab, bound.at_ab + 1e-12) << "σ_e " << e.angle / kDeg << " ε " << eps;
      EXPECT_LE(d.max_side, bound.side + 1e-12) << "σ_e " << e.angle / kDeg << " ε " << eps;
      EXPECT_LE(d.at_axis, bound.axis + 1e-12) << "ε " << eps;
      ++books;
      max_ab = std::max(max_ab, d.at_ab);
      max_side = std::max(max_side, d.max_side);
      max_axis = std::max(max_axis, d.at_axis);
      max_eps = std::max(max_eps, eps);
      max_alpha = std::max(max_alpha, alpha);
    }
    const BookBound global = BookDihedralBound(sigma, max_eps, max_alpha);
    EXPECT_LE(max_ab, global.at_ab);
    EXPECT_LE(max_side, global.side);
    std::printf(
        "books σ=%2.0f°: %3d tets, max at ab %6.2f° (bound %6.2f°, α %6.2f°), max side %6.2f° "
        "(bound %6.2f°), max at vv' %5.2f° (bound %5.2f°), εmax %.3f\n",
        sigma_deg, books, max_ab / kDeg, global.at_ab / kDeg, max_alpha / kDeg, max_side / kDeg,
        global.side / kDeg, max_axis / kDeg, global.axis / kDeg, max_eps);
    EXPECT_GT(books, 10);
  }
}

TEST(CollarDihedralTest, BoundFormulaValues) {
  // ε → 0, γ ≤ 90°: base π/2 + σ, radial 2·atan(1/cos σ).
  const StarBound b = StarDihedralBound(30 * kDeg, 0, 90 * kDeg);
  EXPECT_NEAR(b.base, 120 * kDeg, 1e-12);
  EXPECT_NEAR(b.radial, 2 * std::atan(1 / std::cos(30 * kDeg)), 1e-12);
  // cos σ ≤ ε: the star tet may be inverted; no bound.
  EXPECT_FALSE(StarDihedralBound(80 * kDeg, 0.2, 1.0).valid);
  const BookBound k = BookDihedralBound(0, 0, 90 * kDeg);
  EXPECT_NEAR(k.at_ab, 90 * kDeg, 1e-12);
  EXPECT_NEAR(k.side, 90 * kDeg, 1e-12);
  EXPECT_NEAR(k.axis, 0, 1e-12);
}

}  // namespace
}  // namespace svrc::refine
