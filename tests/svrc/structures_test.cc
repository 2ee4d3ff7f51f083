// Tests of SVRC's containment dimension (Defs 36–37), feature table, balls
// (§3.2.2), Bipartite Location Graph (§3.2.3, Figure 3.10) and the exact input
// normalisation (docs/svrc-design.md §1).
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "core/svrc/balls.h"
#include "core/svrc/containment.h"
#include "core/svrc/location_graph.h"
#include "core/svrc/normalize.h"
#include "core/svrc/points.h"
#include "gtest/gtest.h"

namespace svrc::refine {
namespace {

using geom::Vec3;

TEST(ContainmentTest, Definition37Order) {
  // The nine values of Definition 37, lowest first.
  const std::vector<Cd> order = {{0, 3}, {1, 2}, {1, 3}, {2, 1}, {2, 2}, {2, 3}, {3, 1}, {3, 2}, {3, 3}};
  for (size_t i = 0; i + 1 < order.size(); ++i) {
    EXPECT_LT(order[i], order[i + 1]) << CdToString(order[i]);
    EXPECT_TRUE(IsPossibleCd(order[i]));
  }
  EXPECT_FALSE(IsPossibleCd({0, 1}));  // collars never meet input vertices
  EXPECT_FALSE(IsPossibleCd({0, 2}));
  EXPECT_FALSE(IsPossibleCd({1, 1}));  // circles never meet segments
  EXPECT_EQ(CdOfFeatureDim(2), kCdFacet);
  EXPECT_EQ(CdToString(kCdSegment), "(1,3)");
}

// A unit square facet 0-1-2-3 with its 4 edges, plus a free segment 4-5 and an
// isolated point 6.
plc::FeatureComplex SquareComplex() {
  plc::FeatureComplex c;
  c.points.resize(7);
  auto seg = [&](uint32_t a, uint32_t b, std::vector<uint32_t> facets) {
    plc::FeatureSegment s;
    s.a = a;
    s.b = b;
    s.facets = facets;
    c.segments.push_back(s);
  };
  seg(0, 1, {0});
  seg(0, 3, {0});
  seg(1, 2, {0});
  seg(2, 3, {0});
  seg(4, 5, {});
  c.facets.resize(1);
  return c;
}

TEST(ContainmentTest, FeatureTableSuperfeatures) {
  const FeatureTable t = FeatureTable::Build(SquareComplex());
  EXPECT_EQ(t.size(), 1u + 7 + 5 + 1);
  EXPECT_EQ(t.Dim(FeatureTable::Omega()), 3);
  EXPECT_TRUE(t.Superfeatures(FeatureTable::Omega()).empty());
  // Point 0: segments 0 (0-1) and 1 (0-3), the facet, Ω — lowest dim first.
  const auto s0 = t.Superfeatures(t.OfPoint(0));
  ASSERT_EQ(s0.size(), 4u);
  EXPECT_EQ(s0[0], t.OfSegment(0));
  EXPECT_EQ(s0[1], t.OfSegment(1));
  EXPECT_EQ(s0[2], t.OfFacet(0));
  EXPECT_EQ(s0[3], FeatureTable::Omega());
  // Free segment 4-5: only Ω above it.
  const auto s4 = t.Superfeatures(t.OfSegment(4));
  ASSERT_EQ(s4.size(), 1u);
  EXPECT_EQ(s4[0], FeatureTable::Omega());
  // Isolated point: only Ω.
  ASSERT_EQ(t.Superfeatures(t.OfPoint(6)).size(), 1u);
  EXPECT_TRUE(t.Contains(t.OfFacet(0), t.OfSegment(3)));
  EXPECT_FALSE(t.Contains(t.OfFacet(0), t.OfSegment(4)));
  EXPECT_FALSE(t.Contains(t.OfSegment(0), t.OfFacet(0)));
  EXPECT_EQ(t.Index(t.OfSegment(3)), 3u);
  EXPECT_EQ(t.Dim(t.OfFacet(0)), 2);
}

TEST(PointStoreTest, MembershipPerMesh) {
  PointStore pts;
  const PointId a = pts.Add({0, 0, 0}, FeatureId(1), kCdInputVertex, /*crease=*/true);
  const PointId b = pts.Add({1, 0, 0}, FeatureId(0), kCdSpace);
  EXPECT_EQ(pts.size(), 2u);
  EXPECT_TRUE(pts.IsCrease(a));
  EXPECT_FALSE(pts.IsCrease(b));
  EXPECT_FALSE(pts.InMesh(a, kOmegaMesh));
  pts.SetVertex(a, kOmegaMesh, 17);
  pts.SetVertex(a, MeshId(3), 2);
  EXPECT_EQ(pts.VertexIn(a, kOmegaMesh), 17u);
  EXPECT_EQ(pts.VertexIn(a, MeshId(3)), 2u);
  EXPECT_EQ(pts.VertexIn(b, MeshId(3)), PointStore::kNoVertex);
  pts.SetVertex(a, kOmegaMesh, 18);  // a rebuild renumbers: replaced, not duplicated
  EXPECT_EQ(pts.VertexIn(a, kOmegaMesh), 18u);
}

TEST(BallsTest, DiametralAndCircumBalls) {
  Vec3 c;
  double r;
  DiametralBall({0, 0, 0}, {2, 0, 0}, &c, &r);
  EXPECT_EQ(c, Vec3(1, 0, 0));
  EXPECT_EQ(r, 1.0);
  // Right triangle: circumcentre is the hypotenuse midpoint.
  TriangleCircumball({1, 1, 1}, {3, 1, 1}, {1, 5, 1}, &c, &r);
  EXPECT_NEAR(c.x, 2, 1e-15);
  EXPECT_NEAR(c.y, 3, 1e-15);
  EXPECT_NEAR(c.z, 1, 1e-15);
  EXPECT_NEAR(r, std::sqrt(5.0), 1e-15);
  // Far from the origin the relative-to-a formula keeps precision.
  TriangleCircumball({1e6 + 1, 1e6 + 1, 1e6}, {1e6 + 3, 1e6 + 1, 1e6}, {1e6 + 1, 1e6 + 5, 1e6}, &c, &r);
  EXPECT_NEAR(r, std::sqrt(5.0), 1e-9);
}

TEST(BallsTest, StoreKindsCdAndLife) {
  BallStore balls;
  const BallId v = balls.AddVertexBall(PointId(4), {1, 2, 3}, FeatureId(5), MeshId(2), kCdInputVertex);
  const BallId s = balls.AddPieceBall(PointId(1), PointId(2), {0, 0, 0}, {0, 0, 4}, FeatureId(9), MeshId(3));
  const BallId t = balls.AddTriangleBall(PointId(1), PointId(2), PointId(3), {0, 1, 0}, 2.0, FeatureId(10), MeshId(4));
  EXPECT_TRUE(balls.IsVertexBall(v));
  EXPECT_EQ(balls.Radius(v), 0.0);
  EXPECT_EQ(balls.VertexPoint(v), PointId(4));
  EXPECT_EQ(balls.CdOf(v), kCdInputVertex);
  EXPECT_EQ(balls.NumVertices(s), 2);
  EXPECT_EQ(balls.Center(s), Vec3(0, 0, 2));
  EXPECT_EQ(balls.Radius(s), 2.0);
  EXPECT_EQ(balls.CdOf(s), kCdSegment);  // centre inside the segment (Def 36)
  EXPECT_EQ(balls.CdOf(t), kCdFacet);
  EXPECT_EQ(balls.Vertex(t, 2), PointId(3));
  EXPECT_EQ(balls.NumAlive(), 3u);
  const uint32_t g = balls.Generation(s);
  balls.Kill(s);
  balls.Kill(s);  // idempotent
  EXPECT_FALSE(balls.IsAlive(s));
  EXPECT_EQ(balls.Generation(s), g + 1);
  EXPECT_EQ(balls.NumAlive(), 2u);
}

// Figure 3.10: a native encroacher enqueues at once; a non-native one only
// when a second, *different* one arrives; the same vertex re-linked after a
// cell change does not count twice.
TEST(BallsTest, PartialEncroachmentNeedsTwoDifferentEncroachers) {
  BallStore balls;
  const BallId b = balls.AddPieceBall(PointId(0), PointId(1), {0, 0, 0}, {1, 0, 0}, FeatureId(3), MeshId(1));
  EXPECT_EQ(balls.RecordEncroacher(b, PointId(7), false), EncroachOutcome::kPartial);
  EXPECT_EQ(balls.FirstEncroacher(b), PointId(7));
  EXPECT_EQ(balls.RecordEncroacher(b, PointId(7), false), EncroachOutcome::kNothing);
  EXPECT_EQ(balls.RecordEncroacher(b, PointId(8), false), EncroachOutcome::kEnqueue);
  const BallId c = balls.AddPieceBall(PointId(0), PointId(1), {0, 0, 0}, {1, 0, 0}, FeatureId(3), MeshId(1));
  EXPECT_EQ(balls.RecordEncroacher(c, PointId(9), true), EncroachOutcome::kEnqueue);
  EXPECT_FALSE(balls.FirstEncroacher(c).valid());
}

TEST(LocationGraphTest, AddRemoveBothDirectionsAgree) {
  LocationGraph g;
  BallStore balls;
  std::vector<BallId> ids;
  for (int i = 0; i < 5; ++i) {
    ids.push_back(balls.AddVertexBall(PointId(i), {double(i), 0, 0}, FeatureId(1 + i), MeshId(1 + i), kCdInputVertex));
  }
  const MeshId m = kOmegaMesh;
  // Ball i links to cells i and i+1; cell 2 also gets ball 0 (out of order).
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(g.AddLink(m, i, LocationObject::Ball(ids[i]), {}, &balls).link.valid());
    ASSERT_TRUE(g.AddLink(m, i + 1, LocationObject::Ball(ids[i]), {}, &balls).link.valid());
  }
  g.AddLink(m, 2, LocationObject::Ball(ids[0]), {}, &balls);
  EXPECT_FALSE(g.AddLink(m, 2, LocationObject::Ball(ids[0]), {}, &balls).link.valid());  // duplicate
  EXPECT_EQ(g.stats().duplicates_refused, 1u);
  EXPECT_EQ(g.NumLinks(), 11u);
  ASSERT_TRUE(g.Validate());

