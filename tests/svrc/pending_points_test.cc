// PendingPoints (docs/svrc-design.md §8 item 41) against a brute-force scan:
// every point within r of c is reported, through inserts, erases, splits down
// to the depth cap, points on octant boundaries, clusters 10^-12 wide and
// points outside the root cube.
#include "core/svrc/pending_points.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <vector>

#include "gtest/gtest.h"

namespace svrc::refine {
namespace {

using geom::Vec3;

TEST(PendingPointsTest, ReportsEveryPointWithinTheRadius) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  PendingPoints index(Vec3{0, 0, 0}, 1.0);
  std::map<uint32_t, Vec3> live;
  uint32_t next = 0;
  auto random_point = [&]() -> Vec3 {
    switch (rng() % 5) {
      case 0:  // a cluster 1e-12 wide: splits down to the depth cap
        return Vec3{0.3 + 1e-12 * u(rng), -0.2 + 1e-12 * u(rng), 0.1 + 1e-12 * u(rng)};
      case 1:  // on the octant planes of the first levels
        return Vec3{0.0, std::ldexp(std::round(u(rng) * 8), -3), 0.5};
      case 2:  // outside the root cube
        return Vec3{1.5 * u(rng) + (u(rng) > 0 ? 1.2 : -1.2), u(rng), u(rng)};
      default:
        return Vec3{u(rng), u(rng), u(rng)};
    }
  };
  uint64_t reported = 0;
  for (int step = 0; step < 20000; ++step) {
    const uint64_t op = rng() % 10;
    if (op < 5 || live.empty()) {
      const Vec3 p = random_point();
      index.Insert(next, p);
      live[next++] = p;
    } else if (op < 7) {
      auto it = live.begin();
      std::advance(it, static_cast<long>(rng() % live.size()));
      ASSERT_TRUE(index.Erase(it->first, it->second));
      ASSERT_FALSE(index.Erase(it->first, it->second));
      live.erase(it);
    } else {
      const Vec3 c = random_point();
      const double r = std::pow(10.0, -13.0 * std::abs(u(rng)));  // 1e-13 .. 1
      std::vector<uint32_t> got;
      index.Near(c, r, &got);
      std::sort(got.begin(), got.end());
      ASSERT_TRUE(std::adjacent_find(got.begin(), got.end()) == got.end());
      for (const auto& [id, p] : live) {
        if (geom::Dist2(p, c) <= r * r) {
          ASSERT_TRUE(std::binary_search(got.begin(), got.end(), id)) << "missed point " << id << " at distance "
                                                                      << std::sqrt(geom::Dist2(p, c)) << " of r " << r;
          ++reported;
        }
      }
      for (uint32_t id : got) {
        ASSERT_TRUE(live.count(id)) << "erased point " << id << " reported";
        EXPECT_LE(geom::Dist2(live[id], c), r * r * (1 + 1e-8));
      }
    }
    ASSERT_EQ(index.size(), live.size());
  }
  EXPECT_GT(reported, 1000u);  // the queries found points, clusters included
}

TEST(PendingPointsTest, CoincidentPointsPastTheDepthCap) {
  PendingPoints index(Vec3{0.5, 0.5, 0.5}, 0.5);
  for (uint32_t i = 0; i < 100; ++i) index.Insert(i, Vec3{0.25, 0.25, 0.25});
  std::vector<uint32_t> got;
  index.Near(Vec3{0.25, 0.25, 0.25}, 0.0, &got);
  EXPECT_EQ(got.size(), 100u);
  for (uint32_t i = 0; i < 100; i += 2) ASSERT_TRUE(index.Erase(i, Vec3{0.25, 0.25, 0.25}));
  got.clear();
  index.Near(Vec3{0.25, 0.25, 0.2500001}, 1e-6, &got);
  EXPECT_EQ(got.size(), 50u);
  for (uint32_t id : got) EXPECT_EQ(id % 2, 1u);
}

}  // namespace
}  // namespace svrc::refine
