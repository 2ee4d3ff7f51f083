// The 2D collar system of a facet plane and its restricted Delaunay (thesis
// §2.4.1 "arcs and points", Definitions 28–38 in 2D, Definition 37's (2,1) and
// (2,2) points; docs/svrc-collars.md "Facet collar arcs"): an iterative driver
// inserts ArcRepairs into a Delaunay2 until none remain, then the test checks
// independently that every (2,1) point is a vertex, each arc's restricted
// edges are one path/cycle through its on-arc vertices in arc order, all
// representation angles are ≤ σ, and the chords are edges of the mesh.
#include "core/svrc/collar_arcs.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "core/delaunay/delaunay2.h"
#include "core/geometry/predicates.h"
#include "gtest/gtest.h"

namespace svrc::refine {
namespace {

using delaunay::Delaunay2;
using VertexId2 = Delaunay2::VertexId;
constexpr double kPi = std::numbers::pi;

Vec3 Unit(Vec3 v) { return v / geom::Norm(v); }
double Len(Vec2 a) { return std::hypot(a.x, a.y); }

// A tilted orthonormal frame (u × v = normal), so the 2D ↔ 3D maps are exercised.
plc::FacetFrame TiltedFrame() {
  plc::FacetFrame f;
  f.origin = Vec3(0.25, -0.5, 1.75);
  f.normal = Unit(Vec3(1, 2, 3));
  f.u = Unit(geom::Cross(f.normal, Vec3(1, 0, 0)));
  f.v = geom::Cross(f.normal, f.u);
  return f;
}

Vec3 At(const plc::FacetFrame& f, double s, double t, double h) {
  return f.ToSpace(Vec2(s, t)) + h * f.normal;
}

// (i) one ball crossing the plane: a full circle.
std::vector<CollarBall> OneBall(const plc::FacetFrame& f) {
  return {CollarBall{At(f, 0.3, -0.2, 0.4), 1.0}};
}
// (ii) three balls centred on a line in the plane: circles cross pairwise.
std::vector<CollarBall> LineInPlane(const plc::FacetFrame& f) {
  return {CollarBall{At(f, -1.2, 0, 0), 0.8}, CollarBall{At(f, 0, 0, 0), 0.9},
          CollarBall{At(f, 1.2, 0, 0), 0.8}};
}
// (iii) a chain of graded balls on a segment crossing the plane at 30°: only
// those near the crossing meet the plane, with different circle radii.
std::vector<CollarBall> ObliqueChain(const plc::FacetFrame& f) {
  const Vec3 dir = std::cos(kPi / 6) * f.u + std::sin(kPi / 6) * f.normal;
  const Vec3 p = At(f, 0.1, 0.05, 0);
  std::vector<CollarBall> balls;
  for (int k = -3; k <= 3; ++k) {
    balls.push_back(CollarBall{p + (0.5 * k) * dir, 0.4 + 0.03 * k});
  }
  return balls;
}

struct Mesh {
  Delaunay2 dt = Delaunay2::Square(Vec2(-8, -8), Vec2(8, 8), {0, 1, 2, 3});
  uint32_t next_id = 4;
};

void AddBackground(Mesh* m, uint64_t seed, int n) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-3, 3);
  for (int i = 0; i < n; ++i) m->dt.Insert(Vec2(u(rng), u(rng)), m->next_id++);
}

