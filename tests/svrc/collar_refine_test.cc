// Issue #6 stage (d): SVRC with collars (thesis §3.1.2, Figures 3.5, 3.7–3.9)
// on PLCs with creases. Refinement must terminate under a vertex cap; every
// collar radius is g/3 against a brute-force g over the complex's features;
// balls centred on different creases are disjoint (Lemma 13).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <optional>
#include <map>
#include <set>
#include <tuple>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/plc/families.h"
#include "core/plc/features.h"
#include "core/plc/readers.h"
#include "core/plc/validate.h"
#include "core/svrc/collar_index.h"
#include "core/svrc/collar_size.h"
#include "core/geometry/predicates.h"
#include <random>
#include "core/svrc/refiner.h"
#include "core/mesh/conformity.h"
#include "core/mesh/quality.h"
#include "core/svrc/assemble.h"
#include "core/svrc/sliver.h"
#include "core/svrc/work_queue.h"
#include "gtest/gtest.h"
#include "tests/test_support.h"

namespace svrc::refine {
namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif

struct CollarRun {
  plc::FeatureComplex complex;
  absl::StatusOr<PointSetRefinement> refined = absl::UnknownError("not run");
};

CollarRun Refine(const plc::Plc& plc, uint64_t cap) {
  CollarRun run;
  absl::StatusOr<plc::FeatureComplex> c = plc::BuildFeatureComplex(plc);
  EXPECT_TRUE(c.ok()) << c.status();
  if (!c.ok()) return run;
  run.complex = std::move(*c);
  RefineOptions opt;
  opt.collars = true;
  opt.max_vertices = cap;
  opt.collar_surface = std::getenv("SVRC_COLLAR_SURFACE") != nullptr;
  opt.loose_arcs = std::getenv("SVRC_ARC_LOOSE") != nullptr;
  if (const char* sn = std::getenv("SVRC_ARC_SNAP")) opt.arc_snap = std::atof(sn);
  if (const char* sg = std::getenv("SVRC_SIGMA")) opt.max_rep_angle = std::atof(sg) * M_PI / 180;
  run.refined = RefinePlc(run.complex, opt);
  return run;
}

// Features containing collar k's centre, as oracle ids (points 0..P-1,
// segments P.., facets P+S..).
std::vector<uint32_t> Containing(const plc::FeatureComplex& cx, const PointSetRefinement::Collar& k) {
  const uint32_t P = cx.points.size(), S = cx.segments.size();
  std::vector<uint32_t> out;
  if (k.feature_dim == 0) {
    out.push_back(k.feature);
    for (uint32_t s = 0; s < S; ++s) {
      if (cx.segments[s].a == k.feature || cx.segments[s].b == k.feature) {
        out.push_back(P + s);
        for (uint32_t f : cx.segments[s].facets) out.push_back(P + S + f);
      }
    }
    for (uint32_t f = 0; f < cx.facets.size(); ++f) {
      for (uint32_t q : cx.facets[f].interior_points) {
        if (q == k.feature) out.push_back(P + S + f);
      }
    }
  } else {
    out.push_back(P + k.feature);
    for (uint32_t f : cx.segments[k.feature].facets) out.push_back(P + S + f);
  }
  return out;
}

// Checks every collar of a finished run: radius = g/3 (Figure 3.8, guide §5
// item 9: never larger), Lemma 13 disjointness across creases.
void CheckCollars(const CollarRun& run, const std::string& what) {
  ASSERT_TRUE(run.refined.ok()) << what << ": " << run.refined.status();
  const PointSetRefinement& r = *run.refined;
  const plc::FeatureComplex& cx = run.complex;
  ASSERT_GT(r.collars.size(), 0u) << what;
  const std::vector<geom::Vec3>& x = r.normalised_positions;
  const uint32_t P = cx.points.size(), S = cx.segments.size();
  std::vector<OracleFeature> feats;
  for (uint32_t i = 0; i < P; ++i) feats.push_back({i, 1, {x[i], x[i], x[i]}});
  for (uint32_t s = 0; s < S; ++s) feats.push_back({P + s, 1, {x[cx.segments[s].a], x[cx.segments[s].b], x[0]}});
  for (uint32_t f = 0; f < cx.facets.size(); ++f) {
    for (const auto& t : cx.facets[f].triangles) feats.push_back({P + S + f, 2, {x[t[0]], x[t[1]], x[t[2]]}});
  }
  for (size_t i = 0; i < r.collars.size(); ++i) {
    const auto& k = r.collars[i];
    std::vector<uint32_t> excl = Containing(cx, k);
    std::sort(excl.begin(), excl.end());
    const double g = BruteForceCollarG(feats, k.center, excl);
    EXPECT_LE(k.radius, g / 3) << what << " collar " << i;
    // g/3, or g/3 stepped down by 0.2% up to 8 times to keep the vertices
    // near the sphere off it (CreateCollar's shell).
    const double steps = (1 - k.radius / (g / 3)) / 2e-3;
    EXPECT_NEAR(steps, std::round(steps), 1e-3) << what << " collar " << i << " g=" << g;
    EXPECT_LE(std::round(steps), 8) << what << " collar " << i << " g=" << g;
  }
  // Lemma 13: balls on different creases never intersect. Two centres are on
  // one crease when they lie on one crease segment (a vertex is on the
  // segments ending there).
  auto on_segment = [&](const PointSetRefinement::Collar& k, uint32_t s) {
    return k.feature_dim == 1 ? k.feature == s : (cx.segments[s].a == k.feature || cx.segments[s].b == k.feature);
  };
  for (size_t i = 0; i < r.collars.size(); ++i) {
    for (size_t j = i + 1; j < r.collars.size(); ++j) {
      const auto &a = r.collars[i], &b = r.collars[j];
      bool same = false;
      for (uint32_t s = 0; s < S && !same; ++s) same = on_segment(a, s) && on_segment(b, s);
      if (same) continue;
      EXPECT_GE(geom::Dist(a.center, b.center), a.radius + b.radius) << what << " collars " << i << ", " << j;
    }
  }
}

// CollarIndex (the suppression test of Figure 3.9) against a linear scan:
// radii over 8 decades, so balls land on many grid levels and straddle cells.
TEST(CollarIndex, MatchesLinearScan) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1), e(-8, 0);
  CollarIndex index;
  std::vector<CollarBall> balls;
  for (int i = 0; i < 400; ++i) {
    const CollarBall b{{u(rng), u(rng), u(rng)}, std::pow(10.0, e(rng))};
    balls.push_back(b);
    EXPECT_EQ(index.Add(b), static_cast<uint32_t>(i));
  }
  int inside = 0;
  for (int q = 0; q < 20000; ++q) {
    // Half the queries near a ball (inside, on or just outside its sphere).
    geom::Vec3 x{u(rng), u(rng), u(rng)};
    if (q % 2 == 0) {
      const CollarBall& b = balls[q % balls.size()];
      const geom::Vec3 d{u(rng), u(rng), u(rng)};
      x = b.center + (b.radius * (1 + 0.5 * u(rng)) / geom::Norm(d)) * d;
    }
    uint32_t want = CollarIndex::kNone;
    for (uint32_t i = 0; i < balls.size() && want == CollarIndex::kNone; ++i) {
      if (geom::InBall(x, balls[i].center, balls[i].radius) > 0) want = i;
    }
    ASSERT_EQ(index.FindContaining(x), want) << "query " << q;
    inside += want != CollarIndex::kNone;
  }
  EXPECT_GT(inside, 5000);  // the test exercises hits, not only misses
  // Strictly inside: a point on the sphere is not (Figure 3.9 suppresses
  // points inside the collar, not on S); the lowest id wins.
  CollarIndex two;
  two.Add(CollarBall{{0, 0, 0}, 1});
  two.Add(CollarBall{{0.5, 0, 0}, 1});
  EXPECT_EQ(two.FindContaining({-1, 0, 0}), CollarIndex::kNone);
  EXPECT_EQ(two.FindContaining({1, 0, 0}), 1u);
  EXPECT_EQ(two.FindContaining({0.9, 0, 0}), 0u);
}

