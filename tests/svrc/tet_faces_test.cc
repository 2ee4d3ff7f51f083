// TetFaces (core/svrc/tet_faces.h): face adjacency by bucketing on the
// smallest vertex, against a brute-force map of sorted faces.
#include "core/svrc/tet_faces.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <map>
#include <random>
#include <vector>

#include "gtest/gtest.h"
#include "tests/svrc/output_test_util.h"

namespace svrc::refine {
namespace {

using Tet = std::array<uint32_t, 4>;

// Kuhn's 6 tets per cube of an n×n×n grid (testing::KuhnGrid), vertex ids
// shuffled so buckets mix faces from far-apart tets.
std::vector<Tet> GridTets(int n, uint32_t* num_vertices) {
  const testing::Grid grid = testing::KuhnGrid(n);
  std::vector<uint32_t> id(grid.positions.size());
  for (uint32_t i = 0; i < id.size(); ++i) id[i] = i;
  std::shuffle(id.begin(), id.end(), std::mt19937(7));
  std::vector<Tet> tets;
  tets.reserve(grid.tets.size());
  for (const Tet& t : grid.tets) tets.push_back({id[t[0]], id[t[1]], id[t[2]], id[t[3]]});
  *num_vertices = static_cast<uint32_t>(id.size());
  return tets;
}

std::array<uint32_t, 3> FaceOf(const Tet& t, int f) {
  std::array<uint32_t, 3> k{};
  int j = 0;
  for (int i = 0; i < 4; ++i) {
    if (i != f) k[j++] = t[i];
  }
  std::sort(k.begin(), k.end());
  return k;
}

TEST(TetFaces, MatchesBruteForceOnAGrid) {
  uint32_t nv = 0;
  const std::vector<Tet> tets = GridTets(5, &nv);
  std::map<std::array<uint32_t, 3>, std::vector<uint32_t>> slots;
  for (uint32_t t = 0; t < tets.size(); ++t) {
    for (int f = 0; f < 4; ++f) slots[FaceOf(tets[t], f)].push_back(4 * t + f);
  }
  const TetFaces faces(tets, nv);
  std::vector<uint32_t> opposite(4 * tets.size(), UINT32_MAX);
  uint32_t pairs = 0;
  TetFaces::Overused bad;
  ASSERT_TRUE(faces.Match(
      [&](uint32_t s, uint32_t t) {
        EXPECT_EQ(opposite[s], UINT32_MAX);
        EXPECT_EQ(opposite[t], UINT32_MAX);
        opposite[s] = t;
        opposite[t] = s;
        ++pairs;
      },
      &bad));
  uint32_t interior = 0;
  for (const auto& [k, s] : slots) {
    ASSERT_LE(s.size(), 2u);
    if (s.size() == 1) {
      EXPECT_EQ(opposite[s[0]], UINT32_MAX);
      continue;
    }
    ++interior;
    EXPECT_EQ(opposite[s[0]], s[1]);
  }
  EXPECT_EQ(pairs, interior);
  EXPECT_GT(interior, 0u);
  // Every face is in the bucket of its smallest vertex, once per slot.
  size_t listed = 0;
  for (uint32_t a = 0; a < nv; ++a) {
    for (const TetFace& f : faces.Bucket(a)) {
      EXPECT_EQ((std::array<uint32_t, 3>{a, f.b, f.c}), FaceOf(tets[f.slot / 4], static_cast<int>(f.slot % 4)));
      ++listed;
    }
  }
  EXPECT_EQ(listed, 4 * tets.size());
}

TEST(TetFaces, ReportsTheSmallestFaceInMoreThanTwoTets) {
  // Three tets on face (1, 2, 3), and two on face (0, 4, 5) only.
  const std::vector<Tet> tets = {{1, 2, 3, 6}, {1, 2, 3, 7}, {3, 2, 1, 8}, {0, 4, 5, 9}, {0, 5, 4, 10}};
  const TetFaces faces(tets, 11);
  TetFaces::Overused bad;
  ASSERT_FALSE(faces.Match([](uint32_t, uint32_t) {}, &bad));
  EXPECT_EQ(bad.a, 1u);
  EXPECT_EQ(bad.b, 2u);
  EXPECT_EQ(bad.c, 3u);
  EXPECT_EQ(bad.count, 3u);
  EXPECT_EQ(bad.slots[0] / 4, 0u);
  EXPECT_EQ(bad.slots[1] / 4, 1u);
  EXPECT_EQ(bad.slots[2] / 4, 2u);
}

}  // namespace
}  // namespace svrc::refine
