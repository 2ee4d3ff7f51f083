// Tests of Delaunay3's vertex queries against a reference: the allocation-free
// views (StarView, NeighborsView, StarAndNeighborsView), the vector forms and
// the per-vertex neighbour cache must return exactly what the original
// breadth-first star walk returned — same elements, same order — since SVRC's
// output depends on that order (farthest-corner ties, hints, BLG link order).
// Random, degenerate (grid, SoS) and huge-star (skew lines) inputs; the cache
// is checked after every insertion (invalidation) and across copies.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "core/delaunay/delaunay3.h"

namespace svrc::delaunay {
namespace {

std::vector<Vec3> RandomPoints(int n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vec3> pts(n);
  for (auto& p : pts) p = Vec3(u(rng), u(rng), u(rng));
  return pts;
}

// The star walk as Delaunay3 implemented it before the views existed, through
// the public accessors only: BFS from VertexTet(v) over the faces containing
// v, faces in index order; neighbours by first appearance in star order, then
// position in the tet; per neighbour the first star tet holding it.
struct Reference {
  std::vector<TetId> star;
  std::vector<VertexId> neighbors;
  std::vector<TetId> neighbor_tet;
};

Reference ReferenceWalk(const Delaunay3& dt, VertexId v) {
  Reference r;
  const TetId t0 = dt.VertexTet(v);
  if (!t0.valid()) return r;
  std::vector<char> seen(dt.TetCapacity(), 0);
  r.star.push_back(t0);
  seen[t0.value()] = 1;
  for (size_t k = 0; k < r.star.size(); ++k) {
    const TetId t = r.star[k];
    for (int f = 0; f < 4; ++f) {
      if (dt.TetVertex(t, f) == v) continue;
      const TetId u = dt.Neighbor(t, f);
      if (!seen[u.value()]) {
        seen[u.value()] = 1;
        r.star.push_back(u);
      }
    }
  }
  std::vector<char> nseen(dt.NumVertices(), 0);
  for (TetId t : r.star) {
    for (int i = 0; i < 4; ++i) {
      const VertexId w = dt.TetVertex(t, i);
      if (w == v || w == kInfiniteVertex || nseen[w.value()]) continue;
      nseen[w.value()] = 1;
      r.neighbors.push_back(w);
      r.neighbor_tet.push_back(t);
    }
  }
  return r;
}

template <typename T>
std::vector<T> ToVector(std::span<const T> s) {
  return std::vector<T>(s.begin(), s.end());
}

// Every query form for v equals the reference, element by element.
void ExpectQueriesMatch(const Delaunay3& dt, VertexId v) {
  const Reference ref = ReferenceWalk(dt, v);
  std::vector<TetId> star;
  std::vector<VertexId> nbrs;
  dt.Star(v, &star);
  EXPECT_EQ(star, ref.star) << "Star of " << v.value();
  EXPECT_EQ(ToVector(dt.StarView(v)), ref.star) << "StarView of " << v.value();
  dt.Neighbors(v, &nbrs);
  EXPECT_EQ(nbrs, ref.neighbors) << "Neighbors of " << v.value();
  EXPECT_EQ(ToVector(dt.NeighborsView(v)), ref.neighbors) << "NeighborsView of " << v.value();
  // Twice: the second answer may come from the cache.
  EXPECT_EQ(ToVector(dt.NeighborsView(v)), ref.neighbors) << "NeighborsView (again) of " << v.value();
  const Delaunay3::StarAndNeighbors sn = dt.StarAndNeighborsView(v);
  EXPECT_EQ(ToVector(sn.star), ref.star) << v.value();
  EXPECT_EQ(ToVector(sn.neighbors), ref.neighbors) << v.value();
  EXPECT_EQ(ToVector(sn.neighbor_tet), ref.neighbor_tet) << v.value();
  bool hull = false;
  for (TetId t : ref.star) hull |= dt.IsGhost(t);
  EXPECT_EQ(dt.IsHullVertex(v), hull);
}

void ExpectAllMatch(const Delaunay3& dt) {
  for (uint32_t v = 0; v < dt.NumVertices(); ++v) ExpectQueriesMatch(dt, VertexId(v));
}

TEST(Delaunay3QueriesTest, ViewsMatchReferenceOnRandomPoints) {
  const auto pts = RandomPoints(2000, 21);
  for (bool cache : {false, true}) {
    Delaunay3 dt;
    dt.set_cache_neighbors(cache);
    for (uint32_t i = 0; i < pts.size(); ++i) dt.Insert(pts[i], i);
    ExpectAllMatch(dt);
    // Again, now with every neighbour list cached.
    ExpectAllMatch(dt);
  }
}

// The cache must follow every insertion: vertices of new tets are
// invalidated, all others keep a correct list. Query a rotating sample after
// each insertion (so stale entries would be hit) and compare with a
// triangulation without the cache built by the same calls.
TEST(Delaunay3QueriesTest, CacheFollowsInsertions) {
  const auto pts = RandomPoints(1500, 22);
  Delaunay3 cached, plain;
  cached.set_cache_neighbors(true);
  std::mt19937 rng(5);
  for (uint32_t i = 0; i < pts.size(); ++i) {
    const auto rc = cached.Insert(pts[i], i);
    const auto rp = plain.Insert(pts[i], i);
    ASSERT_EQ(rc.vertex, rp.vertex);
    if (!cached.Is3d()) continue;
    // The new vertex and its cavity, then random others (cached earlier).
    ExpectQueriesMatch(cached, rc.vertex);
    std::uniform_int_distribution<uint32_t> pick(0, cached.NumVertices() - 1);
    for (int k = 0; k < 12; ++k) {
      const VertexId v(pick(rng));
      ExpectQueriesMatch(cached, v);
      EXPECT_EQ(ToVector(cached.NeighborsView(v)), ToVector(plain.NeighborsView(v)));
    }
    const Vec3 q = RandomPoints(1, 1000 + i)[0];
    EXPECT_EQ(cached.NearestVertex(q), plain.NearestVertex(q));
    if (i % 97 == 0) {
      EXPECT_EQ(cached.InRadius(VertexId(i / 2)), plain.InRadius(VertexId(i / 2)));
    }
  }
  ExpectAllMatch(cached);
  // Inserting with hints (the refiner's way) gives the same answers too.
  const auto more = RandomPoints(300, 23);
  for (uint32_t i = 0; i < more.size(); ++i) {
    const VertexId near = cached.NearestVertex(more[i]);
    const TetId hint = cached.VertexTet(near);
    cached.Insert(more[i], 5000 + i, hint);
    // Copy: the view dies at the next query.
    for (VertexId w : ToVector(cached.NeighborsView(near))) ExpectQueriesMatch(cached, w);
  }
  ExpectAllMatch(cached);
  EXPECT_TRUE(cached.Validate(true).ok());
  // The lists were packed in place many times along the way (a vertex
  // stored, invalidated and stored again keeps its latest list).
  EXPECT_GT(cached.neighbor_cache_packs(), 5u);
}

// The neighbour cache bounded (set_neighbor_cache_limit): past the limit
// every list is dropped and the cache starts again. Answers must not change,
// the flushes must happen, and the pool must stay near the limit.
TEST(Delaunay3QueriesTest, BoundedCacheFlushesAndAnswersTheSame) {
  const auto pts = RandomPoints(3000, 26);
  Delaunay3 cached, plain;
  cached.set_cache_neighbors(true);
  cached.set_neighbor_cache_limit(2000);
  std::mt19937 rng(6);
  for (uint32_t i = 0; i < pts.size(); ++i) {
    const auto rc = cached.Insert(pts[i], i);
    plain.Insert(pts[i], i);
    if (!cached.Is3d()) continue;
    std::uniform_int_distribution<uint32_t> pick(0, cached.NumVertices() - 1);
    for (int k = 0; k < 8; ++k) {
      const VertexId v = k == 0 ? rc.vertex : VertexId(pick(rng));
      EXPECT_EQ(ToVector(cached.NeighborsView(v)), ToVector(plain.NeighborsView(v))) << "vertex " << v.value();
    }
    if (testing::Test::HasFailure()) return;
  }
  ExpectAllMatch(cached);
  EXPECT_GT(cached.neighbor_cache_flushes(), 5u);
}

// StarVersion changes exactly for the vertices of new tets, and a vertex
// whose version did not change answers every query as before.
TEST(Delaunay3QueriesTest, StarVersionTracksStarChanges) {
  const auto pts = RandomPoints(300, 25);
  Delaunay3 dt;
  for (uint32_t i = 0; i < 8; ++i) dt.Insert(pts[i], i);
  ASSERT_TRUE(dt.Is3d());
  std::vector<Reference> before;
  std::vector<uint32_t> version;
  for (uint32_t i = 8; i < pts.size(); ++i) {
    before.clear();
    version.clear();
    for (uint32_t v = 0; v < dt.NumVertices(); ++v) {
      before.push_back(ReferenceWalk(dt, VertexId(v)));
      version.push_back(dt.StarVersion(VertexId(v)));
    }
    const auto r = dt.Insert(pts[i], i);
    ASSERT_EQ(r.outcome, Delaunay3::InsertOutcome::kInserted);
    std::vector<char> in_new(dt.NumVertices(), 0);
    for (TetId t : r.created) {
      for (int k = 0; k < 4; ++k) {
        if (dt.TetVertex(t, k) != kInfiniteVertex) in_new[dt.TetVertex(t, k).value()] = 1;
      }
    }
    for (uint32_t v = 0; v + 1 < dt.NumVertices(); ++v) {
      EXPECT_EQ(dt.StarVersion(VertexId(v)) != version[v], in_new[v] != 0) << v;
      if (in_new[v]) continue;
      const Reference now = ReferenceWalk(dt, VertexId(v));
      EXPECT_EQ(now.star, before[v].star) << v;
      EXPECT_EQ(now.neighbors, before[v].neighbors) << v;
    }
  }
}

// A 7^3 integer grid: every cube's corners are cospherical, SoS decides.
TEST(Delaunay3QueriesTest, DegenerateGrid) {
  std::vector<Vec3> pts;
  for (int x = 0; x < 7; ++x)
    for (int y = 0; y < 7; ++y)
      for (int z = 0; z < 7; ++z) pts.emplace_back(x, y, z);
  std::mt19937 rng(3);
  std::shuffle(pts.begin(), pts.end(), rng);
  Delaunay3 dt;
  dt.set_cache_neighbors(true);
  for (uint32_t i = 0; i < pts.size(); ++i) {
    dt.Insert(pts[i], i);
    if (dt.Is3d() && i % 10 == 0) ExpectAllMatch(dt);
  }
  ExpectAllMatch(dt);
}

// Two skew lines: the raw Delaunay has Θ(n²) tets and stars of Θ(n) tets,
// far beyond the scratch buffers' first size (the growth path).
TEST(Delaunay3QueriesTest, HugeStarsOnSkewLines) {
  const int n = 150;
  std::vector<Vec3> pts;
  for (int i = 0; i < n; ++i) pts.emplace_back(0, double(i) / n, 0);
  for (int i = 0; i < n; ++i) pts.emplace_back(double(i) / n, 0, 1);
  Delaunay3 dt;
  dt.set_cache_neighbors(true);
  for (uint32_t i = 0; i < pts.size(); ++i) dt.Insert(pts[i], i);
  size_t largest = 0;
  for (uint32_t v = 0; v < dt.NumVertices(); ++v) largest = std::max(largest, dt.StarView(VertexId(v)).size());
  EXPECT_GT(largest, 200u);
  ExpectAllMatch(dt);
  // After huge stars, small queries still work (scratch reuse).
  const Delaunay3::StarAndNeighbors sn = dt.StarAndNeighborsView(VertexId(0));
  EXPECT_EQ(ToVector(sn.star), ReferenceWalk(dt, VertexId(0)).star);
}

// A copy owns its cache: inserting into the copy leaves the original's
// answers intact and the copy's correct.
TEST(Delaunay3QueriesTest, CopiesKeepIndependentCaches) {
  const auto pts = RandomPoints(600, 24);
  Delaunay3 a;
  a.set_cache_neighbors(true);
  for (uint32_t i = 0; i < 500; ++i) a.Insert(pts[i], i);
  ExpectAllMatch(a);  // fills a's cache
  Delaunay3 b = a;
  for (uint32_t i = 500; i < pts.size(); ++i) b.Insert(pts[i], i);
  ExpectAllMatch(a);
  ExpectAllMatch(b);
  // Turning the cache off and on again drops it.
  b.set_cache_neighbors(false);
  ExpectAllMatch(b);
  b.set_cache_neighbors(true);
  ExpectAllMatch(b);
}

// Queries on a triangulation that is not yet 3D answer empty, and the cache
// does not remember those answers once tets exist.
// Degrees() (Euler's formula on each vertex's link, one pass over the tets)
// against the star walk's neighbour count, vertex by vertex: random points
// (hull and interior), a grid (degenerate, cospherical: SoS decides), two
// skew lines (stars of hundreds of tets), and while only a few points are in.
void ExpectDegreesOfWalks(const Delaunay3& dt) {
  const std::vector<uint32_t> deg = dt.Degrees();
  ASSERT_EQ(deg.size(), dt.NumVertices());
  uint32_t hull = 0;
  for (uint32_t v = 0; v < dt.NumVertices(); ++v) {
    const uint32_t walked = dt.VertexTet(VertexId(v)).valid() ? dt.NeighborsView(VertexId(v)).size() : 0;
    ASSERT_EQ(deg[v], walked) << "vertex " << v;
    hull += dt.VertexTet(VertexId(v)).valid() && dt.IsHullVertex(VertexId(v));
  }
  EXPECT_GT(hull, 0u);
}

TEST(Delaunay3QueriesTest, DegreesAreTheWalkedNeighbourCounts) {
  {
    Delaunay3 dt;
    const std::vector<Vec3> pts = RandomPoints(3000, 25);
    for (uint32_t i = 0; i < pts.size(); ++i) {
      dt.Insert(pts[i], i);
      if (i == 4 || i == 5 || i == 30) ExpectDegreesOfWalks(dt);
    }
    ExpectDegreesOfWalks(dt);
  }
  {
    Delaunay3 dt;
    uint32_t id = 0;
    for (int x = 0; x < 7; ++x) {
      for (int y = 0; y < 7; ++y) {
        for (int z = 0; z < 7; ++z) dt.Insert(Vec3(x, y, z), id++);
      }
    }
    ExpectDegreesOfWalks(dt);
  }
  {
    Delaunay3 dt;
    uint32_t id = 0;
    for (int i = 0; i < 200; ++i) {
      dt.Insert(Vec3(i / 200.0, 0, 0), id++);
      dt.Insert(Vec3(0.5, i / 200.0, 1), id++);
    }
    uint32_t most = 0;
    for (uint32_t d : dt.Degrees()) most = std::max(most, d);
    EXPECT_GE(most, 200u);
    ExpectDegreesOfWalks(dt);
  }
  EXPECT_TRUE(Delaunay3().Degrees().empty());
}

TEST(Delaunay3QueriesTest, PendingVertices) {
  Delaunay3 dt;
  dt.set_cache_neighbors(true);
  dt.Insert(Vec3(0, 0, 0), 0);
  dt.Insert(Vec3(1, 0, 0), 1);
  dt.Insert(Vec3(0, 1, 0), 2);
  EXPECT_TRUE(dt.StarView(VertexId(0)).empty());
  EXPECT_TRUE(dt.NeighborsView(VertexId(0)).empty());
  EXPECT_TRUE(dt.StarAndNeighborsView(VertexId(1)).neighbors.empty());
  dt.Insert(Vec3(0, 0, 1), 3);
  ASSERT_TRUE(dt.Is3d());
  for (uint32_t v = 0; v < 4; ++v) EXPECT_EQ(dt.NeighborsView(VertexId(v)).size(), 3u);
  ExpectAllMatch(dt);
}

}  // namespace
}  // namespace svrc::delaunay