// Checks a repair point: on its circle (1e-12 relative) and not strictly
// inside any other disk (exact); its 3D image on the sphere and the plane.
void CheckRepairPoint(const plc::FacetFrame& f, std::span<const CollarBall> balls,
                      const FacetCollarSystem& sys, const ArcRepair& r) {
  const PlaneCircle* own = nullptr;
  for (const PlaneCircle& c : sys.circles) {
    if (c.ball == r.ball) own = &c;
  }
  ASSERT_NE(own, nullptr);
  const double scale = own->radius + std::max(std::fabs(own->center.x), std::fabs(own->center.y));
  EXPECT_LE(std::fabs(Len(r.x - own->center) - own->radius), 1e-12 * scale)
      << ArcRepairReasonName(r.reason);
  for (const PlaneCircle& c : sys.circles) {
    if (c.ball == r.ball || c.ball == r.other_ball) continue;
    EXPECT_LE(geom::InBall(Vec3(r.x.x, r.x.y, 0), Vec3(c.center.x, c.center.y, 0), c.radius), 0);
  }
  if (r.collar_dim == 1) {
    const PlaneCircle* other = nullptr;
    for (const PlaneCircle& c : sys.circles) {
      if (c.ball == r.other_ball) other = &c;
    }
    ASSERT_NE(other, nullptr);
    EXPECT_LE(std::fabs(Len(r.x - other->center) - other->radius), 1e-12 * scale);
  }
  const Vec3 x = RepairToSpace(f, r);
  const CollarBall& b = balls[r.ball];
  EXPECT_LE(std::fabs(geom::Dist(x, b.center) - b.radius), 1e-12 * (b.radius + geom::Norm(b.center)));
  EXPECT_LE(std::fabs(geom::Dot(x - f.origin, f.normal)), 1e-12 * (1 + geom::Norm(x)));
}

struct DriveResult {
  int inserted = 0;
  int inserted21 = 0;
  int rounds = 0;
  bool converged = false;
  ArcReport last;
};

// The test's driver: per round, insert the repairs largest RepBall first,
// skipping one whose RepBall already holds a point inserted this round (it is
// no longer empty); repeat until no repairs (capped).
DriveResult Drive(const plc::FacetFrame& f, std::span<const CollarBall> balls,
                  const FacetCollarSystem& sys, double sigma, Mesh* m,
                  const ArcOptions& opts = {}, int max_rounds = 300) {
  DriveResult res;
  for (res.rounds = 0; res.rounds < max_rounds; ++res.rounds) {
    std::vector<ArcRepair> reps = ArcRepairs(m->dt, sys, sigma, &res.last, opts);
    if (reps.empty()) {
      res.converged = true;
      break;
    }
    for (const ArcRepair& r : reps) {
      CheckRepairPoint(f, balls, sys, r);
      // Never an existing vertex.
      const VertexId2 v = m->dt.NearestVertex(r.x);
      EXPECT_FALSE(m->dt.Point(v) == r.x);
    }
    std::stable_sort(reps.begin(), reps.end(),
                     [](const ArcRepair& a, const ArcRepair& b) { return a.radius > b.radius; });
    std::vector<Vec2> placed;
    for (const ArcRepair& r : reps) {
      bool stale = false;
      for (Vec2 y : placed) stale = stale || Len(y - r.x) < r.radius;
      if (stale) continue;
      const auto ins = m->dt.Insert(r.x, m->next_id++);
      if (ins.outcome != Delaunay2::InsertOutcome::kInserted) continue;
      placed.push_back(r.x);
      ++res.inserted;
      if (r.collar_dim == 1) ++res.inserted21;
    }
  }
  return res;
}

