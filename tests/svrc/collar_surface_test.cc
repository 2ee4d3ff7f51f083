// Collar-surface sampling (stage (e), thesis §3.1.2, Definitions 30–38,
// Lemma 15): an iterative driver inserts CollarRepairs (largest RepBall first)
// until none is left, on a lone ball, a smooth chain, a vertex ball with two
// chains at 30° and chains among well-spread background points; at the end the
// restricted triangulation is closed with χ = 2 per component of S, each
// partial sphere a surface bounded by its circles, each circle one cycle, all
// angles ≤ σ. Prints the points inserted for σ = 15°, 30°, 45° and the size
// criterion (docs/svrc-collars.md "Collar surface sampling (stage e)").
#include "core/svrc/collar_surface.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "core/delaunay/delaunay3.h"
#include "core/geometry/predicates.h"
#include "gtest/gtest.h"

namespace svrc::refine {
namespace {

using delaunay::Delaunay3;
using delaunay::VertexId;

constexpr double kDeg = std::numbers::pi / 180;

struct Scene {
  std::string name;
  std::vector<CollarBall> balls;
  std::vector<Vec3> points;  // initial vertices
  int components = 1;        // connected components of S
};

void AddCorners(std::vector<Vec3>* pts, double lo, double hi) {
  for (int c = 0; c < 8; ++c) {
    pts->push_back(Vec3(c & 1 ? hi : lo, c & 2 ? hi : lo, c & 4 ? hi : lo));
  }
}

Vec3 RandomUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0, 1);
  for (;;) {
    Vec3 v(n(rng), n(rng), n(rng));
    const double l = geom::Norm(v);
    if (l > 1e-6) return v / l;
  }
}

// Lemma 13 (only the listed pairs of balls meet) and Lemma 14 (those pairs
// are smooth: |c1c2|² ≤ r1² + r2², and their spheres cross).
void ExpectCollarSystem(const std::vector<CollarBall>& b,
                        const std::vector<std::pair<int, int>>& meeting) {
  for (int i = 0; i < static_cast<int>(b.size()); ++i) {
    for (int j = i + 1; j < static_cast<int>(b.size()); ++j) {
      const double d = geom::Dist(b[i].center, b[j].center);
      const bool listed = std::find(meeting.begin(), meeting.end(), std::pair(i, j)) !=
                          meeting.end();
      if (listed) {
        EXPECT_LT(d, b[i].radius + b[j].radius) << i << "," << j;
        EXPECT_GT(d, std::fabs(b[i].radius - b[j].radius)) << i << "," << j;
        EXPECT_LE(d * d, b[i].radius * b[i].radius + b[j].radius * b[j].radius) << i << "," << j;
      } else {
        EXPECT_GE(d, b[i].radius + b[j].radius) << i << "," << j;
      }
    }
  }
}

// (i) One ball, only its centre inside; far points and cube corners.
Scene LoneBall() {
  Scene s{"lone ball", {{Vec3(0.1, -0.2, 0.05), 1.0}}, {}, 1};
  s.points.push_back(s.balls[0].center);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(3, 5);
  for (int i = 0; i < 12; ++i) s.points.push_back(s.balls[0].center + u(rng) * RandomUnit(rng));
  AddCorners(&s.points, -10, 10);
  return s;
}

// (ii) Four balls centred on a segment along x, consecutive spheres crossing.
Scene Chain() {
  Scene s{"chain of 4", {{Vec3(0, 0, 0), 0.55}, {Vec3(0.8, 0, 0), 0.6},
                         {Vec3(1.65, 0, 0), 0.62}, {Vec3(2.45, 0, 0), 0.52}}, {}, 1};
  ExpectCollarSystem(s.balls, {{0, 1}, {1, 2}, {2, 3}});
  // The crease: its endpoints and the centres (crease vertices).
  s.points.push_back(Vec3(-1.5, 0, 0));
  for (const CollarBall& b : s.balls) s.points.push_back(b.center);
  s.points.push_back(Vec3(4, 0, 0));
  AddCorners(&s.points, -6, 8);
  return s;
}

