// Point-set tetrahedralization: canonical output, duplicates merged into the
// first occurrence, errors for degenerate point sets, independence of the
// input order, cancellation/progress, and an independent Delaunay check.
#include "core/delaunay/point_set.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "core/geometry/predicates.h"
#include "tests/delaunay/tet_check.h"

namespace svrc::delaunay {
namespace {

using Tet = std::array<uint32_t, 4>;

std::vector<Vec3> RandomPoints(int n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec3> pts(n);
  for (auto& p : pts) p = Vec3(u(rng), u(rng), u(rng));
  return pts;
}

void ExpectCanonical(const std::vector<Tet>& tets) {
  for (const Tet& t : tets) {
    EXPECT_LT(t[0], t[1]);
    EXPECT_LT(t[0], t[2]);
    EXPECT_LT(t[0], t[3]);
    EXPECT_LT(t[1], t[2]);
    EXPECT_LT(t[1], t[3]);
    EXPECT_EQ(CanonicalRotation(t), t);
  }
  EXPECT_TRUE(std::is_sorted(tets.begin(), tets.end()));
  EXPECT_TRUE(std::adjacent_find(tets.begin(), tets.end()) == tets.end());
}

TEST(CanonicalRotationTest, EvenPermutationSmallestFirst) {
  const Tet t = {7, 3, 9, 5};
  const Tet c = CanonicalRotation(t);
  EXPECT_EQ(c[0], 3u);
  EXPECT_EQ(c[1], 5u);
  // Same orientation: all 12 even permutations map to the same result, the
  // 12 odd ones to the other (mirror) result.
  std::array<int, 4> perm = {0, 1, 2, 3};
  std::set<Tet> even, odd;
  do {
    int inv = 0;
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) inv += perm[i] > perm[j];
    const Tet p = {t[perm[0]], t[perm[1]], t[perm[2]], t[perm[3]]};
    (inv % 2 == 0 ? even : odd).insert(CanonicalRotation(p));
  } while (std::next_permutation(perm.begin(), perm.end()));
  EXPECT_EQ(even.size(), 1u);
  EXPECT_EQ(odd.size(), 1u);
  EXPECT_EQ(*even.begin(), c);
  EXPECT_NE(*odd.begin(), c);
}

TEST(PointSetTest, RandomIsCanonicalAndDelaunay) {
  const auto pts = RandomPoints(5000, 1);
  auto r = TetrahedralizePointSet(pts);
  ASSERT_TRUE(r.ok()) << r.status();
  ExpectCanonical(r->tets);
  EXPECT_EQ(testing::CheckDelaunayTets(pts, r->tets), "");
  std::vector<bool> used(pts.size());
  for (const Tet& t : r->tets)
    for (uint32_t v : t) used[v] = true;
  EXPECT_EQ(std::count(used.begin(), used.end(), false), 0);
  EXPECT_EQ(r->num_duplicates, 0u);
}

TEST(PointSetTest, GridIsDelaunayAndCoversTheCube) {
  std::vector<Vec3> pts;
  for (int x = 0; x < 6; ++x)
    for (int y = 0; y < 6; ++y)
      for (int z = 0; z < 6; ++z) pts.emplace_back(x, y, z);
  auto r = TetrahedralizePointSet(pts);
  ASSERT_TRUE(r.ok()) << r.status();
  ExpectCanonical(r->tets);
  EXPECT_EQ(testing::CheckDelaunayTets(pts, r->tets), "");
  double vol6 = 0;
  for (const Tet& t : r->tets) {
    const Vec3 a = pts[t[0]];
    vol6 += geom::Dot(pts[t[1]] - a, geom::Cross(pts[t[2]] - a, pts[t[3]] - a));
  }
  EXPECT_EQ(vol6, 6.0 * 125);
  // Twice: same bytes.
  auto r2 = TetrahedralizePointSet(pts);
  ASSERT_TRUE(r2.ok());
  EXPECT_EQ(r->tets, r2->tets);
}

TEST(PointSetTest, DuplicatesMergeIntoFirstOccurrence) {
  auto pts = RandomPoints(300, 2);
  pts.push_back(pts[17]);   // 300 -> 17
  pts.push_back(pts[5]);    // 301 -> 5
  pts.push_back(pts[17]);   // 302 -> 17
  pts.insert(pts.begin(), pts[250]);  // new 0; old 250 is now 251 -> 0
  auto r = TetrahedralizePointSet(pts);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(r->num_duplicates, 4u);
  EXPECT_EQ(r->representative[251], 0u);
  EXPECT_EQ(r->representative[301], 18u);
  EXPECT_EQ(r->representative[302], 6u);
  EXPECT_EQ(r->representative[303], 18u);
  for (uint32_t i = 0; i < pts.size(); ++i) {
    if (i != 251 && i < 301) {
      EXPECT_EQ(r->representative[i], i);
    }
  }
  std::set<uint32_t> used;
  for (const Tet& t : r->tets) used.insert(t.begin(), t.end());
  EXPECT_EQ(used.size(), pts.size() - 4);
  for (uint32_t d : {251u, 301u, 302u, 303u}) EXPECT_EQ(used.count(d), 0u);
  EXPECT_EQ(testing::CheckDelaunayTets(pts, r->tets), "");
}

TEST(PointSetTest, DegenerateSetsAreInvalidArgument) {
  auto expect_invalid = [](const std::vector<Vec3>& pts, const std::string& what) {
    auto r = TetrahedralizePointSet(pts);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument) << r.status();
    EXPECT_NE(std::string(r.status().message()).find(what), std::string::npos) << r.status();
  };
  expect_invalid({}, "affinely independent");
  expect_invalid({Vec3(1, 2, 3), Vec3(1, 2, 3)}, "coincide");
  expect_invalid({Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(2, 2, 2), Vec3(3, 3, 3), Vec3(0.5, 0.5, 0.5)}, "collinear");
  expect_invalid({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0), Vec3(3, 7, 0)}, "coplanar");
  expect_invalid({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, NAN)}, "vertex 3");
  expect_invalid({Vec3(0, 0, 0), Vec3(INFINITY, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)}, "vertex 1");
  // Coplanar plus one point is fine.
  const std::vector<Vec3> pyramid = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0), Vec3(0, 0, 1)};
  auto r = TetrahedralizePointSet(pyramid);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->tets.size(), 2u);
}

