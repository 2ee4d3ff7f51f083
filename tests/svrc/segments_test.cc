// Stage (b) of the guide's build plan: free segments (1D meshes, piece
// ConfBalls, encroachment, partial encroachment, yield). validate_every turns
// on the refiner's invariant checks (every ConfBall with a native vertex
// strictly inside is queued, a lower-dimensional encroacher is recorded, every
// unresolved segment point linked to its cell with an Unresolved event; at the
// end nothing is encroached). Here we check the output independently: every
// segment is a chain of edges of the tetrahedralization, lying on the segment.
#include <algorithm>
#include <cmath>
#include <set>
#include <utility>
#include <vector>

#include "core/geometry/predicates.h"
#include "core/svrc/feature_meshes.h"
#include "core/svrc/refiner.h"
#include "gtest/gtest.h"

namespace svrc::refine {
namespace {

using geom::Vec3;

void ExpectConformingSegments(const std::vector<Vec3>& pts, const std::vector<SegmentInput>& segs,
                              const PointSetRefinement& out, double tau) {
  std::set<std::pair<uint32_t, uint32_t>> edges;
  std::set<uint32_t> used;
  for (const auto& t : out.tets) {
    for (int i = 0; i < 4; ++i) {
      used.insert(t[i]);
      for (int j = i + 1; j < 4; ++j) edges.insert({std::min(t[i], t[j]), std::max(t[i], t[j])});
    }
  }
  for (size_t i = 0; i < pts.size(); ++i) {
    EXPECT_EQ(out.positions[i], pts[i]);
    EXPECT_TRUE(used.count(out.input_vertex[i]));
  }
  ASSERT_EQ(out.segment_chains.size(), segs.size());
  for (size_t s = 0; s < segs.size(); ++s) {
    const auto& chain = out.segment_chains[s];
    ASSERT_GE(chain.size(), 2u);
    EXPECT_EQ(chain.front(), segs[s].a);
    EXPECT_EQ(chain.back(), segs[s].b);
    const Vec3 a = pts[segs[s].a], b = pts[segs[s].b];
    const double len = geom::Dist(a, b);
    double prev_t = -1;
    for (size_t k = 0; k < chain.size(); ++k) {
      const Vec3 p = out.positions[chain[k]];
      // On the segment (within rounding), strictly advancing from a to b.
      const double t = geom::Dot(p - a, b - a) / (len * len);
      EXPECT_GT(t, prev_t);
      prev_t = t;
      const Vec3 foot = a + t * (b - a);
      EXPECT_LE(geom::Dist(p, foot), 1e-14 * (1 + geom::Norm(a) + geom::Norm(b)));
      if (k + 1 < chain.size()) {
        const uint32_t u = chain[k], v = chain[k + 1];
        EXPECT_TRUE(edges.count({std::min(u, v), std::max(u, v)}))
            << "segment " << s << ": piece " << u << "-" << v << " is not a mesh edge";
      }
    }
  }
  EXPECT_LE(out.stats.max_aspect, tau * (1 + 1e-12));
  // Volume covers Ω exactly once.
  double vol = 0;
  for (const auto& t : out.tets) {
    const Vec3 &p0 = out.positions[t[0]], &p1 = out.positions[t[1]], &p2 = out.positions[t[2]],
               &p3 = out.positions[t[3]];
    vol += geom::Dot(geom::Cross(p1 - p0, p2 - p0), p3 - p0) / 6.0;
  }
  const Vec3 e = out.omega.hi - out.omega.lo;
  EXPECT_NEAR(vol, e.x * e.y * e.z, 1e-9 * e.x * e.y * e.z);
}

RefineOptions Checked(uint32_t every) {
  RefineOptions o;
  o.validate_every = every;
  return o;
}

TEST(SegmentsTest, OneSegment) {
  std::vector<Vec3> pts = {{0, 0, 0}, {1, 0.3, -0.2}};
  std::vector<SegmentInput> segs = {{0, 1}};
  auto r = RefinePointsAndSegments(pts, segs, Checked(3));
  ASSERT_TRUE(r.ok()) << r.status();
  ExpectConformingSegments(pts, segs, *r, 4.0);
}

// Three orthogonal segments through a point (six pieces meeting at o): no
// crease (90°), every piece must be recovered.
TEST(SegmentsTest, ThreeOrthogonalSegmentsThroughAPoint) {
  std::vector<Vec3> pts = {{0, 0, 0}, {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  std::vector<SegmentInput> segs = {{0, 1}, {0, 2}, {0, 3}, {0, 4}, {0, 5}, {0, 6}};
  auto r = RefinePointsAndSegments(pts, segs, Checked(17));
  ASSERT_TRUE(r.ok()) << r.status();
  ExpectConformingSegments(pts, segs, *r, 4.0);
  // All six pieces are recovered as edges (checked above); the input is
  // symmetric enough that M_Ω's quality refinement alone makes them Delaunay.
  EXPECT_EQ(r->stats.warps, pts.size());
}

// A point 1e-6 from a segment's midpoint: inside the diametral ball, a
// lower-dimensional (non-native) encroacher — partial encroachment — and the
// segment must be split finely enough around it.
TEST(SegmentsTest, PointNearSegmentMidpoint) {
  std::vector<Vec3> pts = {{0, 0, 0}, {1, 0, 0}, {0.5, 1e-6, 0}};
  std::vector<SegmentInput> segs = {{0, 1}};
  auto r = RefinePointsAndSegments(pts, segs, Checked(97));
  ASSERT_TRUE(r.ok()) << r.status();
  ExpectConformingSegments(pts, segs, *r, 4.0);
  // The segment mesh is graded: ~log(1e6) levels of splits near the point.
  EXPECT_GT(r->segment_chains[0].size(), 10u);
  EXPECT_GT(r->stats.segment_vertices, 0u);
  // Insertions near the point would have encroached the pieces: Destroy
  // yielded to the segment mesh (Figure 3.4 lines 9–14).
  EXPECT_GT(r->stats.yields, 0u);
}

// Two skew segments (the segment version of the skew-lines input).
TEST(SegmentsTest, SkewSegmentsAndYield) {
  std::vector<Vec3> pts = {{0, 0, 0}, {0, 1, 0}, {0, 0, 0.05}, {1, 0.5, 0.05}};
  std::vector<SegmentInput> segs = {{0, 1}, {2, 3}};
  auto r = RefinePointsAndSegments(pts, segs, Checked(53));
  ASSERT_TRUE(r.ok()) << r.status();
  ExpectConformingSegments(pts, segs, *r, 4.0);
}

// A comb of parallel segments 0.05 apart (each must be split into ~1/0.05
// pieces: local feature size), and an obtuse (120°) corner: graded 1D meshes
// that agree with M_Ω.
TEST(SegmentsTest, CloseParallelSegmentsAndObtuseCorner) {
  std::vector<Vec3> pts;
  std::vector<SegmentInput> segs;
  for (int i = 0; i < 3; ++i) {
    pts.push_back({0, 0, 0.05 * i});
    pts.push_back({1, 0, 0.05 * i});
    segs.push_back({uint32_t(2 * i), uint32_t(2 * i + 1)});
  }
  const uint32_t o = static_cast<uint32_t>(pts.size());
  pts.push_back({0, 1, 0});
  pts.push_back({1, 1, 0});
  pts.push_back({-0.5, 1 + std::sqrt(0.75), 0});
  segs.push_back({o, o + 1});
  segs.push_back({o, o + 2});
  auto r = RefinePointsAndSegments(pts, segs, Checked(211));
  ASSERT_TRUE(r.ok()) << r.status();
  ExpectConformingSegments(pts, segs, *r, 4.0);
  // The middle segment is refined to its local feature size: no vertex of
  // the two neighbouring segments (0.05 away) lies inside the diametral ball
  // of one of its pieces (so pieces are at most ~0.13 long: ≥ 8 of them).
  const auto& mid = r->segment_chains[1];
  EXPECT_GE(mid.size(), 9u);
  for (size_t i = 0; i + 1 < mid.size(); ++i) {
    const Vec3 a = r->positions[mid[i]], b = r->positions[mid[i + 1]];
    for (int other : {0, 2}) {
      for (uint32_t q : r->segment_chains[other]) {
        EXPECT_LE(geom::InDiametralSphere(a, b, r->positions[q]), 0) << "piece " << i << " vertex " << q;
      }
    }
  }
}

TEST(SegmentsTest, DeterministicAndRejectsBadSegments) {
  std::vector<Vec3> pts = {{0, 0, 0}, {1, 0, 0}, {0.2, 0.1, 0.3}, {0.9, 0.8, -0.4}};
  std::vector<SegmentInput> segs = {{0, 1}, {2, 3}};
  auto a = RefinePointsAndSegments(pts, segs, {});
  auto b = RefinePointsAndSegments(pts, segs, {});
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->positions, b->positions);
  EXPECT_EQ(a->tets, b->tets);
  EXPECT_EQ(a->segment_chains, b->segment_chains);
  std::vector<SegmentInput> bad = {{0, 7}};
  EXPECT_EQ(RefinePointsAndSegments(pts, bad, {}).status().code(), absl::StatusCode::kInvalidArgument);
  // An acute corner is a crease (Definition 5): refused until collars exist.
  std::vector<SegmentInput> acute = {{0, 1}, {0, 2}};
  EXPECT_EQ(RefinePointsAndSegments(pts, acute, {}).status().code(), absl::StatusCode::kUnimplemented);
  std::vector<SegmentInput> loop = {{1, 1}};
  EXPECT_EQ(RefinePointsAndSegments(pts, loop, {}).status().code(), absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace svrc::refine

namespace svrc::refine {
namespace {

// The (1,2) point of a vertex collar (Figure 3.7 line 10) must not be
// strictly inside the vertex's ball, or CreateCollar gives it no ball and the
// vertex ball meets the next chain ball at a neck. armadillo.off's segment
// 70951 (input vertices 22147 and 22518 scaled by 1/128, as normalised; the
// vertex ball of 22147 with its radius from SVRC_COLLAR_DEBUG): the rounded
// point at t = ρ/|ab| is inside, and 64 single ulp steps of t (the loop
// until session 33) leave it inside; StepOutOfBall's doubling steps do not.
TEST(SegmentMesh, StepOutOfBallLeavesTheVertexBallOfAShortSegment) {
  const Vec3 v22147(-38.4341 / 128, -44.6605 / 128, 3.08521 / 128);
  const Vec3 v22518(-38.2737 / 128, -44.6012 / 128, 3.45225 / 128);
  const double rho = 0.0010317468755203655;
  for (const bool vertex_at_a : {true, false}) {
    const Vec3 pa = vertex_at_a ? v22147 : v22518, pb = vertex_at_a ? v22518 : v22147;
    const SegmentMesh m(PointId(0), PointId(1), pa, pb);
    const double len = geom::Dist(pa, pb);
    const double t0 = vertex_at_a ? rho / len : 1 - rho / len;
    ASSERT_GT(geom::InBall(m.PointAt(t0), v22147, rho), 0) << "rounding no longer puts the point inside";
    if (vertex_at_a) {
      double t = t0;
      for (int k = 0; k < 64; ++k) t = std::nextafter(t, 1.0);
      EXPECT_GT(geom::InBall(m.PointAt(t), v22147, rho), 0) << "64 single steps now suffice: find another input";
    }
    const double t = m.StepOutOfBall(t0, /*toward_b=*/vertex_at_a, v22147, rho);
    EXPECT_LE(geom::InBall(m.PointAt(t), v22147, rho), 0) << vertex_at_a;
    EXPECT_TRUE(vertex_at_a ? t > t0 : t < t0);
    EXPECT_LT(std::fabs(t - t0), 1e-12);
    // Already outside: unchanged.
    EXPECT_EQ(m.StepOutOfBall(t, vertex_at_a, v22147, rho), t);
  }
}

}  // namespace
}  // namespace svrc::refine