// (iii) A vertex ball at the origin and two chains along segments at 30°:
// r = 0.22·d, d_{k+1} = 1.3·d_k (smooth and only consecutive balls meet;
// chains 2·d·sin 15° apart > 2·0.22·d).
Scene VertexAndTwoChains() {
  Scene s{"vertex + 2 chains at 30 deg", {{Vec3(0, 0, 0), 0.95}}, {}, 1};
  const Vec3 dirs[2] = {Vec3(1, 0, 0), Vec3(std::cos(30 * kDeg), std::sin(30 * kDeg), 0)};
  std::vector<std::pair<int, int>> meeting;
  for (const Vec3& u : dirs) {
    double d = 0.95;
    int prev = 0;
    for (int k = 0; k < 4; ++k) {
      s.balls.push_back({d * u, 0.22 * d});
      const int cur = static_cast<int>(s.balls.size()) - 1;
      meeting.push_back({prev, cur});
      prev = cur;
      d *= 1.3;
    }
    s.points.push_back(3.0 * u);  // the segment's far end
  }
  ExpectCollarSystem(s.balls, meeting);
  for (const CollarBall& b : s.balls) s.points.push_back(b.center);
  AddCorners(&s.points, -5, 6);
  return s;
}

// (iv) Scene plus a jittered grid of spacing h over its bounding box (+ margin):
// well-spread points inside and outside the balls.
Scene WithBackground(Scene s, double h, uint64_t seed, int margin = 1) {
  s.name += " + grid";
  Vec3 lo(1e9, 1e9, 1e9), hi(-1e9, -1e9, -1e9);
  for (const CollarBall& b : s.balls) {
    lo = Vec3(std::min(lo.x, b.center.x - b.radius), std::min(lo.y, b.center.y - b.radius),
              std::min(lo.z, b.center.z - b.radius));
    hi = Vec3(std::max(hi.x, b.center.x + b.radius), std::max(hi.y, b.center.y + b.radius),
              std::max(hi.z, b.center.z + b.radius));
  }
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> j(-0.25 * h, 0.25 * h);
  const double m = margin * h;
  for (double x = lo.x - m; x <= hi.x + m; x += h) {
    for (double y = lo.y - m; y <= hi.y + m; y += h) {
      for (double z = lo.z - m; z <= hi.z + m; z += h) {
        s.points.push_back(Vec3(x + j(rng), y + j(rng), z + j(rng)));
      }
    }
  }
  return s;
}

struct DriverResult {
  int rounds = 0;
  int inserted = 0;
  int stale = 0;
  int by_reason[4] = {0, 0, 0, 0};  // inserted, by CollarRepair::Reason
  bool converged = false;
  double seconds = 0;
  CollarSurfaceReport last;
};

