// MeshParams::min_dihedral: sliver removal to a target (thesis §6.2.1;
// docs/svrc-design.md §8 item 69), through core::MeshPlc: the target is met
// where it is reachable, every other bound still holds, and what is left
// below an unreachable target is counted exactly, not hidden.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/api.h"
#include "core/mesh/conformity.h"
#include "core/mesh/crease_vertices.h"
#include "core/mesh/quality.h"
#include "core/plc/readers.h"
#include "core/svrc/refiner.h"
#include "gtest/gtest.h"
#include "tests/test_support.h"

namespace svrc::core {
namespace {

struct Case {
  const char* file;
  double max_volume;
};

plc::Plc Read(const char* rel) {
  absl::StatusOr<plc::Plc> p = plc::ReadPlcFile(testing::CorpusPath(rel));
  EXPECT_TRUE(p.ok()) << rel << ": " << p.status();
  return p.ok() ? *p : plc::Plc{};
}

// The smallest dihedral angle of the tets without a crease vertex.
double SmallestAwayFromCreases(const plc::Plc& plc, const mesh::TetMesh& m) {
  return mesh::ComputeQuality(m, mesh::CreaseVertexFlags(plc, m)).other.min_dihedral_deg.min;
}

// Measured in session 40: without the option these inputs have tets
// of 12.2°–15.2° (so each case below is one the option must change); with
// min_dihedral 20 every tet away from the creases reaches 20° (example.poly
// has a 63° crease, refined through without collars).
TEST(MinDihedral, ReachesTheTargetAndKeepsEveryOtherBound) {
  constexpr double kTarget = 20;
  for (const Case& c : {Case{"e_spread/tiny_cube_in_box.poly", 0}, Case{"e_spread/far_offset_close_points.poly", 0},
                        Case{"b_internal/box_internal_facet.poly", 1e-3}, Case{"a_convex/cube.poly", 1e-3},
                        Case{"b_internal/example.poly", 0}}) {
    SCOPED_TRACE(c.file);
    const plc::Plc plc = Read(c.file);
    MeshParams params;
    params.max_volume = c.max_volume;
    absl::StatusOr<mesh::TetMesh> plain = MeshPlc(plc, params);
    ASSERT_TRUE(plain.ok()) << plain.status();
    EXPECT_LT(SmallestAwayFromCreases(plc, *plain), kTarget);
    EXPECT_EQ(plain->stats.Get("min_dihedral.target", -1), -1);  // off: no report

    params.min_dihedral = kTarget;
    absl::StatusOr<mesh::TetMesh> m = MeshPlc(plc, params);
    ASSERT_TRUE(m.ok()) << m.status();
    const mesh::ConformityReport rep = mesh::CheckConformity(plc, *m);
    EXPECT_TRUE(rep.ok()) << rep.Summary();
    const mesh::QualityReport q = mesh::ComputeQuality(*m, mesh::CreaseVertexFlags(plc, *m));
    EXPECT_GE(q.other.min_dihedral_deg.min, kTarget);
    EXPECT_LE(q.other.radius_edge.max, params.radius_edge * (1 + 1e-9));
    if (c.max_volume > 0) {
      EXPECT_LE(q.all.max_volume, c.max_volume * (1 + 1e-9));
    }
    EXPECT_EQ(m->stats.Get("min_dihedral.target"), kTarget);
    EXPECT_EQ(m->stats.Get("min_dihedral.below", -1), 0);
    EXPECT_EQ(m->stats.Get("min_dihedral.smallest"), q.other.min_dihedral_deg.min);
    EXPECT_NE(m->provenance.parameters.find("min_dihedral=20"), std::string::npos) << m->provenance.parameters;
    std::printf("%s: smallest dihedral %.2f without, %.2f with min_dihedral %g (%zu -> %zu tets)\n", c.file,
                SmallestAwayFromCreases(plc, *plain), q.other.min_dihedral_deg.min, kTarget, plain->tets.size(),
                m->tets.size());
  }
}

// 35° is past what the rounds reach (docs/svrc-design.md §8 item 69): the
// mesh still comes back valid and conforming within its bounds, the report
// counts exactly the tets left below the target, and asking for more does
// not give less: the smallest angle is above the one without the option
// (example.poly: 12.22° without; straight to 35° the rounds left 7.57°, with
// the rising levels 19.5°).
TEST(MinDihedral, UnreachableTargetIsCountedNotHidden) {
  const plc::Plc plc = Read("b_internal/example.poly");
  absl::StatusOr<mesh::TetMesh> plain = MeshPlc(plc, MeshParams{});
  ASSERT_TRUE(plain.ok()) << plain.status();
  MeshParams params;
  params.min_dihedral = 35;
  absl::StatusOr<mesh::TetMesh> m = MeshPlc(plc, params);
  ASSERT_TRUE(m.ok()) << m.status();
  const mesh::ConformityReport rep = mesh::CheckConformity(plc, *m);
  EXPECT_TRUE(rep.ok()) << rep.Summary();
  const std::vector<uint8_t> crease = mesh::CreaseVertexFlags(plc, *m);  // its 63° crease
  size_t below = 0;
  double smallest = 180;
  double worst_radius_edge = 0;
  for (const auto& t : m->tets) {
    if (crease[t[0]] || crease[t[1]] || crease[t[2]] || crease[t[3]]) continue;
    const mesh::TetQuality tq =
        mesh::ComputeTetQuality(m->positions[t[0]], m->positions[t[1]], m->positions[t[2]], m->positions[t[3]]);
    below += tq.min_dihedral_deg < params.min_dihedral;
    smallest = std::min(smallest, tq.min_dihedral_deg);
    worst_radius_edge = std::max(worst_radius_edge, tq.radius_edge);
  }
  EXPECT_GT(below, 0u);
  EXPECT_EQ(m->stats.Get("min_dihedral.below"), static_cast<double>(below));
  EXPECT_EQ(m->stats.Get("min_dihedral.smallest"), smallest);
  EXPECT_LE(worst_radius_edge, params.radius_edge * (1 + 1e-9));
  EXPECT_GT(smallest, SmallestAwayFromCreases(plc, *plain));
  // The rounds stop when they stop gaining (4 rounds without fewer slivers,
  // or 1.5x + 1000 the vertices they started with): measured 45,535 tets
  // (23,720 without the option).
  EXPECT_LT(m->tets.size(), 2 * 45535u);
}

TEST(MinDihedral, RefusesTargetsNoTetCanMeetAndIsOffAtZero) {
  const plc::Plc plc = Read("b_internal/box_in_box.poly");
  for (double bad : {kMaxMinDihedralDeg, 80.0, 360.0, std::nan("")}) {
    MeshParams params;
    params.min_dihedral = bad;
    absl::StatusOr<mesh::TetMesh> m = MeshPlc(plc, params);
    EXPECT_EQ(m.status().code(), absl::StatusCode::kInvalidArgument) << bad;
    EXPECT_NE(m.status().message().find("min_dihedral"), std::string::npos) << m.status();
  }
  // The regular tetrahedron's 70.53° is the largest smallest angle a tet has.
  EXPECT_LT(kMaxMinDihedralDeg, std::acos(1.0 / 3) * 180 / M_PI);
  absl::StatusOr<mesh::TetMesh> plain = MeshPlc(plc, MeshParams{});
  ASSERT_TRUE(plain.ok()) << plain.status();
  for (double off : {0.0, -5.0}) {
    MeshParams params;
    params.min_dihedral = off;
    absl::StatusOr<mesh::TetMesh> m = MeshPlc(plc, params);
    ASSERT_TRUE(m.ok()) << m.status();
    EXPECT_EQ(m->positions, plain->positions) << off;
    EXPECT_EQ(m->tets, plain->tets) << off;
  }
}

TEST(MinDihedral, SameMeshEveryRun) {
  const plc::Plc plc = Read("b_internal/example.poly");
  MeshParams params;
  params.min_dihedral = 22;
  absl::StatusOr<mesh::TetMesh> a = MeshPlc(plc, params);
  absl::StatusOr<mesh::TetMesh> b = MeshPlc(plc, params);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->positions, b->positions);
  EXPECT_EQ(a->tets, b->tets);
  EXPECT_EQ(a->tet_region, b->tet_region);
}

// The candidate points (Chew 1997, Li–Teng 2001: the best of several points
// near the circumcentre, by the smallest dihedral angle of the tets each
// would make) against the circumcentre alone, the same rounds otherwise:
// fewer slivers broken and fewer vertices for the same target. Measured on
// cube --max-volume 1e-5 at 15°: 2,943 slivers broken against 4,786.
TEST(MinDihedral, CandidatePointsBreakFewerSliversThanCircumcentres) {
  const plc::Plc plc = Read("a_convex/cube.poly");
  absl::StatusOr<plc::FeatureComplex> cx = plc::BuildFeatureComplex(plc);
  ASSERT_TRUE(cx.ok()) << cx.status();
  uint64_t broken[2] = {0, 0}, vertices[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    refine::RefineOptions opt;
    opt.max_volume = 1e-4;
    opt.sliver_break_deg = 20;
    opt.sliver_break_rounds = 32;
    opt.sliver_yield = true;
    opt.sliver_candidates = k == 0 ? 0 : 16;
    absl::StatusOr<refine::PointSetRefinement> run = refine::RefinePlc(*cx, opt);
    ASSERT_TRUE(run.ok()) << run.status();
    broken[k] = run->stats.slivers_broken;
    vertices[k] = run->stats.vertices;
    EXPECT_EQ(run->stats.sliver_picks_off_centre > 0, k == 1);
  }
  std::printf("cube 1e-4 at 20 degrees: %llu slivers broken at circumcentres (%llu vertices), %llu with candidates "
              "(%llu)\n",
              static_cast<unsigned long long>(broken[0]), static_cast<unsigned long long>(vertices[0]),
              static_cast<unsigned long long>(broken[1]), static_cast<unsigned long long>(vertices[1]));
  EXPECT_LT(broken[1], broken[0]);
  EXPECT_LT(vertices[1], vertices[0]);
}

}  // namespace
}  // namespace svrc::core
