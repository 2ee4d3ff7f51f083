#include "core/mesh/canonical.h"

#include <algorithm>
#include <random>
#include <set>

#include "gtest/gtest.h"

namespace svrc::mesh {
namespace {

// Sign of det[b-a, c-a, d-a]; exact for the small integer coordinates used here.
int OrientSign(const std::vector<Vec3>& p, const std::array<uint32_t, 4>& t) {
  const Vec3 a = p[t[0]], b = p[t[1]] - a, c = p[t[2]] - a, d = p[t[3]] - a;
  const double det = geom::Dot(b, geom::Cross(c, d));
  return (det > 0) - (det < 0);
}

int Parity(std::array<uint32_t, 4> t) {
  int swaps = 0;
  for (int i = 0; i < 4; ++i) {
    for (int j = i + 1; j < 4; ++j) swaps += t[i] > t[j];
  }
  return swaps % 2;
}

TEST(CanonicalTet, EvenPermutationsAgreeOddOnesDiffer) {
  std::array<uint32_t, 4> t = {3, 7, 1, 9};
  std::sort(t.begin(), t.end());
  const auto even_ref = CanonicalTet({1, 3, 7, 9});
  const auto odd_ref = CanonicalTet({1, 3, 9, 7});
  EXPECT_EQ(even_ref, (std::array<uint32_t, 4>{1, 3, 7, 9}));
  EXPECT_EQ(odd_ref, (std::array<uint32_t, 4>{1, 3, 9, 7}));
  int seen = 0;
  do {
    const auto c = CanonicalTet(t);
    EXPECT_EQ(c[0], 1u);
    EXPECT_EQ(Parity(c), Parity(t)) << "not an even permutation";
    EXPECT_EQ(c, Parity(t) == 0 ? even_ref : odd_ref);
    ++seen;
  } while (std::next_permutation(t.begin(), t.end()));
  EXPECT_EQ(seen, 24);
}

TEST(CanonicalTriangle, CyclicRotation) {
  EXPECT_EQ(CanonicalTriangle({5, 2, 8}), (std::array<uint32_t, 3>{2, 8, 5}));
  EXPECT_EQ(CanonicalTriangle({8, 5, 2}), (std::array<uint32_t, 3>{2, 8, 5}));
  EXPECT_EQ(CanonicalTriangle({2, 8, 5}), (std::array<uint32_t, 3>{2, 8, 5}));
  EXPECT_EQ(CanonicalTriangle({2, 5, 8}), (std::array<uint32_t, 3>{2, 5, 8}));
}

TetMesh RandomMesh(uint32_t seed, size_t num_points, size_t num_tets) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> coord(-20, 20);
  TetMesh m;
  for (size_t i = 0; i < num_points; ++i) {
    m.positions.push_back(Vec3(coord(rng), coord(rng), coord(rng)));
  }
  m.num_input_vertices = static_cast<uint32_t>(num_points / 2);
  std::uniform_int_distribution<uint32_t> vid(0, static_cast<uint32_t>(num_points - 1));
  while (m.tets.size() < num_tets) {
    std::array<uint32_t, 4> t = {vid(rng), vid(rng), vid(rng), vid(rng)};
    const int s = OrientSign(m.positions, t);
    if (s == 0) continue;
    if (s < 0) std::swap(t[2], t[3]);
    m.tets.push_back(t);
    m.tet_region.push_back(static_cast<int32_t>(rng() % 3));
    m.triangles.push_back({t[0], t[1], t[2]});
    m.triangle_marker.push_back(static_cast<int32_t>(rng() % 5) - 2);
  }
  m.regions.resize(3);
  return m;
}

TEST(Canonicalize, PreservesOrientationAndContent) {
  TetMesh m = RandomMesh(1, 60, 500);
  std::multiset<std::pair<std::array<uint32_t, 4>, int32_t>> before;
  for (size_t i = 0; i < m.tets.size(); ++i) {
    before.insert({CanonicalTet(m.tets[i]), m.tet_region[i]});
  }
  std::multiset<std::pair<std::array<uint32_t, 3>, int32_t>> tri_before;
  for (size_t i = 0; i < m.triangles.size(); ++i) {
    tri_before.insert({CanonicalTriangle(m.triangles[i]), m.triangle_marker[i]});
  }
  const auto positions = m.positions;
  Canonicalize(&m);
  EXPECT_EQ(m.positions, positions);
  ASSERT_EQ(m.tets.size(), 500u);
  ASSERT_EQ(m.tet_region.size(), 500u);
  std::multiset<std::pair<std::array<uint32_t, 4>, int32_t>> after;
  for (size_t i = 0; i < m.tets.size(); ++i) {
    EXPECT_GT(OrientSign(m.positions, m.tets[i]), 0) << "tet " << i;
    EXPECT_EQ(*std::min_element(m.tets[i].begin(), m.tets[i].end()), m.tets[i][0]);
    if (i > 0) {
      EXPECT_LE(m.tets[i - 1], m.tets[i]);
    }
    after.insert({m.tets[i], m.tet_region[i]});
  }
  EXPECT_EQ(before, after);
  std::multiset<std::pair<std::array<uint32_t, 3>, int32_t>> tri_after;
  for (size_t i = 0; i < m.triangles.size(); ++i) {
    if (i > 0) {
      EXPECT_LE(m.triangles[i - 1], m.triangles[i]);
    }
    tri_after.insert({m.triangles[i], m.triangle_marker[i]});
  }
  EXPECT_EQ(tri_before, tri_after);
  EXPECT_TRUE(IsCanonical(m));
}

TEST(Canonicalize, IdempotentAndDeterministic) {
  TetMesh a = RandomMesh(7, 40, 300);
  TetMesh b = a;
  // The same mesh with tets listed in another order and rotated by other even
  // permutations canonicalizes to the same arrays.
  std::mt19937 rng(99);
  std::vector<size_t> perm(b.tets.size());
  for (size_t i = 0; i < perm.size(); ++i) perm[i] = i;
  std::shuffle(perm.begin(), perm.end(), rng);
  TetMesh c = b;
  for (size_t i = 0; i < perm.size(); ++i) {
    auto t = b.tets[perm[i]];
    if (rng() % 2) t = {t[1], t[0], t[3], t[2]};
    if (rng() % 2) t = {t[0], t[2], t[3], t[1]};
    c.tets[i] = t;
    c.tet_region[i] = b.tet_region[perm[i]];
    auto f = b.triangles[perm[i]];
    if (rng() % 2) f = {f[1], f[2], f[0]};
    c.triangles[i] = f;
    c.triangle_marker[i] = b.triangle_marker[perm[i]];
  }
  EXPECT_FALSE(IsCanonical(a));
  Canonicalize(&a);
  Canonicalize(&c);
  EXPECT_EQ(a.tets, c.tets);
  EXPECT_EQ(a.tet_region, c.tet_region);
  EXPECT_EQ(a.triangles, c.triangles);
  EXPECT_EQ(a.triangle_marker, c.triangle_marker);
  TetMesh again = a;
  Canonicalize(&again);
  EXPECT_EQ(again.tets, a.tets);
  EXPECT_EQ(again.tet_region, a.tet_region);
  EXPECT_EQ(again.triangles, a.triangles);
  EXPECT_EQ(again.triangle_marker, a.triangle_marker);
}

TEST(Canonicalize, EmptyTagArraysAreAllowed) {
  TetMesh m = RandomMesh(3, 20, 50);
  m.tet_region.clear();
  m.triangle_marker.clear();
  Canonicalize(&m);
  EXPECT_TRUE(m.tet_region.empty());
  EXPECT_TRUE(IsCanonical(m));
}

// The sort (records with ids packed two to a word, session 15) gives the
// order of the plain comparison: items lexicographically by unsigned id,
// then tag (signed), then the original position. Ids above 2^31 (the sign
// bit of a packed word), repeated items with different and equal tags,
// negative tags, triangles and tets.
// Both sort paths: ids up to 2^31 (one sort of all records) and dense ids
// below the item count (bucketed by the first id, then sorted per bucket),
// each with repeated items and tags.
TEST(Canonicalize, OrderIsItemThenTagThenPosition) {
  for (const bool sparse : {true, false}) {
    SCOPED_TRACE(sparse ? "sparse ids" : "dense ids");
    std::mt19937 rng(15);
    auto id = [&] {
      if (!sparse) return static_cast<uint32_t>(rng() % 40);
      const uint32_t small = rng() % 6;
      return rng() % 3 == 0 ? 0x80000000u + small : small;
    };
    TetMesh m;
    for (int i = 0; i < 3000; ++i) {
      m.tets.push_back(CanonicalTet({id(), id(), id(), id()}));
      m.tet_region.push_back(static_cast<int32_t>(rng() % 5) - 2);
      m.triangles.push_back(CanonicalTriangle({id(), id(), id()}));
      m.triangle_marker.push_back(static_cast<int32_t>(rng() % 5) - 2);
    }
    auto reference = [](auto items, std::vector<int32_t> tags) {
      std::vector<size_t> perm(items.size());
      for (size_t i = 0; i < perm.size(); ++i) perm[i] = i;
      std::stable_sort(perm.begin(), perm.end(), [&](size_t a, size_t b) {
        if (items[a] != items[b]) return items[a] < items[b];
        return tags[a] < tags[b];
      });
      decltype(items) out_items;
      std::vector<int32_t> out_tags;
      for (size_t k : perm) {
        out_items.push_back(items[k]);
        out_tags.push_back(tags[k]);
      }
      return std::make_pair(out_items, out_tags);
    };
    const auto tets = reference(m.tets, m.tet_region);
    const auto tris = reference(m.triangles, m.triangle_marker);
    Canonicalize(&m);
    EXPECT_EQ(m.tets, tets.first);
    EXPECT_EQ(m.tet_region, tets.second);
    EXPECT_EQ(m.triangles, tris.first);
    EXPECT_EQ(m.triangle_marker, tris.second);
  }
}

TEST(SpatialOrder, IsAPermutationAndDeterministic) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1e3, 1e3);
  std::vector<Vec3> pts;
  for (int i = 0; i < 2000; ++i) pts.push_back(Vec3(u(rng), u(rng), u(rng)));
  pts.push_back(pts[10]);  // a duplicate: ties by index
  const auto order = SpatialOrder(pts);
  ASSERT_EQ(order.size(), pts.size());
  std::vector<uint32_t> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  for (uint32_t i = 0; i < sorted.size(); ++i) ASSERT_EQ(sorted[i], i);
  EXPECT_EQ(order, SpatialOrder(pts));
  const auto p10 = std::find(order.begin(), order.end(), 10u);
  ASSERT_NE(p10 + 1, order.end());
  EXPECT_EQ(*(p10 + 1), 2000u);
}