// Independent end checks (not through ArcRepairs' own bookkeeping).
// expect_chords: the path runs through on-arc vertices only (require_on_arc).
void CheckFinal(const plc::FacetFrame& f, std::span<const CollarBall> balls,
                const FacetCollarSystem& sys, const Delaunay2& dt, double sigma,
                bool expect_chords = true) {
  ASSERT_TRUE(dt.Validate().ok());
  // Every (2,1) point is a vertex.
  for (const Point21& p : sys.points21) {
    EXPECT_TRUE(dt.Point(dt.NearestVertex(p.x)) == p.x);
  }
  const std::vector<ArcEdge> edges = RestrictedArcEdges(dt, sys);
  const std::vector<ArcChain> chains = ArcChains(dt, sys);
  ASSERT_EQ(chains.size(), sys.arcs.size());
  std::vector<VertexId2> scratch;
  for (uint32_t a = 0; a < sys.arcs.size(); ++a) {
    const CollarArc& arc = sys.arcs[a];
    std::vector<ArcEdge> mine;
    for (const ArcEdge& e : edges) {
      if (e.arc == a) mine.push_back(e);
    }
    ASSERT_FALSE(mine.empty()) << "arc " << a;
    // Walk the restricted edges in arc order.
    std::vector<uint32_t> walk;
    if (arc.full) {
      const ArcEdge& first = mine.front();
      const ArcEdge& last = mine.back();
      const uint32_t start =
          (first.a == last.a || first.a == last.b) ? first.a.value() : first.b.value();
      walk.push_back(start);
    } else {
      walk.push_back(dt.NearestVertex(sys.points21[arc.end[0]].x).value());
    }
    for (const ArcEdge& e : mine) {
      EXPECT_EQ(e.crossings, 1u);
      EXPECT_LE(e.angle, sigma);
      const uint32_t cur = walk.back();
      ASSERT_TRUE(e.a.value() == cur || e.b.value() == cur) << "arc " << a << " path broken";
      walk.push_back(e.a.value() == cur ? e.b.value() : e.a.value());
    }
    if (arc.full) {
      ASSERT_EQ(walk.back(), walk.front());
      walk.pop_back();
      EXPECT_GE(walk.size(), 3u);
    } else {
      EXPECT_TRUE(dt.Point(VertexId2(walk.back())) == sys.points21[arc.end[1]].x);
    }
    // The walk is simple (each vertex once; a circle closes once).
    std::vector<uint32_t> sorted = walk;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end()) << "arc " << a;
    if (!expect_chords) continue;
    // The walk's vertices are exactly the on-arc vertices in arc order (for a
    // circle, up to rotation): a simple path through the chord chain.
    const ArcChain& chain = chains[a];
    EXPECT_TRUE(chain.complete) << "arc " << a;
    std::vector<uint32_t> chain_ids;
    for (VertexId2 v : chain.vertices) chain_ids.push_back(v.value());
    if (arc.full) {
      ASSERT_EQ(walk.size(), chain_ids.size());
      auto it = std::find(chain_ids.begin(), chain_ids.end(), walk.front());
      ASSERT_NE(it, chain_ids.end());
      std::rotate(chain_ids.begin(), it, chain_ids.end());
    }
    EXPECT_EQ(walk, chain_ids) << "arc " << a;
    // Each chord is a Delaunay edge.
    for (size_t i = 0; i + 1 < walk.size(); ++i) {
      dt.Neighbors(VertexId2(walk[i]), &scratch);
      EXPECT_NE(std::find(scratch.begin(), scratch.end(), VertexId2(walk[i + 1])), scratch.end());
    }
  }
  if (!expect_chords) return;
  EXPECT_TRUE(ArcChordsPresent(dt, sys));
  // Back in 3D the chains lie on their spheres and in the plane.
  for (const ArcChain3& c3 : ArcChainsToSpace(f, dt, sys, chains)) {
    const CollarBall& b = balls[c3.ball];
    for (const Vec3& x : c3.points) {
      EXPECT_LE(std::fabs(geom::Dist(x, b.center) - b.radius),
                1e-12 * (b.radius + geom::Norm(b.center)));
      EXPECT_LE(std::fabs(geom::Dot(x - f.origin, f.normal)), 1e-12 * (1 + geom::Norm(x)));
    }
  }
}

// --- The collar description ------------------------------------------------

TEST(CollarArcs, OneBallIsAFullCircle) {
  const plc::FacetFrame f = TiltedFrame();
  const auto balls = OneBall(f);
  const FacetCollarSystem sys = FacetCollars(f, balls);
  ASSERT_EQ(sys.circles.size(), 1u);
  EXPECT_NEAR(sys.circles[0].center.x, 0.3, 1e-14);
  EXPECT_NEAR(sys.circles[0].center.y, -0.2, 1e-14);
  EXPECT_NEAR(sys.circles[0].radius, std::sqrt(1 - 0.16), 1e-14);
  ASSERT_EQ(sys.arcs.size(), 1u);
  EXPECT_TRUE(sys.arcs[0].full);
  EXPECT_TRUE(sys.points21.empty());
  // A ball that misses the plane contributes nothing.
  const std::vector<CollarBall> far = {CollarBall{At(f, 0, 0, 2), 1.5}};
  EXPECT_TRUE(FacetCollars(f, far).circles.empty());
}

