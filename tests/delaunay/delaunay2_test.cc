// Delaunay2: Validate after every insertion on random and degenerate inputs,
// SoS order independence, exact change reports, queries against brute force.
#include "core/delaunay/delaunay2.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/geometry/constructions.h"
#include "core/geometry/predicates.h"
#include "core/util/sha256.h"

namespace svrc::delaunay {
namespace {

using geom::Vec2;
using VertexId = Delaunay2::VertexId;
using TriId = Delaunay2::TriId;

constexpr std::array<uint32_t, 4> kCornerIds = {1000000, 1000001, 1000002, 1000003};

Delaunay2 Box(double lo, double hi) { return Delaunay2::Square({lo, lo}, {hi, hi}, kCornerIds); }

// Live triangles as (slot, generation) pairs.
std::set<std::pair<uint32_t, uint32_t>> LiveSet(const Delaunay2& d) {
  std::set<std::pair<uint32_t, uint32_t>> s;
  for (TriId t : d.Triangles()) s.insert({t.value(), d.Generation(t)});
  return s;
}

// The triangulation as a canonical set of global-id triples (rotation-
// normalised, orientation kept).
std::set<std::array<uint32_t, 3>> Canonical(const Delaunay2& d) {
  std::set<std::array<uint32_t, 3>> s;
  for (TriId t : d.Triangles()) {
    std::array<uint32_t, 3> g;
    for (int i = 0; i < 3; ++i) g[i] = d.GlobalId(d.TriVertex(t, i));
    std::rotate(g.begin(), std::min_element(g.begin(), g.end()), g.end());
    s.insert(g);
  }
  return s;
}

// Inserts all points, validating and checking the change report each time.
void InsertAllChecked(Delaunay2& d, const std::vector<Vec2>& pts, const std::vector<uint32_t>& ids) {
  for (size_t i = 0; i < pts.size(); ++i) {
    const auto before = LiveSet(d);
    std::map<uint32_t, std::set<uint32_t>> before_vertices;  // slot -> vertex ids
    for (TriId t : d.Triangles()) {
      for (int k = 0; k < 3; ++k) before_vertices[t.value()].insert(d.TriVertex(t, k).value());
    }
    const auto r = d.Insert(pts[i], ids[i]);
    ASSERT_EQ(r.outcome, Delaunay2::InsertOutcome::kInserted) << i;
    const auto after = LiveSet(d);
    // destroyed == before \ after, created == after \ before (by slot+generation).
    std::set<std::pair<uint32_t, uint32_t>> gone, born;
    std::set_difference(before.begin(), before.end(), after.begin(), after.end(),
                        std::inserter(gone, gone.end()));
    std::set_difference(after.begin(), after.end(), before.begin(), before.end(),
                        std::inserter(born, born.end()));
    std::set<uint32_t> gone_slots, born_slots, destroyed, created;
    for (auto& [s, g] : gone) gone_slots.insert(s);
    for (auto& [s, g] : born) born_slots.insert(s);
    for (TriId t : r.destroyed) destroyed.insert(t.value());
    for (TriId t : r.created) created.insert(t.value());
    ASSERT_EQ(destroyed, gone_slots) << i;
    ASSERT_EQ(created, born_slots) << i;
    ASSERT_EQ(r.destroyed.size(), gone.size());
    ASSERT_EQ(r.created.size(), born.size());
    // Cavity vertices = vertices of destroyed triangles, each once, not p.
    std::set<uint32_t> cav;
    for (TriId t : r.destroyed) cav.insert(before_vertices[t.value()].begin(), before_vertices[t.value()].end());
    std::set<uint32_t> reported;
    for (VertexId v : r.cavity_vertices) ASSERT_TRUE(reported.insert(v.value()).second);
    ASSERT_EQ(reported, cav);
    ASSERT_EQ(r.created.size(), r.cavity_vertices.size());  // a fan around p
    const absl::Status st = d.Validate(true);
    ASSERT_TRUE(st.ok()) << "after insertion " << i << ": " << st;
  }
}

TEST(Delaunay2Test, EmptyBoxIsValid) {
  Delaunay2 d = Box(0, 1);
  EXPECT_EQ(d.NumTriangles(), 2u);
  EXPECT_TRUE(d.Validate().ok()) << d.Validate();
}

TEST(Delaunay2Test, RandomPointsValidAfterEveryInsertion) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Vec2> pts;
  std::vector<uint32_t> ids;
  for (int i = 0; i < 400; ++i) {
    pts.push_back({u(rng), u(rng)});
    ids.push_back(i);
  }
  Delaunay2 d = Box(-3, 3);
  InsertAllChecked(d, pts, ids);
  EXPECT_EQ(d.NumVertices(), 404u);
  EXPECT_EQ(d.NumTriangles(), 2u * 404 - 6);
}

// A square grid: every cell's four corners are cocircular. SoS gives one
// triangulation regardless of the insertion order.
TEST(Delaunay2Test, GridIsValidAndOrderIndependent) {
  std::vector<Vec2> pts;
  std::vector<uint32_t> ids;
  for (int x = 0; x < 12; ++x) {
    for (int y = 0; y < 12; ++y) {
      pts.push_back({double(x), double(y)});
      ids.push_back(x * 12 + y);
    }
  }
  std::set<std::array<uint32_t, 3>> first;
  std::mt19937_64 rng(3);
  for (int trial = 0; trial < 4; ++trial) {
    std::vector<size_t> order(pts.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    if (trial > 0) std::shuffle(order.begin(), order.end(), rng);
    std::vector<Vec2> p;
    std::vector<uint32_t> g;
    for (size_t i : order) {
      p.push_back(pts[i]);
      g.push_back(ids[i]);
    }
    Delaunay2 d = Delaunay2::Square({-2, -2}, {13, 13}, kCornerIds);  // box corners cocircular with grid
    InsertAllChecked(d, p, g);
    const auto canon = Canonical(d);
    if (trial == 0) {
      first = canon;
    } else {
      EXPECT_EQ(canon, first) << "trial " << trial;
    }
  }
}

TEST(Delaunay2Test, CocircularPointsAndCentre) {
  std::vector<Vec2> pts;
  std::vector<uint32_t> ids;
  for (int x = -25; x <= 25; ++x) {
    for (int y = -25; y <= 25; ++y) {
      if (x * x + y * y == 625) {
        pts.push_back({double(x), double(y)});
        ids.push_back(static_cast<uint32_t>(pts.size()));
      }
    }
  }
  ASSERT_GE(pts.size(), 12u);
  pts.push_back({0, 0});
  ids.push_back(999);
  Delaunay2 d = Box(-50, 50);
  InsertAllChecked(d, pts, ids);
  // Collinear points on a line through the box.
  std::vector<Vec2> line;
  std::vector<uint32_t> lids;
  for (int i = -20; i <= 20; ++i) {
    line.push_back({double(i), double(i) * 0.5 + 1.0 / 1024});
    lids.push_back(2000 + i + 20);
  }
  InsertAllChecked(d, line, lids);
}

TEST(Delaunay2Test, DuplicatesAndOutsidePointsChangeNothing) {
  Delaunay2 d = Box(0, 4);
  ASSERT_EQ(d.Insert({1, 1}, 1).outcome, Delaunay2::InsertOutcome::kInserted);
  const auto before = LiveSet(d);
  auto r = d.Insert({1, 1}, 2);
  EXPECT_EQ(r.outcome, Delaunay2::InsertOutcome::kDuplicate);
  EXPECT_EQ(r.vertex, VertexId(4));
  EXPECT_EQ(d.Insert({5, 1}, 3).outcome, Delaunay2::InsertOutcome::kOutside);
  EXPECT_EQ(d.Insert({4, 1}, 3).outcome, Delaunay2::InsertOutcome::kOutside);  // on the box side
  EXPECT_EQ(d.Insert({0, 0}, 3).outcome, Delaunay2::InsertOutcome::kDuplicate);  // a corner
  EXPECT_EQ(LiveSet(d), before);
  EXPECT_EQ(d.NumVertices(), 5u);
  EXPECT_TRUE(d.Validate().ok());
}

TEST(Delaunay2Test, ByteIdenticalAcrossRuns) {
  auto run = [] {
    std::mt19937_64 rng(11);
    std::uniform_int_distribution<int> g(1, 30);
    Delaunay2 d = Box(0, 31);
    for (int i = 0; i < 500; ++i) d.Insert({double(g(rng)), double(g(rng))}, i);
    std::string bytes;
    for (uint32_t t = 0; t < d.TriCapacity(); ++t) {
      const TriId id(t);
      bytes += std::to_string(d.Generation(id)) + ":";
      if (!d.IsAlive(id)) continue;
      for (int i = 0; i < 3; ++i) {
        bytes += std::to_string(d.TriVertex(id, i).value()) + "," +
                 std::to_string(d.Neighbor(id, i).value()) + ";";
      }
    }
    EXPECT_TRUE(d.Validate().ok()) << d.Validate();
    return util::Sha256Hex(bytes);
  };
  EXPECT_EQ(run(), run());
}

TEST(Delaunay2Test, QueriesMatchBruteForce) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 10);
  Delaunay2 d = Box(-5, 15);
  for (int i = 0; i < 300; ++i) d.Insert({u(rng), u(rng)}, i);
  ASSERT_TRUE(d.Validate().ok());
  // Incidence by brute force.
  std::vector<std::set<uint32_t>> incident(d.NumVertices());
  for (TriId t : d.Triangles()) {
    for (int i = 0; i < 3; ++i) incident[d.TriVertex(t, i).value()].insert(t.value());
  }
  std::vector<TriId> star;
  std::vector<VertexId> nbrs;
  std::vector<Vec2> corners;
  for (uint32_t v = 0; v < d.NumVertices(); ++v) {
    d.Star(VertexId(v), &star);
    std::set<uint32_t> s;
    for (TriId t : star) s.insert(t.value());
    ASSERT_EQ(s, incident[v]) << v;
    ASSERT_EQ(s.size(), star.size());
    // Consecutive star triangles share an edge at v (counter-clockwise fan).
    for (size_t k = 0; k + 1 < star.size(); ++k) {
      bool adjacent = false;
      for (int e = 0; e < 3; ++e) adjacent |= d.Neighbor(star[k], e) == star[k + 1];
      ASSERT_TRUE(adjacent);
    }
    d.Neighbors(VertexId(v), &nbrs);
    std::set<uint32_t> nb_brute;
    for (uint32_t t : incident[v]) {
      for (int i = 0; i < 3; ++i) {
        const uint32_t w = d.TriVertex(TriId(t), i).value();
        if (w != v) nb_brute.insert(w);
      }
    }
    std::set<uint32_t> nb;
    for (VertexId w : nbrs) nb.insert(w.value());
    ASSERT_EQ(nb, nb_brute) << v;
    ASSERT_EQ(nb.size(), nbrs.size());
    // r_v and R_v.
    double shortest = 1e300, longest_r = 0;
    for (uint32_t w : nb_brute) shortest = std::min(shortest, geom::Norm2(d.Point(VertexId(w)) - d.Point(VertexId(v))));
    for (uint32_t t : incident[v]) longest_r = std::max(longest_r, d.Circumradius(TriId(t)));
    EXPECT_DOUBLE_EQ(d.InRadius(VertexId(v)), 0.5 * std::sqrt(shortest));
    if (d.IsCorner(VertexId(v))) {
      EXPECT_TRUE(std::isinf(d.OutRadius(VertexId(v))));
    } else {
      Vec2 far;
      EXPECT_NEAR(d.OutRadius(VertexId(v), &far), longest_r, 1e-12 * longest_r);
      EXPECT_NEAR(std::sqrt(geom::Norm2(far - d.Point(VertexId(v)))), d.OutRadius(VertexId(v)), 1e-12);
      d.VoronoiCorners(VertexId(v), &corners);
      EXPECT_EQ(corners.size(), star.size());
    }
  }
  // Locate and nearest vertex.
  for (int q = 0; q < 500; ++q) {
    const Vec2 p{u(rng) * 1.5 - 2.5, u(rng) * 1.5 - 2.5};
    const TriId t = d.Locate(p, TriId(q % d.TriCapacity()));
    ASSERT_TRUE(t.valid());
    for (int e = 0; e < 3; ++e) {
      ASSERT_GE(geom::Orient2d(d.Point(d.TriVertex(t, (e + 1) % 3)), d.Point(d.TriVertex(t, (e + 2) % 3)), p), 0);
    }
    uint32_t best = 0;
    for (uint32_t v = 1; v < d.NumVertices(); ++v) {
      const int c = geom::CompareDistance(p, d.Point(VertexId(best)), d.Point(VertexId(v)));
      if (c > 0 || (c == 0 && v < best)) best = v;
    }
    EXPECT_EQ(d.NearestVertex(p).value(), best);
  }
  EXPECT_FALSE(d.Locate({100, 0}).valid());
}

