// Restricted Delaunay of collar spheres and circles (Definitions 28–34):
// closed 2-manifold with χ = 2 on a dense sphere sample, hand-checked
// representation angles, circle cycles, validator catches bad topology.
#include "core/svrc/restricted_delaunay.h"

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "core/delaunay/delaunay3.h"
#include "gtest/gtest.h"

namespace svrc::refine {
namespace {

using delaunay::Delaunay3;
using delaunay::VertexId;

Vec3 RandomUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0, 1);
  for (;;) {
    Vec3 v(n(rng), n(rng), n(rng));
    const double l = geom::Norm(v);
    if (l > 1e-6) return v / l;
  }
}

void AddCorners(Delaunay3* dt, uint32_t* id, double lo, double hi) {
  for (int c = 0; c < 8; ++c) {
    dt->Insert(Vec3(c & 1 ? hi : lo, c & 2 ? hi : lo, c & 4 ? hi : lo), (*id)++);
  }
}

// Dense sample of a sphere (radial jitter ±jitter·ρ) plus interior and exterior
// points away from S, as a refined mesh around a collar would have.
Delaunay3 SphereSample(uint64_t seed, const CollarBall& ball, int n, double jitter,
                       int extra) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  Delaunay3 dt;
  uint32_t id = 0;
  for (int i = 0; i < n; ++i) {
    const double r = ball.radius * (1 + jitter * u(rng));
    dt.Insert(ball.center + r * RandomUnit(rng), id++);
  }
  for (int i = 0; i < extra; ++i) {
    const double r = ball.radius * (i % 2 == 0 ? 0.3 * (u(rng) + 1) : 1.6 + 0.5 * (u(rng) + 1));
    dt.Insert(ball.center + r * RandomUnit(rng), id++);
  }
  AddCorners(&dt, &id, -4, 4);
  return dt;
}

TEST(RestrictedSphereTest, DenseSampleIsClosedManifoldEulerTwo) {
  for (double jitter : {0.0, 0.01, 0.03}) {
    for (uint64_t seed = 1; seed <= 3; ++seed) {
      const std::vector<CollarBall> balls = {{Vec3(0.1, -0.2, 0.05), 1.0}};
      const Delaunay3 dt = SphereSample(seed, balls[0], 600, jitter, 40);
      const std::vector<RestrictedTriangle> tris = RestrictedSphereTriangles(dt, balls, 0);
      TopologyReport rep;
      const absl::Status st = ValidateRestrictedTopology(tris, {}, &rep);
      EXPECT_TRUE(st.ok()) << st << " jitter " << jitter << " seed " << seed;
      EXPECT_EQ(rep.euler, 2) << "jitter " << jitter;
      // Every sample point near S is a vertex of the restricted triangulation
      // only if its cell meets S; the count of triangles is 2V − 4.
      double max_angle = 0;
      for (const RestrictedTriangle& t : tris) {
        EXPECT_EQ(t.num_roots, 1);
        EXPECT_NEAR(geom::Dist(t.x, balls[0].center), 1.0, 1e-12);
        // The RepBall is empty: no vertex strictly closer to x than its vertices.
        const VertexId nv = dt.NearestVertex(t.x);
        EXPECT_LE(t.rep_radius, geom::Dist(t.x, dt.Point(nv)) * (1 + 1e-9));
        max_angle = std::max(max_angle, t.angle);
      }
      if (jitter == 0.0) {
        EXPECT_LT(max_angle, 1e-6);  // all vertices on S: σ = 0
      } else {
        EXPECT_GT(max_angle, 1e-3);
      }
    }
  }
}

TEST(RestrictedSphereTest, HandCheckedRepresentationAngle) {
  // Triangle t in the plane z = h with circumcentre (0.3, 0, h), circumradius
  // 0.1; apexes above and below. Its Voronoi edge is the vertical line x = 0.3,
  // y = 0 and meets the unit sphere at (0.3, 0, √0.91): σ = asin(0.3).
  const double h = std::sqrt(0.91);
  Delaunay3 dt;
  uint32_t id = 0;
  std::vector<VertexId> tri;
  for (int k = 0; k < 3; ++k) {
    const double a = 2 * std::numbers::pi * k / 3;
    tri.push_back(dt.Insert(Vec3(0.3 + 0.1 * std::cos(a), 0.1 * std::sin(a), h), id++).vertex);
  }
  dt.Insert(Vec3(0.3, 0, h + 0.12), id++);
  dt.Insert(Vec3(0.3, 0, h - 0.12), id++);
  const std::vector<CollarBall> balls = {{Vec3(0, 0, 0), 1.0}};
  const std::vector<RestrictedTriangle> tris = RestrictedSphereTriangles(dt, balls, 0);
  bool found = false;
  for (const RestrictedTriangle& t : tris) {
    std::vector<VertexId> v(t.v, t.v + 3);
    if (v != tri) continue;
    found = true;
    EXPECT_NEAR(t.angle, std::asin(0.3), 1e-12);
    EXPECT_NEAR(t.x.x, 0.3, 1e-12);
    EXPECT_NEAR(t.x.y, 0.0, 1e-12);
    EXPECT_NEAR(t.x.z, h, 1e-12);
    EXPECT_NEAR(t.rep_radius, 0.1, 1e-12);
  }
  EXPECT_TRUE(found);
  // With a second ball covering x, the root is not on S: t is not restricted.
  const std::vector<CollarBall> two = {{Vec3(0, 0, 0), 1.0}, {Vec3(0.3, 0, h), 0.05}};
  for (const RestrictedTriangle& t : RestrictedSphereTriangles(dt, two, 0)) {
    std::vector<VertexId> v(t.v, t.v + 3);
    EXPECT_NE(v, tri);
  }
}

