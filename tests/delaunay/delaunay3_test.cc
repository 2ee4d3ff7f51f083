// Tests of the incremental 3D Delaunay kernel: Validate (neighbours,
// orientation, convex hull, empty sphere) after every insertion on random and
// degenerate inputs, insertion-order independence, reported cavities, hints,
// duplicates and the Voronoi queries checked against brute force.
#include "core/delaunay/delaunay3.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <set>
#include <vector>

#include "core/delaunay/spatial_sort.h"
#include "core/geometry/predicates.h"

namespace svrc::delaunay {
namespace {

using Tet = std::array<uint32_t, 4>;

std::vector<Vec3> RandomPoints(int n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vec3> pts(n);
  for (auto& p : pts) p = Vec3(u(rng), u(rng), u(rng));
  return pts;
}

std::vector<Vec3> Grid(int k) {
  std::vector<Vec3> pts;
  for (int x = 0; x < k; ++x)
    for (int y = 0; y < k; ++y)
      for (int z = 0; z < k; ++z) pts.emplace_back(x, y, z);
  return pts;
}

// Integer points on the sphere x²+y²+z² = r2 (exactly cospherical).
std::vector<Vec3> SpherePoints(int r2) {
  std::vector<Vec3> pts;
  const int r = static_cast<int>(std::sqrt(r2)) + 1;
  for (int x = -r; x <= r; ++x)
    for (int y = -r; y <= r; ++y)
      for (int z = -r; z <= r; ++z)
        if (x * x + y * y + z * z == r2) pts.emplace_back(x, y, z);
  return pts;
}

// Canonical sorted tets over global ids (even rotation, smallest first).
std::vector<Tet> CanonicalTets(const Delaunay3& dt) {
  std::vector<Tet> out;
  for (TetId t : dt.FiniteTets()) {
    Tet v;
    for (int i = 0; i < 4; ++i) v[i] = dt.GlobalId(dt.TetVertex(t, i));
    static constexpr int kFirst[4][4] = {{0, 1, 2, 3}, {1, 0, 3, 2}, {2, 3, 0, 1}, {3, 2, 1, 0}};
    int k = static_cast<int>(std::min_element(v.begin(), v.end()) - v.begin());
    Tet r;
    for (int i = 0; i < 4; ++i) r[i] = v[kFirst[k][i]];
    while (!(r[1] < r[2] && r[1] < r[3])) r = {r[0], r[2], r[3], r[1]};
    out.push_back(r);
  }
  std::sort(out.begin(), out.end());
  return out;
}

double Volume6(const Delaunay3& dt, TetId t) {
  const Vec3 a = dt.Point(dt.TetVertex(t, 0));
  const Vec3 b = dt.Point(dt.TetVertex(t, 1)) - a, c = dt.Point(dt.TetVertex(t, 2)) - a,
             d = dt.Point(dt.TetVertex(t, 3)) - a;
  return geom::Dot(b, geom::Cross(c, d));
}

// Inserts pts (global id = index, in the given order) validating after
// every insertion; returns the triangulation.
Delaunay3 BuildValidated(const std::vector<Vec3>& pts, const std::vector<uint32_t>& order,
                         bool every_step = true) {
  Delaunay3 dt;
  for (size_t k = 0; k < order.size(); ++k) {
    const uint32_t i = order[k];
    const auto r = dt.Insert(pts[i], i);
    EXPECT_NE(r.outcome, Delaunay3::InsertOutcome::kDuplicate) << "point " << i;
    if (every_step || k + 1 == order.size()) {
      const absl::Status s = dt.Validate(true);
      EXPECT_TRUE(s.ok()) << "after inserting point " << i << " (step " << k << "): " << s;
      if (!s.ok()) break;
    }
  }
  return dt;
}

std::vector<uint32_t> Iota(size_t n) {
  std::vector<uint32_t> o(n);
  for (size_t i = 0; i < n; ++i) o[i] = static_cast<uint32_t>(i);
  return o;
}

std::vector<uint32_t> Shuffled(size_t n, uint32_t seed) {
  std::vector<uint32_t> o = Iota(n);
  std::mt19937 rng(seed);
  std::shuffle(o.begin(), o.end(), rng);
  return o;
}

// CavityBoundary (the dry run BreakSlivers scores candidate points with,
// docs/svrc-design.md §8 item 69) reports exactly the faces Insert then
// joins to the new point: as many, with the same vertex sets, and nothing
// in the mesh changes in between. Beyond the hull, from a tet not in
// conflict, or past max_tets: false.
TEST(Delaunay3Test, CavityBoundaryIsTheFacesInsertJoins) {
  const std::vector<Vec3> pts = RandomPoints(400, 11);
  Delaunay3 dt;
  for (uint32_t i = 0; i < 300; ++i) dt.Insert(pts[i], i);
  std::vector<uint32_t> boundary;
  for (uint32_t i = 300; i < 400; ++i) {
    const TetId start = dt.Locate(pts[i]);
    ASSERT_TRUE(start.valid());
    const std::vector<Tet> before = CanonicalTets(dt);
    if (dt.IsGhost(start)) {
      EXPECT_FALSE(dt.CavityBoundary(pts[i], i, start, 1000, &boundary)) << i;
      dt.Insert(pts[i], i);
      continue;
    }
    ASSERT_TRUE(dt.CavityBoundary(pts[i], i, start, 1000, &boundary)) << i;
    EXPECT_EQ(CanonicalTets(dt), before) << "the dry run changed the mesh at point " << i;
    std::multiset<std::array<uint32_t, 3>> faces;
    for (uint32_t slot : boundary) {
      std::array<uint32_t, 3> f;
      for (int k = 0, j = 0; k < 4; ++k) {
        if (k != static_cast<int>(slot % 4)) f[j++] = dt.TetVertex(TetId(slot / 4), k).value();
      }
      std::sort(f.begin(), f.end());
      faces.insert(f);
    }
    if (faces.size() > 4) {
      EXPECT_FALSE(dt.CavityBoundary(pts[i], i, start, 1, &boundary)) << i;  // more than one tet
    }
    const auto r = dt.Insert(pts[i], i, start);
    ASSERT_EQ(r.outcome, Delaunay3::InsertOutcome::kInserted);
    std::multiset<std::array<uint32_t, 3>> joined;
    for (TetId t : r.created) {
      std::array<uint32_t, 3> f;
      for (int k = 0, j = 0; k < 4; ++k) {
        if (dt.TetVertex(t, k) != r.vertex) f[j++] = dt.TetVertex(t, k).value();
      }
      std::sort(f.begin(), f.end());
      joined.insert(f);
    }
    EXPECT_EQ(faces, joined) << "point " << i;
  }
  // A tet the point is not in conflict with (far from it).
  const Vec3 far_point(10, 10, 10);
  EXPECT_FALSE(dt.CavityBoundary(Vec3(0.5, 0.5, 0.5), 1000, dt.Locate(far_point), 1000, &boundary));
  EXPECT_TRUE(dt.Validate(true).ok());
}

TEST(Delaunay3Test, EmptyAndPending) {
  Delaunay3 dt;
  EXPECT_FALSE(dt.Is3d());
  EXPECT_EQ(dt.Locate(Vec3(0, 0, 0)), kNoneTet);
  EXPECT_EQ(dt.Insert(Vec3(0, 0, 0), 0).outcome, Delaunay3::InsertOutcome::kPending);
  EXPECT_EQ(dt.Insert(Vec3(0, 0, 0), 1).outcome, Delaunay3::InsertOutcome::kDuplicate);
  EXPECT_EQ(dt.Insert(Vec3(1, 0, 0), 2).outcome, Delaunay3::InsertOutcome::kPending);
  EXPECT_EQ(dt.Insert(Vec3(2, 0, 0), 3).outcome, Delaunay3::InsertOutcome::kPending);  // collinear
  EXPECT_EQ(dt.Insert(Vec3(0, 1, 0), 4).outcome, Delaunay3::InsertOutcome::kPending);
  EXPECT_EQ(dt.Insert(Vec3(1, 1, 0), 5).outcome, Delaunay3::InsertOutcome::kPending);  // coplanar
  EXPECT_FALSE(dt.Is3d());
  const auto r = dt.Insert(Vec3(0, 0, 1), 6);
  EXPECT_EQ(r.outcome, Delaunay3::InsertOutcome::kInserted);
  EXPECT_TRUE(dt.Is3d());
  EXPECT_EQ(dt.NumVertices(), 6u);
  EXPECT_EQ(r.created.size(), dt.NumTets());
  EXPECT_EQ(r.cavity_vertices.size(), 5u);
  ASSERT_TRUE(dt.Validate(true).ok()) << dt.Validate(true);
  // Hull volume: pyramid over the unit square (2x1 strip with (2,0,0)).
  double vol6 = 0;
  for (TetId t : dt.FiniteTets()) vol6 += Volume6(dt, t);
  // Hull of (0..2,0,0),(0,1,0),(1,1,0),(0,0,1): base area 1.5, height 1.
  EXPECT_EQ(vol6, 3.0);
}

TEST(Delaunay3Test, SingleTet) {
  Delaunay3 dt;
  dt.Insert(Vec3(0, 0, 0), 10);
  dt.Insert(Vec3(1, 0, 0), 11);
  dt.Insert(Vec3(0, 1, 0), 12);
  dt.Insert(Vec3(0, 0, 1), 13);
  ASSERT_TRUE(dt.Validate(true).ok());
  EXPECT_EQ(dt.NumFiniteTets(), 1u);
  EXPECT_EQ(dt.NumGhostTets(), 4u);
  const TetId t = dt.FiniteTets()[0];
  EXPECT_GT(geom::Orient3d(dt.Point(dt.TetVertex(t, 0)), dt.Point(dt.TetVertex(t, 1)),
                           dt.Point(dt.TetVertex(t, 2)), dt.Point(dt.TetVertex(t, 3))),
            0);
  const Vec3 c = dt.Circumcenter(t);
  EXPECT_NEAR(c.x, 0.5, 1e-15);
  EXPECT_NEAR(c.y, 0.5, 1e-15);
  EXPECT_NEAR(c.z, 0.5, 1e-15);
  EXPECT_NEAR(dt.Circumradius(t), std::sqrt(0.75), 1e-15);
}

TEST(Delaunay3Test, RandomValidateEveryStep) {
  const auto pts = RandomPoints(300, 1);
  Delaunay3 dt = BuildValidated(pts, Iota(pts.size()));
  EXPECT_EQ(dt.NumVertices(), 300u);
  // Euler for a 3-ball: V − E + F − T = 1; with ghosts, ghost count = hull faces.
}

TEST(Delaunay3Test, CubicGridValidateEveryStep) {
  const auto pts = Grid(5);
  for (uint32_t seed : {0u, 7u}) {
    const auto order = seed == 0 ? Iota(pts.size()) : Shuffled(pts.size(), seed);
    Delaunay3 dt = BuildValidated(pts, order);
    double vol6 = 0;
    for (TetId t : dt.FiniteTets()) {
      const double v = Volume6(dt, t);
      EXPECT_GT(v, 0);
      vol6 += v;
    }
    EXPECT_EQ(vol6, 6.0 * 64.0);  // the 4x4x4 cube, exactly (integer coordinates)
  }
}

TEST(Delaunay3Test, CospherialValidateEveryStep) {
  // 8 cube corners, then integer points on spheres of radius² 50 and 81.
  std::vector<Vec3> pts;
  for (int x : {-1, 1})
    for (int y : {-1, 1})
      for (int z : {-1, 1}) pts.emplace_back(x, y, z);
  Delaunay3 cube = BuildValidated(pts, Iota(pts.size()));
  EXPECT_GE(cube.NumFiniteTets(), 5u);  // 5 or 6: the perturbation picks
  double vol6 = 0;
  for (TetId t : cube.FiniteTets()) vol6 += Volume6(cube, t);
  EXPECT_EQ(vol6, 48.0);
  for (int r2 : {50, 81}) {
    const auto sphere = SpherePoints(r2);
    ASSERT_GT(sphere.size(), 50u);
    BuildValidated(sphere, Iota(sphere.size()));
    BuildValidated(sphere, Shuffled(sphere.size(), r2));
  }
}

TEST(Delaunay3Test, CoplanarPlusOne) {
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> u(-20, 20);
  std::vector<Vec3> pts;
  std::set<std::pair<int, int>> seen;
  while (pts.size() < 120) {
    const int x = u(rng), y = u(rng);
    if (seen.insert({x, y}).second) pts.emplace_back(x, y, 0);
  }
  pts.emplace_back(0.5, 0.25, 3);
  // Apex last: 120 pending points, then one insertion builds everything.
  BuildValidated(pts, Iota(pts.size()));
  // Apex early: then the others land exactly on the hull plane.
  std::vector<uint32_t> order = Iota(pts.size());
  std::rotate(order.begin(), order.begin() + 120, order.end());
  std::swap(order[0], order[5]);
  Delaunay3 a = BuildValidated(pts, order);
  Delaunay3 b = BuildValidated(pts, Shuffled(pts.size(), 11));
  EXPECT_EQ(CanonicalTets(a), CanonicalTets(b));
}

TEST(Delaunay3Test, CollinearHeavy) {
  std::vector<Vec3> pts;
  for (int i = 0; i < 40; ++i) pts.emplace_back(i, 0, 0);        // x axis
  for (int i = 1; i < 40; ++i) pts.emplace_back(0, i, 0);        // y axis
  for (int i = 1; i < 40; ++i) pts.emplace_back(i * 0.5, i * 0.5, 7);  // a skew line
  for (int i = 0; i < 10; ++i) pts.emplace_back(3, 3, i - 5);    // a vertical line
  Delaunay3 a = BuildValidated(pts, Iota(pts.size()));
  Delaunay3 b = BuildValidated(pts, Shuffled(pts.size(), 5));
  EXPECT_EQ(CanonicalTets(a), CanonicalTets(b));
}

TEST(Delaunay3Test, OrderIndependentOnDegenerateInputs) {
  const auto grid = Grid(5);
  const auto ref = CanonicalTets(BuildValidated(grid, Iota(grid.size()), false));
  for (uint32_t seed = 1; seed <= 4; ++seed) {
    EXPECT_EQ(CanonicalTets(BuildValidated(grid, Shuffled(grid.size(), seed), false)), ref);
  }
  const auto hilbert = HilbertOrder(grid);
  EXPECT_EQ(CanonicalTets(BuildValidated(grid, hilbert, false)), ref);
  const auto sphere = SpherePoints(81);
  const auto sref = CanonicalTets(BuildValidated(sphere, Iota(sphere.size()), false));
  EXPECT_EQ(CanonicalTets(BuildValidated(sphere, Shuffled(sphere.size(), 9), false)), sref);
}

TEST(Delaunay3Test, SameRunTwiceSameArrays) {
  const auto pts = RandomPoints(2000, 2);
  auto run = [&] {
    Delaunay3 dt;
    for (uint32_t i = 0; i < pts.size(); ++i) dt.Insert(pts[i], i);
    std::vector<uint32_t> raw;
    for (uint32_t t = 0; t < dt.TetCapacity(); ++t) {
      for (int i = 0; i < 4; ++i) raw.push_back(dt.IsAlive(TetId(t)) ? dt.TetVertex(TetId(t), i).value() : 0);
      for (int f = 0; f < 4; ++f) raw.push_back(dt.IsAlive(TetId(t)) ? dt.Neighbor(TetId(t), f).value() : 0);
    }
    return raw;
  };
  EXPECT_EQ(run(), run());
}

TEST(Delaunay3Test, Duplicates) {
  const auto grid = Grid(3);
  Delaunay3 dt = BuildValidated(grid, Iota(grid.size()));
  const uint32_t nv = dt.NumVertices();
  for (uint32_t i = 0; i < grid.size(); ++i) {
    // Without a hint (walk) and with a hint: every tet incident to the twin.
    auto r = dt.Insert(grid[i], 1000 + i);
    EXPECT_EQ(r.outcome, Delaunay3::InsertOutcome::kDuplicate);
    EXPECT_EQ(r.vertex, VertexId(i));
    std::vector<TetId> star;
    dt.Star(VertexId(i), &star);
    for (TetId t : star) {
      r = dt.Insert(grid[i], 1000 + i, t);
      EXPECT_EQ(r.outcome, Delaunay3::InsertOutcome::kDuplicate);
      EXPECT_EQ(r.vertex, VertexId(i));
    }
    // Priority below every existing vertex too.
    std::vector<TetId> all = dt.FiniteTets();
    for (TetId t : all) {
      r = dt.Insert(grid[i], 0xFFFFFF00u - i, t);
      EXPECT_EQ(r.outcome, Delaunay3::InsertOutcome::kDuplicate);
    }
  }
  EXPECT_EQ(dt.NumVertices(), nv);
  EXPECT_TRUE(dt.Validate(true).ok());
}

TEST(Delaunay3Test, InsertReportsCavity) {
  const auto pts = RandomPoints(400, 4);
  Delaunay3 dt;
  for (uint32_t i = 0; i < 8; ++i) dt.Insert(pts[i], i);
  for (uint32_t i = 8; i < pts.size(); ++i) {
    // Tets in conflict before the insertion, with their generations.
    std::set<uint32_t> conflict;
    std::vector<std::pair<uint32_t, uint32_t>> gens;
    for (uint32_t t = 0; t < dt.TetCapacity(); ++t) {
      if (dt.IsAlive(TetId(t)) && dt.InConflict(TetId(t), pts[i], i)) {
        conflict.insert(t);
        gens.emplace_back(t, dt.Generation(TetId(t)));
      }
    }
    const auto r = dt.Insert(pts[i], i);
    ASSERT_EQ(r.outcome, Delaunay3::InsertOutcome::kInserted);
    std::set<uint32_t> destroyed;
    for (TetId t : r.destroyed) destroyed.insert(t.value());
    EXPECT_EQ(destroyed, conflict);
    for (auto [t, g] : gens) EXPECT_NE(dt.Generation(TetId(t)), g);
    std::set<uint32_t> cav;
    for (TetId t : r.created) {
      ASSERT_TRUE(dt.IsAlive(t));
      bool has_v = false;
      for (int k = 0; k < 4; ++k) {
        const VertexId w = dt.TetVertex(t, k);
        if (w == r.vertex) has_v = true;
        else if (w != kInfiniteVertex) cav.insert(w.value());
      }
      EXPECT_TRUE(has_v);
    }
    std::set<uint32_t> reported;
    for (VertexId w : r.cavity_vertices) EXPECT_TRUE(reported.insert(w.value()).second);
    EXPECT_EQ(reported, cav);
    std::vector<TetId> star;
    dt.Star(r.vertex, &star);
    EXPECT_EQ(star.size(), r.created.size());
  }
  EXPECT_TRUE(dt.Validate(true).ok());
}

TEST(Delaunay3Test, InsertFromConflictingHintMatchesWalk) {
  const auto pts = RandomPoints(500, 6);
  Delaunay3 walk, hinted;
  for (uint32_t i = 0; i < pts.size(); ++i) {
    walk.Insert(pts[i], i);
    TetId hint = kNoneTet;
    if (hinted.Is3d()) {
      // The conflicting tet farthest from the walk's start, found by brute force.
      for (uint32_t t = hinted.TetCapacity(); t-- > 0;) {
        if (hinted.IsAlive(TetId(t)) && hinted.InConflict(TetId(t), pts[i], i)) {
          hint = TetId(t);
          break;
        }
      }
      ASSERT_TRUE(hint.valid());
    }
    const auto r = hinted.Insert(pts[i], i, hint);
    ASSERT_EQ(r.outcome, i < 3 ? Delaunay3::InsertOutcome::kPending : Delaunay3::InsertOutcome::kInserted);
  }
  ASSERT_TRUE(hinted.Validate(true).ok());
  EXPECT_EQ(CanonicalTets(walk), CanonicalTets(hinted));
}

TEST(Delaunay3Test, BoundingCubeThenInterior) {
  // SVRC's M_Ω: 8 cube corners as ordinary vertices, then interior points.
  Delaunay3 dt;
  uint32_t id = 0;
  for (int x : {-2, 2})
    for (int y : {-2, 2})
      for (int z : {-2, 2}) dt.Insert(Vec3(x, y, z), id++);
  const auto pts = RandomPoints(200, 8);
  for (const auto& p : pts) {
    dt.Insert(p, id++);
    ASSERT_TRUE(dt.Validate(true).ok());
  }
  for (uint32_t v = 0; v < dt.NumVertices(); ++v) {
    EXPECT_EQ(dt.IsHullVertex(VertexId(v)), v < 8) << v;
    if (v >= 8) EXPECT_TRUE(std::isfinite(dt.OutRadius(VertexId(v))));
    else EXPECT_TRUE(std::isinf(dt.OutRadius(VertexId(v))));
  }
  EXPECT_EQ(dt.NumGhostTets(), 12u);
}

TEST(Delaunay3Test, QueriesMatchBruteForce) {
  const auto pts = RandomPoints(300, 12);
  Delaunay3 dt;
  for (uint32_t i = 0; i < pts.size(); ++i) dt.Insert(pts[i], i);
  ASSERT_TRUE(dt.Validate(true).ok());
  std::vector<TetId> star;
  std::vector<VertexId> nbrs;
  std::vector<Vec3> corners;
  for (uint32_t v = 0; v < dt.NumVertices(); ++v) {
    std::set<uint32_t> bf_star, bf_nbrs;
    bool hull = false;
    for (uint32_t t = 0; t < dt.TetCapacity(); ++t) {
      if (!dt.IsAlive(TetId(t))) continue;
      bool inc = false;
      for (int i = 0; i < 4; ++i) inc |= dt.TetVertex(TetId(t), i) == VertexId(v);
      if (!inc) continue;
      bf_star.insert(t);
      hull |= dt.IsGhost(TetId(t));
      for (int i = 0; i < 4; ++i) {
        const VertexId w = dt.TetVertex(TetId(t), i);
        if (w != VertexId(v) && w != kInfiniteVertex) bf_nbrs.insert(w.value());
      }
    }
    dt.Star(VertexId(v), &star);
    std::set<uint32_t> s;
    for (TetId t : star) s.insert(t.value());
    EXPECT_EQ(s, bf_star);
    dt.Neighbors(VertexId(v), &nbrs);
    std::set<uint32_t> nb;
    for (VertexId w : nbrs) nb.insert(w.value());
    EXPECT_EQ(nb, bf_nbrs);
    EXPECT_EQ(dt.IsHullVertex(VertexId(v)), hull);
    double shortest = INFINITY;
    for (uint32_t w : bf_nbrs) shortest = std::min(shortest, geom::Dist(pts[v], pts[w]));
    EXPECT_EQ(dt.InRadius(VertexId(v)), 0.5 * shortest);
    dt.VoronoiCorners(VertexId(v), &corners);
    double R = 0;
    for (const Vec3& c : corners) R = std::max(R, geom::Dist(c, pts[v]));
    if (hull) {
      EXPECT_TRUE(std::isinf(dt.OutRadius(VertexId(v))));
    } else {
      Vec3 far;
      EXPECT_EQ(dt.OutRadius(VertexId(v), &far), R);
      EXPECT_EQ(geom::Dist(far, pts[v]), R);
    }
  }
  // Circumcentres are equidistant from the four vertices. The shape the
  // computation reports (session 41; OmegaMesh's flatness test reads it) is
  // the same doubles as computing it again from the vertices.
  for (TetId t : dt.FiniteTets()) {
    const Vec3 c = dt.Circumcenter(t);
    const double r = dt.Circumradius(t);
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(geom::Dist(c, dt.Point(dt.TetVertex(t, i))), r, 1e-9 * (1 + r));
    Delaunay3::TetShape shape;
    const Vec3 c2 = dt.Circumcenter(t, &shape);
    EXPECT_TRUE(c2.x == c.x && c2.y == c.y && c2.z == c.z);
    const Vec3& a = dt.Point(dt.TetVertex(t, 0));
    const Vec3 b = dt.Point(dt.TetVertex(t, 1)) - a, cc = dt.Point(dt.TetVertex(t, 2)) - a,
               d = dt.Point(dt.TetVertex(t, 3)) - a;
    EXPECT_EQ(shape.det, geom::Dot(b, geom::Cross(cc, d)));
    EXPECT_GT(shape.det, 0);  // positively oriented
    EXPECT_EQ(shape.longest2, std::max({geom::Norm2(b), geom::Norm2(cc), geom::Norm2(d), geom::Dist2(b, cc),
                                        geom::Dist2(b, d), geom::Dist2(cc, d)}));
  }
  // Nearest vertex and point location.
  const auto queries = RandomPoints(500, 13);
  for (const Vec3& q : queries) {
    uint32_t best = 0;
    for (uint32_t v = 1; v < pts.size(); ++v) {
      if (geom::Dist2(q, pts[v]) < geom::Dist2(q, pts[best])) best = v;
    }
    EXPECT_EQ(dt.NearestVertex(q), VertexId(best));
    const TetId t = dt.Locate(q);
    ASSERT_TRUE(t.valid());
    if (!dt.IsGhost(t)) {
      for (int f = 0; f < 4; ++f) {
        Vec3 p[4];
        for (int i = 0; i < 4; ++i) p[i] = dt.Point(dt.TetVertex(t, i));
        p[f] = q;
        EXPECT_GE(geom::Orient3d(p[0], p[1], p[2], p[3]), 0);
      }
    } else {
      EXPECT_TRUE(dt.InConflict(t, q, 100000));
    }
  }
  // Far outside queries.
  EXPECT_EQ(dt.NearestVertex(Vec3(-100, 0.5, 0.5)).valid(), true);
}

// VertexAt(p) is NearestVertex(p) exactly when a vertex sits at p, else none:
// on every vertex (grid points lie on faces and edges of many tets, so
// Locate may return any tet of the star), on circumcentres (equidistant from
// four vertices, the refiner's phantom-corner query), on midpoints of grid
// edges and on random points, with and without hints.
TEST(Delaunay3Test, VertexAtMatchesNearestVertex) {
  const auto grid = Grid(4);
  Delaunay3 dt;
  for (uint32_t i = 0; i < grid.size(); ++i) dt.Insert(grid[i], i);
  std::vector<Vec3> queries = grid;
  for (TetId t : dt.FiniteTets()) queries.push_back(dt.Circumcenter(t));
  for (size_t i = 0; i + 1 < grid.size(); ++i) queries.push_back(0.5 * (grid[i] + grid[i + 1]));
  for (const Vec3& q : RandomPoints(200, 5)) queries.push_back(q);
  queries.push_back(Vec3(-3, 0.5, 0.5));  // outside the hull
  int at_vertex = 0;
  for (size_t k = 0; k < queries.size(); ++k) {
    const Vec3& q = queries[k];
    const VertexId near = dt.NearestVertex(q);
    const VertexId want = dt.Point(near) == q ? near : kNoneVertex;
    EXPECT_EQ(dt.VertexAt(q), want) << k;
    const TetId hint(static_cast<uint32_t>(k * 7919) % dt.TetCapacity());
    EXPECT_EQ(dt.VertexAt(q, dt.IsAlive(hint) ? hint : kNoneTet), want) << k;
    at_vertex += want.valid();
  }
  EXPECT_GE(at_vertex, static_cast<int>(grid.size()));
  EXPECT_FALSE(Delaunay3().VertexAt(Vec3(0, 0, 0)).valid());
}

TEST(Delaunay3Test, Large100kEmptySphere) {
  const auto pts = RandomPoints(100000, 21);
  const auto order = BrioOrder(HilbertOrder(pts));
  Delaunay3 dt;
  dt.Reserve(pts.size());
  for (uint32_t i : order) dt.Insert(pts[i], i);
  EXPECT_EQ(dt.NumVertices(), 100000u);
  const absl::Status s = dt.Validate(true);
  EXPECT_TRUE(s.ok()) << s;
  // ~6.7 tets per vertex for uniform points.
  EXPECT_GT(dt.NumFiniteTets(), 600000u);
  EXPECT_LT(dt.NumFiniteTets(), 700000u);
}

TEST(SpatialSortTest, HilbertIsAPermutationAndAdjacentCellsAreAdjacent) {
  // Consecutive Hilbert indices are face-adjacent cells.
  std::vector<std::pair<uint64_t, std::array<uint32_t, 3>>> cells;
  for (uint32_t x = 0; x < 8; ++x)
    for (uint32_t y = 0; y < 8; ++y)
      for (uint32_t z = 0; z < 8; ++z) cells.push_back({HilbertIndex21(x << 18, y << 18, z << 18), {x, y, z}});
  std::sort(cells.begin(), cells.end());
  for (size_t i = 1; i < cells.size(); ++i) {
    EXPECT_NE(cells[i].first, cells[i - 1].first);
    int d = 0;
    for (int k = 0; k < 3; ++k) d += std::abs(int(cells[i].second[k]) - int(cells[i - 1].second[k]));
    EXPECT_EQ(d, 1) << i;
  }
  const auto pts = RandomPoints(1000, 3);
  auto o = BrioOrder(HilbertOrder(pts));
  std::sort(o.begin(), o.end());
  EXPECT_EQ(o, Iota(1000));
}

// NearVertex: a vertex nearest to the query up to rounding (double squared
// distances): the exact nearest on random queries, and from a circumcentre,
// where the corners tie, a vertex no farther than the nearest by more than
// rounding; on an integer grid (exact ties everywhere) likewise. With and
// without the neighbour cache.
TEST(Delaunay3Test, NearVertexIsNearestUpToRounding) {
  for (const bool cache : {false, true}) {
    for (const bool grid : {false, true}) {
      const std::vector<Vec3> pts = grid ? Grid(6) : RandomPoints(600, 21);
      Delaunay3 dt = BuildValidated(pts, Shuffled(pts.size(), 5), /*every_step=*/false);
      dt.set_cache_neighbors(cache);
      auto min_d2 = [&](const Vec3& q) {
        double m = HUGE_VAL;
        for (const Vec3& p : pts) m = std::min(m, geom::Dist2(q, p));
        return m;
      };
      std::vector<Vec3> queries = RandomPoints(300, 23);
      if (grid) {
        for (Vec3& q : queries) q = q * 5.0;
      } else {
        for (const Vec3& q : queries) EXPECT_EQ(dt.NearVertex(q), dt.NearestVertex(q)) << q.x << " " << q.y << " " << q.z;
      }
      int k = 0;
      for (TetId t : dt.FiniteTets()) {
        if (k++ % 3 == 0) queries.push_back(dt.Circumcenter(t));
      }
      for (const Vec3& q : queries) {
        const VertexId v = dt.NearVertex(q, dt.FiniteTets()[k++ % dt.NumFiniteTets()]);
        ASSERT_TRUE(v.valid());
        const double m = min_d2(q);
        EXPECT_LE(geom::Dist2(q, dt.Point(v)), m + 1e-12 * (1 + m)) << q.x << " " << q.y << " " << q.z;
      }
    }
  }
}

}  // namespace
}  // namespace svrc::delaunay