// The refiner's COLLAR loop in miniature: compute the repairs, insert them
// largest radius first, skipping one whose RepBall an earlier insertion of the
// round already destroyed (a stale event); repeat until none is left.
DriverResult Drive(Delaunay3* dt, uint32_t* next_id, const CollarDescription& cd,
                   const CollarSurfaceOptions& opt, int max_rounds, int max_points) {
  DriverResult r;
  const auto t0 = std::chrono::steady_clock::now();
  for (r.rounds = 0; r.rounds < max_rounds && r.inserted < max_points; ++r.rounds) {
    const std::vector<CollarRepair> reps = CollarRepairs(*dt, cd, opt, &r.last);
    if (reps.empty()) {
      r.converged = true;
      break;
    }
    for (size_t i = 1; i < reps.size(); ++i) EXPECT_GE(reps[i - 1].radius, reps[i].radius);
    for (const CollarRepair& rp : reps) {
      // On S, exactly: on its sphere (to rounding) and not strictly inside
      // another ball; a circle point on both spheres of its circle.
      const CollarBall& b = cd.balls[rp.ball];
      EXPECT_NEAR(geom::Dist(rp.x, b.center), b.radius, 1e-12 * b.radius);
      EXPECT_GT(rp.radius, 0);
      if (rp.collar_dim == 1) {
        const CollarCircle& cc = cd.circles[rp.circle];
        EXPECT_TRUE(rp.ball == cc.a);
        const CollarBall& b2 = cd.balls[cc.b];
        EXPECT_NEAR(geom::Dist(rp.x, b2.center), b2.radius, 1e-12 * b2.radius);
        for (uint32_t j = 0; j < cd.balls.size(); ++j) {
          if (j == cc.a || j == cc.b) continue;
          EXPECT_LE(geom::InBall(rp.x, cd.balls[j].center, cd.balls[j].radius), 0);
        }
      } else {
        EXPECT_EQ(rp.collar_dim, 2);
        EXPECT_TRUE(OnCollarSurface(rp.x, rp.ball, cd.balls));
      }
      const VertexId nv = dt->NearestVertex(rp.x);
      if (geom::Dist(rp.x, dt->Point(nv)) < rp.radius * (1 - 1e-9)) {
        ++r.stale;
        continue;
      }
      const auto ins = dt->Insert(rp.x, (*next_id)++);
      EXPECT_EQ(ins.outcome, Delaunay3::InsertOutcome::kInserted);
      ++r.inserted;
      ++r.by_reason[rp.reason];
    }
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

Delaunay3 Build(const Scene& s, uint32_t* next_id) {
  Delaunay3 dt;
  *next_id = 0;
  for (const Vec3& p : s.points) dt.Insert(p, (*next_id)++);
  return dt;
}

using Triple = std::array<uint32_t, 3>;

std::vector<Triple> Triples(const std::vector<RestrictedTriangle>& tris, uint32_t ball) {
  std::vector<Triple> out;
  for (const RestrictedTriangle& t : tris) {
    if (t.ball == ball) out.push_back({t.v[0].value(), t.v[1].value(), t.v[2].value()});
  }
  std::sort(out.begin(), out.end());
  return out;
}

// The end state: everything the stage (e) guide asks for, checked with the
// independent validator and full scans, not only with CollarRepairs itself.
void CheckFinal(const Delaunay3& dt, const CollarDescription& cd, const CollarSurfaceOptions& opt,
                const Scene& s, const DriverResult& r) {
  ASSERT_TRUE(r.converged) << s.name << ": " << r.rounds << " rounds, " << r.inserted;
  const CollarSurfaceReport& rep = r.last;
  EXPECT_TRUE(rep.consistent) << s.name << " roots " << rep.bad_roots << " facets " << rep.bad_facets
                              << " links " << rep.bad_links << " empty " << rep.empty_spheres
                              << " circles " << rep.bad_circles << " bnd " << rep.bad_boundaries
                              << " inserted " << r.inserted << " rounds " << r.rounds;
  EXPECT_EQ(rep.num_components, s.components);
  EXPECT_EQ(rep.triangulation_components, s.components);
  for (int chi : rep.euler_per_component) EXPECT_EQ(chi, 2) << s.name;
  if (!opt.size_criterion) {
    EXPECT_LE(rep.worst_angle, opt.sigma);
    EXPECT_LE(rep.worst_circle_angle, opt.sigma);
  }
  const CollarRestriction res = ComputeCollarRestriction(dt, cd, opt);
  // Local search = full scan; snapping changes no restricted simplex.
  CollarSurfaceOptions full = opt;
  full.local_search = false;
  CollarSurfaceOptions nosnap = opt;
  nosnap.delta = 0;
  const CollarRestriction res_full = ComputeCollarRestriction(dt, cd, full);
  const CollarRestriction res_nosnap = ComputeCollarRestriction(dt, cd, nosnap);
  for (uint32_t i = 0; i < cd.balls.size(); ++i) {
    const std::vector<Triple> t = Triples(res.triangles, i);
    EXPECT_EQ(t, Triples(res_full.triangles, i)) << "ball " << i;
    EXPECT_EQ(t, Triples(res_nosnap.triangles, i)) << "ball " << i;
    EXPECT_EQ(t, Triples(RestrictedSphereTriangles(dt, cd.balls, i), i)) << "ball " << i;
    // Each partial sphere: a surface whose boundary is its circles' cycles
    // (the validator's (a)–(e) with those circles), χ = 2 − #circles.
    std::vector<std::vector<RestrictedEdge>> circles;
    for (uint32_t k : cd.circles_of_ball[i]) {
      if (res.circle_state[k] != 0) circles.push_back(res.circle_edges[k]);
    }
    std::vector<RestrictedTriangle> mine;
    for (const RestrictedTriangle& tr : res.triangles) {
      if (tr.ball == i) mine.push_back(tr);
    }
    TopologyReport tr;
    const absl::Status st = ValidateRestrictedTopology(mine, circles, &tr);
    EXPECT_TRUE(st.ok()) << s.name << " ball " << i << ": " << st;
    EXPECT_EQ(tr.euler, 2 - static_cast<int>(circles.size())) << s.name << " ball " << i;
    EXPECT_EQ(rep.euler_per_ball[i], tr.euler);
  }
  for (uint32_t k = 0; k < cd.circles.size(); ++k) {
    ASSERT_EQ(res.circle_edges[k].size(), res_full.circle_edges[k].size()) << "circle " << k;
    for (size_t e = 0; e < res.circle_edges[k].size(); ++e) {
      EXPECT_EQ(res.circle_edges[k][e].v[0], res_full.circle_edges[k][e].v[0]);
      EXPECT_EQ(res.circle_edges[k][e].v[1], res_full.circle_edges[k][e].v[1]);
    }
    EXPECT_EQ(res.circle_edges[k].size(), res_nosnap.circle_edges[k].size());
    if (res.circle_state[k] == 0) continue;
    EXPECT_EQ(res.circle_state[k], 1) << "no partly covered circle in these scenes";
    EXPECT_GE(res.circle_edges[k].size(), 3u);
    for (const RestrictedEdge& e : res.circle_edges[k]) {
      EXPECT_NEAR(geom::Dist(e.x, cd.circles[k].circle.center), cd.circles[k].circle.radius,
                  1e-12);
    }
  }
}

struct Row {
  std::string scene, mode;
  uint32_t start = 0, end = 0;
  int inserted = 0, rounds = 0;
  int by_reason[4] = {0, 0, 0, 0};
  double seconds = 0, worst = 0;
  double local_ms = 0, full_ms = 0;  // one ComputeCollarRestriction at the end
  uint64_t candidates = 0;
};

Row RunOne(const Scene& s, const CollarSurfaceOptions& opt, const std::string& mode) {
  uint32_t id = 0;
  Delaunay3 dt = Build(s, &id);
  const CollarDescription cd = BuildCollarDescription(s.balls);
  Row row{s.name, mode, dt.NumVertices()};
  const DriverResult r = Drive(&dt, &id, cd, opt, 200, 60000);
  CheckFinal(dt, cd, opt, s, r);
  row.end = dt.NumVertices();
  row.inserted = r.inserted;
  row.rounds = r.rounds;
  for (int k = 0; k < 4; ++k) row.by_reason[k] = r.by_reason[k];
  row.seconds = r.seconds;
  row.worst = std::max(r.last.worst_angle, r.last.worst_circle_angle) / kDeg;
  row.candidates = r.last.candidates;
  CollarSurfaceOptions full = opt;
  full.local_search = false;
  for (int pass = 0; pass < 2; ++pass) {
    const auto t0 = std::chrono::steady_clock::now();
    const CollarRestriction res = ComputeCollarRestriction(dt, cd, pass == 0 ? opt : full);
    const double ms =
        1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    (pass == 0 ? row.local_ms : row.full_ms) = ms;
  }
  return row;
}

CollarSurfaceOptions Sigma(double deg) {
  CollarSurfaceOptions o;
  o.sigma = deg * kDeg;
  return o;
}

CollarSurfaceOptions SizeMode() {
  CollarSurfaceOptions o;
  o.size_criterion = true;
  return o;
}

TEST(CollarSurfaceTest, LoneBallFromCentreOnly) {
  const Scene s = LoneBall();
  RunOne(s, Sigma(30), "30");
}

TEST(CollarSurfaceTest, SmoothChain) {
  for (double deg : {15.0, 30.0, 45.0}) RunOne(Chain(), Sigma(deg), "deg");
}

TEST(CollarSurfaceTest, VertexBallWithTwoChainsAt30Degrees) {
  RunOne(VertexAndTwoChains(), Sigma(30), "30");
}

TEST(CollarSurfaceTest, ChainInWellSpreadBackground) {
  RunOne(WithBackground(Chain(), 0.4, 7), Sigma(30), "30");
}

TEST(CollarSurfaceTest, SizeCriterion) {
  RunOne(WithBackground(Chain(), 0.4, 7), SizeMode(), "size");
}

// CollarRepairs' size test reads css(x) from the balls within 3ρ of x's own
// ball, found through the balls sorted by centre x; it must equal
// CollarSurfaceSize over every ball. Checked on the ratio and count it
// reports, against a full computation, on balls of two sizes that overlap.
TEST(CollarSurfaceTest, SizeTestReadsTheCollarSurfaceSizeOfAllBalls) {
  // A ball of radius 1 with eight balls of radius 0.2 around its equator,
  // centred 1.1 from its centre: next to them, css(x) on the big sphere is
  // their term |x c_j| < 1, not the big ball's own radius.
  Scene s;
  s.name = "big ball + 8 small";
  s.balls.push_back({Vec3(0, 0, 0), 1.0});
  for (int k = 0; k < 8; ++k) {
    const double a = k * std::numbers::pi / 4 + 0.1;
    s.balls.push_back({Vec3(1.1 * std::cos(a), 1.1 * std::sin(a), 0), 0.2});
  }
  s = WithBackground(s, 0.15, 7);
  uint32_t next = 0;
  const Delaunay3 dt = Build(s, &next);
  const CollarDescription cd = BuildCollarDescription(s.balls);
  CollarSurfaceOptions opt = SizeMode();
  const CollarRestriction res = ComputeCollarRestriction(dt, cd, opt, nullptr);
  // Every representation ball's radius over css(x), from all the balls.
  std::vector<double> ratios;
  int from_other = 0;  // triangles whose css is another ball's term
  for (const RestrictedTriangle& t : res.triangles) {
    const double css = CollarSurfaceSize(t.x, cd);
    ratios.push_back(t.rep_radius / css);
    from_other += css < s.balls[t.ball].radius;
  }
  for (uint32_t k = 0; k < cd.circles.size(); ++k) {
    for (const RestrictedEdge& e : res.circle_edges[k]) {
      ratios.push_back(geom::Dist(e.x, dt.Point(e.v[0])) / CollarSurfaceSize(e.x, cd));
    }
  }
  ASSERT_GT(res.triangles.size(), 100u);
  EXPECT_GT(from_other, static_cast<int>(res.triangles.size() / 10));
  // ε_s at the median ratio: about half the balls fail the test.
  std::vector<double> sorted = ratios;
  std::sort(sorted.begin(), sorted.end());
  opt.eps_s = sorted[sorted.size() / 2];
  const int too_big = static_cast<int>(std::count_if(ratios.begin(), ratios.end(), [&](double r) { return r > opt.eps_s; }));
  CollarSurfaceReport rep;
  CollarRepairs(dt, cd, opt, &rep, nullptr);
  EXPECT_EQ(rep.too_big, too_big);
  EXPECT_EQ(rep.max_rep_ratio, sorted.back());
}

TEST(CollarSurfaceTest, ReportsTheViolationAndWhere) {
  // A lone centre vertex: the sphere is inside one cell, (d) fires and names a
  // sphere point; after it, the repairs are RepBall centres or circle points.
  const Scene s = LoneBall();
  uint32_t id = 0;
  Delaunay3 dt = Build(s, &id);
  const CollarDescription cd = BuildCollarDescription(s.balls);
  CollarSurfaceReport rep;
  const std::vector<CollarRepair> reps = CollarRepairs(dt, cd, Sigma(30), &rep);
  ASSERT_EQ(reps.size(), 1u);
  EXPECT_EQ(rep.empty_spheres, 1);
  EXPECT_FALSE(rep.consistent);
  EXPECT_EQ(reps[0].reason, CollarRepair::kTopology);
  EXPECT_EQ(reps[0].collar_dim, 2);
  EXPECT_NEAR(reps[0].radius, 1.0, 1e-12);  // the centre is the nearest vertex
}

// Whether two restrictions are the same to the bit (vertices, roots, angles,
// radii, candidates, circle edges and states).
bool SameRestriction(const CollarRestriction& a, const CollarRestriction& b, std::string* why) {
  auto same_vec = [](const Vec3& p, const Vec3& q) { return p.x == q.x && p.y == q.y && p.z == q.z; };
  if (a.triangles.size() != b.triangles.size()) {
    *why = "triangle count " + std::to_string(a.triangles.size()) + " vs " + std::to_string(b.triangles.size());
    return false;
  }
  for (size_t i = 0; i < a.triangles.size(); ++i) {
    const RestrictedTriangle& s = a.triangles[i];
    const RestrictedTriangle& t = b.triangles[i];
    if (s.ball != t.ball || s.v[0] != t.v[0] || s.v[1] != t.v[1] || s.v[2] != t.v[2] || !same_vec(s.x, t.x) ||
        s.angle != t.angle || s.rep_radius != t.rep_radius || s.num_roots != t.num_roots) {
      *why = "triangle " + std::to_string(i);
      return false;
    }
  }
  if (a.candidates_per_ball != b.candidates_per_ball) {
    *why = "candidates";
    return false;
  }
  if (a.circle_state != b.circle_state || a.circle_params != b.circle_params) {
    *why = "circle states or params";
    return false;
  }
  for (size_t k = 0; k < a.circle_edges.size(); ++k) {
    if (a.circle_edges[k].size() != b.circle_edges[k].size()) {
      *why = "circle " + std::to_string(k);
      return false;
    }
    for (size_t e = 0; e < a.circle_edges[k].size(); ++e) {
      const RestrictedEdge& s = a.circle_edges[k][e];
      const RestrictedEdge& t = b.circle_edges[k][e];
      if (s.v[0] != t.v[0] || s.v[1] != t.v[1] || !same_vec(s.x, t.x) || s.angle != t.angle) {
        *why = "circle " + std::to_string(k) + " edge " + std::to_string(e);
        return false;
      }
    }
  }
  return true;
}

// The refiner's COLLAR rounds keep a CollarRestrictionCache: a ball whose
// read cells kept their generations reuses its last triangles. Round by round
// of the driver, the cached restriction must equal a fresh one to the bit,
// and most balls must be reused once the repairs become local. With a
// generation function that never moves (a broken dependency record), the
// cached result must go wrong: the comparison can fail.
struct CacheRun {
  int rounds = 0, mismatches = 0;
  uint64_t computed = 0, reused = 0;
  uint64_t owners_computed = 0, owners_reused = 0;
  uint64_t circle_owners_computed = 0, circle_owners_reused = 0;
  std::string first_why;
};

// Inserts at most `per_round` repairs a round (largest first), so that later
// rounds leave most balls untouched, as the refiner's tail rounds do.
CacheRun DriveWithCache(const Scene& s, bool track_generations, size_t per_round, int max_rounds) {
  uint32_t id = 0;
  Delaunay3 dt = Build(s, &id);
  const CollarDescription cd = BuildCollarDescription(s.balls);
  const CollarSurfaceOptions opt = Sigma(30);
  std::vector<uint32_t> gen(dt.NumVertices(), 0);
  CollarRestrictionCache cache;
  cache.generation = [&](uint32_t v) { return v < gen.size() ? gen[v] : 0u; };
  CacheRun run;
  for (run.rounds = 0; run.rounds < max_rounds; ++run.rounds) {
    const CollarRestriction cached = ComputeCollarRestriction(dt, cd, opt, &cache);
    const CollarRestriction fresh = ComputeCollarRestriction(dt, cd, opt);
    std::string why;
    if (!SameRestriction(cached, fresh, &why)) {
      if (run.mismatches++ == 0) run.first_why = "round " + std::to_string(run.rounds) + ": " + why;
    }
    // The repairs drive the mesh, as in Drive (their restriction comes from
    // the cache, every ball reused: nothing moved since the line above).
    const std::vector<CollarRepair> reps = CollarRepairs(dt, cd, opt, nullptr, &cache);
    if (reps.empty()) break;
    size_t taken = 0;
    for (const CollarRepair& rp : reps) {
      if (taken == per_round) break;
      const VertexId nv = dt.NearestVertex(rp.x);
      if (geom::Dist(rp.x, dt.Point(nv)) < rp.radius * (1 - 1e-9)) continue;
      ++taken;
      const auto ins = dt.Insert(rp.x, id++);
      if (ins.outcome != Delaunay3::InsertOutcome::kInserted) continue;
      gen.resize(dt.NumVertices(), 0);
      if (track_generations) {
        for (VertexId u : ins.cavity_vertices) ++gen[u.value()];
      }
    }
  }
  // Of the first call of each round (CollarRepairs' call reuses every ball).
  run.computed = cache.balls_computed;
  run.owners_computed = cache.owners_computed;
  run.owners_reused = cache.owners_reused;
  run.circle_owners_computed = cache.circle_owners_computed;
  run.circle_owners_reused = cache.circle_owners_reused;
  run.reused = cache.balls_reused - static_cast<uint64_t>(run.rounds) * s.balls.size();
  return run;
}

// Ten balls along x, consecutive ones crossing (|c1c2|² = 0.25 ≤ 2·0.4²).
Scene LongChain() {
  Scene s{"chain of 10", {}, {}, 1};
  std::vector<std::pair<int, int>> meeting;
  for (int k = 0; k < 10; ++k) {
    s.balls.push_back({Vec3(0.5 * k, 0, 0), 0.4});
    if (k > 0) meeting.push_back({k - 1, k});
  }
  ExpectCollarSystem(s.balls, meeting);
  s.points.push_back(Vec3(-1.5, 0, 0));
  for (const CollarBall& b : s.balls) s.points.push_back(b.center);
  s.points.push_back(Vec3(6, 0, 0));
  AddCorners(&s.points, -4, 9);
  return s;
}

TEST(CollarSurfaceTest, CachedRestrictionEqualsFreshRoundByRound) {
  // Grids reaching 4 spacings past the balls: the box corners' big tets
  // (every ball's candidates when the grid ends at the spheres) stay apart.
  for (const Scene& s : {WithBackground(LongChain(), 0.3, 3, 4), WithBackground(VertexAndTwoChains(), 0.3, 5, 4)}) {
    const CacheRun run = DriveWithCache(s, /*track_generations=*/true, /*per_round=*/1, /*max_rounds=*/40);
    EXPECT_EQ(run.mismatches, 0) << s.name << ": " << run.first_why;
    EXPECT_GT(run.rounds, 3) << s.name;
    // One repair a round changes the cells of a few balls only: at most half
    // of the balls are computed again (measured: 172 of 400, 150 of 360).
    EXPECT_LE(2 * run.computed, static_cast<uint64_t>(run.rounds) * s.balls.size()) << s.name;
    // Inside a computed ball most owners' triangles are taken from its last
    // computation (a repair changes a few stars), and the result is still
    // the fresh one (mismatches above).
    EXPECT_GT(run.owners_reused, run.owners_computed) << s.name;
    EXPECT_GT(run.circle_owners_reused, run.circle_owners_computed) << s.name;
    std::printf("%s: %d rounds, balls computed %llu, reused %llu; owners computed %llu, reused %llu; circle owners "
                "computed %llu, reused %llu\n",
                s.name.c_str(), run.rounds, static_cast<unsigned long long>(run.computed),
                static_cast<unsigned long long>(run.reused), static_cast<unsigned long long>(run.owners_computed),
                static_cast<unsigned long long>(run.owners_reused),
                static_cast<unsigned long long>(run.circle_owners_computed),
                static_cast<unsigned long long>(run.circle_owners_reused));
  }
  const CacheRun broken = DriveWithCache(WithBackground(LongChain(), 0.3, 3, 4), /*track_generations=*/false, 1, 10);
  EXPECT_GT(broken.mismatches, 0) << "a cache that never sees a cell change must return stale triangles";
}

// The measurement asked for by issue #6: points inserted per σ and for the
// size criterion. Printed; the assertions are those of CheckFinal. ~8 s
// release, so not in the core run: --gtest_also_run_disabled_tests
// --gtest_filter='*Measure*'.
TEST(CollarSurfaceTest, DISABLED_MeasureSigmaAndSizeCriterion) {
  std::vector<Row> rows;
  const std::vector<Scene> scenes = {LoneBall(), Chain(), VertexAndTwoChains(),
                                     WithBackground(Chain(), 0.3, 7),
                                     WithBackground(VertexAndTwoChains(), 0.25, 8)};
  for (const Scene& s : scenes) {
    for (double deg : {15.0, 30.0, 45.0}) {
      rows.push_back(RunOne(s, Sigma(deg), std::to_string(static_cast<int>(deg)) + " deg"));
    }
    rows.push_back(RunOne(s, SizeMode(), "size eps_s=0.3"));
  }
  std::printf(
      "| scene | criterion | vertices before | inserted | topology/angle/circle/size | rounds | "
      "worst angle | ms | restriction local/full ms (candidates/vertices) |\n");
  for (const Row& r : rows) {
    std::printf("| %s | %s | %u | %d | %d/%d/%d/%d | %d | %.1f | %.0f | %.1f/%.1f (%llu/%u) |\n",
                r.scene.c_str(), r.mode.c_str(), r.start, r.inserted, r.by_reason[0],
                r.by_reason[1], r.by_reason[2], r.by_reason[3], r.rounds, r.worst,
                1e3 * r.seconds, r.local_ms, r.full_ms,
                static_cast<unsigned long long>(r.candidates), r.end);
  }
}

}  // namespace
}  // namespace svrc::refine