TEST(RestrictedSphereTest, SnappedVerticesGiveZeroAngle) {
  // Vertices within δρ of S snap onto it; the snapped triangle's normal then
  // passes through the centre: σ(T) = 0 exactly up to rounding (Def. 34 remark).
  const std::vector<CollarBall> balls = {{Vec3(0, 0, 0), 1.0}};
  const Delaunay3 dt = SphereSample(9, balls[0], 400, 0.01, 20);
  std::vector<Vec3> snapped(dt.NumVertices());
  for (uint32_t i = 0; i < dt.NumVertices(); ++i) {
    snapped[i] = SnapToSphere(dt.Point(VertexId(i)), balls[0], 0.02);
  }
  const auto raw = RestrictedSphereTriangles(dt, balls, 0);
  const auto snap = RestrictedSphereTriangles(dt, balls, 0, snapped);
  ASSERT_EQ(raw.size(), snap.size());
  double max_raw = 0, max_snap = 0;
  for (size_t i = 0; i < raw.size(); ++i) {
    max_raw = std::max(max_raw, raw[i].angle);
    max_snap = std::max(max_snap, snap[i].angle);
  }
  EXPECT_GT(max_raw, 1e-3);
  // Snapped normal through o vs x on the Voronoi edge of the unsnapped points.
  EXPECT_LT(max_snap, max_raw);
}

TEST(RestrictedCircleTest, TwoBallsCircleIsOneCycleAndPartialSpheresValid) {
  // Two smooth collar balls on a crease segment along z (Lemma 14 holds:
  // |c1c2|² = 1 ≤ 0.64 + 0.64). Sample both partial spheres and the circle.
  const std::vector<CollarBall> balls = {{Vec3(0, 0, -0.5), 0.8}, {Vec3(0, 0, 0.5), 0.8}};
  Circle3 circle;
  ASSERT_TRUE(SphereSphereCircle(balls[0], balls[1], &circle));
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  Delaunay3 dt;
  uint32_t id = 0;
  for (int k = 0; k < 64; ++k) {
    const double t = 2 * std::numbers::pi * (k + 0.2 * u(rng)) / 64;
    dt.Insert(CirclePoint(circle, t), id++);
  }
  for (int b = 0; b < 2; ++b) {
    int made = 0;
    while (made < 500) {
      const Vec3 p = balls[b].center + balls[b].radius * RandomUnit(rng);
      if (!OnCollarSurface(p, b, balls)) continue;
      // Keep a band free next to the circle (wider than half the circle
      // spacing, 0.031) so that circle points own it.
      if (std::fabs(p.z) < 0.06) continue;
      dt.Insert(p, id++);
      ++made;
    }
  }
  AddCorners(&dt, &id, -3, 3);
  const std::vector<RestrictedEdge> edges = RestrictedCircleEdges(dt, circle, {});
  TopologyReport rep;
  std::vector<std::vector<RestrictedEdge>> circles = {edges};
  for (uint32_t b = 0; b < 2; ++b) {
    const auto tris = RestrictedSphereTriangles(dt, balls, b);
    const absl::Status st = ValidateRestrictedTopology(tris, circles, &rep);
    EXPECT_TRUE(st.ok()) << st;
    EXPECT_EQ(rep.bad_circles, 0);
    // A partial sphere bounded by one circle is a disk: χ = 1.
    EXPECT_EQ(rep.euler, 1) << "ball " << b;
  }
  EXPECT_GE(edges.size(), 60u);
  for (const RestrictedEdge& e : edges) {
    EXPECT_NEAR(geom::Dist(e.x, circle.center), circle.radius, 1e-12);
    EXPECT_LT(e.angle, 0.3);
  }
}

TEST(ValidatorTest, CatchesOpenSurfaceAndBadLinks) {
  using V = VertexId;
  // A lone triangle: its edges have one restricted triangle each → (b).
  std::vector<RestrictedTriangle> tris(1);
  tris[0].v[0] = V(0);
  tris[0].v[1] = V(1);
  tris[0].v[2] = V(2);
  tris[0].num_roots = 1;
  TopologyReport rep;
  EXPECT_FALSE(ValidateRestrictedTopology(tris, {}, &rep).ok());
  EXPECT_EQ(rep.bad_facets, 3);
  EXPECT_EQ(rep.bad_links, 3);
  // Two roots on one Voronoi edge → (a).
  tris[0].num_roots = 2;
  EXPECT_FALSE(ValidateRestrictedTopology(tris, {}, &rep).ok());
  EXPECT_EQ(rep.bad_roots, 1);
  // Tetrahedron boundary: closed, χ = 2.
  std::vector<RestrictedTriangle> tet(4);
  const uint32_t f[4][3] = {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}};
  for (int i = 0; i < 4; ++i) {
    for (int k = 0; k < 3; ++k) tet[i].v[k] = V(f[i][k]);
    tet[i].num_roots = 1;
  }
  EXPECT_TRUE(ValidateRestrictedTopology(tet, {}, &rep).ok());
  EXPECT_EQ(rep.euler, 2);
  // (e): a circle with only two edges is not a cycle of ≥ 3.
  std::vector<std::vector<RestrictedEdge>> c(1, std::vector<RestrictedEdge>(2));
  c[0][0].v[0] = V(0);
  c[0][0].v[1] = V(1);
  c[0][1].v[0] = V(0);
  c[0][1].v[1] = V(1);
  EXPECT_FALSE(ValidateRestrictedTopology(tet, c, &rep).ok());
  EXPECT_EQ(rep.bad_circles, 1);
  // (d): no triangle at all.
  EXPECT_FALSE(ValidateRestrictedTopology({}, {}, &rep).ok());
  EXPECT_TRUE(rep.empty_sphere);
}

}  // namespace
}  // namespace svrc::refine