TEST(CollarArcs, LineOfThreeBallsGivesFourPointsAndFourArcs) {
  const plc::FacetFrame f = TiltedFrame();
  const auto balls = LineInPlane(f);
  const FacetCollarSystem sys = FacetCollars(f, balls);
  ASSERT_EQ(sys.circles.size(), 3u);
  EXPECT_EQ(sys.unmatched_ends, 0);
  ASSERT_EQ(sys.points21.size(), 4u);
  // x of the (0,1) crossing: h = (d² + r0² − r1²)/(2d) from centre −1.2.
  const double h01 = (1.44 + 0.64 - 0.81) / 2.4;
  for (const Point21& p : sys.points21) {
    const bool left = p.a == 0;
    EXPECT_NEAR(p.x.x, left ? -1.2 + h01 : 1.2 - h01, 1e-14);
    EXPECT_NEAR(std::fabs(p.x.y), std::sqrt(0.64 - h01 * h01), 1e-14);
    // On both spheres in 3D.
    const Vec3 x = f.ToSpace(p.x);
    EXPECT_NEAR(geom::Dist(x, balls[p.a].center), balls[p.a].radius, 1e-13);
    EXPECT_NEAR(geom::Dist(x, balls[p.b].center), balls[p.b].radius, 1e-13);
  }
  // Ball 0 and 2: one arc each; ball 1: an upper and a lower arc (the upper
  // one runs through CircleFrame's angle 0 and is joined back into one).
  int per_ball[3] = {0, 0, 0};
  for (uint32_t a = 0; a < sys.arcs.size(); ++a) {
    const CollarArc& arc = sys.arcs[a];
    ++per_ball[arc.ball];
    EXPECT_FALSE(arc.full);
    ASSERT_NE(arc.end[0], kNoArcIndex);
    ASSERT_NE(arc.end[1], kNoArcIndex);
    // Ends are exactly the (2,1) points; the middle is on S, just past the
    // ends is strictly inside another disk.
    EXPECT_TRUE(sys.ArcPoint(a, 0) == sys.points21[arc.end[0]].x);
    EXPECT_TRUE(sys.ArcPoint(a, arc.length) == sys.points21[arc.end[1]].x);
    EXPECT_TRUE(OnArc(sys.ArcPoint(a, 0.5 * arc.length), sys, a));
    const PlaneCircle& c = sys.circles[arc.circle];
    auto inside_other = [&](Vec2 p) {
      for (const PlaneCircle& o : sys.circles) {
        if (&o != &c && geom::InBall(Vec3(p.x, p.y, 0), Vec3(o.center.x, o.center.y, 0),
                                     o.radius) > 0) {
          return true;
        }
      }
      return false;
    };
    EXPECT_FALSE(inside_other(sys.ArcPoint(a, 0.5 * arc.length)));
    const Vec2 before(c.center.x + c.radius * std::cos(arc.t0 - 1e-3),
                      c.center.y + c.radius * std::sin(arc.t0 - 1e-3));
    const Vec2 after(c.center.x + c.radius * std::cos(arc.t0 + arc.length + 1e-3),
                     c.center.y + c.radius * std::sin(arc.t0 + arc.length + 1e-3));
    EXPECT_TRUE(inside_other(before));
    EXPECT_TRUE(inside_other(after));
  }
  EXPECT_EQ(per_ball[0], 1);
  EXPECT_EQ(per_ball[1], 2);
  EXPECT_EQ(per_ball[2], 1);
}

TEST(CollarArcs, ObliqueChainMeetsThePlaneInThreeCircles) {
  const plc::FacetFrame f = TiltedFrame();
  const auto balls = ObliqueChain(f);
  const FacetCollarSystem sys = FacetCollars(f, balls);
  // Heights 0.25·k: |h| < ρ only for k = −1, 0, 1 (balls 2, 3, 4).
  ASSERT_EQ(sys.circles.size(), 3u);
  EXPECT_EQ(sys.circles[0].ball, 2u);
  EXPECT_EQ(sys.circles[2].ball, 4u);
  EXPECT_EQ(sys.points21.size(), 4u);
  EXPECT_EQ(sys.arcs.size(), 4u);
  EXPECT_EQ(sys.unmatched_ends, 0);
}