TEST(PointSetTest, InputOrderDoesNotMatter) {
  const auto pts = RandomPoints(3000, 3);
  auto r = TetrahedralizePointSet(pts);
  ASSERT_TRUE(r.ok());
  // Reverse the input, tetrahedralize, map the ids back.
  std::vector<Vec3> rev(pts.rbegin(), pts.rend());
  auto q = TetrahedralizePointSet(rev);
  ASSERT_TRUE(q.ok());
  const uint32_t n = static_cast<uint32_t>(pts.size());
  std::vector<Tet> back;
  for (const Tet& t : q->tets) back.push_back(CanonicalRotation({n - 1 - t[0], n - 1 - t[1], n - 1 - t[2], n - 1 - t[3]}));
  std::sort(back.begin(), back.end());
  EXPECT_EQ(back, r->tets);
}

TEST(PointSetTest, ProgressAndCancel) {
  const auto pts = RandomPoints(10000, 4);
  PointSetOptions opt;
  opt.poll_interval = 1000;
  std::vector<uint64_t> seen;
  opt.progress = [&](uint64_t done, uint64_t total) {
    EXPECT_EQ(total, 10000u);
    seen.push_back(done);
  };
  ASSERT_TRUE(TetrahedralizePointSet(pts, opt).ok());
  ASSERT_FALSE(seen.empty());
  EXPECT_EQ(seen.back(), 10000u);
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  int polls = 0;
  opt.cancel = [&]() { return ++polls == 3 ? absl::CancelledError("stop") : absl::OkStatus(); };
  auto r = TetrahedralizePointSet(pts, opt);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), absl::StatusCode::kCancelled);
  EXPECT_EQ(polls, 3);
}

}  // namespace
}  // namespace svrc::delaunay