// ForceInsert-style use: the hint is a triangle known to conflict with p.
TEST(Delaunay2Test, InsertFromConflictingHint) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(0, 1);
  Delaunay2 d = Box(-1, 2);
  for (int i = 0; i < 200; ++i) {
    const Vec2 p{u(rng), u(rng)};
    const TriId near = d.Locate(p);
    ASSERT_TRUE(d.InConflict(near, p, i));
    const auto r = d.Insert(p, i, near);
    ASSERT_EQ(r.outcome, Delaunay2::InsertOutcome::kInserted);
  }
  EXPECT_TRUE(d.Validate().ok()) << d.Validate();
}

// NearVertex (2D): the exact nearest on random queries; from circumcentres
// (three tied corners) and on an integer grid, no farther than the nearest
// by more than rounding.
TEST(Delaunay2Test, NearVertexIsNearestUpToRounding) {
  for (const bool grid : {false, true}) {
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    Delaunay2 d = Box(-1, 11);
    std::vector<Vec2> pts;
    std::vector<uint32_t> ids;
    for (int i = 0; i < 400; ++i) {
      pts.push_back(grid ? Vec2{double(i % 20) / 2, double(i / 20) / 2} : Vec2{10 * u(rng), 10 * u(rng)});
      ids.push_back(100 + i);
    }
    InsertAllChecked(d, pts, ids);
    auto min_d2 = [&](Vec2 q) {
      double m = HUGE_VAL;
      for (uint32_t v = 0; v < d.NumVertices(); ++v) {
        const Vec2 p = d.Point(VertexId(v));
        m = std::min(m, (p.x - q.x) * (p.x - q.x) + (p.y - q.y) * (p.y - q.y));
      }
      return m;
    };
    std::vector<Vec2> queries;
    for (int q = 0; q < 300; ++q) queries.push_back({10 * u(rng), 10 * u(rng)});
    if (!grid) {
      for (Vec2 q : queries) EXPECT_EQ(d.NearVertex(q), d.NearestVertex(q));
    }
    const std::vector<TriId> tris = d.Triangles();
    for (TriId t : tris) {
      const Vec2 c = d.Circumcenter(t);
      if (c.x > -1 && c.x < 11 && c.y > -1 && c.y < 11) queries.push_back(c);
    }
    size_t k = 0;
    for (Vec2 q : queries) {
      const VertexId v = d.NearVertex(q, tris[k++ % tris.size()]);
      ASSERT_TRUE(v.valid());
      const Vec2 p = d.Point(v);
      const double m = min_d2(q);
      EXPECT_LE((p.x - q.x) * (p.x - q.x) + (p.y - q.y) * (p.y - q.y), m + 1e-12 * (1 + m));
    }
  }
}

}  // namespace
}  // namespace svrc::delaunay