// --- Restricted Delaunay, hand-checked ---------------------------------------

TEST(CollarArcs, RegularPolygonOnACircleHasZeroAngleChords) {
  plc::FacetFrame f;
  f.origin = Vec3(0, 0, 0);
  f.u = Vec3(1, 0, 0);
  f.v = Vec3(0, 1, 0);
  f.normal = Vec3(0, 0, 1);
  const std::vector<CollarBall> balls = {CollarBall{Vec3(0, 0, 0), 1.0}};
  const FacetCollarSystem sys = FacetCollars(f, balls);
  Mesh m;
  const int n = 12;
  for (int k = 0; k < n; ++k) {
    const double t = 2 * kPi * (k + 0.5) / n;
    m.dt.Insert(Vec2(std::cos(t), std::sin(t)), m.next_id++);
  }
  const std::vector<ArcEdge> edges = RestrictedArcEdges(m.dt, sys);
  ASSERT_EQ(edges.size(), static_cast<size_t>(n));
  for (const ArcEdge& e : edges) {
    EXPECT_NEAR(e.angle, 0, 1e-12);
    EXPECT_NEAR(e.rep_radius, 2 * std::sin(kPi / (2 * n)), 1e-12);
    EXPECT_EQ(e.crossings, 1u);
  }
  ArcReport rep;
  EXPECT_TRUE(ArcRepairs(m.dt, sys, 1e-6, &rep).empty());
  EXPECT_EQ(rep.restricted_edges, n);
  EXPECT_TRUE(ArcChordsPresent(m.dt, sys));
  CheckFinal(f, balls, sys, m.dt, 1e-6);
}

TEST(CollarArcs, RepairsOnAnEmptyMesh) {
  const plc::FacetFrame f = TiltedFrame();
  const auto balls = LineInPlane(f);
  const FacetCollarSystem sys = FacetCollars(f, balls);
  Mesh m;
  ArcReport rep;
  const std::vector<ArcRepair> reps = ArcRepairs(m.dt, sys, kPi / 6, &rep);
  EXPECT_EQ(rep.missing_points21, 4);
  // The (2,1) points come first, radius 0, collar dimension 1.
  ASSERT_GE(reps.size(), 4u);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(reps[i].reason, ArcRepairReason::kMissingPoint21);
    EXPECT_EQ(reps[i].collar_dim, 1);
    EXPECT_EQ(reps[i].radius, 0);
  }
  for (const ArcRepair& r : reps) CheckRepairPoint(f, balls, sys, r);
  EXPECT_FALSE(ArcChordsPresent(m.dt, sys));
}

TEST(CollarArcs, OffArcVertexIsRepaired) {
  // A vertex 1e-3 off a sampled circle sits in the restricted path: its
  // edges are flagged and their crossings inserted until it drops out.
  plc::FacetFrame f;
  f.origin = Vec3(0, 0, 0);
  f.u = Vec3(1, 0, 0);
  f.v = Vec3(0, 1, 0);
  f.normal = Vec3(0, 0, 1);
  const std::vector<CollarBall> balls = {CollarBall{Vec3(0, 0, 0.5), 1.0}};
  const FacetCollarSystem sys = FacetCollars(f, balls);
  const double r = sys.circles[0].radius;
  Mesh m;
  for (int k = 0; k < 16; ++k) {
    const double t = 2 * kPi * k / 16;
    m.dt.Insert(Vec2(r * std::cos(t), r * std::sin(t)), m.next_id++);
  }
  const double t = 2 * kPi * 0.5 / 16;
  m.dt.Insert(Vec2((r + 1e-3) * std::cos(t), (r + 1e-3) * std::sin(t)), m.next_id++);
  ArcReport rep;
  const auto reps = ArcRepairs(m.dt, sys, kPi / 4, &rep);
  EXPECT_EQ(rep.off_arc_edges, 2);
  EXPECT_FALSE(reps.empty());
  for (const ArcRepair& rp : reps) EXPECT_EQ(rp.reason, ArcRepairReason::kOffArcVertex);
  const DriveResult res = Drive(f, balls, sys, kPi / 4, &m);
  EXPECT_TRUE(res.converged);
  CheckFinal(f, balls, sys, m.dt, kPi / 4);
  // With Snap δ = 2e-3 the vertex counts as on the circle.
  ArcOptions snap;
  snap.snap = 2e-3;
  Mesh m2;
  for (int k = 0; k < 16; ++k) {
    const double tk = 2 * kPi * k / 16;
    m2.dt.Insert(Vec2(r * std::cos(tk), r * std::sin(tk)), m2.next_id++);
  }
  m2.dt.Insert(Vec2((r + 1e-3) * std::cos(t), (r + 1e-3) * std::sin(t)), m2.next_id++);
  ArcRepairs(m2.dt, sys, kPi / 4, &rep, snap);
  EXPECT_EQ(rep.off_arc_edges, 0);
}