TEST(CollarRefine, CreaseFacetPairs) {
  for (double deg : {30.0, 10.0, 5.0, 1.0, 0.1}) {
    if (deg < 1) continue;  // 0.1°: ~10^7 vertices outside collars of g/3 (docs/svrc-collars.md)
    if (kSanitized && deg < 30) continue;
    const std::string what = "crease_pair_" + std::to_string(deg);
    CollarRun run = Refine(plc::families::CreaseFacetPair(deg), 400000);
    CheckCollars(run, what);
    if (run.refined.ok()) {
      std::printf("%s: %zu collars, %llu vertices, %llu suppressed, %llu (1,2) points, %.2f s\n", what.c_str(),
                  run.refined->collars.size(), (unsigned long long)run.refined->stats.vertices,
                  (unsigned long long)run.refined->stats.suppressed_points,
                  (unsigned long long)run.refined->stats.points_12, run.refined->stats.seconds);
    }
  }
}

}  // namespace
}  // namespace svrc::refine
namespace svrc::refine {
// Corpus inputs with creases (issue #6 list): stage (d) terminates under a cap.
TEST(CollarRefine, CorpusCreases) {
  for (const char* rel : {"a_convex/tetra.poly", "b_internal/example.poly", "c_creases/wedge-1.smesh",
                          "c_creases/knife_edge.poly", "d_small_angles/segment_fan.poly",
                          "c_creases/schonhardt.off"}) {
    if (kSanitized) break;
    absl::StatusOr<plc::Plc> plc = plc::ReadPlcFile(testing::CorpusPath(rel));
    ASSERT_TRUE(plc.ok()) << rel << ": " << plc.status();
    CollarRun run = Refine(*plc, 2000000);
    CheckCollars(run, rel);
    if (run.refined.ok()) {
      std::printf("%s: %zu collars, %llu vertices, %.2f s\n", rel, run.refined->collars.size(),
                  (unsigned long long)run.refined->stats.vertices, run.refined->stats.seconds);
    }
  }
}

// RefineOptions::early_crease_vertices: crease input vertices enter M_Ω
// before the queues run, so FastCollarSize searches an almost empty M_Ω whose
// cells carry many links. g(v) is a property of the PLC, so every vertex
// collar must come out bit-identical to the one a later warp creates, and
// every collar must still match the brute-force g/3.
TEST(CollarRefine, EarlyCreaseVerticesGiveTheSameVertexCollars) {
  for (const char* rel : {"c_creases/knife_edge.poly", "a_convex/tetra.poly"}) {
    absl::StatusOr<plc::Plc> plc = plc::ReadPlcFile(testing::CorpusPath(rel));
    ASSERT_TRUE(plc.ok()) << rel << ": " << plc.status();
    std::map<uint32_t, double> radius[2];
    for (int early = 0; early < 2; ++early) {
      CollarRun run;
      absl::StatusOr<plc::FeatureComplex> c = plc::BuildFeatureComplex(*plc);
      ASSERT_TRUE(c.ok()) << c.status();
      run.complex = std::move(*c);
      RefineOptions opt;
      opt.collars = true;
      opt.max_vertices = 2000000;
      opt.early_crease_vertices = early == 1;
      run.refined = RefinePlc(run.complex, opt);
      CheckCollars(run, std::string(rel) + (early ? " early" : " late"));
      if (!run.refined.ok()) return;
      for (const auto& k : run.refined->collars) {
        if (k.feature_dim == 0) radius[early][k.feature] = k.radius;
      }
    }
    EXPECT_FALSE(radius[0].empty()) << rel;
    EXPECT_EQ(radius[0], radius[1]) << rel;
  }
}

TEST(CollarRefineDebug, One) {
  const char* a = getenv("SVRC_ANGLE");
  if (!a) GTEST_SKIP();
  const plc::Plc plc = plc::families::CreaseFacetPair(atof(a));
  CollarRun run = Refine(plc, 400000);
  CheckCollars(run, "debug");
  if (run.refined.ok() && std::getenv("SVRC_COLLAR_SURFACE") != nullptr) {
    const std::vector<ConstrainedFace> faces = ConstrainedFacesOf(*run.refined, run.complex);
    {
      const auto& X = run.refined->normalised_positions;
      auto area = [&](uint32_t a, uint32_t b, uint32_t c) { return 0.5 * geom::Norm(geom::Cross(X[b] - X[a], X[c] - X[a])); };
      for (uint32_t f = 0; f < run.complex.facets.size(); ++f) {
        double want = 0, got = 0;
        for (const auto& t : run.complex.facets[f].triangles) want += area(t[0], t[1], t[2]);
        for (const auto& t : run.refined->facet_triangles[f]) got += area(t[0], t[1], t[2]);
        std::printf("facet %u: area %.9f covered %.9f (%zu faces)\n", f, want, got, run.refined->facet_triangles[f].size());
        std::map<std::pair<uint32_t, uint32_t>, int> ecount;
        for (const auto& t : run.refined->facet_triangles[f]) {
          for (int k = 0; k < 3; ++k) ++ecount[{std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3])}];
        }
        int shown = 0;
        for (const auto& [e, n] : ecount) {
          if (n != 1 || shown >= 8) continue;
          const geom::Vec3 m = 0.5 * (X[e.first] + X[e.second]);
          bool outline = false;
          for (const auto& loop : run.complex.facets[f].loops) {
            for (size_t q = 0; q < loop.size(); ++q) {
              const geom::Vec3 &A = X[loop[q]], &B = X[loop[(q + 1) % loop.size()]];
              const geom::Vec3 d = B - A;
              const double t = std::clamp(geom::Dot(m - A, d) / geom::Dot(d, d), 0.0, 1.0);
              if (geom::Dist(m, A + t * d) < 1e-9) outline = true;
            }
          }
          if (outline) continue;
          double best = 1e9;
          int bi = -1;
          for (size_t i = 0; i < run.refined->collars.size(); ++i) {
            const auto& k = run.refined->collars[i];
            const double d = geom::Dist(m, k.center) / k.radius;
            if (d < best) { best = d; bi = (int)i; }
          }
          // boundary edges of the facet lie on its segments: skip those on the box/fin outline
          int uses = 0;
          for (const auto& t : run.refined->tets) {
            int c = 0;
            for (int q = 0; q < 4; ++q) c += (t[q] == e.first || t[q] == e.second);
            uses += c == 2;
          }
          std::printf("   cd %d %d, tets on edge %d;", run.refined->point_cd[e.first], run.refined->point_cd[e.second], uses);
          std::printf("   open edge %u-%u mid (%.5f %.5f %.5f) nearest collar %d at %.3f radii\n", e.first, e.second, m.x, m.y, m.z, bi, best);
          ++shown;
        }
      }
    }
    mesh::MeshStats stats;
    absl::StatusOr<OutputStageResult> out =
        BuildOutputMesh(plc, run.refined->normalised_positions, run.refined->tets, run.complex.point_of_vertex, faces,
                        CoordinateMapOf(*run.refined), false, &stats);
    ASSERT_TRUE(out.ok()) << out.status();
    const mesh::ConformityReport rep = mesh::CheckConformity(plc, out->mesh);
    const mesh::QualityReport q = mesh::ComputeQuality(out->mesh);
    {
      std::set<std::tuple<double, double, double>> crease_pos;
      for (uint32_t s = 0; s < run.complex.segments.size(); ++s) {
        if (!run.complex.segments[s].crease) continue;
        for (uint32_t p : run.refined->segment_chains[s]) {
          const geom::Vec3& x = run.refined->positions[p];
          crease_pos.insert({x.x, x.y, x.z});
        }
      }
      for (uint32_t i = 0; i < run.complex.points.size(); ++i) {
        if (!run.complex.points[i].crease) continue;
        const geom::Vec3& x = run.refined->positions[i];
        crease_pos.insert({x.x, x.y, x.z});
      }
      std::vector<uint8_t> flag(out->mesh.positions.size());
      for (size_t i = 0; i < flag.size(); ++i) {
        const geom::Vec3& x = out->mesh.positions[i];
        flag[i] = crease_pos.count({x.x, x.y, x.z}) ? 1 : 0;
      }
      std::printf("%s", mesh::FormatQualityReport(mesh::ComputeQuality(out->mesh, flag)).c_str());
    }
    std::printf("stitched: %zu tets, checker %s: %s; min dihedral %.2f max dihedral %.2f max radius-edge %.3f\n",
                out->mesh.tets.size(), rep.ok() ? "OK" : "FAIL", rep.Summary().c_str(), q.all.dihedral_deg.min,
                q.all.dihedral_deg.max, q.all.radius_edge.max);
  }
  if (run.refined.ok()) {
    const RefineStats& st = run.refined->stats;
    std::printf("collars %zu (vertex %llu), vertices %llu, suppressed %llu, (1,2) %llu, cells explored %llu (max %llu), refine %.2f s\n",
                run.refined->collars.size(), (unsigned long long)st.vertex_collars, (unsigned long long)st.vertices,
                (unsigned long long)st.suppressed_points, (unsigned long long)st.points_12,
                (unsigned long long)st.collar_cells_explored, (unsigned long long)st.max_collar_cells, st.seconds);
  }
}
}
namespace svrc::refine {
// A corpus input refined twice, with `set(opt, false)` and `set(opt, true)`
// (σ = 60°, collars on or off, max_volume), and the two refinements compared
// bit for bit: tets and every point. The runs are returned for the callers'
// own checks of what the switch did.
struct SameRefinementCase {
  const char* rel;
  bool collars;
  double max_volume;
  bool cell_test = false;  // RefineOptions::tet_quality off: Figure 3.5's cell test throughout
};
// The same tets over bit-identical points.
void ExpectSameRefinement(const PointSetRefinement& a, const PointSetRefinement& b, const char* rel) {
  EXPECT_EQ(a.tets, b.tets) << rel;
  EXPECT_EQ(a.normalised_positions.size(), b.normalised_positions.size()) << rel;
  for (size_t i = 0; i < std::min(a.normalised_positions.size(), b.normalised_positions.size()); ++i) {
    if (!(a.normalised_positions[i] == b.normalised_positions[i])) {
      ADD_FAILURE() << rel << " point " << i;
      break;
    }
  }
}
std::array<PointSetRefinement, 2> RefineTwiceAndCompare(const SameRefinementCase& c,
                                                        const std::function<void(RefineOptions*, bool)>& set) {
  std::array<PointSetRefinement, 2> out;
  absl::StatusOr<plc::Plc> plc = plc::ReadPlcFile(testing::CorpusPath(c.rel));
  EXPECT_TRUE(plc.ok()) << c.rel << ": " << plc.status();
  if (!plc.ok()) return out;
  absl::StatusOr<plc::FeatureComplex> cx = plc::BuildFeatureComplex(*plc);
  EXPECT_TRUE(cx.ok()) << cx.status();
  if (!cx.ok()) return out;
  for (int on = 0; on < 2; ++on) {
    RefineOptions opt;
    opt.collars = c.collars;
    opt.collar_surface = c.collars;
    opt.max_rep_angle = 60 * M_PI / 180;
    opt.max_volume = c.max_volume;
    if (c.cell_test) opt.tet_quality = false;
    set(&opt, on == 1);
    absl::StatusOr<PointSetRefinement> run = RefinePlc(*cx, opt);
    EXPECT_TRUE(run.ok()) << c.rel << ": " << run.status();
    if (!run.ok()) return out;
    out[on] = *std::move(run);
  }
  ExpectSameRefinement(out[0], out[1], c.rel);
  return out;
}

// RefineOptions::recycle_balls (BallStore recycling, §8 items 75, 76; on
// by default since session 45): new balls take the records of dead ones once
// nothing names them. Ids change; the refinement must not: Destroy's yield
// tie-break and UpdateLocation's newest-first order read BallStore::Seq (the
// order balls were made in), not the id. With the id there, cube.poly 1e-4
// gave 18,528 output tets instead of 18,377 (session 44) and this test fails.
// With recycling the run's invariants hold (checked every 25 events: every
// ball is linked to every cell it meets, the queues hold every bad simplex
// at the end) and about half the records go (measured: without resetting
// tri_of_ball_, the invariant check fails on cube.poly). Two guards are not
// shown to matter by these inputs: a stale Encroached event no longer
// clears the flag of the ball now in its record, and a dead ball still
// linked somewhere would not be recycled (no such ball was seen).
// PointSetRefinement::tet_neighbors is M_Ω's adjacency in the order of
// `tets` (each face shared with the tet it names, hull faces on no other
// tet), and the sliver pass given it (SliverInput::neighbors, instead of
// building its face table) makes the same flips: the same tets in the same
// order and the same counts (docs/svrc-design.md §8 item 80).
TEST(CollarRefine, RefinersAdjacencyGivesTheSameSliverPass) {
  for (const auto& [rel, max_volume] : std::vector<std::pair<const char*, double>>{
           {"a_convex/cube.poly", 1e-4}, {"b_internal/box_internal_facet.poly", 1e-4}, {"b_internal/box_in_box.poly", 0}}) {
    absl::StatusOr<plc::Plc> plc = plc::ReadPlcFile(testing::CorpusPath(rel));
    ASSERT_TRUE(plc.ok()) << rel << ": " << plc.status();
    absl::StatusOr<plc::FeatureComplex> cx = plc::BuildFeatureComplex(*plc);
    ASSERT_TRUE(cx.ok()) << cx.status();
    RefineOptions opt;
    opt.max_volume = max_volume;
    opt.output_tet_neighbors = true;
    absl::StatusOr<PointSetRefinement> run = RefinePlc(*cx, opt);
    ASSERT_TRUE(run.ok()) << rel << ": " << run.status();
    ASSERT_EQ(run->tet_neighbors.size(), run->tets.size()) << rel;
    // Each face of each tet: the same three vertices in the tet named, which
    // names it back; faces named by no tet are on exactly one tet.
    std::map<std::array<uint32_t, 3>, int> face_count;
    size_t hull = 0;
    for (uint32_t t = 0; t < run->tets.size(); ++t) {
      for (int f = 0; f < 4; ++f) {
        std::array<uint32_t, 3> k;
        for (int j = 0, m = 0; j < 4; ++j) {
          if (j != f) k[m++] = run->tets[t][j];
        }
        std::sort(k.begin(), k.end());
        ++face_count[k];
        const uint32_t n = run->tet_neighbors[t][f];
        if (n == 0xFFFFFFFFu) {
          ++hull;
          continue;
        }
        ASSERT_LT(n, run->tets.size());
        int shared = 0;
        for (uint32_t v : run->tets[n]) shared += std::binary_search(k.begin(), k.end(), v);
        EXPECT_EQ(shared, 3) << rel << " tet " << t << " face " << f;
        const auto& back = run->tet_neighbors[n];
        EXPECT_TRUE(back[0] == t || back[1] == t || back[2] == t || back[3] == t) << rel << " tet " << t;
      }
    }
    size_t single = 0;
    for (const auto& [k, c] : face_count) {
      ASSERT_LE(c, 2);
      single += c == 1;
    }
    EXPECT_EQ(hull, single) << rel;
    EXPECT_GT(hull, 0u) << rel;
    const std::vector<ConstrainedFace> faces = ConstrainedFacesOf(*run, *cx);
    SliverOptions so;
    so.skip_tet = run->tet_outside;
    so.keep_max_volume = max_volume > 0;
    absl::StatusOr<SliverResult> table = RemoveSlivers(run->normalised_positions, run->tets, faces, run->segment_chains, so);
    std::vector<std::array<uint32_t, 4>> nbr = run->tet_neighbors;
    SliverOptions so_out = so;
    so_out.output_neighbors = true;
    absl::StatusOr<SliverResult> given =
        RemoveSlivers(run->normalised_positions, run->tets, faces, run->segment_chains, so_out, &nbr);
    ASSERT_TRUE(table.ok()) << rel << ": " << table.status();
    ASSERT_TRUE(given.ok()) << rel << ": " << given.status();
    EXPECT_GT(table->stats.flips(), 0u) << rel;
    EXPECT_EQ(given->tets, table->tets) << rel;
    EXPECT_EQ(given->stats.flips(), table->stats.flips()) << rel;
    EXPECT_EQ(given->stats.candidates, table->stats.candidates) << rel;
    EXPECT_EQ(given->stats.bad_after, table->stats.bad_after) << rel;
    // The pass's final adjacency (SliverOptions::output_neighbors) is its
    // output tets' adjacency, and the output stage labelling with it
    // (BuildOutputMesh's neighbor_tets, core::MeshPlc's path) gives the same
    // mesh as with its own face table (docs/svrc-design.md §8 item 82).
    SCOPED_TRACE(rel);
    const std::vector<std::array<uint32_t, 4>>& tets = given->tets;
    const std::vector<std::array<uint32_t, 4>>& out_nbr = given->neighbors;
    ASSERT_EQ(out_nbr.size(), tets.size());
    // Against the faces of the output tets: a shared face names the other
    // tet, a face of one tet names none. (face: the one opposite local
    // vertex f, sorted.)
    auto face = [&](uint32_t t, int f) {
      std::array<uint32_t, 3> k;
      for (int j = 0, m = 0; j < 4; ++j) {
        if (j != f) k[m++] = tets[t][j];
      }
      std::sort(k.begin(), k.end());
      return k;
    };
    std::map<std::array<uint32_t, 3>, std::vector<uint32_t>> tets_of_face;
    for (uint32_t t = 0; t < tets.size(); ++t) {
      for (int f = 0; f < 4; ++f) tets_of_face[face(t, f)].push_back(t);
    }
    for (uint32_t t = 0; t < tets.size(); ++t) {
      for (int f = 0; f < 4; ++f) {
        const std::vector<uint32_t>& on = tets_of_face.at(face(t, f));
        ASSERT_LE(on.size(), 2u);
        const uint32_t want = on.size() == 1 ? 0xFFFFFFFFu : (on[0] == t ? on[1] : on[0]);
        ASSERT_EQ(out_nbr[t][f], want) << "tet " << t << " face " << f;
      }
    }
    const CoordinateMap map = CoordinateMapOf(*run);
    absl::StatusOr<OutputStageResult> by_table =
        BuildOutputMesh(*plc, run->normalised_positions, tets, cx->point_of_vertex, faces, map, false);
    absl::StatusOr<OutputStageResult> by_flips =
        BuildOutputMesh(*plc, run->normalised_positions, tets, cx->point_of_vertex, faces, map, false, nullptr, out_nbr);
    ASSERT_TRUE(by_table.ok()) << by_table.status();
    ASSERT_TRUE(by_flips.ok()) << by_flips.status();
    EXPECT_GT(by_table->mesh.tets.size(), 0u);
    EXPECT_EQ(by_flips->mesh.positions.size(), by_table->mesh.positions.size());
    EXPECT_TRUE(std::equal(by_flips->mesh.positions.begin(), by_flips->mesh.positions.end(), by_table->mesh.positions.begin(),
                           by_table->mesh.positions.end(), [](const geom::Vec3& a, const geom::Vec3& b) {
                             return a.x == b.x && a.y == b.y && a.z == b.z;
                           }));
    EXPECT_EQ(by_flips->mesh.tets, by_table->mesh.tets);
    EXPECT_EQ(by_flips->mesh.tet_region, by_table->mesh.tet_region);
    EXPECT_EQ(by_flips->mesh.triangles, by_table->mesh.triangles);
    EXPECT_EQ(by_flips->mesh.triangle_marker, by_table->mesh.triangle_marker);
    // BuildOutputMesh reads the rows it is given: one out of range is refused.
    std::vector<std::array<uint32_t, 4>> corrupt = out_nbr;
    corrupt[0][0] = static_cast<uint32_t>(tets.size());
    EXPECT_EQ(BuildOutputMesh(*plc, run->normalised_positions, tets, cx->point_of_vertex, faces, map, false, nullptr,
                              corrupt)
                  .status()
                  .code(),
              absl::StatusCode::kInvalidArgument);
    // A neighbour id out of range, or a row count that is not the tets', is refused.
    nbr = run->tet_neighbors;
    nbr[0][0] = static_cast<uint32_t>(run->tets.size());
    EXPECT_EQ(RemoveSlivers(run->normalised_positions, run->tets, faces, run->segment_chains, so, &nbr).status().code(),
              absl::StatusCode::kInvalidArgument);
    nbr = run->tet_neighbors;
    nbr.pop_back();
    EXPECT_EQ(RemoveSlivers(run->normalised_positions, run->tets, faces, run->segment_chains, so, &nbr).status().code(),
              absl::StatusCode::kInvalidArgument);
  }
}

TEST(CollarRefine, RecycledBallRecordsGiveTheSameRefinementInHalfTheRecords) {
  if (kSanitized) GTEST_SKIP() << "release only";
  struct Case {
    const char* rel;
    double max_volume;
  };
  for (const Case& c : {Case{"a_convex/cube.poly", 1e-4}, Case{"b_internal/box_internal_facet.poly", 1e-4},
                        Case{"b_internal/box_in_box.poly", 0}, Case{"e_spread/tiny_cube_in_box.poly", 1e-3},
                        Case{"e_spread/far_offset_close_points.poly", 0}}) {
    absl::StatusOr<plc::Plc> plc = plc::ReadPlcFile(testing::CorpusPath(c.rel));
    ASSERT_TRUE(plc.ok()) << c.rel << ": " << plc.status();
    absl::StatusOr<plc::FeatureComplex> cx = plc::BuildFeatureComplex(*plc);
    ASSERT_TRUE(cx.ok()) << cx.status();
    std::array<RefineStats, 2> stats;
    std::array<PointSetRefinement, 2> runs;
    for (int on = 0; on < 2; ++on) {
      RefineOptions opt;
      opt.max_volume = c.max_volume;
      opt.recycle_balls = on == 1;
      if (on == 1) opt.validate_every = 25;
      absl::StatusOr<PointSetRefinement> run = RefinePlc(*cx, opt);
      ASSERT_TRUE(run.ok()) << c.rel << ": " << run.status();
      stats[on] = run->stats;
      runs[on] = *run;
      const std::vector<ConstrainedFace> faces = ConstrainedFacesOf(*run, *cx);
      absl::StatusOr<OutputStageResult> out = BuildOutputMesh(*plc, run->normalised_positions, run->tets,
                                                              cx->point_of_vertex, faces, CoordinateMapOf(*run), false);
      ASSERT_TRUE(out.ok()) << c.rel << ": " << out.status();
      const mesh::ConformityReport rep = mesh::CheckConformity(*plc, out->mesh);
      EXPECT_TRUE(rep.ok()) << c.rel << " recycle " << on << ": " << rep.Summary();
      EXPECT_LE(mesh::ComputeQuality(out->mesh).all.radius_edge.max, 2.0 * (1 + 1e-9)) << c.rel;
    }
    ExpectSameRefinement(runs[0], runs[1], c.rel);
    EXPECT_EQ(stats[0].balls_recycled, 0u) << c.rel;
    EXPECT_GT(stats[1].balls_recycled, 0u) << c.rel;
    EXPECT_LT(static_cast<double>(stats[1].ball_records), 0.75 * static_cast<double>(stats[0].ball_records)) << c.rel;
    std::printf("%s: %llu ball records without recycling, %llu with (%llu recycled)\n", c.rel,
                (unsigned long long)stats[0].ball_records, (unsigned long long)stats[1].ball_records,
                (unsigned long long)stats[1].balls_recycled);
  }
}

// RefineOptions::certify_cells: ForceInsertOmega's certificates of good
// cells must give Size()'s verdicts bit for bit, so the refinement is the
// same with and without them. segment_fan.poly (collars, COLLAR rounds)
// differed until a certified cell's stale queued events were removed as
// RefreshEvents removes them (a stale Unresolved event left queued was later
// refreshed in place and kept its old place in its bucket: 6213 instead of
// 6617 output vertices); cube.poly with max_volume exercises size targets.
// The same switch turns on OmegaMesh::ShrunkSize (cavity cells sized from
// their memo when their farthest corner survived), which must not change
// the refinement either. Since session 41 cells with star tets on both sides
// of the output's boundary are certified too (over their kept tets): the
// cube's boundary cells take that path (CellCert::partial), here also under
// Figure 3.5's cell test (tet_quality off), where IsBad reads τ·r_v. On
// these inputs no such cell's bound ever exceeded τ·r_v or a size target
// (checked against Size() in session 41), so the test shows the same
// refinement and that the path is taken, not that each of its conditions
// is needed; docs/svrc-design.md §8 item 70 argues them. Since session 43
// the same holds for such cells clipped to Ω (CellCert::clipped; item 73).
TEST(CollarRefine, CertifiedCellsGiveTheSameRefinement) {
  if (kSanitized) GTEST_SKIP() << "release only";
  for (const SameRefinementCase& c :
       {SameRefinementCase{"d_small_angles/segment_fan.poly", true, 0}, SameRefinementCase{"a_convex/cube.poly", false, 1e-4},
        SameRefinementCase{"b_internal/box_in_box.poly", false, 0},
        SameRefinementCase{"a_convex/cube.poly", false, 1e-4, /*cell_test=*/true},
        SameRefinementCase{"b_internal/box_internal_facet.poly", false, 1e-4, /*cell_test=*/true}}) {
    const auto runs = RefineTwiceAndCompare(c, [](RefineOptions* o, bool on) { o->certify_cells = on; });
    EXPECT_EQ(runs[0].stats.sizes_certified, 0u) << c.rel;
    EXPECT_EQ(runs[0].stats.sizes_shrunk, 0u) << c.rel;
    EXPECT_GT(runs[1].stats.sizes_certified, 500u) << c.rel;
    EXPECT_GT(runs[1].stats.sizes_shrunk, 500u) << c.rel;
    EXPECT_EQ(runs[0].stats.sizes_certified_partial, 0u) << c.rel;
    if (c.max_volume > 0) {
      EXPECT_GT(runs[1].stats.sizes_certified_partial, c.cell_test ? 300u : 1000u) << c.rel << (c.cell_test ? " (cell test)" : "");
      if (!c.cell_test) {
        EXPECT_GT(runs[1].stats.sizes_certified_clipped, 300u) << c.rel;
      }
    }
    EXPECT_EQ(runs[0].stats.sizes_certified_clipped, 0u) << c.rel;
  }
}

// Destroy in M_Ω reads v's balls and the other cells' unresolved 0-balls
// only (RefineOptions::destroy_gather_all = false, docs/svrc-design.md §8
// item 36): the same warps and yields as the union of every ball of the
// cells visited, so the same refinement bit for bit, with fewer balls read.
// A yield ball not linked to v, or a warp target linked to its cell without
// the unresolved flag, would change the output here.
TEST(CollarRefine, DestroyReadsWhatItNeedsWithTheSameRefinement) {
  for (const SameRefinementCase& c :
       {SameRefinementCase{"c_creases/knife_edge.poly", true, 0}, SameRefinementCase{"d_small_angles/segment_fan.poly", true, 0},
        SameRefinementCase{"a_convex/cube.poly", false, 1e-4}, SameRefinementCase{"b_internal/box_internal_facet.poly", false, 1e-4},
        SameRefinementCase{"b_internal/box_in_box.poly", false, 0},
        SameRefinementCase{"e_spread/tiny_cube_in_box.poly", false, 0}}) {
    if (kSanitized && c.collars) continue;  // seconds in release, a minute under ASan; the others cover the code
    const auto runs = RefineTwiceAndCompare(c, [](RefineOptions* o, bool on) {
      o->destroy_index = false;  // the cells' modes
      o->destroy_gather_all = !on;
    });
    EXPECT_EQ(runs[0].stats.warps, runs[1].stats.warps) << c.rel;
    EXPECT_EQ(runs[0].stats.yields, runs[1].stats.yields) << c.rel;
    EXPECT_LT(runs[1].stats.destroy_balls_read, runs[0].stats.destroy_balls_read) << c.rel;
    std::printf("%s: Destroy read %llu balls, %llu with every ball of its cells\n", c.rel,
                (unsigned long long)runs[1].stats.destroy_balls_read, (unsigned long long)runs[0].stats.destroy_balls_read);
  }
}

// Destroy without the search of the cells meeting B when at most
// RefineOptions::local_destroy_cells cells hold unresolved 0-balls (§8 item
// 40): a warp target within θr of c lies in a cell meeting B, and v's own
// balls hold every yield, so gathering from v and all unresolved cells makes
// the same choices. Bit-identical refinements against the search on every
// Destroy (0), with more local Destroys at the default.
TEST(CollarRefine, LocalDestroyMakesTheSameRefinement) {
  for (const SameRefinementCase& c :
       {SameRefinementCase{"c_creases/knife_edge.poly", true, 0}, SameRefinementCase{"a_convex/cube.poly", false, 1e-4},
        SameRefinementCase{"b_internal/box_internal_facet.poly", false, 1e-4},
        SameRefinementCase{"e_spread/tiny_cube_in_box.poly", false, 0}}) {
    if (kSanitized && c.collars) continue;
    const auto runs = RefineTwiceAndCompare(c, [](RefineOptions* o, bool on) {
      o->destroy_index = false;  // the cells' modes
      o->local_destroy_cells = on ? 256 : 0;
    });
    EXPECT_EQ(runs[0].stats.warps, runs[1].stats.warps) << c.rel;
    EXPECT_EQ(runs[0].stats.yields, runs[1].stats.yields) << c.rel;
    EXPECT_GT(runs[1].stats.destroys_local, runs[0].stats.destroys_local) << c.rel;
    std::printf("%s: %llu of the Destroys local, %llu with the search whenever a cell holds an unresolved point\n",
                c.rel, (unsigned long long)runs[1].stats.destroys_local, (unsigned long long)runs[0].stats.destroys_local);
  }
}

// Destroy's warp targets from the index of pending points (RefineOptions::
// destroy_index, §8 item 41) instead of the cells: the 0-balls linked
// unresolved into M_Ω are indexed by position, and those within θr of c are
// the targets the cells meeting B would give. Bit-identical refinements
// against the search of the cells meeting B on every Destroy, including the
// collar path (knife_edge, segment_fan), where points become suppressed after
// they were indexed. An index missing a target (a 0-ball linked without
// being indexed, a query that misses the points in a neighbouring octant)
// changes the refinement here.
TEST(CollarRefine, IndexedDestroyMakesTheSameRefinement) {
  for (const SameRefinementCase& c :
       {SameRefinementCase{"c_creases/knife_edge.poly", true, 0}, SameRefinementCase{"d_small_angles/segment_fan.poly", true, 0},
        SameRefinementCase{"a_convex/cube.poly", false, 1e-4}, SameRefinementCase{"b_internal/box_internal_facet.poly", false, 1e-4},
        SameRefinementCase{"b_internal/box_in_box.poly", false, 0},
        SameRefinementCase{"e_spread/tiny_cube_in_box.poly", false, 0}}) {
    if (kSanitized && c.collars) continue;
    const auto runs = RefineTwiceAndCompare(c, [](RefineOptions* o, bool on) {
      o->destroy_index = on;
      o->local_destroy_cells = 0;  // off: the search on every Destroy
    });
    EXPECT_EQ(runs[0].stats.warps, runs[1].stats.warps) << c.rel;
    EXPECT_EQ(runs[0].stats.yields, runs[1].stats.yields) << c.rel;
    EXPECT_GT(runs[0].stats.warps, 0u) << c.rel;
    EXPECT_GT(runs[1].stats.destroy_index_visited, 0u) << c.rel;
    std::printf("%s: %llu warps; Destroy read %llu cells with the search, %llu cells and %llu index nodes/points "
                "with the index\n",
                c.rel, (unsigned long long)runs[1].stats.warps, (unsigned long long)runs[0].stats.destroy_cells_visited,
                (unsigned long long)runs[1].stats.destroy_cells_visited,
                (unsigned long long)runs[1].stats.destroy_index_visited);
  }
}

// The size rounds label M_Ω with Delaunay3's adjacency (neighbour slots and
// a star walk per constrained face) instead of the labelling's face table
// (RefineOptions::label_with_adjacency, §8 item 43): the same labelling, so
// the same size targets and the same refinement bit for bit, on inputs with
// max_volume (size rounds) and several regions. A neighbour slot off by a
// face, or a constrained face found in the wrong tet, changes the regions
// the flood reaches and with them the targets.
TEST(CollarRefine, LabellingWithTheMeshAdjacencyMakesTheSameRefinement) {
  for (const SameRefinementCase& c :
       {SameRefinementCase{"a_convex/cube.poly", false, 1e-4}, SameRefinementCase{"b_internal/box_internal_facet.poly", false, 1e-4},
        SameRefinementCase{"b_internal/box_in_box.poly", false, 1e-3},
        SameRefinementCase{"e_spread/tiny_cube_in_box.poly", false, 1e-2}}) {
    const auto runs = RefineTwiceAndCompare(c, [](RefineOptions* o, bool on) { o->label_with_adjacency = on; });
    EXPECT_GT(runs[0].stats.size_rounds, 0u) << c.rel;
    EXPECT_EQ(runs[0].stats.size_rounds, runs[1].stats.size_rounds) << c.rel;
  }
}

// M_Ω's circumcentre cache and Size() memos bounded and direct-mapped
// (RefineOptions::omega_cc_log2 / omega_memo_log2, §8 item 44): tables of
// 64 circumcentres and 16 memos, where nearly every lookup meets another
// tet's or vertex's record, against unbounded tables (a half to one record
// per slot and vertex, §8 item 74); and
// the neighbour lists dropped whenever they pass 256 entries (§8 item 47). The
// same refinement bit for bit, on the collar path (knife_edge, segment_fan)
// and with size rounds; a record answering for the wrong tet or vertex, or
// a ShrunkSize on an evicted memo, changes it.
TEST(CollarRefine, BoundedOmegaCachesMakeTheSameRefinement) {
  for (const SameRefinementCase& c :
       {SameRefinementCase{"c_creases/knife_edge.poly", true, 0}, SameRefinementCase{"d_small_angles/segment_fan.poly", true, 0},
        SameRefinementCase{"a_convex/cube.poly", false, 1e-4}, SameRefinementCase{"b_internal/box_internal_facet.poly", false, 1e-4}}) {
    if (kSanitized && c.collars) continue;
    const auto runs = RefineTwiceAndCompare(c, [](RefineOptions* o, bool on) {
      o->omega_cc_log2 = on ? 6 : 0;
      o->omega_memo_log2 = on ? 4 : 0;
      o->omega_neighbor_entries = on ? 256 : 0;
    });
    EXPECT_EQ(runs[0].stats.neighbor_cache_flushes, 0u) << c.rel;
    EXPECT_GT(runs[1].stats.neighbor_cache_flushes, 10u) << c.rel;
    EXPECT_GT(runs[1].stats.circumcentres, 2 * runs[0].stats.circumcentres) << c.rel;
    EXPECT_GT(runs[1].stats.sizes_computed, runs[0].stats.sizes_computed) << c.rel;
    EXPECT_GT(runs[1].stats.sizes_shrunk, 0u) << c.rel;
    std::printf("%s: %llu circumcentres and %llu star walks with 64 / 16 records, %llu and %llu unbounded\n",
                c.rel, (unsigned long long)runs[1].stats.circumcentres, (unsigned long long)runs[1].stats.sizes_computed,
                (unsigned long long)runs[0].stats.circumcentres, (unsigned long long)runs[0].stats.sizes_computed);
  }
}

// RefineOptions::release_label_caches: a size labelling frees M_Ω's
// circumcentre cache and size memos, and its own arrays before the tests
// that refill the caches (session 28: cube 1e-6's peak RSS 487 → 453 MB).
// The caches do not change answers, so the refinement is the same bit for
// bit; with the release the circumcentres are computed again.
TEST(CollarRefine, ReleasedLabelCachesGiveTheSameRefinement) {
  for (const SameRefinementCase& c :
       {SameRefinementCase{"a_convex/cube.poly", false, 1e-4}, SameRefinementCase{"b_internal/box_internal_facet.poly", false, 1e-4},
        SameRefinementCase{"e_spread/tiny_cube_in_box.poly", false, 1e-3}, SameRefinementCase{"c_creases/knife_edge.poly", true, 1e-3}}) {
    if (kSanitized && c.collars) continue;
    const auto runs = RefineTwiceAndCompare(c, [](RefineOptions* o, bool on) {
      o->release_label_caches = on;
      o->release_cache_min_bytes = 0;  // these runs' tables are small
    });
    EXPECT_GT(runs[1].stats.circumcentres, runs[0].stats.circumcentres) << c.rel;
    EXPECT_GE(runs[1].stats.size_rounds, 1u) << c.rel;
  }
}

// RefineOptions::tight_ball_cells: without collars, the cells a new ball is
// linked to (and Destroy's cells) pass every Delaunay neighbour's bisector
// test, not only the nearest vertex's. Still a superset of the cells the ball
// meets, and the no-collar path's links are order-neutral (§8 item 37), so
// the refinement is the same bit for bit, with fewer links.
TEST(CollarRefine, TightBallCellsGiveTheSameRefinementWithFewerLinks) {
  for (const SameRefinementCase& c :
       {SameRefinementCase{"a_convex/cube.poly", false, 1e-4}, SameRefinementCase{"b_internal/box_internal_facet.poly", false, 1e-4},
        SameRefinementCase{"b_internal/box_in_box.poly", false, 0}, SameRefinementCase{"e_spread/tiny_cube_in_box.poly", false, 1e-3},
        SameRefinementCase{"e_spread/far_offset_close_points.poly", false, 0}}) {
    const auto runs = RefineTwiceAndCompare(c, [](RefineOptions* o, bool on) {
      o->tight_ball_cells = on;
      o->validate_every = kSanitized ? 0 : 211;  // every ball linked to each cell it meets
    });
    EXPECT_LT(runs[1].stats.links_added, runs[0].stats.links_added) << c.rel;
    std::printf("%s: %llu links added, %llu with the nearest vertex's bisector only\n", c.rel,
                (unsigned long long)runs[1].stats.links_added, (unsigned long long)runs[0].stats.links_added);
  }
}

// RefineOptions::drop_dead_tet_events: a tet's Skinny event leaves the queue
// when the tet is destroyed instead of waiting to be popped stale. The live
// events keep their order, so the refinement is the same bit for bit, and
// the events removed are exactly the tet events that were popped stale.
TEST(CollarRefine, DroppedDeadTetEventsGiveTheSameRefinement) {
  for (const SameRefinementCase& c :
       {SameRefinementCase{"a_convex/cube.poly", false, 1e-4}, SameRefinementCase{"b_internal/box_internal_facet.poly", false, 1e-4},
        SameRefinementCase{"e_spread/tiny_cube_in_box.poly", false, 1e-3}}) {
    const auto runs = RefineTwiceAndCompare(c, [](RefineOptions* o, bool on) { o->drop_dead_tet_events = on; });
    const int k = static_cast<int>(EventType::kSkinny);
    EXPECT_EQ(runs[0].stats.events_removed_dead[k], 0u) << c.rel;
    EXPECT_GT(runs[1].stats.events_removed_dead[k], 1000u) << c.rel;
    EXPECT_EQ(runs[1].stats.events_pushed[k], runs[0].stats.events_pushed[k]) << c.rel;
    EXPECT_EQ(runs[1].stats.events_stale[k] + runs[1].stats.events_removed_dead[k], runs[0].stats.events_stale[k])
        << c.rel;
    // Ball records: split facet triangles leave dead ones (ids are not reused).
    EXPECT_GT(runs[1].stats.balls_alive, 0u) << c.rel;
    EXPECT_GT(runs[1].stats.ball_records, runs[1].stats.balls_alive) << c.rel;
    std::printf("%s: %llu tet events removed when their tet died\n", c.rel,
                (unsigned long long)runs[1].stats.events_removed_dead[k]);
  }
}

// The corpus file `file`, or families::NestedBoxes(3, 1e-2, 1/8) (three
// regions with max volumes 1e-2, 1.25e-3, 1.5625e-4) for "nested".
absl::StatusOr<plc::Plc> CaseInput(const std::string& file) {
  if (file == "nested") return plc::families::NestedBoxes(3, 1e-2, 1.0 / 8);
  return plc::ReadPlcFile(testing::CorpusPath(file));
}

// The output tets whose volume exceeds their bound: the smaller of
// `max_volume` (≤ 0: none) and their region's max volume. nullopt when a tet
// has neither.
std::optional<size_t> TetsAboveTheirBound(const mesh::TetMesh& m, double max_volume) {
  size_t over = 0;
  for (size_t t = 0; t < m.tets.size(); ++t) {
    double bound = max_volume > 0 ? max_volume : HUGE_VAL;
    const double region = m.regions[m.tet_region[t]].max_volume;
    if (region > 0) bound = std::min(bound, region);
    if (bound == HUGE_VAL) return std::nullopt;
    const geom::Vec3 a = m.positions[m.tets[t][0]];
    const double vol = geom::Dot(m.positions[m.tets[t][1]] - a,
                                 geom::Cross(m.positions[m.tets[t][2]] - a, m.positions[m.tets[t][3]] - a)) / 6;
    over += vol > bound;
  }
  return over;
}

// RefinePlc(cx, opt) and its output mesh, checked: conforming, radius-edge
// ≤ 2 on every tet. nullopt (with a failure) when a stage fails.
struct RefinedMesh {
  PointSetRefinement run;
  mesh::TetMesh mesh;
};
std::optional<RefinedMesh> RefineAndCheck(const plc::Plc& plc, const plc::FeatureComplex& cx, const RefineOptions& opt,
                                          const std::string& what) {
  absl::StatusOr<PointSetRefinement> run = RefinePlc(cx, opt);
  if (!run.ok()) {
    ADD_FAILURE() << what << ": " << run.status();
    return std::nullopt;
  }
  const std::vector<ConstrainedFace> faces = ConstrainedFacesOf(*run, cx);
  absl::StatusOr<OutputStageResult> out = BuildOutputMesh(plc, run->normalised_positions, run->tets,
                                                          cx.point_of_vertex, faces, CoordinateMapOf(*run), false);
  if (!out.ok()) {
    ADD_FAILURE() << what << ": " << out.status();
    return std::nullopt;
  }
  const mesh::ConformityReport rep = mesh::CheckConformity(plc, out->mesh);
  EXPECT_TRUE(rep.ok()) << what << ": " << rep.Summary();
  EXPECT_LE(mesh::ComputeQuality(out->mesh).all.radius_edge.max, 2.0 * (1 + 1e-9)) << what;
  return RefinedMesh{*std::move(run), std::move(out->mesh)};
}

// UpdateLocation's bisector filter (RefineOptions::bisector_link_filter,
// docs/svrc-design.md §8 item 37): a shrunk cell drops its link to a lower
// ball lying wholly beyond the bisector of its vertex and the new point.
// V_new(u) lies on u's side of that bisector, so the links stay conservative:
// CheckInvariants (validate_every) fails when a ball is not linked to the
// cell holding its centre or to the cell of a vertex strictly inside it
// (checked: it fails when the filter drops balls within 0.5 r beyond the
// bisector). The outputs differ (the order of Encroached events follows the
// order of the links, and FastCollarSize reads a cell's features from its
// links) and must still conform. Measured: links left at the end of cube
// --max-volume 1e-5 548,000 → 160,000, links added 1.21 M → 0.95 M.
TEST(CollarRefine, BisectorLinkFilterKeepsLinksConservative) {
  struct Case {
    const char* rel;
    double max_volume;
  };
  for (const Case& c : {Case{"a_convex/cube.poly", 1e-3}, Case{"b_internal/box_internal_facet.poly", 1e-3},
                        Case{"b_internal/box_in_box.poly", 0}, Case{"e_spread/far_offset_close_points.poly", 0}}) {
    absl::StatusOr<plc::Plc> plc = CaseInput(c.rel);
    ASSERT_TRUE(plc.ok()) << plc.status();
    absl::StatusOr<plc::FeatureComplex> cx = plc::BuildFeatureComplex(*plc);
    ASSERT_TRUE(cx.ok()) << cx.status();
    uint64_t left[2] = {0, 0};
    for (int on = 0; on < 2; ++on) {
      RefineOptions opt;
      opt.max_volume = c.max_volume;
      opt.bisector_link_filter = on == 1;
      opt.validate_every = kSanitized ? 0 : 97;
      const std::optional<RefinedMesh> r = RefineAndCheck(*plc, *cx, opt, absl::StrCat(c.rel, " filter ", on));
      ASSERT_TRUE(r.has_value());
      left[on] = r->run.stats.links_added - r->run.stats.links_removed;
    }
    EXPECT_LT(left[1], left[0]) << c.rel;
    std::printf("%s: links left at the end %llu without the filter, %llu with\n", c.rel, (unsigned long long)left[0],
                (unsigned long long)left[1]);
  }
}

// RefineStats::link_changes_by_kind splits the location graph's link
// changes by the insertion that made them (the output-sensitivity bench
// prints it): the kinds' insertions are the refiner's insertions, an M_Ω
// point counted unlinked changed no link, and nearly every change is made
// by some insertion (the rest by the initial meshes and the labelling).
TEST(CollarRefine, LinkChangesByKindAddUpToTheLinkCounters) {
  for (const char* rel : {"a_convex/cube.poly", "b_internal/box_internal_facet.poly"}) {
    absl::StatusOr<plc::Plc> plc = CaseInput(rel);
    ASSERT_TRUE(plc.ok()) << plc.status();
    absl::StatusOr<plc::FeatureComplex> cx = plc::BuildFeatureComplex(*plc);
    ASSERT_TRUE(cx.ok()) << cx.status();
    RefineOptions opt;
    opt.max_volume = 1e-3;
    const std::optional<RefinedMesh> r = RefineAndCheck(*plc, *cx, opt, rel);
    ASSERT_TRUE(r.has_value());
    const RefineStats& st = r->run.stats;
    uint64_t omega = 0, changes = 0;
    for (int k : {kOmegaCd0, kOmegaCd1, kOmegaCd2, kOmegaCd3Linked, kOmegaCd3Unlinked}) omega += st.insertions_by_kind[k];
    for (uint64_t c : st.link_changes_by_kind) changes += c;
    EXPECT_EQ(omega, st.insertions) << rel;
    EXPECT_EQ(st.insertions_by_kind[kSegmentMesh], st.segment_vertices) << rel;
    EXPECT_GT(st.insertions_by_kind[kFacetMesh], 0u) << rel;
    EXPECT_GE(st.insertions_by_kind[kFacetMesh], st.facet_vertices) << rel;  // plus segment points entering M_F
    EXPECT_GT(st.insertions_by_kind[kOmegaCd3Linked], 0u) << rel;
    EXPECT_GT(st.insertions_by_kind[kOmegaCd3Unlinked], 0u) << rel;
    EXPECT_EQ(st.link_changes_by_kind[kOmegaCd3Unlinked], 0u) << rel;
    EXPECT_GE(st.link_changes_by_kind[kOmegaCd3Linked], st.insertions_by_kind[kOmegaCd3Linked]) << rel;
    const uint64_t all = st.links_added + st.links_removed;
    EXPECT_LE(changes, all) << rel;
    EXPECT_GE(changes, all - all / 50) << rel;
    std::printf("%s: %llu of %llu link changes made by insertions\n", rel, (unsigned long long)changes,
                (unsigned long long)all);
    // The refinement loop's time by kind (session 42): every live event is
    // classified once, by the lowest-dimensional mesh it inserted into; a
    // segment event inserts at least one segment point; the classified time
    // is Run()'s time less its queue drains between rounds.
    uint64_t live = 0, classified = st.other_events;
    double seconds = st.seconds_other_events;
    for (int t = 0; t < 4; ++t) live += st.events_popped[t] - st.events_stale[t];
    for (int k = 0; k < kNumLinkChangeKinds; ++k) {
      classified += st.events_by_kind[k];
      seconds += st.seconds_by_kind[k];
      EXPECT_GE(st.seconds_by_kind[k], 0.0) << rel;
      EXPECT_EQ(st.events_by_kind[k] == 0, st.seconds_by_kind[k] == 0.0) << rel << " kind " << k;
    }
    EXPECT_EQ(classified, live) << rel;
    EXPECT_GT(st.events_by_kind[kFacetMesh], 0u) << rel;
    EXPECT_GT(st.events_by_kind[kSegmentMesh], 0u) << rel;
    EXPECT_LE(st.events_by_kind[kSegmentMesh], st.segment_vertices) << rel;
    EXPECT_GT(st.events_by_kind[kOmegaCd3Linked], 0u) << rel;
    EXPECT_GT(seconds, 0.0) << rel;
    EXPECT_LE(seconds, st.seconds * (1 + 1e-9)) << rel;
  }
}

// RefineOptions::propagate_size_targets: max_volume targets carried from a
// size round's labelling to the tets and points of later cavities. Without
// it the rounds refine in waves, each labelling finding the last round's new
// vertices without a target (cube.poly --max-volume 1e-5: 5 rounds, 6
// labellings); with it one round settles. RefineOptions::size_kept_tets
// then sizes cells on the output's tets only (docs/svrc-design.md §8 item
// 33). Every tet within its region's bound and the radius-edge bound with
// both on are checked end to end in PlcRefine.MaxVolumeGlobalAndPerRegion.
TEST(CollarRefine, PropagatedSizeTargetsSettleInOneRound) {
  struct Case {
    const char* what;
    plc::Plc plc;
    double max_volume;
  };
  absl::StatusOr<plc::Plc> cube = plc::ReadPlcFile(testing::CorpusPath("a_convex/cube.poly"));
  ASSERT_TRUE(cube.ok()) << cube.status();
  absl::StatusOr<plc::Plc> facet = plc::ReadPlcFile(testing::CorpusPath("b_internal/box_internal_facet.poly"));
  ASSERT_TRUE(facet.ok()) << facet.status();
  const std::vector<Case> cases = {{"cube 1e-4", *cube, 1e-4},
                                   {"box_internal_facet 1e-4", *facet, 1e-4},
                                   {"nested boxes", plc::families::NestedBoxes(3, 1e-2, 1.0 / 8), 0}};
  for (const Case& c : cases) {
    absl::StatusOr<plc::FeatureComplex> cx = plc::BuildFeatureComplex(c.plc);
    ASSERT_TRUE(cx.ok()) << cx.status();
    // Runs: 0 neither switch, 1 propagation only, 2 propagation and cells
    // sized on the output's tets (size_kept_tets, the default).
    uint64_t rounds[3] = {0, 0, 0}, insertions[3] = {0, 0, 0}, outside[3] = {0, 0, 0};
    for (int run_i = 0; run_i < 3; ++run_i) {
      RefineOptions opt;
      opt.max_volume = c.max_volume;
      opt.propagate_size_targets = run_i >= 1;
      opt.size_kept_tets = run_i == 2;
      opt.tet_quality = false;  // the cell test's rounds (tet_quality labels before the first round)
      absl::StatusOr<PointSetRefinement> run = RefinePlc(*cx, opt);
      ASSERT_TRUE(run.ok()) << c.what << ": " << run.status();
      rounds[run_i] = run->stats.size_rounds;
      insertions[run_i] = run->stats.insertions;
      outside[run_i] = run->stats.sizes_outside;
      EXPECT_EQ(run->stats.size_targets_propagated > 0, run_i >= 1) << c.what;
    }
    EXPECT_GT(rounds[0], rounds[1]) << c.what;
    EXPECT_LE(rounds[1], 1u) << c.what;
    EXPECT_LE(rounds[2], 1u) << c.what;
    // A target carried across a facet into the exterior would refine Ω's
    // exterior at the region's size: several times the points.
    EXPECT_LE(insertions[1], insertions[0] * 11 / 10) << c.what;
    // Ω's exterior no longer graded: 13% (nested boxes) to 43% (cube 1e-4)
    // fewer points.
    EXPECT_EQ(outside[1], 0u) << c.what;
    EXPECT_GT(outside[2], 0u) << c.what;
    EXPECT_LT(insertions[2], insertions[1] * 9 / 10) << c.what;
    std::printf("%s: size rounds %llu / %llu / %llu; insertions %llu / %llu / %llu\n", c.what,
                (unsigned long long)rounds[0], (unsigned long long)rounds[1], (unsigned long long)rounds[2],
                (unsigned long long)insertions[0], (unsigned long long)insertions[1], (unsigned long long)insertions[2]);
  }
}

// RefineOptions::tet_quality (docs/svrc-design.md §8 item 34): once M_Ω is
// labelled, quality is tested per output tet (radius-edge > τ/2) instead of
// per Voronoi cell (R_v/r_v > τ), and so is max_volume when the regions'
// bounds differ. Both meshes conform and meet radius-edge
// ≤ 2 on every output tet; the per-tet test needs far fewer tets on the
// spread inputs, where the cell test grades the mesh more gently than the
// bound needs (measured: tiny_cube_in_box 3,596 → 1,316 tets, tetgen -pq2
// 1,286; far_offset_close_points 4,060 → 1,084, tetgen 978; box_in_box,
// since §8 item 37's link order, 345 → 320). The run with
// validate_every checks the final invariant: no output tet is bad.
TEST(CollarRefine, TetQualityMeetsTheBoundWithFewerTets) {
  struct Case {
    const char* file;  // corpus path, or "nested" for families::NestedBoxes
    double max_ratio;  // tets with the per-tet test / with the cell test
    uint32_t validate_every;
  };
  for (const Case& c : {Case{"e_spread/tiny_cube_in_box.poly", 0.5, 64}, Case{"e_spread/far_offset_close_points.poly", 0.5, 0},
                        Case{"b_internal/box_in_box.poly", 1.0, 0}, Case{"nested", 0.5, 0}}) {
    // nested: three regions with max volumes 1e-2, 1.25e-3, 1.5625e-4. A
    // cell takes the smallest target of its tets; tested per tet once the
    // targets differ: 4,165 tets with the cell tests, 1,152 (tetgen -pq2a:
    // 1,690); each tet's volume bound is checked by
    // PlcRefine.MaxVolumeGlobalAndPerRegion.
    absl::StatusOr<plc::Plc> plc = CaseInput(c.file);
    ASSERT_TRUE(plc.ok()) << plc.status();
    absl::StatusOr<plc::FeatureComplex> cx = plc::BuildFeatureComplex(*plc);
    ASSERT_TRUE(cx.ok()) << cx.status();
    size_t tets[2] = {0, 0};
    for (int per_tet = 0; per_tet < 2; ++per_tet) {
      RefineOptions opt;
      opt.tet_quality = per_tet == 1;
      opt.validate_every = per_tet == 1 && !kSanitized ? c.validate_every : 0;
      const std::optional<RefinedMesh> r = RefineAndCheck(*plc, *cx, opt, absl::StrCat(c.file, " per_tet ", per_tet));
      ASSERT_TRUE(r.has_value());
      tets[per_tet] = r->mesh.tets.size();
    }
    EXPECT_LT(static_cast<double>(tets[1]), c.max_ratio * static_cast<double>(tets[0])) << c.file;
    std::printf("%s: %zu tets with the cell test, %zu with the per-tet test\n", c.file, tets[0], tets[1]);
  }
}

// RefineOptions::tet_volumes (docs/svrc-design.md §8 item 35): with
// max_volume, each output tet is tested on its volume against its region's
// bound instead of its circumradius against the regular tet's of that
// volume. Both runs conform, keep radius-edge ≤ 2 and every tet within its
// region's bound (the volumes are read on the output, in input coordinates);
// the volume test needs fewer tets (measured: cube --max-volume 1e-5 230,224
// → 180,423, tetgen -pq2a 197,050). A volume test against a larger bound
// than the region's fails the bound check; one that never fires fails the
// tet count.
TEST(CollarRefine, VolumeTestMeetsTheBoundWithFewerTets) {
  struct Case {
    const char* file;  // corpus path, or "nested" for families::NestedBoxes
    double max_volume;  // global bound (0: the regions' own)
    double max_ratio;   // tets with the volume test / with the circumradius test
  };
  for (const Case& c : {Case{"a_convex/cube.poly", 1e-3, 0.9}, Case{"b_internal/box_in_box.poly", 2e-4, 0.9},
                        Case{"nested", 0, 1.03}}) {
    // nested: three regions with max volumes 1e-2, 1.25e-3, 1.5625e-4; its
    // small boxes' radius-edge and grading set most sizes, so the two tests
    // give about as many tets and the event order decides the rest: 1,179 →
    // 1,159 with FIFO Skinny₃ buckets, 1,210 → 1,222 newest first (design §8
    // item 52). Bounded at +3%: not more tets than that for the exact bound.
    absl::StatusOr<plc::Plc> plc = CaseInput(c.file);
    ASSERT_TRUE(plc.ok()) << plc.status();
    absl::StatusOr<plc::FeatureComplex> cx = plc::BuildFeatureComplex(*plc);
    ASSERT_TRUE(cx.ok()) << cx.status();
    size_t tets[2] = {0, 0};
    for (int volumes = 0; volumes < 2; ++volumes) {
      RefineOptions opt;
      opt.max_volume = c.max_volume;
      opt.tet_volumes = volumes == 1;
      opt.validate_every = volumes == 1 && !kSanitized ? 256 : 0;
      const std::optional<RefinedMesh> r = RefineAndCheck(*plc, *cx, opt, absl::StrCat(c.file, " volumes ", volumes));
      ASSERT_TRUE(r.has_value());
      const mesh::TetMesh& m = r->mesh;
      ASSERT_EQ(m.tet_region.size(), m.tets.size()) << c.file;
      const std::optional<size_t> over = TetsAboveTheirBound(m, c.max_volume);
      ASSERT_TRUE(over.has_value()) << c.file << ": a tet without a volume bound";
      EXPECT_EQ(*over, 0u) << c.file << " volumes " << volumes << ": tets above their region's bound";
      tets[volumes] = m.tets.size();
    }
    EXPECT_LT(static_cast<double>(tets[1]), c.max_ratio * static_cast<double>(tets[0])) << c.file;
    std::printf("%s: %zu tets with the circumradius test, %zu with the volume test\n", c.file, tets[0], tets[1]);
  }
}

// RefineOptions::newest_first_tets (docs/svrc-design.md §8 item 52): under
// per-tet quality the Skinny₃ buckets are served newest first. The order
// inside a bucket is free (the thesis orders buckets), so either order must
// give a conforming mesh meeting radius-edge 2 and every region's volume
// bound, with the location graph's invariants checked along the way; the
// outputs differ (the option takes effect) and their tet counts stay within
// 10% of each other (measured, M_Ω's tets with the exterior: 12,963 →
// 13,440 on box_in_box 2e-4, 2,152 → 2,241 on nested; output tets on 46
// bench rows: geometric mean ×0.974).
TEST(CollarRefine, NewestFirstSkinnyTetsGiveAValidMeshEitherWay) {
  struct Case {
    const char* file;
    double max_volume;
  };
  for (const Case& c : {Case{"b_internal/box_in_box.poly", 2e-4}, Case{"nested", 0}}) {
    absl::StatusOr<plc::Plc> plc = CaseInput(c.file);
    ASSERT_TRUE(plc.ok()) << plc.status();
    absl::StatusOr<plc::FeatureComplex> cx = plc::BuildFeatureComplex(*plc);
    ASSERT_TRUE(cx.ok()) << cx.status();
    std::vector<std::array<uint32_t, 4>> tets[2];
    for (int newest = 0; newest < 2; ++newest) {
      RefineOptions opt;
      opt.max_volume = c.max_volume;
      opt.newest_first_tets = newest == 1;
      opt.validate_every = kSanitized ? 0 : 128;
      const std::string what = absl::StrCat(c.file, " newest_first ", newest);
      const std::optional<RefinedMesh> r = RefineAndCheck(*plc, *cx, opt, what);
      ASSERT_TRUE(r.has_value()) << what;
      const std::optional<size_t> over = TetsAboveTheirBound(r->mesh, c.max_volume);
      ASSERT_TRUE(over.has_value()) << what << ": a tet without a volume bound";
      EXPECT_EQ(*over, 0u) << what << ": tets above their region's bound";
      tets[newest] = r->run.tets;
    }
    EXPECT_NE(tets[0], tets[1]) << c.file << ": the option changed nothing";
    const double ratio = static_cast<double>(tets[1].size()) / static_cast<double>(tets[0].size());
    EXPECT_GT(ratio, 0.9) << c.file;
    EXPECT_LT(ratio, 1.1) << c.file;
    std::printf("%s: %zu refinement tets oldest first, %zu newest first\n", c.file, tets[0].size(), tets[1].size());
  }
}

// RefineOptions::sliver_break_deg (docs/svrc-design.md §8 item 38): after
// the per-tet refinement, kept tets below 5° whose circumcentre would be
// inserted as is get it inserted. example.poly at radius-edge 1.414 kept one
// tet at 3.16° through the flip pass (session 14's volume test and link
// order); with the round its smallest dihedral is 15.0°. Checked on the
// output after the flip pass, as core::MeshPlc runs it: conforming, radius-
// edge ≤ 1.414, at most 5% more tets.
TEST(CollarRefine, SliverRoundLiftsTheSmallestDihedral) {
  absl::StatusOr<plc::Plc> plc = CaseInput("b_internal/example.poly");
  ASSERT_TRUE(plc.ok()) << plc.status();
  absl::StatusOr<plc::FeatureComplex> cx = plc::BuildFeatureComplex(*plc);
  ASSERT_TRUE(cx.ok()) << cx.status();
  double min_dihedral[2] = {0, 0};
  size_t tets[2] = {0, 0};
  for (int round = 0; round < 2; ++round) {
    RefineOptions opt;
    opt.tau = 2 * 1.414;
    opt.attempt_creases = true;  // its 63° crease is refined through, as core::MeshPlc does
    opt.sliver_break_deg = round == 1 ? 5 : 0;
    absl::StatusOr<PointSetRefinement> run = RefinePlc(*cx, opt);
    ASSERT_TRUE(run.ok()) << run.status();
    EXPECT_EQ(run->stats.slivers_broken > 0, round == 1);
    const std::vector<ConstrainedFace> faces = ConstrainedFacesOf(*run, *cx);
    SliverOptions so;
    so.max_radius_edge = 1.414;
    so.skip_tet = run->tet_outside;
    so.keep_max_volume = true;
    absl::StatusOr<SliverResult> flipped =
        RemoveSlivers(run->normalised_positions, run->tets, faces, run->segment_chains, so);
    ASSERT_TRUE(flipped.ok()) << flipped.status();
    absl::StatusOr<OutputStageResult> out = BuildOutputMesh(*plc, run->normalised_positions, flipped->tets,
                                                            cx->point_of_vertex, faces, CoordinateMapOf(*run), false);
    ASSERT_TRUE(out.ok()) << out.status();
    const mesh::ConformityReport rep = mesh::CheckConformity(*plc, out->mesh);
    EXPECT_TRUE(rep.ok()) << "round " << round << ": " << rep.Summary();
    const mesh::QualityReport q = mesh::ComputeQuality(out->mesh);
    EXPECT_LE(q.all.radius_edge.max, 1.414 * (1 + 1e-9)) << "round " << round;
    min_dihedral[round] = q.all.dihedral_deg.min;
    tets[round] = out->mesh.tets.size();
  }
  EXPECT_GE(min_dihedral[1], 5.0);
  EXPECT_LE(static_cast<double>(tets[1]), 1.05 * static_cast<double>(tets[0]));
  std::printf("example.poly at 1.414: smallest dihedral %.2f without the round (%zu tets), %.2f with (%zu tets)\n",
              min_dihedral[0], tets[0], min_dihedral[1], tets[1]);
}

// PointSetRefinement::tet_outside (the refiner's labels, kept up to the end
// once M_Ω is labelled) lets the sliver pass skip ∂Ω's exterior
// (SliverOptions::skip_tet). Flips never cross a constrained face, so the
// output mesh must come out the same, bit for bit, with fewer candidates
// (measured: cube 1e-4 12,737 → 3,611; instructions −4%, tiny_cube_in_box
// −19%). A kept tet flagged outside would keep a sliver the full pass flips.
TEST(CollarRefine, SliverPassSkipsTheExteriorWithTheSameOutput) {
  struct Case {
    const char* file;
    double max_volume;
  };
  for (const Case& c : {Case{"e_spread/tiny_cube_in_box.poly", 0}, Case{"b_internal/box_in_box.poly", 1e-3}}) {
    absl::StatusOr<plc::Plc> plc = plc::ReadPlcFile(testing::CorpusPath(c.file));
    ASSERT_TRUE(plc.ok()) << plc.status();
    absl::StatusOr<plc::FeatureComplex> cx = plc::BuildFeatureComplex(*plc);
    ASSERT_TRUE(cx.ok()) << cx.status();
    RefineOptions opt;
    opt.max_volume = c.max_volume;
    absl::StatusOr<PointSetRefinement> run = RefinePlc(*cx, opt);
    ASSERT_TRUE(run.ok()) << c.file << ": " << run.status();
    ASSERT_EQ(run->tet_outside.size(), run->tets.size()) << c.file;
    size_t outside = 0;
    for (uint8_t o : run->tet_outside) outside += o;
    EXPECT_GT(outside, 0u) << c.file;
    const std::vector<ConstrainedFace> faces = ConstrainedFacesOf(*run, *cx);
    std::vector<mesh::TetMesh> meshes;
    uint64_t candidates[2] = {0, 0};
    for (int skip = 0; skip < 2; ++skip) {
      SliverOptions so;
      if (skip == 1) so.skip_tet = run->tet_outside;
      absl::StatusOr<SliverResult> flipped =
          RemoveSlivers(run->normalised_positions, run->tets, faces, run->segment_chains, so);
      ASSERT_TRUE(flipped.ok()) << flipped.status();
      candidates[skip] = flipped->stats.candidates;
      absl::StatusOr<OutputStageResult> out = BuildOutputMesh(*plc, run->normalised_positions, flipped->tets,
                                                              cx->point_of_vertex, faces, CoordinateMapOf(*run), false);
      ASSERT_TRUE(out.ok()) << out.status();
      meshes.push_back(std::move(out->mesh));
    }
    EXPECT_EQ(meshes[0].positions, meshes[1].positions) << c.file;
    EXPECT_EQ(meshes[0].tets, meshes[1].tets) << c.file;
    EXPECT_EQ(meshes[0].tet_region, meshes[1].tet_region) << c.file;
    EXPECT_LT(candidates[1], candidates[0]) << c.file;
    std::printf("%s: %zu of %zu tets outside; sliver candidates %llu -> %llu\n", c.file, outside, run->tets.size(),
                (unsigned long long)candidates[0], (unsigned long long)candidates[1]);
  }
}

// RefineOptions::reuse_round_work: the COLLAR rounds' per-ball restricted
// Delaunay of S, the settled facets' arc checks and EnqueueMissing's memory
// of simplices found in M_Ω must give the refinement of a run that
// recomputes them every round, bit for bit; so must BreakSlivers' rounds
// that skip the tets an earlier round found clear. knife_edge.poly and
// segment_fan.poly run many COLLAR rounds; cube.poly with max_volume runs
// size rounds (each ends in EnqueueMissing) and sliver rounds.
TEST(CollarRefine, ReusedRoundWorkGivesTheSameRefinement) {
  if (kSanitized) GTEST_SKIP() << "release only";
  for (const SameRefinementCase& c :
       {SameRefinementCase{"c_creases/knife_edge.poly", true, 0}, SameRefinementCase{"d_small_angles/segment_fan.poly", true, 0},
        SameRefinementCase{"a_convex/cube.poly", false, 1e-4}}) {
    const auto runs = RefineTwiceAndCompare(c, [](RefineOptions* o, bool on) { o->reuse_round_work = on; });
    EXPECT_EQ(runs[0].stats.collar_balls_reused, 0u) << c.rel;
    EXPECT_EQ(runs[0].stats.arc_facets_settled, 0u) << c.rel;
    EXPECT_EQ(runs[0].stats.sliver_scan_reused, 0u) << c.rel;
    if (c.collars) {
      EXPECT_GT(runs[1].stats.collar_balls_reused, 0u) << c.rel;
      EXPECT_GT(runs[1].stats.collar_rounds, 3u) << c.rel;
    } else {
      // BreakSlivers' later rounds skip the tets an earlier one cleared.
      EXPECT_GT(runs[1].stats.sliver_scan_reused, 0u) << c.rel;
    }
  }
}

// RefineOptions::skip_unchanged_tets (docs/svrc-design.md §8 item 53): a
// size round tests only the tets whose label it changed, and gives the same
// refinement as testing every tet; with validate_every the final invariant
// check finds no bad tet left. cube: one region; box_in_box and
// box_internal_facet: two kept regions on either side of internal facets;
// tiny_cube_in_box: a round that corrects a propagated label (measured: 1
// of 4,596 tets; example.poly 3e-4: 68 of 136,171), so the comparison
// is seen to tell a changed label from an unchanged one.
TEST(CollarRefine, SizeRoundsSkippingUnchangedLabelsGiveTheSameRefinement) {
  for (const SameRefinementCase& c :
       {SameRefinementCase{"a_convex/cube.poly", false, 1e-4}, SameRefinementCase{"b_internal/box_in_box.poly", false, 2e-4},
        SameRefinementCase{"b_internal/box_internal_facet.poly", false, 1e-4},
        SameRefinementCase{"e_spread/tiny_cube_in_box.poly", false, 1e-3}}) {
    const auto runs = RefineTwiceAndCompare(c, [](RefineOptions* o, bool on) {
      o->skip_unchanged_tets = on;
      o->validate_every = kSanitized ? 0 : 512;
    });
    EXPECT_EQ(runs[0].stats.labels_unchanged, 0u) << c.rel;
    EXPECT_EQ(runs[0].stats.labels_changed, 0u) << c.rel;
    // Most tets keep their propagated label through the confirming round.
    EXPECT_GT(runs[1].stats.labels_unchanged, runs[1].tets.size() / 2) << c.rel;
    if (std::string_view(c.rel) == "e_spread/tiny_cube_in_box.poly") {
      EXPECT_GT(runs[1].stats.labels_changed, 0u) << c.rel;
    }
    EXPECT_EQ(runs[0].stats.size_rounds, runs[1].stats.size_rounds) << c.rel;
  }
}

// Cancellation and deadlines are polled inside the COLLAR rounds too, every
// poll_interval repairs, with a progress report each time: a round can
// insert tens of thousands of points (fandisk.off: a 900 s deadline ended
// the job at 963 s when only Run() polled). With poll_interval 16, the
// vertices added between two reports stay far below one round's repairs
// (knife_edge.poly's round 0: ~230 points on S and ~200 on facet arcs).
TEST(CollarRefine, CollarRoundsPollBetweenRepairs) {
  absl::StatusOr<plc::Plc> plc = plc::ReadPlcFile(testing::CorpusPath("c_creases/knife_edge.poly"));
  ASSERT_TRUE(plc.ok()) << plc.status();
  absl::StatusOr<plc::FeatureComplex> cx = plc::BuildFeatureComplex(*plc);
  ASSERT_TRUE(cx.ok()) << cx.status();
  RefineOptions opt;
  opt.collars = true;
  opt.collar_surface = true;
  opt.max_rep_angle = 60 * M_PI / 180;
  opt.poll_interval = 16;
  uint64_t polls = 0, last = 0, max_gap = 0;
  opt.poll = [&] {
    ++polls;
    return absl::OkStatus();
  };
  opt.progress = [&](const char*, uint64_t vertices, uint64_t, double) {
    if (last > 0) max_gap = std::max(max_gap, vertices - std::min(vertices, last));
    last = vertices;
  };
  absl::StatusOr<PointSetRefinement> run = RefinePlc(*cx, opt);
  ASSERT_TRUE(run.ok()) << run.status();
  EXPECT_GT(run->stats.collar_rounds, 3u);
  EXPECT_GT(polls, 100u);
  std::printf("polls %llu, most vertices between two reports %llu\n", static_cast<unsigned long long>(polls),
              static_cast<unsigned long long>(max_gap));
  EXPECT_LE(max_gap, 120u);
}

// The dihedral bounds of docs/svrc-collars.md §1 (Theorems 1 and 2) on the
// stars and books RipStitchCollar builds for real inputs: every tet whose own
// σ, ε (and γ / α) meet its theorem's premises has every dihedral within its
// own bound (the stitch counts violations; the synthetic scenes of
// rip_stitch_test check the same). And the σ the bounds are a function of:
// with the thesis' snap band δ = 0.02 (§3.1.2: the angle test sees vertices
// near S moved onto it) the stitched stars, which use the true positions,
// exceed σ where the sample of S is about as fine as δ·ρ (measured in
// session 11: knife_edge.poly 84.8°, segment_fan.poly 87.8° at σ = 60°;
// stars with edges of 0.02–0.04 ρ and vertices up to 0.019 ρ off the
// sphere). With collar_snap = 0 (the default since then) the rounds test
// the true angles and no star or book exceeds σ.
TEST(CollarRefine, StitchedTetsMeetTheirDihedralBounds) {
  for (const char* rel : {"c_creases/knife_edge.poly", "d_small_angles/segment_fan.poly"}) {
    if (kSanitized && std::string(rel).find("segment_fan") != std::string::npos) continue;
    absl::StatusOr<plc::Plc> plc = plc::ReadPlcFile(testing::CorpusPath(rel));
    ASSERT_TRUE(plc.ok()) << plc.status();
    absl::StatusOr<plc::FeatureComplex> cx = plc::BuildFeatureComplex(*plc);
    ASSERT_TRUE(cx.ok()) << cx.status();
    for (double snap : {0.02, 0.0}) {
      RefineOptions opt;
      opt.collars = true;
      opt.collar_surface = true;
      opt.max_rep_angle = 60 * M_PI / 180;
      opt.collar_snap = snap;
      absl::StatusOr<PointSetRefinement> run = RefinePlc(*cx, opt);
      ASSERT_TRUE(run.ok()) << rel << ": " << run.status();
      const RefineStats& st = run->stats;
      const StitchShape& sh = st.stitch;
      std::printf("%s snap %g: %llu stars, %llu books, %u within the premises (largest dihedral %.2f), others %.2f; "
                  "star sigma %.2f eps %.3f gamma %.2f, dihedral base %.2f radial %.2f; book sigma %.2f\n",
                  rel, snap, static_cast<unsigned long long>(st.stitch_stars),
                  static_cast<unsigned long long>(st.stitch_books), sh.bounded(), sh.max_bounded_dihedral_deg,
                  sh.max_unbounded_dihedral_deg, sh.star_sigma_max_deg, sh.star_eps_max, sh.star_gamma_max_deg,
                  sh.max_star_base_deg, sh.max_star_radial_deg, sh.book_sigma_max_deg);
      EXPECT_GT(st.stitch_stars, 1000u) << rel;
      EXPECT_GT(sh.bounded(), (st.stitch_stars + st.stitch_books) * 9 / 10) << rel << " snap " << snap;
      EXPECT_EQ(sh.violations(), 0u) << rel << " snap " << snap;
      EXPECT_EQ(st.collar_snap, snap) << rel << ": the rounds fell back to the snap band";
      if (snap == 0) {
        EXPECT_LE(sh.star_sigma_max_deg, 60 + 1e-9) << rel;
        EXPECT_LE(sh.book_sigma_max_deg, 60 + 1e-9) << rel;
      }
    }
  }
}
}  // namespace svrc::refine
namespace svrc::refine {
namespace {

// RefineOptions::crossings_once_topology_holds (docs/svrc-collars.md
// "Session 19"): the facet-crossing check in every COLLAR round once the
// restricted triangulation's topology has held, instead of only in a round
// with nothing else to repair. Each batch of arc points the late check found
// restarted rounds that had settled (crease_pair 5°: settled 7 times, 86
// rounds); checked along the way they go in with the angle repairs. Both
// runs conform. Measured before the collar shell (CreateCollar keeps
// vertices 0.2% of the radius off a new sphere): 85 → 27 rounds, 19,349 →
// 17,635 vertices. With it the late check no longer restarts that often:
// 40 → 39 rounds, 16,201 → 20,091 vertices; the early check is still no
// slower in rounds, which is all this asserts now.
TEST(CollarRefine, CrossingsCheckedOnceTopologyHoldsSettleInFewerRounds) {
  if (kSanitized) GTEST_SKIP() << "release only (seconds per run)";
  const plc::Plc plc = plc::families::CreaseFacetPair(5);
  absl::StatusOr<plc::FeatureComplex> cx = plc::BuildFeatureComplex(plc);
  ASSERT_TRUE(cx.ok()) << cx.status();
  RefineStats stats[2];
  for (int early = 0; early < 2; ++early) {
    RefineOptions opt;
    opt.tau = 4;
    opt.collars = true;
    opt.collar_surface = true;
    opt.max_rep_angle = 60 * M_PI / 180;
    opt.crossings_once_topology_holds = early == 1;
    absl::StatusOr<PointSetRefinement> run = RefinePlc(*cx, opt);
    ASSERT_TRUE(run.ok()) << run.status();
    const std::vector<ConstrainedFace> faces = ConstrainedFacesOf(*run, *cx);
    absl::StatusOr<OutputStageResult> out = BuildOutputMesh(plc, run->normalised_positions, run->tets,
                                                            cx->point_of_vertex, faces, CoordinateMapOf(*run), false);
    ASSERT_TRUE(out.ok()) << out.status();
    const mesh::ConformityReport rep = mesh::CheckConformity(plc, out->mesh);
    EXPECT_TRUE(rep.ok()) << "early " << early << ": " << rep.Summary();
    stats[early] = run->stats;
  }
  EXPECT_LE(stats[1].collar_rounds, stats[0].collar_rounds);
  std::printf("crease_pair 5 deg: %llu rounds, %llu vertices with the late check; %llu, %llu checked once topology "
              "holds\n",
              (unsigned long long)stats[0].collar_rounds, (unsigned long long)stats[0].vertices,
              (unsigned long long)stats[1].collar_rounds, (unsigned long long)stats[1].vertices);
}

// RepairStitchedCrossings listed a crossing once per tet of the crossing edge,
// computed from the edge in that tet's orientation; the two orientations
// differ in the last bits, so one crossing became two hits, the second
// inserted 6.9e-18 from the first and M_F refined to the resolution of
// doubles (FAILED_PRECONDITION). Reached on schonhardt.off with the exact
// vertex-link test (docs/svrc-collars.md "Session 21"); this run must mesh,
// conform, and go through the stitched-crossing repair (if a change elsewhere
// stops it from reaching that repair, this input no longer tests it). Since
// the collar shell schonhardt.off has no stitched crossing at radius-edge 2
// or 1.8; at 1.6 it has one.
TEST(CollarRefine, StitchedCrossingsAreOnePointPerEdge) {
  if (kSanitized) GTEST_SKIP() << "release only (seconds per run)";
  absl::StatusOr<plc::Plc> plc = plc::ReadPlcFile(testing::CorpusPath("c_creases/schonhardt.off"));
  ASSERT_TRUE(plc.ok()) << plc.status();
  absl::StatusOr<plc::FeatureComplex> cx = plc::BuildFeatureComplex(*plc);
  ASSERT_TRUE(cx.ok()) << cx.status();
  RefineOptions opt;
  opt.tau = 3.2;
  opt.collars = true;
  opt.collar_surface = true;
  opt.max_rep_angle = 60 * M_PI / 180;
  opt.collar_exact_vertex_links = true;
  absl::StatusOr<PointSetRefinement> run = RefinePlc(*cx, opt);
  ASSERT_TRUE(run.ok()) << run.status();
  EXPECT_GT(run->stats.stitched_crossings, 0u);
  const std::vector<ConstrainedFace> faces = ConstrainedFacesOf(*run, *cx);
  absl::StatusOr<OutputStageResult> out = BuildOutputMesh(*plc, run->normalised_positions, run->tets,
                                                          cx->point_of_vertex, faces, CoordinateMapOf(*run), false);
  ASSERT_TRUE(out.ok()) << out.status();
  const mesh::ConformityReport rep = mesh::CheckConformity(*plc, out->mesh);
  EXPECT_TRUE(rep.ok()) << rep.Summary();
  std::printf("schonhardt.off at 1.6, exact vertex links: %llu stitched crossings, %zu tets\n",
              (unsigned long long)run->stats.stitched_crossings, run->tets.size());
}

// RefineOptions::unresolved_kept_warp (session 42, docs/svrc-design.md §8
// item 71): an Unresolved event next to the output's boundary whose
// farthest-corner gap ball holds no warp target destroys the kept corner's
// ball when that one holds one. The pending point is then inserted at once
// instead of after insertions at exterior corners: fewer M_Ω vertices for
// the same output (within 1% of the tets), the invariants holding
// throughout (validate_every), the output conforming within the bound.
// Measured (factor 16): M_Ω vertices 593 → 556, 3,694 → 3,627 and 3,785 →
// 3,723 with 3, 11 and 9 such warps, the same numbers of output tets.
TEST(CollarRefine, UnresolvedEventsWarpAtTheKeptCorner) {
  struct Case {
    const char* rel;
    double max_volume;
    uint32_t validate_every;
  };
  for (const Case& c : {Case{"a_convex/cube.poly", 1e-3, 97}, Case{"a_convex/cube.poly", 1e-4, 0},
                        Case{"b_internal/box_internal_facet.poly", 1e-4, 0}}) {
    absl::StatusOr<plc::Plc> plc = CaseInput(c.rel);
    ASSERT_TRUE(plc.ok()) << plc.status();
    absl::StatusOr<plc::FeatureComplex> cx = plc::BuildFeatureComplex(*plc);
    ASSERT_TRUE(cx.ok()) << cx.status();
    uint64_t vertices[2] = {0, 0}, warps[2] = {0, 0};
    size_t tets[2] = {0, 0};
    for (int on = 0; on < 2; ++on) {
      RefineOptions opt;
      opt.max_volume = c.max_volume;
      opt.unresolved_kept_warp = on == 1;
      opt.validate_every = kSanitized ? 0 : c.validate_every;
      const std::string what = absl::StrCat(c.rel, " ", c.max_volume, " kept warp ", on);
      const std::optional<RefinedMesh> r = RefineAndCheck(*plc, *cx, opt, what);
      ASSERT_TRUE(r.has_value()) << what;
      vertices[on] = r->run.stats.vertices;
      warps[on] = r->run.stats.unresolved_kept_warps;
      tets[on] = r->mesh.tets.size();
    }
    const std::string what = absl::StrCat(c.rel, " ", c.max_volume);
    EXPECT_EQ(warps[0], 0u) << what;
    EXPECT_GT(warps[1], 0u) << what;
    EXPECT_LT(vertices[1], vertices[0]) << what;
    EXPECT_NEAR(static_cast<double>(tets[1]), static_cast<double>(tets[0]), 0.01 * tets[0]) << what;
    std::printf("%s: M_Ω vertices %llu -> %llu, kept-corner warps %llu, output tets %zu -> %zu\n", what.c_str(),
                (unsigned long long)vertices[0], (unsigned long long)vertices[1], (unsigned long long)warps[1], tets[0],
                tets[1]);
  }
}

}  // namespace
}  // namespace svrc::refine