  std::vector<BallId> b2;
  g.BallsOf(m, 2, &b2);  // link order: ball 1 (cell i+1), ball 2, ball 0
  EXPECT_EQ(b2, (std::vector<BallId>{ids[1], ids[2], ids[0]}));
  std::vector<uint32_t> c0;
  g.CellsOf(LocationObject::Ball(ids[0]), m, &c0);
  EXPECT_EQ(c0, (std::vector<uint32_t>{0, 1, 2}));
  std::vector<uint32_t> other_mesh;
  g.CellsOf(LocationObject::Ball(ids[0]), MeshId(7), &other_mesh);
  EXPECT_TRUE(other_mesh.empty());

  // Cell 2 changes: all its links go.
  std::vector<LocationObject> removed;
  g.RemoveCellLinks(m, 2, &removed);
  EXPECT_EQ(removed.size(), 3u);
  EXPECT_FALSE(g.IsLinked(m, 2, LocationObject::Ball(ids[0])));
  EXPECT_TRUE(g.IsLinked(m, 1, LocationObject::Ball(ids[0])));
  ASSERT_TRUE(g.Validate());
  // Ball 3 dies: its links go.
  std::vector<uint32_t> cells;
  g.RemoveObjectLinks(LocationObject::Ball(ids[3]), kNoneMesh, &cells);
  EXPECT_EQ(cells, (std::vector<uint32_t>{3, 4}));
  EXPECT_TRUE(g.RemoveLink(m, 0, LocationObject::Ball(ids[0])));
  EXPECT_FALSE(g.RemoveLink(m, 0, LocationObject::Ball(ids[0])));
  EXPECT_EQ(g.NumLinks(), 11u - 3 - 2 - 1);
  EXPECT_EQ(g.stats().links_removed, 6u);
  ASSERT_TRUE(g.Validate());
  // Freed slots are reused and lists stay consistent.
  g.AddLink(m, 2, LocationObject::Collar(0), {}, &balls);
  g.AddLink(MeshId(3), 2, LocationObject::Collar(0), {}, &balls);
  std::vector<LocationObject> objs;
  g.ObjectsOf(m, 2, &objs);
  ASSERT_EQ(objs.size(), 1u);
  EXPECT_EQ(objs[0], LocationObject::Collar(0));
  ASSERT_TRUE(g.Validate());
}

TEST(LocationGraphTest, TrapsEncroachmentAndUnresolved) {
  LocationGraph g;
  BallStore balls;
  const BallId piece = balls.AddPieceBall(PointId(0), PointId(1), {0, 0, 0}, {1, 0, 0}, FeatureId(3), MeshId(1));
  const BallId vb = balls.AddVertexBall(PointId(5), {0.5, 0.5, 0}, FeatureId(2), MeshId(2), kCdInputVertex);
  const MeshId m = kOmegaMesh;
  // Unresolved 0-ball: the first such link of a cell reports it.
  LinkFacts unresolved;
  unresolved.unresolved = true;
  EXPECT_TRUE(g.AddLink(m, 4, LocationObject::Ball(vb), unresolved, &balls).cell_became_unresolved);
  EXPECT_EQ(g.NumUnresolved(m, 4), 1u);
  // Non-native encroachers: partial, then the same again (nothing), then a
  // different one (enqueue).
  LinkFacts enc;
  enc.encroaches = true;
  enc.native = false;
  enc.vertex_point = PointId(7);
  EXPECT_EQ(g.AddLink(m, 4, LocationObject::Ball(piece), enc, &balls).encroach, EncroachOutcome::kPartial);
  EXPECT_EQ(g.AddLink(m, 9, LocationObject::Ball(piece), enc, &balls).encroach, EncroachOutcome::kNothing);
  enc.vertex_point = PointId(8);
  EXPECT_EQ(g.AddLink(m, 10, LocationObject::Ball(piece), enc, &balls).encroach, EncroachOutcome::kEnqueue);
  // A link that does not encroach reports nothing.
  EXPECT_EQ(g.AddLink(m, 11, LocationObject::Ball(piece), {}, &balls).encroach, EncroachOutcome::kNothing);
  g.RemoveLink(m, 4, LocationObject::Ball(vb));
  EXPECT_EQ(g.NumUnresolved(m, 4), 0u);
  EXPECT_TRUE(g.Validate());
}

// Random add/remove sequences keep both directions in agreement and are
// deterministic.
TEST(LocationGraphTest, RandomizedValidate) {
  auto run = [] {
    LocationGraph g;
    BallStore balls;
    for (int i = 0; i < 50; ++i) balls.AddVertexBall(PointId(i), {0, 0, 0}, FeatureId(i), MeshId(1), kCdInputVertex);
    std::mt19937 rng(3);
    for (int step = 0; step < 4000; ++step) {
      const MeshId m(rng() % 3);
      const uint32_t cell = rng() % 40;
      const LocationObject o = LocationObject::Ball(BallId(rng() % 50));
      LinkFacts f;
      f.unresolved = rng() % 2;
      switch (rng() % 4) {
        case 0: case 1: g.AddLink(m, cell, o, f, &balls); break;
        case 2: g.RemoveLink(m, cell, o); break;
        case 3: g.RemoveCellLinks(m, cell, nullptr); break;
      }
      if (step % 500 == 0 && !g.Validate()) return std::vector<BallId>{};
    }
    EXPECT_TRUE(g.Validate());
    std::vector<BallId> out;
    for (uint32_t c = 0; c < 40; ++c) g.BallsOf(MeshId(1), c, &out);
    return out;
  };
  const auto a = run();
  EXPECT_FALSE(a.empty());
  EXPECT_EQ(a, run());
}

TEST(NormalizeTest, FarOffsetBoxRoundTripsExactly) {
  // far_offset_close_points: a 1000-box at 1e6 with two points 1e-3 apart.
  std::vector<Vec3> pts = {{1e6, 1e6, 1e6}, {1001000.0, 1001000.0, 1001000.0},
                           {1000500.0, 1000500.0, 1000000.001}, {1000500.0, 1000500.001, 1000000.001}};
  auto n = ChooseNormalization(pts);
  ASSERT_TRUE(n.ok());
  EXPECT_EQ(n->translation, Vec3(1e6, 1e6, 1e6));  // Sterbenz applies on every axis
  for (const Vec3& p : pts) {
    const Vec3 y = n->Forward(p);
    EXPECT_EQ(n->Backward(y), p);
    for (int a = 0; a < 3; ++a) {
      EXPECT_GE(y[a], 0.0);
      EXPECT_LT(y[a], 1.0);
    }
  }
  // The 1e-3 gap is now relative to a unit box: differences are exact images.
  const Vec3 d = n->Forward(pts[3]) - n->Forward(pts[2]);
  EXPECT_EQ(n->ToInputLength(d.y), pts[3].y - pts[2].y);
}

TEST(NormalizeTest, StraddlingBoxScalesOnlyAndRejectsNonFinite) {
  std::vector<Vec3> pts = {{-3, 0.25, 7}, {5, -1, 1e-3}, {0, 0, 0}};
  auto n = ChooseNormalization(pts);
  ASSERT_TRUE(n.ok());
  EXPECT_EQ(n->translation, Vec3(0, 0, 0));
  EXPECT_EQ(n->exponent, 3);  // extent 7 → 7/8 < 1
  for (const Vec3& p : pts) EXPECT_EQ(n->Backward(n->Forward(p)), p);
  pts.push_back({NAN, 0, 0});
  EXPECT_FALSE(ChooseNormalization(pts).ok());
  EXPECT_FALSE(ChooseNormalization(std::vector<Vec3>{}).ok());
}

TEST(NormalizeTest, RandomInputsRoundTrip) {
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 50; ++trial) {
    std::uniform_real_distribution<double> off(-1e9, 1e9), ext(1e-6, 1e4);
    const Vec3 o(off(rng), off(rng), off(rng));
    const double e = ext(rng);
    std::uniform_real_distribution<double> u(0, e);
    std::vector<Vec3> pts;
    for (int i = 0; i < 20; ++i) pts.push_back(o + Vec3(u(rng), u(rng), u(rng)));
    auto n = ChooseNormalization(pts);
    ASSERT_TRUE(n.ok());
    for (const Vec3& p : pts) ASSERT_EQ(n->Backward(n->Forward(p)), p);
  }
}

}  // namespace
}  // namespace svrc::refine