TEST(CollarArcs, ConsistencyAloneAcceptsOneChordForALongArc) {
  // Line of three balls: the outer arcs span 262.8°. The thesis' criteria
  // (consistency + σ) accept the single chord between their (2,1) ends; the
  // default size test (eps = 1) makes every chord subtend ≤ 120°.
  const plc::FacetFrame f = TiltedFrame();
  const auto balls = LineInPlane(f);
  const FacetCollarSystem sys = FacetCollars(f, balls);
  ArcOptions pure;
  pure.require_on_arc = false;
  pure.eps = 0;
  Mesh m1;
  ASSERT_TRUE(Drive(f, balls, sys, kPi / 12, &m1, pure).converged);
  Mesh m2;
  ASSERT_TRUE(Drive(f, balls, sys, kPi / 12, &m2).converged);
  const auto c1 = ArcChains(m1.dt, sys);
  const auto c2 = ArcChains(m2.dt, sys);
  for (uint32_t a = 0; a < sys.arcs.size(); ++a) {
    if (sys.arcs[a].length < kPi) continue;
    EXPECT_NEAR(sys.arcs[a].length * 180 / kPi, 262.8, 0.1);
    EXPECT_TRUE(c1[a].complete);
    EXPECT_EQ(c1[a].vertices.size(), 2u);
    EXPECT_TRUE(c2[a].complete);
    const PlaneCircle& c = sys.circles[sys.arcs[a].circle];
    for (size_t i = 0; i + 1 < c2[a].vertices.size(); ++i) {
      const Vec2 p = m2.dt.Point(c2[a].vertices[i]) - c.center;
      const Vec2 q = m2.dt.Point(c2[a].vertices[i + 1]) - c.center;
      const double sub = std::atan2(p.x * q.y - p.y * q.x, p.x * q.x + p.y * q.y);
      EXPECT_GT(sub, 0);  // counter-clockwise along the arc
      EXPECT_LE(sub, 2 * kPi / 3 + 1e-12);
    }
  }
}

// --- The iterative driver on the scenarios (i)–(iv) -------------------------

struct Scenario {
  const char* name;
  std::vector<CollarBall> (*balls)(const plc::FacetFrame&);
  int background;  // random points in [−3, 3]² inserted first
  uint64_t seed;
};

class CollarArcsDrive : public ::testing::TestWithParam<Scenario> {};

