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
    ASSERT_TRUE(g.AddLink(m, i, LocationObject::Ball(ids[i]), {}, &balls).added);
    ASSERT_TRUE(g.AddLink(m, i + 1, LocationObject::Ball(ids[i]), {}, &balls).added);
  }
  g.AddLink(m, 2, LocationObject::Ball(ids[0]), {}, &balls);
  EXPECT_FALSE(g.AddLink(m, 2, LocationObject::Ball(ids[0]), {}, &balls).added);  // duplicate
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

// A cell-side entry is 4 bytes: the object's id in 30 bits, its kind and
// the unresolved flag in the other two (§8 item 45). A ball and a collar of
// the same id in one cell stay two links, each with its own flag; an id
// that does not fit is refused before anything is stored.
TEST(LocationGraphTest, CellEntriesKeepKindAndFlagApart) {
  LocationGraph g;
  BallStore balls;
  const MeshId m = kOmegaMesh;
  LinkFacts unresolved;
  unresolved.unresolved = true;
  const uint32_t id = 37;
  ASSERT_TRUE(g.AddLink(m, 3, LocationObject::Collar(id), {}, &balls).added);
  ASSERT_TRUE(g.AddLink(m, 3, LocationObject::Ball(BallId(id)), unresolved, &balls).added);
  EXPECT_FALSE(g.AddLink(m, 3, LocationObject::Ball(BallId(id)), {}, &balls).added);  // the flag is no part of the link
  EXPECT_EQ(g.NumUnresolved(m, 3), 1u);
  std::vector<LocationObject> objs;
  g.ObjectsOf(m, 3, &objs);
  EXPECT_EQ(objs, (std::vector<LocationObject>{LocationObject::Collar(id), LocationObject::Ball(BallId(id))}));
  std::vector<BallId> unresolved_balls;
  g.ForEachUnresolvedBall(m, 3, [&](BallId b) { unresolved_balls.push_back(b); });
  EXPECT_EQ(unresolved_balls, std::vector<BallId>{BallId(id)});
  // The ball's entry is the second: removing it must leave the collar's.
  EXPECT_TRUE(g.RemoveLink(m, 3, LocationObject::Ball(BallId(id))));
  EXPECT_EQ(g.NumUnresolved(m, 3), 0u);
  objs.clear();
  g.ObjectsOf(m, 3, &objs);
  EXPECT_EQ(objs, std::vector<LocationObject>{LocationObject::Collar(id)});
  EXPECT_TRUE(g.Validate());
  EXPECT_TRUE(g.RemoveLink(m, 3, LocationObject::Collar(id)));
  EXPECT_THROW(g.AddLink(m, 3, LocationObject::Ball(BallId(uint32_t{1} << 30)), {}, &balls), std::bad_alloc);
  EXPECT_THROW(g.AddLink(m, 3, LocationObject::Collar(uint32_t{1} << 30), {}, &balls), std::bad_alloc);
  EXPECT_EQ(g.NumLinks(), 0u);
  EXPECT_TRUE(g.Validate());
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

// The reference model for the BLG's iteration order: every link ever added,
// in AddLink order, with a live flag. Each answer of the graph (BallsOf,
// ObjectsOf, CellsOf, the lists RemoveCellLinks / RemoveObjectLinks report) is
// the live links filtered, in that order: the refiner's output bytes depend on
// it (issue #5 replaced the linked lists by arrays with order-keeping removal).
struct BlgModel {
  struct Link {
    MeshId mesh;
    uint32_t cell;
    LocationObject object;
    bool unresolved;
    bool live;
  };
  std::vector<Link> links;

  Link* Find(MeshId m, uint32_t c, LocationObject o) {
    for (Link& l : links) {
      if (l.live && l.mesh == m && l.cell == c && l.object == o) return &l;
    }
    return nullptr;
  }
  bool IsLinked(MeshId m, uint32_t c, LocationObject o) const {
    return std::any_of(links.begin(), links.end(), [&](const Link& l) {
      return l.live && l.mesh == m && l.cell == c && l.object == o;
    });
  }
  std::vector<LocationObject> Objects(MeshId m, uint32_t c) const {
    std::vector<LocationObject> out;
    for (const Link& l : links) {
      if (l.live && l.mesh == m && l.cell == c) out.push_back(l.object);
    }
    return out;
  }
  std::vector<uint32_t> Cells(LocationObject o, MeshId m) const {
    std::vector<uint32_t> out;
    for (const Link& l : links) {
      if (l.live && l.object == o && (!m.valid() || l.mesh == m)) out.push_back(l.cell);
    }
    return out;
  }
  uint32_t NumLive() const {
    return static_cast<uint32_t>(std::count_if(links.begin(), links.end(), [](const Link& l) { return l.live; }));
  }
};

// Compares every query of `g` with the model over the whole id range.
void ExpectSameAsModel(const LocationGraph& g, const BlgModel& model, int meshes, uint32_t cells,
                       uint32_t balls, uint32_t collars, int step) {
  ASSERT_EQ(g.NumLinks(), model.NumLive()) << "step " << step;
  for (int m = 0; m < meshes; ++m) {
    // UnresolvedCells: exactly the cells with an unresolved link.
    std::vector<uint32_t> want_cells, got_cells = g.UnresolvedCells(MeshId(m));
    for (const BlgModel::Link& l : model.links) {
      if (l.live && l.unresolved && l.mesh == MeshId(m)) want_cells.push_back(l.cell);
    }
    std::sort(want_cells.begin(), want_cells.end());
    want_cells.erase(std::unique(want_cells.begin(), want_cells.end()), want_cells.end());
    std::sort(got_cells.begin(), got_cells.end());
    ASSERT_EQ(got_cells, want_cells) << "UnresolvedCells mesh " << m << " step " << step;
  }
  for (int m = 0; m < meshes; ++m) {
    for (uint32_t c = 0; c < cells; ++c) {
      const std::vector<LocationObject> want = model.Objects(MeshId(m), c);
      std::vector<LocationObject> got;
      g.ObjectsOf(MeshId(m), c, &got);
      ASSERT_EQ(got, want) << "ObjectsOf mesh " << m << " cell " << c << " step " << step;
      std::vector<BallId> want_balls, got_balls;
      uint32_t want_unresolved = 0;
      for (const BlgModel::Link& l : model.links) {
        if (!l.live || l.mesh != MeshId(m) || l.cell != c) continue;
        if (l.object.kind == ObjectKind::kBall) want_balls.push_back(BallId(l.object.id));
        if (l.unresolved) ++want_unresolved;
      }
      g.BallsOf(MeshId(m), c, &got_balls);
      ASSERT_EQ(got_balls, want_balls) << "BallsOf mesh " << m << " cell " << c << " step " << step;
      std::vector<BallId> each;
      g.ForEachBall(MeshId(m), c, [&](BallId b) { each.push_back(b); });
      ASSERT_EQ(each, want_balls) << "ForEachBall mesh " << m << " cell " << c << " step " << step;
      ASSERT_EQ(g.NumUnresolved(MeshId(m), c), want_unresolved) << "mesh " << m << " cell " << c;
    }
  }
  for (uint32_t kind = 0; kind < 2; ++kind) {
    for (uint32_t id = 0; id < (kind == 0 ? balls : collars); ++id) {
      const LocationObject o{static_cast<ObjectKind>(kind), id};
      for (int m = 0; m < meshes; ++m) {
        std::vector<uint32_t> got;
        g.CellsOf(o, MeshId(m), &got);
        ASSERT_EQ(got, model.Cells(o, MeshId(m))) << "CellsOf kind " << kind << " id " << id << " mesh " << m;
        for (uint32_t c = 0; c < cells; ++c) {
          ASSERT_EQ(g.IsLinked(MeshId(m), c, o), model.IsLinked(MeshId(m), c, o));
        }
      }
    }
  }
}

// Random sequences of every mutating call, checked step by step against the
// model: identical iteration orders after order-keeping removals from the
// front, middle and back of arrays, after arrays grow past several block
// sizes (one cell and one ball collect > 64 links) and after emptied blocks
// are reused by other cells and objects.
TEST(LocationGraphTest, MatchesReferenceModelOrder) {
  constexpr int kMeshes = 3;
  constexpr uint32_t kCells = 12, kBalls = 24, kCollars = 3;
  LocationGraph g;
  BallStore balls;
  for (uint32_t i = 0; i < kBalls; ++i) {
    balls.AddVertexBall(PointId(i), {0, 0, 0}, FeatureId(i), MeshId(1), kCdInputVertex);
  }
  BlgModel model;
  std::mt19937 rng(7);
  auto random_object = [&] {
    return rng() % 8 == 0 ? LocationObject::Collar(rng() % kCollars) : LocationObject::Ball(BallId(rng() % kBalls));
  };
  uint64_t removed_total = 0;
  for (int step = 0; step < 6000; ++step) {
    // Phases: mostly adds (arrays grow), then mixed, then mostly removals.
    const int phase = step / 2000;
    const uint32_t op = rng() % 16;
    const MeshId m(rng() % kMeshes);
    const uint32_t c = rng() % kCells;
    const LocationObject o = random_object();
    const bool add = phase == 0 ? op < 13 : phase == 1 ? op < 8 : op < 4;
    if (add) {
      LinkFacts f;
      f.unresolved = rng() % 3 == 0;
      const AddLinkResult r = g.AddLink(m, c, o, f, &balls);
      BlgModel::Link* existing = model.Find(m, c, o);
      ASSERT_EQ(r.added, existing == nullptr) << "step " << step;
      if (existing == nullptr) {
        uint32_t unresolved_before = 0;
        for (const BlgModel::Link& l : model.links) unresolved_before += l.live && l.mesh == m && l.cell == c && l.unresolved;
        EXPECT_EQ(r.cell_became_unresolved, f.unresolved && unresolved_before == 0);
        model.links.push_back({m, c, o, f.unresolved, true});
      }
    } else {
      switch (op % 4) {
        case 0: {  // by (mesh, cell, object)
          BlgModel::Link* l = model.Find(m, c, o);
          ASSERT_EQ(g.RemoveLink(m, c, o), l != nullptr);
          if (l != nullptr) l->live = false, ++removed_total;
          break;
        }
        case 1: {  // a random live link, by its triple
          std::vector<BlgModel::Link*> live;
          for (BlgModel::Link& l : model.links) {
            if (l.live) live.push_back(&l);
          }
          if (live.empty()) break;
          BlgModel::Link* l = live[rng() % live.size()];
          ASSERT_TRUE(g.RemoveLink(l->mesh, l->cell, l->object));
          l->live = false;
          ++removed_total;
          break;
        }
        case 2: {  // a whole cell, reported in link order; or some of its links, by mask
          if (rng() % 2 == 0) {
            // RemoveCellLinksWhere: the masked links go, the rest keep their order.
            const std::vector<LocationObject> before = model.Objects(m, c);
            std::vector<uint8_t> drop(before.size());
            for (uint8_t& d : drop) d = rng() % 3 == 0;
            g.RemoveCellLinksWhere(m, c, drop);
            size_t k = 0;
            for (BlgModel::Link& l : model.links) {
              if (!l.live || l.mesh != m || l.cell != c) continue;
              if (drop[k++]) l.live = false, ++removed_total;
            }
            break;
          }
          std::vector<LocationObject> got;
          g.RemoveCellLinks(m, c, &got);
          ASSERT_EQ(got, model.Objects(m, c)) << "RemoveCellLinks step " << step;
          for (BlgModel::Link& l : model.links) {
            if (l.live && l.mesh == m && l.cell == c) l.live = false, ++removed_total;
          }
          break;
        }
        case 3: {  // a whole object, in one mesh or in all
          const MeshId which = rng() % 2 ? m : kNoneMesh;
          std::vector<uint32_t> got;
          g.RemoveObjectLinks(o, which, &got);
          ASSERT_EQ(got, model.Cells(o, which)) << "RemoveObjectLinks step " << step;
          for (BlgModel::Link& l : model.links) {
            if (l.live && l.object == o && (!which.valid() || l.mesh == which)) l.live = false, ++removed_total;
          }
          break;
        }
      }
    }
    if (step % 97 == 0 || step == 5999) {
      ASSERT_TRUE(g.Validate()) << "step " << step;
      ASSERT_NO_FATAL_FAILURE(ExpectSameAsModel(g, model, kMeshes, kCells, kBalls, kCollars, step));
    }
  }
  EXPECT_EQ(g.stats().links_removed, removed_total);
  EXPECT_EQ(g.stats().links_added, model.links.size());

  // Long arrays: one cell and one ball collect many links (several block
  // growths); removing every third link keeps the rest in order.
  const MeshId m(1);
  for (uint32_t i = 0; i < kBalls; ++i) g.RemoveObjectLinks(LocationObject::Ball(BallId(i)), kNoneMesh, nullptr);
  for (uint32_t i = 0; i < kCollars; ++i) g.RemoveObjectLinks(LocationObject::Collar(i), kNoneMesh, nullptr);
  ASSERT_EQ(g.NumLinks(), 0u);
  std::vector<uint32_t> want_cells;
  for (uint32_t c = 100; c < 200; ++c) {
    g.AddLink(m, c, LocationObject::Ball(BallId(5)), {}, &balls);
    want_cells.push_back(c);
  }
  std::vector<BallId> want_balls;
  for (uint32_t b = 0; b < kBalls; ++b) {
    const uint32_t id = (b * 7) % kBalls;  // not in id order
    g.AddLink(m, 150, LocationObject::Ball(BallId(id)), {}, &balls);
    if (id != 5) want_balls.push_back(BallId(id));
  }
  for (uint32_t k = 0; k < 70; ++k) g.AddLink(m, 150, LocationObject::Collar(k), {}, &balls);
  std::vector<BallId> got_balls;
  g.BallsOf(m, 150, &got_balls);
  std::vector<BallId> first_balls = want_balls;
  first_balls.insert(first_balls.begin() + 0, BallId(5));  // ball 5's link to cell 150 came first
  EXPECT_EQ(got_balls, first_balls);
  for (size_t i = 0; i < want_cells.size(); i += 3) {
    ASSERT_TRUE(g.RemoveLink(m, want_cells[i], LocationObject::Ball(BallId(5))));
  }
  std::vector<uint32_t> kept_cells;
  for (size_t i = 0; i < want_cells.size(); ++i) {
    if (i % 3 != 0) kept_cells.push_back(want_cells[i]);
  }
  std::vector<uint32_t> got_cells;
  g.CellsOf(LocationObject::Ball(BallId(5)), m, &got_cells);
  EXPECT_EQ(got_cells, kept_cells);
  // Cell 150 (index 50, 50 % 3 != 0) still has ball 5 first.
  got_balls.clear();
  g.BallsOf(m, 150, &got_balls);
  EXPECT_EQ(got_balls, first_balls);
  for (uint32_t k = 0; k < 70; k += 2) ASSERT_TRUE(g.RemoveLink(m, 150, LocationObject::Collar(k)));
  std::vector<LocationObject> objs;
  g.ObjectsOf(m, 150, &objs);
  ASSERT_EQ(objs.size(), first_balls.size() + 35);
  for (size_t i = 0; i < first_balls.size(); ++i) EXPECT_EQ(objs[i], LocationObject::Ball(first_balls[i]));
  for (uint32_t k = 0; k < 35; ++k) EXPECT_EQ(objs[first_balls.size() + k], LocationObject::Collar(2 * k + 1));
  EXPECT_TRUE(g.Validate());
}

// Cells whose arrays once grew long and then shrank (a coarse cell holding
// many balls early in a run, refined later) no longer keep their large blocks
// for good: once the arena would have to grow while its arrays fit in half of
// it, it is packed. Every query still matches the model, in order, and the
// storage stays within a small multiple of the live links (without the
// packing every round's blocks of up to 64 entries stay).
TEST(LocationGraphTest, CompactsArraysThatShrank) {
  constexpr int kMeshes = 2;
  constexpr uint32_t kBalls = 96;
  LocationGraph g;
  BallStore balls;
  for (uint32_t i = 0; i < kBalls; ++i) {
    balls.AddVertexBall(PointId(i), {0, 0, 0}, FeatureId(i), MeshId(1), kCdInputVertex);
  }
  BlgModel model;
  std::mt19937 rng(11);
  uint32_t max_live = 0;
  constexpr uint32_t kCellsPerRound = 40;
  for (uint32_t round = 0; round < 12; ++round) {
    // Fresh cells collect up to 64 links each (blocks of 64), then all but a
    // few go: by mask (RemoveCellLinksWhere) or by object.
    const uint32_t first = round * kCellsPerRound;
    for (uint32_t c = first; c < first + kCellsPerRound; ++c) {
      const MeshId m(c % kMeshes);
      const uint32_t n = 33 + rng() % 32;
      for (uint32_t k = 0; k < n; ++k) {
        const LocationObject o = LocationObject::Ball(BallId((c * 7 + k * 13) % kBalls));
        LinkFacts f;
        f.unresolved = rng() % 4 == 0;
        const AddLinkResult r = g.AddLink(m, c, o, f, &balls);
        ASSERT_EQ(r.added, model.Find(m, c, o) == nullptr);
        if (r.added) model.links.push_back({m, c, o, f.unresolved, true});
      }
    }
    max_live = std::max(max_live, g.NumLinks());
    for (uint32_t c = first; c < first + kCellsPerRound; ++c) {
      const MeshId m(c % kMeshes);
      const std::vector<LocationObject> before = model.Objects(m, c);
      std::vector<uint8_t> drop(before.size());
      for (size_t i = 0; i < drop.size(); ++i) drop[i] = i % 9 != 4;
      g.RemoveCellLinksWhere(m, c, drop);
      size_t k = 0;
      for (BlgModel::Link& l : model.links) {
        if (!l.live || l.mesh != m || l.cell != c) continue;
        if (drop[k++]) l.live = false;
      }
    }
    if (round % 3 == 2) {
      const LocationObject o = LocationObject::Ball(BallId(rng() % kBalls));
      g.RemoveObjectLinks(o, kNoneMesh, nullptr);
      for (BlgModel::Link& l : model.links) {
        if (l.live && l.object == o) l.live = false;
      }
    }
    // Every array in order, both sides (ExpectSameAsModel's IsLinked sweep
    // over all cell × ball pairs is too slow here under the sanitizers).
    ASSERT_TRUE(g.Validate()) << "round " << round;
    ASSERT_EQ(g.NumLinks(), model.NumLive());
    for (uint32_t c = 0; c < first + kCellsPerRound; ++c) {
      std::vector<LocationObject> got;
      g.ObjectsOf(MeshId(c % kMeshes), c, &got);
      ASSERT_EQ(got, model.Objects(MeshId(c % kMeshes), c)) << "cell " << c << " round " << round;
    }
    for (uint32_t b = 0; b < kBalls; ++b) {
      for (int m = 0; m < kMeshes; ++m) {
        std::vector<uint32_t> got;
        g.CellsOf(LocationObject::Ball(BallId(b)), MeshId(m), &got);
        ASSERT_EQ(got, model.Cells(LocationObject::Ball(BallId(b)), MeshId(m))) << "ball " << b << " round " << round;
      }
    }
  }
  EXPECT_GT(g.stats().compactions, 0u);
  // Packed blocks are ≤ 2× their arrays and the pool is at most 1.5× its
  // packed size before it may grow again. Measured: 13,108 entries for at
  // most 4,348 live links; 39,928 with the cell side never packed.
  EXPECT_LE(g.ArenaEntries(), 4u * max_live) << "max live links " << max_live;
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