namespace svrc::refine {
namespace {

// The definition, written plainly: no repeated edge (either direction), every
// vertex of degree 2 (a loop counts 2) or, with exact_degrees false, as many
// vertices as edges; connected by a search; ≥ min vertices.
bool OneCycleByDegrees(const std::vector<std::pair<uint32_t, uint32_t>>& e, size_t min_vertices, bool exact_degrees) {
  if (e.empty()) return false;
  std::set<std::pair<uint32_t, uint32_t>> seen;
  std::map<uint32_t, std::vector<uint32_t>> adj;
  for (auto [a, b] : e) {
    if (!seen.insert(std::minmax(a, b)).second) return false;
    adj[a].push_back(b);
    adj[b].push_back(a);
  }
  for (const auto& [v, n] : adj) {
    if (exact_degrees && n.size() != 2) return false;
  }
  if (adj.size() != e.size()) return false;
  std::set<uint32_t> reached{adj.begin()->first};
  std::vector<uint32_t> stack{adj.begin()->first};
  while (!stack.empty()) {
    const uint32_t v = stack.back();
    stack.pop_back();
    for (uint32_t w : adj[v]) {
      if (reached.insert(w).second) stack.push_back(w);
    }
  }
  return reached.size() == adj.size() && adj.size() >= min_vertices;
}

// The link/circle test: what it accepts and rejects, exact and by average
// degree (the lollipop: accepted by every caller until session 21), the
// stack-array version against the allocating one and both against the
// definition on random small graphs, and past 48 edges.
TEST(CollarSurfaceTest, CycleTestAnswersAsTheReference) {
  using E = std::vector<std::pair<uint32_t, uint32_t>>;
  for (bool exact : {true, false}) {
    EXPECT_TRUE(detail::IsOneCycle(E{{7, 3}, {3, 9}, {9, 7}}, 3, exact));
    EXPECT_TRUE(detail::IsOneCycle(E{{1, 2}, {4, 1}, {3, 4}, {2, 3}}, 3, exact));
    EXPECT_FALSE(detail::IsOneCycle(E{{7, 3}, {3, 9}, {9, 7}}, 4, exact));                       // too few vertices
    EXPECT_FALSE(detail::IsOneCycle(E{{1, 2}, {2, 3}, {3, 4}}, 3, exact));                       // a path
    EXPECT_FALSE(detail::IsOneCycle(E{{1, 2}, {2, 3}, {3, 1}, {4, 5}, {5, 6}, {6, 4}}, 3, exact));  // two cycles
    EXPECT_FALSE(detail::IsOneCycle(E{{1, 2}, {2, 1}, {2, 3}, {3, 1}}, 3, exact));               // a repeated edge
    EXPECT_FALSE(detail::IsOneCycle(E{}, 0, exact));
  }
  // Degrees 1, 3, 2, 2 (a lollipop) and 1, 3, 2, 3, 1 (a triangle with two
  // tails): connected, as many vertices as edges.
  for (const E& e : {E{{1, 2}, {2, 3}, {2, 4}, {3, 4}}, E{{1, 2}, {2, 3}, {3, 4}, {4, 2}, {4, 5}}}) {
    EXPECT_FALSE(detail::IsOneCycle(e, 3, true));
    EXPECT_FALSE(detail::IsOneCycleGeneral(e, 3, true));
    EXPECT_TRUE(detail::IsOneCycle(e, 3, false));
    EXPECT_TRUE(detail::IsOneCycleGeneral(e, 3, false));
  }
  std::mt19937_64 rng(3);
  int trues[2] = {0, 0};
  for (int it = 0; it < 200000; ++it) {
    const uint32_t nv = 1 + rng() % 9, ne = 1 + rng() % 10;
    E e;
    if (it % 3 == 0) {
      for (uint32_t i = 0; i < nv; ++i) e.push_back({100 + i, 100 + (i + 1) % nv});
      if (rng() % 2) e.push_back({100 + static_cast<uint32_t>(rng() % nv), 100 + static_cast<uint32_t>(rng() % nv)});
      if (rng() % 2) e.erase(e.begin() + static_cast<long>(rng() % e.size()));
    } else {
      for (uint32_t i = 0; i < ne; ++i) e.push_back({static_cast<uint32_t>(rng() % nv), static_cast<uint32_t>(rng() % nv)});
    }
    std::shuffle(e.begin(), e.end(), rng);
    const size_t mv = rng() % 5;
    for (bool exact : {true, false}) {
      const bool ref = detail::IsOneCycleGeneral(e, mv, exact);
      ASSERT_EQ(detail::IsOneCycle(e, mv, exact), ref) << "graph " << it << " exact " << exact;
      ASSERT_EQ(ref, OneCycleByDegrees(e, mv, exact)) << "graph " << it << " exact " << exact;
      trues[exact ? 1 : 0] += ref ? 1 : 0;
    }
  }
  EXPECT_GT(trues[1], 15000);
  EXPECT_GT(trues[0], trues[1]);  // the average test accepts graphs the exact one does not
  // Past the arrays: a 60-gon, and a 60-gon with one chord.
  E big;
  for (uint32_t i = 0; i < 60; ++i) big.push_back({i, (i + 1) % 60});
  EXPECT_TRUE(detail::IsOneCycle(big, 3, true));
  big.push_back({0, 30});
  EXPECT_FALSE(detail::IsOneCycle(big, 3, true));
  big.back() = {0, 100};  // a 60-gon with a tail: 61 vertices, 61 edges
  EXPECT_FALSE(detail::IsOneCycle(big, 3, true));
  EXPECT_TRUE(detail::IsOneCycle(big, 3, false));
}

}  // namespace
}  // namespace svrc::refine