TEST_P(CollarArcsDrive, ConvergesToAConsistentSampleWithChords) {
  const Scenario& sc = GetParam();
  const plc::FacetFrame f = TiltedFrame();
  const auto balls = sc.balls(f);
  const FacetCollarSystem sys = FacetCollars(f, balls);
  ASSERT_EQ(sys.unmatched_ends, 0);
  struct Mode {
    const char* name;
    ArcOptions opts;
    bool chords;
  };
  ArcOptions pure;
  pure.require_on_arc = false;
  pure.eps = 0;
  ArcOptions sized;
  sized.eps = 0.5;
  const Mode modes[] = {{"on_arc+eps1", ArcOptions{}, true},
                        {"on_arc+eps0.5", sized, true},
                        {"thesis_only", pure, false}};
  for (const Mode& mode : modes) {
    for (double deg : {15.0, 30.0, 45.0}) {
      const double sigma = deg * kPi / 180;
      Mesh m;
      AddBackground(&m, sc.seed, sc.background);
      const uint32_t before = m.dt.NumVertices();
      const DriveResult res = Drive(f, balls, sys, sigma, &m, mode.opts);
      ASSERT_TRUE(res.converged) << sc.name << " " << mode.name << " sigma=" << deg;
      EXPECT_EQ(m.dt.NumVertices() - before, static_cast<uint32_t>(res.inserted));
      const bool chords = ArcChordsPresent(m.dt, sys);
      std::printf("[arcs] %-14s %-14s sigma=%2.0f arcs=%zu p21=%zu inserted=%3d (2,1)=%d "
                  "rounds=%2d max_angle=%5.2f deg off_arc_edges=%d chords=%d\n",
                  sc.name, mode.name, deg, sys.arcs.size(), sys.points21.size(), res.inserted,
                  res.inserted21, res.rounds, res.last.max_angle * 180 / kPi,
                  res.last.off_arc_edges, chords ? 1 : 0);
      CheckFinal(f, balls, sys, m.dt, sigma, mode.chords);
      if (mode.opts.eps > 0) {
        for (const ArcEdge& e : RestrictedArcEdges(m.dt, sys)) {
          EXPECT_LE(e.rep_radius, mode.opts.eps * sys.circles[sys.arcs[e.arc].circle].radius);
        }
      }
    }
  }
}

// RestrictedArcEdges tests each Voronoi edge against the circles whose
// boxes meet its box, found in a grid; the output must be the all-circles
// output to the bit. An 8 x 8 lattice of disjoint balls with radii spread
// 0.04–0.3 (full circles), and one ball 5–40x the median (grid cells or the
// all-circles fallback), over a plane with 3000 background points.
TEST(CollarArcs, CircleGridGivesTheAllCirclesEdges) {
  const plc::FacetFrame f = TiltedFrame();
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> h(-0.03, 0.03), rad(0.04, 0.3);
  for (double big : {1.5, 12.0}) {
    std::vector<CollarBall> balls;
    for (int i = 0; i < 8; ++i) {
      for (int j = 0; j < 8; ++j) balls.push_back(CollarBall{At(f, -2.8 + 0.8 * i, -2.8 + 0.8 * j, h(rng)), rad(rng)});
    }
    balls.push_back(CollarBall{At(f, 5 + big, 0, 0), big});
    const FacetCollarSystem sys = FacetCollars(f, balls);
    ASSERT_EQ(sys.arcs.size(), 65u);
    Mesh m;
    AddBackground(&m, 21, 3000);
    const std::vector<ArcEdge> grid = RestrictedArcEdges(m.dt, sys);
    const std::vector<ArcEdge> all = RestrictedArcEdges(m.dt, sys, /*index_circles=*/false);
    ASSERT_EQ(grid.size(), all.size()) << "big=" << big;
    ASSERT_GT(all.size(), 500u);
    for (size_t i = 0; i < all.size(); ++i) {
      EXPECT_TRUE(grid[i].a == all[i].a && grid[i].b == all[i].b && grid[i].arc == all[i].arc &&
                  grid[i].x.x == all[i].x.x && grid[i].x.y == all[i].x.y && grid[i].s == all[i].s &&
                  grid[i].crossings == all[i].crossings && grid[i].angle == all[i].angle)
          << "edge " << i << " big=" << big;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    Scenarios, CollarArcsDrive,
    ::testing::Values(Scenario{"one_ball", OneBall, 0, 1},
                      Scenario{"line3", LineInPlane, 0, 1},
                      Scenario{"oblique30", ObliqueChain, 0, 1},
                      Scenario{"one_ball_bg", OneBall, 200, 7},
                      Scenario{"line3_bg", LineInPlane, 200, 11},
                      Scenario{"line3_bg2", LineInPlane, 400, 12},
                      Scenario{"oblique30_bg", ObliqueChain, 200, 13},
                      Scenario{"oblique30_bg2", ObliqueChain, 400, 14}),
    [](const ::testing::TestParamInfo<Scenario>& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace svrc::refine