TEST(SpatialOrder, FollowsACurveOnAGrid) {
  // On a 4x4x4 grid, consecutive points of a Hilbert order are grid neighbours.
  std::vector<Vec3> pts;
  for (int z = 0; z < 4; ++z) {
    for (int y = 0; y < 4; ++y) {
      for (int x = 0; x < 4; ++x) pts.push_back(Vec3(x, y, z));
    }
  }
  // Stretch so that the grid spacing is a power-of-two fraction of the box.
  pts.push_back(Vec3(8 - 1e-9, 8 - 1e-9, 8 - 1e-9));
  auto order = SpatialOrder(pts);
  order.erase(std::find(order.begin(), order.end(), 64u));
  for (size_t i = 1; i < order.size(); ++i) {
    EXPECT_DOUBLE_EQ(geom::Dist(pts[order[i - 1]], pts[order[i]]), 1.0)
        << pts[order[i - 1]].x << "," << pts[order[i - 1]].y << "," << pts[order[i - 1]].z << " -> "
        << pts[order[i]].x << "," << pts[order[i]].y << "," << pts[order[i]].z;
  }
}

TEST(SpatialOrder, HandlesDegenerateInput) {
  EXPECT_TRUE(SpatialOrder({}).empty());
  std::vector<Vec3> same(5, Vec3(1, 2, 3));
  EXPECT_EQ(SpatialOrder(same), (std::vector<uint32_t>{0, 1, 2, 3, 4}));
  std::vector<Vec3> with_nan = {Vec3(1, 1, 1), Vec3(NAN, 0, 0), Vec3(0, 0, 0)};
  EXPECT_EQ(SpatialOrder(with_nan).size(), 3u);
}

TEST(PermuteVertices, RewritesIds) {
  TetMesh m = RandomMesh(11, 30, 40);
  TetMesh p = m;
  std::vector<uint32_t> new_to_old = SpatialOrder(m.positions);
  PermuteVertices(&p, new_to_old);
  for (size_t i = 0; i < m.tets.size(); ++i) {
    for (int k = 0; k < 4; ++k) EXPECT_EQ(p.positions[p.tets[i][k]], m.positions[m.tets[i][k]]);
    EXPECT_GT(OrientSign(p.positions, p.tets[i]), 0);
  }
  for (size_t i = 0; i < m.triangles.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(p.positions[p.triangles[i][k]], m.positions[m.triangles[i][k]]);
    }
  }
}

}  // namespace
}  // namespace svrc::mesh
