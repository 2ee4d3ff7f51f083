// Delaunay1: Validate after every insertion, exact change reports, order
// independence, degenerate spacings, queries.
#include "core/delaunay/delaunay1.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/geometry/predicates.h"
#include "core/util/sha256.h"

namespace svrc::delaunay {
namespace {

using geom::Vec3;
using VertexId = Delaunay1::VertexId;
using PieceId = Delaunay1::PieceId;

std::set<std::pair<uint32_t, uint32_t>> LiveSet(const Delaunay1& d) {
  std::set<std::pair<uint32_t, uint32_t>> s;
  for (PieceId p : d.Pieces()) s.insert({p.value(), d.Generation(p)});
  return s;
}

std::vector<uint32_t> OrderedIds(const Delaunay1& d) {
  std::vector<uint32_t> ids;
  for (VertexId v : d.Vertices()) ids.push_back(d.GlobalId(v));
  return ids;
}

void InsertAllChecked(Delaunay1& d, const Vec3& a, const Vec3& b, const std::vector<double>& ts,
                      uint32_t first_id) {
  for (size_t i = 0; i < ts.size(); ++i) {
    const Vec3 p = a + ts[i] * (b - a);
    const auto before = LiveSet(d);
    const auto r = d.Insert(p, first_id + static_cast<uint32_t>(i));
    ASSERT_EQ(r.outcome, Delaunay1::InsertOutcome::kInserted) << i << " t=" << ts[i];
    const auto after = LiveSet(d);
    std::set<std::pair<uint32_t, uint32_t>> gone, born;
    std::set_difference(before.begin(), before.end(), after.begin(), after.end(),
                        std::inserter(gone, gone.end()));
    std::set_difference(after.begin(), after.end(), before.begin(), before.end(),
                        std::inserter(born, born.end()));
    ASSERT_EQ(gone.size(), 1u);
    ASSERT_EQ(born.size(), 2u);
    ASSERT_EQ(gone.begin()->first, r.destroyed.value());
    std::set<uint32_t> born_slots, created{r.created[0].value(), r.created[1].value()};
    for (auto& [s, g] : born) born_slots.insert(s);
    ASSERT_EQ(born_slots, created);
    ASSERT_EQ(d.PieceStart(r.created[0]), r.cavity_vertices[0]);
    ASSERT_EQ(d.PieceEnd(r.created[0]), r.vertex);
    ASSERT_EQ(d.PieceEnd(r.created[1]), r.cavity_vertices[1]);
    const absl::Status st = d.Validate();
    ASSERT_TRUE(st.ok()) << i << ": " << st;
  }
}

TEST(Delaunay1Test, RandomInsertionsValidAndOrderIndependent) {
  const Vec3 a{1e6, -1e6, 3}, b{1e6 + 1e-3, -1e6 + 2e-3, 3 - 1e-3};  // far from the origin, short
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(0.001, 0.999);
  std::vector<double> ts;
  for (int i = 0; i < 300; ++i) ts.push_back(u(rng));
  Delaunay1 d1(a, b, 100000, 100001);
  InsertAllChecked(d1, a, b, ts, 0);
  // Same points, reversed order: same chain.
  std::vector<double> rev(ts.rbegin(), ts.rend());
  Delaunay1 d2(a, b, 100000, 100001);
  for (size_t i = 0; i < rev.size(); ++i) {
    d2.Insert(a + rev[i] * (b - a), static_cast<uint32_t>(rev.size() - 1 - i));
  }
  ASSERT_TRUE(d2.Validate().ok());
  EXPECT_EQ(OrderedIds(d1), OrderedIds(d2));
  EXPECT_EQ(d1.NumPieces(), 301u);
}

TEST(Delaunay1Test, DegenerateSpacings) {
  const Vec3 a{0, 0, 0}, b{1, 1, 1};
  Delaunay1 d(a, b, 0, 1);
  std::vector<double> ts;
  for (int k = 1; k < 64; ++k) ts.push_back(k / 64.0);  // uniform, exact
  InsertAllChecked(d, a, b, ts, 10);
  // Pairs of points one ulp apart along x (distinct positions).
  Delaunay1 e({0, 0, 0}, {1, 0, 0}, 0, 1);
  double x = 0.5;
  for (int i = 0; i < 20; ++i) {
    ASSERT_EQ(e.Insert({x, 0, 0}, 100 + i).outcome, Delaunay1::InsertOutcome::kInserted);
    x = std::nextafter(x, 1.0);
    ASSERT_TRUE(e.Validate().ok());
  }
  EXPECT_EQ(e.Insert({0.5, 0, 0}, 999).outcome, Delaunay1::InsertOutcome::kDuplicate);
  EXPECT_EQ(e.Insert({1, 0, 0}, 999).outcome, Delaunay1::InsertOutcome::kDuplicate);
  EXPECT_EQ(e.Insert({1.5, 0, 0}, 999).outcome, Delaunay1::InsertOutcome::kOutside);
  EXPECT_EQ(e.Insert({-1e-300, 0, 0}, 999).outcome, Delaunay1::InsertOutcome::kOutside);
  EXPECT_EQ(e.NumVertices(), 22u);
}

TEST(Delaunay1Test, QueriesAndDeterminism) {
  auto run = [] {
    const Vec3 a{0, 0, 0}, b{0, 0, 8};
    Delaunay1 d(a, b, 0, 1);
    std::mt19937_64 rng(4);
    std::uniform_int_distribution<int> g(1, 799);
    for (int i = 0; i < 200; ++i) d.Insert({0, 0, g(rng) / 100.0}, 2 + i);
    EXPECT_TRUE(d.Validate().ok());
    std::string bytes;
    for (PieceId p : d.Pieces()) {
      bytes += std::to_string(p.value()) + "/" + std::to_string(d.Generation(p)) + ":" +
               std::to_string(d.PieceStart(p).value()) + "-" + std::to_string(d.PieceEnd(p).value()) + ";";
    }
    // Queries against brute force.
    for (VertexId v : d.Vertices()) {
      double lo = HUGE_VAL, hi = -1;
      for (VertexId w : {d.Prev(v), d.Next(v)}) {
        if (!w.valid()) continue;
        const double h = 0.5 * geom::Dist(d.Point(v), d.Point(w));
        lo = std::min(lo, h);
        hi = std::max(hi, h);
      }
      Vec3 far;
      EXPECT_DOUBLE_EQ(d.InRadius(v), lo);
      EXPECT_DOUBLE_EQ(d.OutRadius(v, &far), hi);
      EXPECT_NEAR(geom::Dist(far, d.Point(v)), hi, 1e-15);
    }
    for (int q = 0; q < 200; ++q) {
      const Vec3 p{0.3, -0.1, -1 + q * 0.05};
      uint32_t best = 0;
      for (uint32_t v = 1; v < d.NumVertices(); ++v) {
        const int c = geom::CompareDistance(p, d.Point(VertexId(best)), d.Point(VertexId(v)));
        if (c > 0 || (c == 0 && v < best)) best = v;
      }
      EXPECT_EQ(d.NearestVertex(p).value(), best) << q;
    }
    return util::Sha256Hex(bytes);
  };
  EXPECT_EQ(run(), run());
}

}  // namespace
}  // namespace svrc::delaunay
