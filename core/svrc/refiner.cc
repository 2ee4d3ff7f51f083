// The SVRC refiner, stages (a)–(b) of the guide's plan: M_Ω, 0-balls of input
// points, free segments with 1D meshes and piece ConfBalls. Figure numbers are
// the thesis'. See refiner.h and docs/svrc-design.md.
#include "core/svrc/refiner.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <limits>
#include <span>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <tuple>

#include "absl/cleanup/cleanup.h"
#include "absl/functional/function_ref.h"
#include "absl/strings/str_cat.h"
#include "core/mesh/conformity.h"
#include "core/mesh/stats_payload.h"
#include "core/geometry/constructions.h"
#include "core/geometry/predicates.h"
#include "core/plc/features.h"
#include "core/plc/intersect.h"
#include "core/svrc/balls.h"
#include "core/svrc/collar_arcs.h"
#include "core/svrc/collar_index.h"
#include "core/svrc/collar_surface.h"
#include "core/svrc/rip_stitch.h"
#include "core/svrc/sliver.h"
#include "core/svrc/collar_size.h"
#include "core/svrc/containment.h"
#include "core/svrc/facet_mesh.h"
#include "core/svrc/feature_meshes.h"
#include "core/util/grow.h"
#include "core/svrc/labelling.h"
#include "core/svrc/location_graph.h"
#include "core/svrc/pending_points.h"
#include "core/svrc/normalize.h"
#include "core/svrc/points.h"
#include "core/svrc/work_queue.h"

namespace svrc::refine {
namespace {

using geom::Vec2;
using geom::Vec3;
using VertexId2 = FacetMesh::VertexId2;
using TriId2 = FacetMesh::TriId2;

// "Deeply inside" a protective ball: inside by more than the rounding noise
// of constructed points (docs/svrc-design.md §8 item 12). Facet Steiner
// points are rounded off their plane and frames are not exact, so exact ties
// of the construction (a circumcentre on a piece's diametral sphere at a 90°
// edge) come out strictly inside or outside at random; counting those as
// encroachment (or as a reason to yield) refines without end in self-similar
// corners (measured on cube.poly: to 3·10^−5 and the vertex budget).
// Encroachment and yields therefore need the exact predicate AND this margin;
// whatever the margin lets through is caught exactly at the end: a piece or
// triangle that is not a simplex of its meshes is enqueued (EnqueueMissing).
bool DeepInside(const Vec3& c, double r, const Vec3& x) {
  return geom::Dist2(x, c) < r * r * (1 - 1e-9) - 1e-13 * r;
}
bool DeepInside2(Vec2 c, double r, Vec2 x) {
  const double dx = x.x - c.x, dy = x.y - c.y;
  return dx * dx + dy * dy < r * r * (1 - 1e-9) - 1e-13 * r;
}
// Whether B(c, r) lies wholly beyond the bisector of x and y, on y's side:
// the signed distance from c to it, (|xc|² − |yc|²) / (2|xy|), exceeds r,
// so the ball misses V(x) (which lies on x's side). xc2 = |xc|², yc2 =
// |yc|², xy = |xy|. Conservative: the relative slack and 10^−12·scale2 keep
// rounding on the side of "may meet" (guide §3 allows inflated location).
bool BallBeyondBisector(double xc2, double yc2, double xy, double r, double scale2) {
  return xc2 - yc2 > 2.0 * r * xy * (1 + 1e-9) + 1e-12 * scale2;
}
// The same with |xy| taken from x and y only when the answer needs it: the
// right-hand side is at least 10^−12·scale2 (r, |xy| ≥ 0), so a difference
// at or below that is "may meet" without the square root. Bit for bit
// BallBeyondBisector(xc2, yc2, Dist(x, y), r, scale2).
bool BallBeyondBisectorOf(double xc2, double yc2, const Vec3& x, const Vec3& y, double r, double scale2) {
  if (!(xc2 - yc2 > 1e-12 * scale2)) return false;
  return BallBeyondBisector(xc2, yc2, geom::Dist(x, y), r, scale2);
}
// A deterministic offset in [−1, 1) from a point id (splitmix64): the
// Steiner points of facet and segment meshes are moved off the exact
// circumcentre/midpoint by 10^−6 of the gap radius (docs/svrc-design.md §8
// item 13). Exact midpoints and circumcentres of a dyadic facet mesh are
// exactly cocircular in fours (square cells); rounded into M_Ω, four
// cocircular coplanar points form flat tets on the facet (measured:
// far_offset_close_points, 2 tets inverted by the back map). Off-centre
// insertion is what warping does anyway (θ-medial points, Th. §3.1.1).
double Jitter(uint64_t id, uint64_t salt) {
  uint64_t z = id * 0x9E3779B97F4A7C15ull + salt;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) * 0x1.0p-52 - 1.0;
}
constexpr double kJitter = 1e-6;
// A new collar ball keeps every vertex at least kCollarShellGap of its radius
// off its sphere, stepping its radius down from g/3 by that much at most
// kCollarShellSteps times (CreateCollar). 2e-3: the RepBalls it leaves stay
// well above kMinCollarRepairRatio (1e-4).
constexpr double kCollarShellGap = 2e-3;
constexpr int kCollarShellSteps = 8;

Vec2 Mid2(Vec2 a, Vec2 b) { return {0.5 * (a.x + b.x), 0.5 * (a.y + b.y)}; }
double HalfLen2(Vec2 a, Vec2 b) { return 0.5 * std::hypot(a.x - b.x, a.y - b.y); }
// 6|V| of tet x, and the cube of its longest edge: their ratio is the
// flatness BreakFlatTets and BreakSlivers screen tets by.
double Volume6(const std::array<Vec3, 4>& x) {
  return std::fabs(geom::Dot(x[1] - x[0], geom::Cross(x[2] - x[0], x[3] - x[0])));
}
double LongestEdgeCubed(const std::array<Vec3, 4>& x) {
  double l2 = 0;
  for (int i = 0; i < 4; ++i) {
    for (int j = i + 1; j < 4; ++j) l2 = std::max(l2, geom::Dist2(x[i], x[j]));
  }
  return l2 * std::sqrt(l2);
}

class Refiner {
 public:
  Refiner(const RefineOptions& options, Normalization norm, const Vec3& center, double half)
      : options_(options), norm_(norm), omega_(center, half), pending_(center, half), collar_snap_(options.collar_snap) {
    omega_.SetCacheLimits(options.omega_cc_log2, options.omega_memo_log2, options.omega_neighbor_entries);
    balls_.EnableRecycling(options.recycle_balls && !options.collars);
  }

  absl::Status Initialize(std::span<const Vec3> normalised, std::span<const SegmentInput> segments);
  // Shared by both entry points: the complex's points are `normalised` (global
  // ids 0..n−1), its segments and facets become meshes (Figure 3.3).
  absl::Status Setup(const plc::FeatureComplex& complex, std::span<const Vec3> normalised);
  absl::Status Run();
  absl::Status CheckInvariants(bool final);
  // Hands the balls killed since the last call back to the ball store
  // (RefineOptions::recycle_balls).
  void RecycleBalls();
  PointSetRefinement Output(std::span<const Vec3> input);
  // Output() is the refiner's last use: it first frees what only the
  // refinement reads (the location graph, the balls, the queues, the COLLAR
  // rounds' memos), whose bytes would otherwise add to the output's at the
  // run's peak (crease_pair_1deg: the peak heap was in Output()).
  void ReleaseRefinementState();
  // The counters Output() reports, except the per-vertex scans (max degree,
  // max aspect): also for a run that fails (attached to its status).
  void FillCounters(RefineStats* out) const;
  const RefineStats& stats() const { return stats_; }
  // The facts the output stage relies on, checked on the final meshes: every
  // segment piece is an edge and every in-facet triangle a face of M_Ω, all
  // their vertices in M_Ω. INTERNAL naming the first failure.
  absl::Status VerifyConformity() const;
 public:
  // max_volume (issue #5 "size events"): labels the regions of the current,
  // conforming M_Ω (flood fill across faces that are not in-facet triangles,
  // seeds and holes of the complex), and gives every vertex of a kept tet the
  // size target R_t = the circumradius of a regular tet of its region's
  // volume bound (the smallest bound of its tets; `global_max_volume` in
  // input units applies to every kept region; ≤ 0: none). A cell with
  // R_v ≤ R_t has incident tets of circumradius ≤ R_t, hence volume ≤ the
  // bound (the regular tet has the largest volume for its circumradius).
  // Vertices created later get no target until the next call (inheriting one
  // leaked targets across facets into the exterior: measured, the whole Ω
  // refined to max_volume); a τ-well-spaced neighbour of a small cell is small.
  // Enqueues the cells above target; returns whether any was.
  absl::StatusOr<bool> SetSizeTargets(const plc::FeatureComplex& complex, double global_max_volume,
                                      bool all_vertices = false);
  void CountSizeRound() { ++stats_.size_rounds; }
  // Set by RefinePlc (docs/svrc-design.md §8 item 34): M_Ω's Skinny test off
  // until the features conform (features_first); output tets tested per tet
  // once M_Ω is labelled (tet_quality); max_volume per tet too (set by the
  // first labelling when the regions' bounds differ, or RefineOptions::tet_sizes).
  bool skinny_deferred_ = false;
  // RefineOptions::newest_first_tets.
  void ServeSkinnyTetsNewestFirst() { queues_.SetNewestFirst(EventType::kSkinny, 3, true); }
  bool tet_mode_ = false;
  bool tet_sizes_ = false;
  // RefineOptions::collar_tet_quality: tet_mode_ without labels (TetBad).
  bool collar_tets_ = false;
  // collar_tets_: enqueues every bad tet of M_Ω (after the features conform).
  void EnqueueBadTets() {
    const delaunay::Delaunay3& dt = omega_.dt();
    for (uint32_t i = 0; i < dt.TetCapacity(); ++i) {
      if (dt.IsAlive(TetId(i))) EnqueueTetIfBad(TetId(i));
    }
  }
 private:
  // End of the queues: a piece that is not an edge of M_Ω or of a facet mesh
  // containing it, or an in-facet triangle that is not a face of M_Ω, has a
  // non-encroached but tied ball (vertices exactly on its sphere on several
  // sides, decided by the perturbation against it): enqueue it Encroached.
  // Returns whether anything was enqueued.
  bool EnqueueMissing();
  bool OmegaHasEdge(PointId a, PointId b) const;
  bool OmegaHasFace(PointId a, PointId b, PointId c) const;
  bool FacetHasEdge(uint32_t f, PointId a, PointId b);

 private:
  // --- Destroy (Figure 3.4) -------------------------------------------------
  absl::Status Destroy(const WorkEvent& event);
  // A gap ball of M_Ω (Skinny₃ / Unresolved₃ of cell v): warp, else yield,
  // else insert the centre.
  // skinny: a Skinny event's gap ball (the kept corners, CellSize::kept_*);
  // else an Unresolved event's (the whole cell).
  absl::Status DestroyOmega(VertexId v, bool skinny);
  // Whether Destroy of the CD-3 gap ball B(c, r) would warp: a pending 0-ball
  // within θr of c (DestroyOmegaAt's test).
  bool HasWarpTarget(const Vec3& c, double r);
  std::vector<uint32_t> warp_probe_;
  // Vertex ball b is a warp target of a gap ball centred at c with
  // (θr)² = theta_r2: its point is in neither M_Ω nor suppressed, and its
  // centre lies within θr of c (*d2: the squared distance).
  bool WarpTargetWithin(BallId b, const Vec3& c, double theta_r2, double* d2);
  // Figure 3.4 for the gap ball B(c, r) of M_Ω, c in the cell of v.
  absl::Status DestroyOmegaAt(const Vec3& c, double r, TetId hint, VertexId v, Cd cd_ball = kCdSpace);
 public:
  // Near-flat tets of M_Ω (6|V| ≤ 10^−6·ℓ³, ℓ the longest edge), which the
  // flip pass cannot always remove (four nearly cocircular coplanar points
  // whose both diagonals are locked by facets): one lying on a facet has an
  // in-facet triangle of that facet among its faces, whose ball is enqueued
  // Encroached (its circumcentre breaks the cocircularity); one off the
  // facets gets the centroid of its vertices as a gap ball (inside its
  // circumsphere: any sphere through the near-circle contains its disk).
  // Tets with all vertices on ∂Ω are left (dropped from the output).
  // Returns whether anything was done (then Run() again).
  absl::StatusOr<bool> BreakFlatTets();
  // Per-tet mode, at the end: every kept tet whose smallest dihedral angle
  // is below min_deg has its circumcentre (or with sliver_candidates a
  // point near it, §8 item 69) destroyed (as a Skinny tet's); returns how
  // many were (§8 item 38). `first`: the first of a series of rounds with
  // only Run() between them; later rounds skip the tets an earlier one
  // found clear for good (TetLabel::sliver_clear).
  absl::StatusOr<uint64_t> BreakSlivers(double min_deg, bool first);
  // Vertices in all meshes so far, and the budget they may not reach.
  uint64_t Vertices() const { return TotalVertices(); }
  uint64_t VertexBudget() const { return budget_; }
  // Whether Destroy of q ∈ V(v) yields to a lower ball (BreakSlivers).
  bool YieldsAt(VertexId v, const Vec3& q) const;
  // The smallest dihedral angle of the tets inserting q into M_Ω would
  // create (Delaunay3::CavityBoundary from t). -1: t is not in conflict
  // with q, or q's cavity reaches beyond the hull or past 512 tets.
  double NewTetsMinDihedral(const Vec3& q, TetId t);
  // BreakSlivers' point for the sliver t (circumcentre cc, radius r) under
  // RefineOptions::sliver_candidates, and the vertex whose cell holds it;
  // false: every candidate would yield (and sliver_yield is off).
  bool PickSliverPoint(TetId t, const Vec3& cc, double r, double min_deg, Vec3* at, VertexId* near);
 private:
  // A gap ball of segment mesh `seg` whose centre is the midpoint of the piece
  // starting at local vertex u (Encroached₁ of the piece ball, Skinny₁).
  absl::Status DestroySegmentPiece(uint32_t seg, uint32_t u);
  // A gap ball ⟨(c, r), F⟩ of facet mesh f (uv coordinates): Skinny₂ /
  // Unresolved₂ of a cell, or a triangle's circumdisk (Encroached₂, or a
  // yield from M_Ω). `hint`: a triangle of M_F in conflict with c.
  // `tri`: the triangle whose ball is being destroyed (kNone for a cell's
  // gap ball); a piece of F crossing it is yielded to.
  absl::Status DestroyFacet(uint32_t f, Vec2 c, double r, TriId2 hint, TriId2 tri = TriId2(), Cd cd_ball = kCdFacet,
                            bool jitter = true);
  // Destroys a conforming ball of a lower feature (a yield target or an
  // Encroached event): a segment piece or a facet triangle.
  absl::Status DestroyBall(BallId b);

  // Line 3 of Figure 3.4: 𝓑 = the balls linked to `cells` of `mesh`, each
  // once, in link order (shared by the Ω and facet Destroy).
  template <typename Cell>
  void GatherBalls(MeshId mesh, const std::vector<Cell>& cells, std::vector<BallId>* out) {
    CollectBalls(out, [&](const auto& add) {
      for (Cell u : cells) blg_.ForEachBall(mesh, u.value(), add);
    });
  }
  // *out = the balls visit(add) passes to add, each once, in first-seen
  // order (ball_mark_/ball_stamp_).
  template <typename Visit>
  void CollectBalls(std::vector<BallId>* out, Visit&& visit) {
    ++ball_stamp_;
    if (ball_mark_.size() < balls_.size()) ball_mark_.resize(balls_.size() + 64, 0);
    out->clear();
    auto add = [&](BallId b) {
      if (ball_mark_[b.value()] == ball_stamp_) return;
      ball_mark_[b.value()] = ball_stamp_;
      out->push_back(b);
    };
    visit(add);
  }

  // Destroy's 𝓑 as lines 4–9 of Figure 3.4 read it in M_Ω (c ∈ V(v)): every
  // ball of v's cell, and only the unresolved 0-balls of the other cells.
  // Line 9's yields are balls with c strictly inside: such a ball meets
  // V(v) ∋ c, so it is linked to v. Line 4's warp targets are 0-balls not
  // yet in M_Ω, each linked (unresolved) to the one cell holding its point.
  // The other links of the other cells (facet and segment balls near them)
  // could only be dropped by those tests; PreferWarp/PreferYield are total
  // orders, so the choice is the one the union of all their balls gives
  // (§8 item 36).
  void GatherDestroyBalls(VertexId v, const std::vector<VertexId>& cells, std::vector<BallId>* out) {
    CollectBalls(out, [&](const auto& add) {
      blg_.ForEachBall(kOmegaMesh, v.value(), add);
      for (VertexId u : cells) {
        if (u != v) blg_.ForEachUnresolvedBall(kOmegaMesh, u.value(), add);
      }
    });
  }

  // The same with the warp targets from the pending-point index
  // (near_pending_, the query Destroy made; §8 item 41) instead of the
  // unresolved cells. The query's entries whose point entered M_Ω or became
  // suppressed since they were indexed fail line 4's tests as they would in
  // a cell; they leave the index here.
  void GatherIndexedDestroyBalls(VertexId v, std::vector<BallId>* out) {
    CollectBalls(out, [&](const auto& add) {
      blg_.ForEachBall(kOmegaMesh, v.value(), add);
      for (uint32_t id : near_pending_) add(BallId(id));
    });
    for (uint32_t id : near_pending_) {
      const PointId q = balls_.VertexPoint(BallId(id));
      if (points_.InMesh(q, kOmegaMesh) || Suppressed(q)) ErasePending(BallId(id));
    }
  }

  // Destroy's choices (Figure 3.4 lines 6 and 13): the warp target with the
  // lowest CD, then nearest to c, then the lowest point id; the yield ball
  // with the lowest CD, then the largest, then the one made first
  // (BallStore::Seq: ids are recycled; determinism).
  bool PreferWarp(BallId b, double d2, BallId warp, double warp_d2) const {
    if (!warp.valid()) return true;
    const Cd a = balls_.CdOf(b), w = balls_.CdOf(warp);
    return a < w || (a == w && (d2 < warp_d2 || (d2 == warp_d2 && balls_.VertexPoint(b) < balls_.VertexPoint(warp))));
  }
  bool PreferYield(BallId b, BallId yield) const {
    if (!yield.valid()) return true;
    const Cd a = balls_.CdOf(b), y = balls_.CdOf(yield);
    return a < y || (a == y && (balls_.Radius(b) > balls_.Radius(yield) ||
                                (balls_.Radius(b) == balls_.Radius(yield) && balls_.Seq(b) < balls_.Seq(yield))));
  }

  // --- ForceInsert (Figure 3.5) + UpdateLocation (3.6) + PropagateLocation (3.9)
  absl::Status ForceInsertOmega(PointId p, TetId hint);
  // Adds the link changes made while it lives to RefineStats::
  // link_changes_by_kind[kind] (an M_Ω point of CD 3 that changed none
  // counts as kOmegaCd3Unlinked).
  struct LinkChangeCount {
    Refiner* r;
    int kind;
    uint64_t before;
    LinkChangeCount(Refiner* refiner, int k)
        : r(refiner), kind(k), before(refiner->blg_.stats().links_added + refiner->blg_.stats().links_removed) {}
    ~LinkChangeCount() {
      const uint64_t d = r->blg_.stats().links_added + r->blg_.stats().links_removed - before;
      const int k = (kind == kOmegaCd3Linked && d == 0) ? kOmegaCd3Unlinked : kind;
      r->stats_.link_changes_by_kind[k] += d;
      ++r->stats_.insertions_by_kind[k];
      r->event_kinds_ |= 1u << k;
      ++r->event_insertions_;
    }
  };
  // The kinds (bit per LinkChangeKind) and number of the insertions of the
  // event being run (Run()'s per-kind time).
  uint32_t event_kinds_ = 0;
  uint32_t event_insertions_ = 0;
  // RefineStats::seconds_by_kind: an event's time to the lowest-dimensional
  // mesh it inserted into, else its one M_Ω insertion's kind, else "other".
  void CountEventTime(double seconds);
  absl::Status ForceInsertSegment(uint32_t seg, uint32_t u, double t, Cd cd = kCdSegment);

  // --- Collars (stage (d): thesis §3.1.2, Figures 3.5, 3.7–3.9) ---------------
 public:
  // The exact distance from x to feature f (normalised coordinates), +inf if
  // point p lies on f (combinatorially) or f is Ω.
  double FeatureDistance(FeatureId f, PointId p, const Vec3& x) const;
  // The distance from x to facet idx (normalised coordinates).
  double FacetDistance(uint32_t idx, const Vec3& x) const;
  // How far apart the facets through a collar ball's centre are at x.
  double FacetGapOnSphere(const Vec3& x, uint32_t ball) const;
  // Does feature f contain point p (an input point or a segment point)?
  bool FeatureContains(FeatureId f, PointId p) const;
  // Facets whose feature contains p, sorted (none for a point of Ω).
  void FacetsOfPoint(PointId p, std::vector<uint32_t>* out) const {
    out->clear();
    const FeatureId parent = points_.Parent(p);
    if (parent == FeatureTable::Omega()) return;
    if (features_.Dim(parent) == 2) {
      out->push_back(features_.Index(parent));
      return;
    }
    const std::span<const uint32_t> th = FacetsThrough(p);
    out->assign(th.begin(), th.end());
    std::sort(out->begin(), out->end());
  }
  // The facets containing every point of `pts` (FacetsOfPoint), ascending,
  // into *fa (*fb is scratch).
  void CommonFacets(std::span<const PointId> pts, std::vector<uint32_t>* fa, std::vector<uint32_t>* fb) const {
    FacetsOfPoint(pts[0], fa);
    for (size_t j = 1; j < pts.size() && !fa->empty(); ++j) {
      FacetsOfPoint(pts[j], fb);
      std::erase_if(*fa, [&](uint32_t f) { return !std::binary_search(fb->begin(), fb->end(), f); });
    }
  }
  // Whether the centroid of the triangle a, b, c (facet f's frame) is in f's
  // region or on its boundary: a triangle with its corners on a non-convex
  // outline can span a notch or a hole.
  bool CentroidInRegion(uint32_t f, Vec2 a, Vec2 b, Vec2 c) const {
    const Vec2 g{(a.x + b.x + c.x) / 3, (a.y + b.y + c.y) / 3};
    return facets_[f].region().Locate(g) != FacetRegion::Where::kOutside;
  }
  // The facet a triangle of points lies on: the first facet containing its
  // three points whose region contains its centroid, or kNoFacet.
  uint32_t FacetOfTriangle(const std::array<PointId, 3>& k, std::vector<uint32_t>* fa,
                           std::vector<uint32_t>* fb) const {
    CommonFacets(k, fa, fb);
    for (uint32_t f : *fa) {
      if (CentroidInRegion(f, Uv(f, k[0]), Uv(f, k[1]), Uv(f, k[2]))) return f;
    }
    return kNoFacet;
  }
  // The faces of the stitched tets lying on a facet (FacetOfTriangle), as
  // (facet, sorted point ids), in ascending face order.
  // `on_plane` (optional): how many of them have a point of Ω
  // (RefineOptions::stitch_faces_on_plane).
  std::vector<std::pair<uint32_t, std::array<uint32_t, 3>>> StitchedFacetFaces(uint64_t* on_plane = nullptr) const;
  // The facets containing crease point p (an input point or a point of a
  // segment), ascending: the complex's incidence lists, no search.
  std::span<const uint32_t> FacetsThrough(PointId p) const {
    const FeatureId parent = points_.Parent(p);
    if (features_.Dim(parent) == 0) return point_facets_[features_.Index(parent)];
    if (features_.Dim(parent) == 1) return seg_facets_[features_.Index(parent)];
    return {};
  }
  const CollarIndex& collars() const { return collars_; }
  PointId CollarCentre(uint32_t i) const { return collar_centre_[i]; }
  // Features of the complex for oracles: 0 point, 1 segment, 2 facet.
  uint32_t NumFeatures() const { return features_.size(); }
  int FeatureDim(FeatureId f) const { return features_.Dim(f); }
 private:
 public:
  // COLLAR events (thesis §3.1.2, Figure 3.10's RepBall trap), in rounds at
  // the end of the queues (Figure 3.11 pops them last): the restricted
  // Delaunay of the collar surface in M_Ω (CollarRepairs) and of each facet's
  // arcs (ArcRepairs); every repair point is destroyed as a gap ball of CD
  // (3,d) / (2,d). Returns whether anything was inserted.
  absl::StatusOr<bool> CollarRound() { return CollarRoundImpl(); }
  // Lemma 17: consecutive collar balls on one crease segment meeting below
  // π/2 get a crease point between them (the thesis' encroachment of the
  // piece by the neck circle); returns whether any was inserted.
  absl::StatusOr<bool> SplitCollarNecks();
  // SVRC_COLLAR_DEBUG, when the COLLAR rounds fail: the intersecting ball
  // pairs meeting below π/2 (Lemma 14) by kind and the worst 12, to stderr
  // (docs/svrc-collars.md "Session 8").
  void DebugNonSmoothPairs() const;
  // RefineOptions::early_crease_vertices: every crease input vertex (not a
  // duplicate) into M_Ω, in input order, each with its collar.
  absl::Status InsertCreaseVertices();
  // After a failed stitch: the representation points of T′ faces whose star
  // is inverted go in as COLLAR repairs (CD (3,2)); returns how many.
  absl::StatusOr<uint32_t> RepairStitchFailures();
  // Inserts size_points_ (CollectOversizedDelaunayTets); returns how many.
  absl::StatusOr<uint32_t> InsertSizePoints();
  // Stars and books of the stitched mesh above their region's volume bound
  // (normalised): a point of S for each, into stitch_failures_.
  void CollectOversizedDelaunayTets(std::span<const Vec3> positions,
                                   absl::FunctionRef<std::array<uint32_t, 4>(size_t)> tet_at, size_t count,
                                   const Labelling& lab, std::span<const double> comp_volume);
  void QueueOversizedStitchRepairs(std::span<const Vec3> positions, std::span<const std::array<uint32_t, 4>> tets,
                                   const Labelling& lab, std::span<const double> comp_volume);
  // Consecutive collared points along each crease segment's M_s, in order:
  // (segment, vertex u of M_s, the next collared vertex w, their balls).
  struct CreaseBallPair {
    uint32_t seg, u, w, ball_u, ball_w;
  };
  std::vector<CreaseBallPair> CreaseBallPairs() const;
  // Cancellation and deadlines inside a Destroy's attempt loop, every 256
  // attempts: a long yield chain never reaches Run()'s poll between events
  // (measured: f_real/hinge.stl spent > 15 min in one DestroyFacet and
  // ignored a 900 s deadline).
  absl::Status PollInDestroy(int attempt) const {
    if (attempt == 0 || attempt % 256 != 0 || !options_.poll) return absl::OkStatus();
    return options_.poll();
  }
  // Run()'s poll between events and a COLLAR round's between repairs: at
  // every poll_interval-th unit of work n, the poll, then a progress report
  // (`radius`: the work about to be done).
  absl::Status PollAt(uint64_t n, double radius) const {
    if (n % options_.poll_interval != 0) return absl::OkStatus();
    if (options_.poll) {
      absl::Status s = options_.poll();
      if (!s.ok()) return s;
    }
    if (options_.progress) options_.progress(phase_, TotalVertices(), queues_.size(), radius);
    return absl::OkStatus();
  }
  // The stage RefinePlc is in (refine_phase), reported once as it begins and
  // then at every poll.
  void EnterPhase(const char* phase) {
    phase_ = phase;
    if (options_.progress) options_.progress(phase_, TotalVertices(), queues_.size(), 0);
  }
  const char* phase_ = refine_phase::kRefine;
  // RipStitchCollar (Figure 3.12) on the final M_Ω; fills stitched_.
  absl::Status Stitch() { return StitchImpl(); }
  void ClearStitch() {
    stitched_done_ = false;
    stitched_.clear();
  }
  // After a stitch: edges of the final tets near the collars that cross a
  // facet through a collar's centre at a point outside every ball get that
  // point as a facet Steiner point (CD (2,3)); returns how many went in. The
  // caller runs the queues, the COLLAR rounds and the stitch again.
  absl::StatusOr<uint32_t> RepairStitchedCrossings();
  // Segment pa–pb crosses facet f's plane (SegmentCrossesPlane): its ends
  // beyond tol on opposite sides, and beyond f's own flatness
  // (facet_plane_tol_); *x = the crossing.
  bool FacetCrossing(uint32_t f, const Vec3& pa, const Vec3& pb, double tol, Vec3* x) const {
    return SegmentCrossesPlane(frames_[f].origin, frames_[f].normal, pa, pb, std::max(tol, facet_plane_tol_[f]), x);
  }
 private:
  absl::StatusOr<bool> CollarRoundImpl();
  absl::Status StitchImpl();
  // Figure 3.7 for crease point p, just inserted into M_Ω as vertex nv.
  absl::Status CreateCollar(PointId p, VertexId nv);
  // Figure 3.9's suppression: p is strictly inside a collar ball and is not a
  // crease point (crease vertices and points of crease segments are always
  // resolved). Monotone (collars only grow): cached once true.
  bool Suppressed(PointId p);
  // An element with a vertex or its centroid strictly inside a collar ball is
  // left to RipStitchCollar (stage (f)) by the end-of-run checks.
  bool InsideCollars(std::span<const PointId> verts) const;
  // A triangle of a facet mesh with a vertex or its centroid strictly inside
  // a collar: it need not conform to non-crease segments there.
  bool TriangleInCollars(const FacetMesh& m, TriId2 t) const {
    if (!options_.collars || collars_.size() == 0) return false;
    const std::array<PointId, 3> v{m.PointOf(m.dt().TriVertex(t, 0)), m.PointOf(m.dt().TriVertex(t, 1)),
                                   m.PointOf(m.dt().TriVertex(t, 2))};
    return InsideCollars(v);
  }
  // Triangle t of M_F meets the open piece (ua, ub) of piece ball b (its
  // segment a segment of F): FacetMesh::MeetsSegmentPart.
  bool TriangleStraddlesPiece(const FacetMesh& m, TriId2 t, BallId b, Vec2 ua, Vec2 ub) const {
    const int32_t k = m.RegionSegment(piece_seg_[b.value()]);
    if (k < 0) {
      return TriangleMeetsSegment(m.dt().Point(m.dt().TriVertex(t, 0)), m.dt().Point(m.dt().TriVertex(t, 1)),
                                  m.dt().Point(m.dt().TriVertex(t, 2)), ua, ub);
    }
    return m.MeetsSegmentPart(t, static_cast<size_t>(k), ua, ub);
  }
  // A piece of a non-crease segment whose midpoint is strictly inside a collar.
  bool PieceInCollars(BallId piece) const {
    if (!options_.collars || collars_.size() == 0) return false;
    const PointId a = balls_.Vertex(piece, 0), b = balls_.Vertex(piece, 1);
    if (points_.IsCrease(a) && points_.IsCrease(b)) return false;
    return collars_.StrictlyInside(0.5 * (points_.Xyz(a) + points_.Xyz(b)));
  }
  absl::Status ForceInsertFacet(uint32_t f, PointId p, Vec2 uv, TriId2 hint);

  // --- BLG helpers -------------------------------------------------------------
  // Cells of M_Ω that may meet B(c, r), given a vertex w nearest to c: BFS over
  // Delaunay neighbours filtered by the bisector bound (|xc|² − |wc|²) ≤ 2r|xw|
  // (a superset of the cells meeting B, which form a connected set).
  // The cells whose Voronoi cells may meet B(c, r), w the vertex nearest c
  // (or the cell holding c). `loose`: against w's bisector only (the
  // invariant check's, independent of RefineOptions::tight_ball_cells).
  void CellsMeetingBall(const Vec3& c, double r, VertexId w, std::vector<VertexId>* out, bool loose = false);
  // PropagateLocation of a ball of radius > 0 into M_Ω: link every cell that
  // may meet it, starting near `start`.
  void LinkBallToOmega(BallId b, VertexId start);
  // The seed of a search for the cells meeting a ball or disk centred at c
  // (CellsMeetingBall, CellsMeetingDisk): without collars a vertex nearest
  // up to rounding (NearVertex, §8 item 72) — its cell meets the ball, the
  // search keeps the cells that pass its test, and Destroy's choices are
  // total orders over their balls; with collars the exact nearest, since the
  // event order follows the links' order there (§8 item 37).
  VertexId SeedVertex(const Vec3& c, TetId hint) const {
    const delaunay::Delaunay3& dt = omega_.dt();
    return options_.collars ? dt.NearestVertex(c, hint) : dt.NearVertex(c, hint);
  }
  VertexId2 SeedVertex(const delaunay::Delaunay2& dt, Vec2 c, TriId2 hint) const {
    return options_.collars ? dt.NearestVertex(c, hint) : dt.NearVertex(c, hint);
  }
  // PropagateLocation of a 0-ball into M_Ω: link the cell containing its
  // point (an unresolved object), refresh that cell's events.
  void LinkVertexBallToOmega(BallId b, VertexId start);
  // AddLink(x, Ω, B) for a piece ball with Figure 3.10's encroachment trap.
  void AddBallLink(VertexId x, BallId b);
  bool Encroaches(BallId b, VertexId x) const;
  // x strictly (exact) and deeply (margin) inside ball b in 3D.
  bool Inside(BallId b, const Vec3& x) const;
  void EnqueueEncroached(BallId b);
  // The balls of the (new) in-facet triangles `tris` of facet f: remember
  // each ball's triangle, link it into M_Ω (PropagateLocation, Figure 3.9).
  void AdoptTriangleBalls(uint32_t f, std::span<const TriId2> tris, VertexId start);

  // --- facet meshes (stage (c)) ----------------------------------------------
  // Cells of M_F that may meet the disk B(c, r) (same bisector bound as 3D).
  void CellsMeetingDisk(uint32_t f, Vec2 c, double r, VertexId2 w, std::vector<VertexId2>* out);
  // PropagateLocation of a segment piece ball into M_F (a facet containing
  // the segment) and of a 0-ball of a point of F (unresolved in M_F).
  void LinkPieceToFacet(BallId b, uint32_t f, TriId2 hint);
  void LinkVertexBallToFacet(BallId b, uint32_t f, TriId2 hint);
  // AddLink(x, F, piece ball) with Figure 3.10's trap, decided in uv.
  void AddFacetPieceLink(uint32_t f, VertexId2 x, BallId b);
  bool EncroachesInFacet(uint32_t f, BallId b, VertexId2 x) const;
  // The point's coordinates in F's frame: its M_F vertex if it has one, else
  // its xyz projected (a pure function of xyz, so the same value every time;
  // design §2 "rounded once").
  Vec2 Uv(uint32_t f, PointId p) const;
  // Does point p (a vertex of the mesh the ball lives in) encroach ball b in
  // some mesh it was linked in? (End-of-run partial encroachment check.)
  bool EncroachedByPoint(BallId b, PointId p) const;

  // --- Events -----------------------------------------------------------------
  void RefreshEvents(VertexId v, const CellSize* size = nullptr);
  void RefreshSegmentEvents(uint32_t seg, uint32_t v);
  void RefreshFacetEvents(uint32_t f, VertexId2 v, const CellSize2* size = nullptr);
  bool IsLive(const WorkEvent& event);
  // On the corners of the output's tets at v once M_Ω is labelled
  // (CellSize::kept_outradius; docs/svrc-design.md §8 item 33).
  bool IsSkinny(const CellSize& s) const { return s.kept_outradius > CellTau() * s.inradius; }
  // τ of the cell test: +inf while it is deferred or replaced by the per-tet
  // test (RefineOptions::features_first, tet_quality).
  double CellTau() const { return skinny_deferred_ || tet_mode_ ? HUGE_VAL : options_.tau; }
  // tet_quality: whether t is an output tet of M_Ω's labelling that is bad
  // (radius-edge above τ/2, or with tet_sizes_ its volume above its region's
  // bound — with tet_volumes — or its circumradius above its target); its
  // circumcentre and radius. Tets whose circumcentre Size()
  // would not read plainly (flat, outside Ω) are never bad here.
  bool TetBad(TetId t, Vec3* cc, double* radius) const;
  // Enqueues t's Skinny event when TetBad; returns whether it did.
  bool EnqueueTetIfBad(TetId t);
  // t's label (tet_labels_) when it is t's own (set or carried for the tet
  // now in the slot); null otherwise.
  const TetLabel* LiveLabel(TetId t) const {
    if (t.value() >= tet_labels_.size()) return nullptr;
    const TetLabel& lab = tet_labels_[t.value()];
    return lab.gen == omega_.dt().Generation(t) + 1 ? &lab : nullptr;
  }
  // WorkEvent::object of a per-tet Skinny event: the tet slot | kTetEvent.
  static constexpr uint32_t kTetEvent = 1u << 31;
  // Skinny, or larger than the size target of max_volume (SetSizeTargets).
  bool IsBad(VertexId v, const CellSize& s) const {
    return IsSkinny(s) || AboveSizeTarget(v, s.kept_outradius);
  }
  // A kept corner at distance R exceeds v's size target (max_volume).
  bool AboveSizeTarget(VertexId v, double R) const {
    return v.value() < size_target_.size() && R > size_target_[v.value()];
  }
  bool IsSkinny(const SegmentMesh::Size1& s) const { return s.outradius > options_.tau * s.inradius; }
  // Facet meshes: Voronoi aspect bound facet_tau_factor·τ (RefineOptions).
  bool IsSkinny(const CellSize2& s) const {
    return s.outradius > options_.facet_tau_factor * options_.tau * s.inradius;
  }

  bool IsOmega(MeshId m) const { return m == kOmegaMesh; }
  bool IsSegMesh(MeshId m) const { return !segs_.empty() && m.value() >= seg_mesh0_ && m.value() < seg_mesh0_ + segs_.size(); }
  bool IsFacetMesh(MeshId m) const {
    return !facets_.empty() && m.value() >= facet_mesh0_ && m.value() < facet_mesh0_ + facets_.size();
  }
  uint32_t FacetIndex(MeshId m) const { return m.value() - facet_mesh0_; }
  MeshId FacetMeshId(uint32_t f) const { return MeshId(facet_mesh0_ + f); }
  uint32_t SegIndex(MeshId m) const { return m.value() - seg_mesh0_; }
  MeshId SegMesh(uint32_t seg) const { return MeshId(seg_mesh0_ + seg); }
  BallId VertexBallOf(PointId p) const {
    return p.value() < vertex_ball_.size() ? vertex_ball_[p.value()] : kNoneBall;
  }
  void SetVertexBall(PointId p, BallId b) {
    if (vertex_ball_.size() <= p.value()) vertex_ball_.resize(p.value() + 1, kNoneBall);
    vertex_ball_[p.value()] = b;
  }
  uint64_t TotalVertices() const {
    return omega_.dt().NumVertices() + stats_.segment_vertices + stats_.facet_vertices;
  }

  RefineOptions options_;
  Normalization norm_;
  FeatureTable features_;
  PointStore points_;
  BallStore balls_;
  LocationGraph blg_;
  WorkQueues queues_;
  OmegaMesh omega_;
  // The points of the 0-balls linked unresolved into M_Ω (LinkVertexBallToOmega),
  // erased when their point enters M_Ω; entries that became suppressed are
  // erased when a query meets them. in_pending_: per ball.
  PendingPoints pending_;
  std::vector<uint8_t> in_pending_;
  std::vector<uint32_t> near_pending_;  // scratch
  void AddPending(BallId b) {
    if (in_pending_.size() <= b.value()) in_pending_.resize(b.value() + b.value() / 4 + 64, 0);
    if (in_pending_[b.value()]) return;
    in_pending_[b.value()] = 1;
    pending_.Insert(b.value(), balls_.Center(b));
  }
  void ErasePending(BallId b) {
    if (b.value() >= in_pending_.size() || !in_pending_[b.value()]) return;
    in_pending_[b.value()] = 0;
    pending_.Erase(b.value(), balls_.Center(b));
  }
  std::vector<SegmentMesh> segs_;
  uint32_t seg_mesh0_ = 0;  // MeshId of segment 0 (= its FeatureId)
  std::vector<uint32_t> seg_input_a_;  // input endpoint at t = 0 of each segment
  uint32_t num_input_ = 0;
  std::vector<uint32_t> duplicate_of_;  // first input point with the same coordinates
  util::PodVector<BallId> vertex_ball_;     // per global point: its 0-ball (kNoneBall: none)
  util::PodVector<uint32_t> piece_vertex_;  // per ball: local vertex starting its piece
  util::PodVector<uint32_t> piece_seg_;     // per ball: its segment
  // Facets (stage (c)).
  std::vector<FacetMesh> facets_;
  std::vector<plc::FacetFrame> frames_;  // normalised frames
  // The conformity checker's on-plane tolerance (mesh::OnFeatureTolerance)
  // in normalised coordinates.
  double on_plane_tol_ = 0;
  // Per facet: twice the largest distance of its input points from its
  // frame's plane (normalised), the least distance at which a point counts as
  // off that plane (FacetCrossing, StitchedFacetFaces). Validation accepts
  // facets planar to 1e-8 of their diameter (docs/plc.md); a slanted facet
  // far from the origin is planar only to the rounding of its input
  // coordinates, which the normalisation keeps.
  std::vector<double> facet_plane_tol_;
  uint32_t facet_mesh0_ = 0;             // MeshId of facet 0 (= its FeatureId)
  std::vector<std::vector<uint32_t>> point_facets_;  // per complex point: facets containing it
  std::vector<std::vector<uint32_t>> seg_facets_;    // per segment: facets containing it
  util::PodVector<uint32_t> tri_of_ball_;    // per triangle ball: its M_F triangle slot
  std::vector<uint32_t> facet_input_;    // per facet: index in Plc::facets
  std::vector<int32_t> facet_marker_;
  CellSize2 last_size2_;
  uint32_t last_size2_facet_ = 0xFFFFFFFFu;
  VertexId2 last_size2_vertex_;
  uint32_t last_size2_gen_ = 0;
  std::vector<VertexId2> bfs2_, nbrs2_;
  std::vector<uint32_t> mark2_;
  uint32_t stamp2_ = 0;
  // Balls that got a first, non-native encroacher (PartiallyEncroached),
  // with their generation then: an entry of another generation is a ball
  // that died since (its record possibly another ball's: recycle_balls).
  std::vector<std::pair<BallId, uint32_t>> partial_;
  std::vector<double> size_target_;  // per M_Ω vertex: max R_v from max_volume (+inf: none)
  // Per M_Ω tet slot (TetLabel): set by SetSizeTargets' labelling, carried
  // to new tets by PropagateSizeTargets; empty while M_Ω is not labelled.
  util::PodVector<TetLabel> tet_labels_;
  // The labels' classes: a region's size target (circumradius) and volume
  // bound, normalised (+inf: none). Class 0 is (+inf, +inf). Append-only,
  // so a pair keeps its class across labellings (SetSizeTargets compares
  // classes to find unchanged labels).
  struct LabelClass {
    double target = HUGE_VAL;
    double volume = HUGE_VAL;
  };
  std::vector<LabelClass> label_classes_{LabelClass{}};
  std::map<std::pair<double, double>, uint32_t> label_class_index_{{{HUGE_VAL, HUGE_VAL}, 0}};
  // The class of the pair, added if new; nullopt past 2^30 classes.
  std::optional<uint32_t> LabelClassOf(double target, double volume);
  const LabelClass& ClassOf(const TetLabel& lab) const { return label_classes_[lab.label_class()]; }
  void PropagateSizeTargets(const delaunay::Delaunay3::InsertResult& inserted);
  std::vector<TetLabel> created_labels_;  // scratch
  // Per M_Ω tet slot: the queue slot of its latest Skinny tet event, or
  // kNoTetEvent. A tet's events die with it (EventLive: the generation moves
  // on), so ForceInsertOmega removes them from the queue when the tet is
  // destroyed instead of leaving them until popped. Cube --max-volume 1e-6
  // pushes 3.0 M tet events and 90% of them were popped stale; waiting in the
  // queue, they were its peak of 2.3 M slots (91 MB of a 419 MB heap).
  static constexpr uint32_t kNoTetEvent = 0xFFFFFFFFu;
  util::PodVector<uint32_t> tet_event_;
  void DropDeadTetEvents(std::span<const TetId> destroyed);
  // Collars (stage (d)).
  const plc::FeatureComplex* complex_ = nullptr;
  plc::FeatureComplex own_complex_;  // the point-set path's complex (Initialize)
  CollarIndex collars_;
  std::vector<PointId> collar_centre_;          // per collar
  std::vector<uint8_t> has_collar_;             // per point
  // The last failed stitch's repairable failures: a point of S and its
  // collar dimension (2: a partial sphere's, an inverted star; 1: a crease
  // circle's, a flat book), and the ball.
  struct StitchRepair {
    Vec3 x;
    uint32_t ball = 0;
    uint8_t collar_dim = 2;
  };
  std::vector<StitchRepair> stitch_failures_;
  // Points of Ω for kept Delaunay tets above their volume bound
  // (CollectOversizedDelaunayTets): the circumcentre, clamped to Ω, and
  // the tet's circumradius.
  std::vector<std::pair<Vec3, double>> size_points_;
  std::vector<uint8_t> neck_point_;             // per point: SplitCollarNecks' points get a ball even inside a collar
  std::vector<uint8_t> suppressed_;             // per point: 1 once strictly inside a collar
  std::vector<std::vector<uint32_t>> point_segments_;  // per complex point: segments ending there
  bool stitched_done_ = false;
  std::vector<std::array<uint32_t, 4>> stitched_;     // final tets (point ids) after RipStitchCollar
 public:
  StitchResult stitch_report_;
  double collar_snap_ = 0;  // the COLLAR rounds' snap band (RefineOptions::collar_snap, then its fallback)
  CollarSurfaceReport surface_report_;
  bool topology_held_ = false;  // some COLLAR round had no topology or circle repair
  uint32_t collar_rounds_ = 0, collar_repairs_ = 0, arc_repairs_ = 0, crossing_count_ = 0;
  std::array<uint64_t, 4> collar_repairs_by_reason_{};  // by CollarRepair::Reason
  // The COLLAR rounds' restricted Delaunay of S, per ball, reused across
  // rounds while the cells it read keep their generations.
  CollarRestrictionCache restriction_cache_;
  // EnqueueMissing's memory per ball: ~0 inside the collars, else 1 + the
  // sum of its M_Ω vertices' cell generations when it was last found in M_Ω.
  std::vector<uint64_t> known_present_;
  // CollarRoundImpl's memory per facet: the collar balls near it and its
  // vertex count when ArcRepairs last found nothing to repair there.
  struct FacetArcMemo {
    bool settled = false;
    uint32_t vertices = 0;
    std::vector<uint32_t> near;
  };
  std::vector<FacetArcMemo> arc_memo_;
  // Per facet, the collar balls whose sphere may reach its square (the test
  // of CollarRoundImpl), scanned once per ball: balls are only appended and
  // never change, nor do a facet's frame and square. Every round used to test
  // every ball against every facet (fandisk.off: 8,035 facets × 5,619 balls).
  struct FacetNearBalls {
    uint32_t scanned = 0;
    std::vector<uint32_t> ids;
  };
  std::vector<FacetNearBalls> facet_near_;
  uint32_t centre_repairs_ = 0;  // points on S cutting a crease vertex's cell back inside its collar
  // Arc points for stitched tets crossing a facet inside a collar, beyond the
  // chords of T′ (RepairStitchedCrossings).
  uint32_t stitched_arc_crossings_ = 0;
  uint32_t stitched_crossings_ = 0;  // all points for stitched tets crossing a facet
 private:
  RefineStats stats_;
  uint64_t budget_ = 0;
  // Where the budget came from, for its error: the default (max(10^6, 2000 ×
  // input points)) can be raised.
  std::string BudgetHint() const {
    // The mesh grades down to the input's smallest gap between disjoint
    // features: name them, the usual reason a valid input needs so many.
    std::string gap;
    if (complex_ != nullptr && !complex_->closest_features.empty()) {
      gap = absl::StrCat("; the input's closest disjoint features are ", complex_->closest_features, ", ",
                         complex_->min_feature_distance, " apart (spread ", complex_->spread, ")");
    }
    if (options_.max_vertices != 0) return absl::StrCat(" (a budget set by the caller", gap, ")");
    return absl::StrCat(" (the default: max(1000000, 2000 x ", num_input_,
                        " input points); a larger max_vertices (svrc mesh --max-vertices N) lets it go on", gap, ")");
  }
  // The cell size IsLive computed for the event Destroy gets next.
  CellSize last_size_;
  VertexId last_size_vertex_;
  uint32_t last_size_gen_ = 0;
  // Scratch.
  std::vector<VertexId> bfs_, nbrs_;
  std::vector<uint32_t> mark_;
  uint32_t stamp_ = 0;
  std::vector<uint32_t> cavity_faces_;  // NewTetsMinDihedral
  std::vector<uint32_t> ball_mark_;
  uint32_t ball_stamp_ = 0;
  std::vector<BallId> gathered_;
  std::vector<BallId> dying_scratch_;  // RecycleBalls' buffer (BallStore::TakeDying)
  std::vector<LocationObject> objects_;
  std::vector<LocationObject> moves_;  // UpdateLocation: 0-balls moving to the new cell
  // UpdateLocation (Figure 3.6) for one old cell u of `mesh` that shrank when
  // the point of new cell `nv` was inserted: its links stay in place except
  // dead balls, 0-balls whose point is now in the mesh or suppressed, 0-balls
  // now nearer to the new point (nearer_to_new(b): they move to nv), and
  // lower balls for which piece_meets(b) says no. Lower balls are recorded
  // once per insertion in `moved` (ball_mark_/ball_stamp_) for the new cell.
  template <typename PieceMeets, typename NearerToNew>
  void FilterShrunkCell(MeshId mesh, uint32_t u, uint32_t nv, std::vector<BallId>* moved, PieceMeets&& piece_meets,
                        NearerToNew&& nearer_to_new) {
    objects_.clear();
    blg_.ObjectsOf(mesh, u, &objects_);
    if (objects_.empty()) return;
    drop_.assign(objects_.size(), 0);
    moves_.clear();
    for (size_t k = 0; k < objects_.size(); ++k) {
      const LocationObject& o = objects_[k];
      const BallId b(o.id);
      if (!balls_.IsAlive(b)) {
        drop_[k] = 1;
      } else if (!balls_.IsVertexBall(b)) {
        if (ball_mark_[b.value()] != ball_stamp_) {
          ball_mark_[b.value()] = ball_stamp_;
          moved->push_back(b);
        }
        if (!piece_meets(b)) drop_[k] = 1;
      } else {
        const PointId q = balls_.VertexPoint(b);
        if (points_.InMesh(q, mesh) || Suppressed(q)) {
          drop_[k] = 1;
        } else if (nearer_to_new(b)) {
          drop_[k] = 1;
          moves_.push_back(o);
        }
      }
    }
    blg_.RemoveCellLinksWhere(mesh, u, drop_);
    LinkFacts unresolved;
    unresolved.unresolved = true;
    for (const LocationObject& o : moves_) blg_.AddLink(mesh, nv, o, unresolved, &balls_);
  }
  // ForceInsertOmega's certificates of good cells (see there), per M_Ω
  // vertex: r_v and whether every tet of the star passes IsBad's test.
  // Cleared when the size targets change.
  struct CellCert {
    double inradius = 0;   // r_v now
    double outradius = 0;  // R_v at the last Size(): ≥ R_v now
    bool valid = false;
    bool exterior = false;  // every star tet outside the output at the last Size() (§8 item 33)
    // `valid` but for some star tets outside the output (and some not):
    // R_u ≤ outradius still, and the star tets not known outside have
    // |cc − u| ≤ kept (≥ the kept corner's distance), ≤ τ·r_u and ≤ u's size
    // target.
    bool partial = false;
    // `partial` for a cell clipped to Ω (its kept tets all plain): it stays
    // certified only while a new tet keeps it next to the outside (then
    // Size() reads its kept corner from the kept tets as before; with none
    // outside it would read the clipped cell's). Beside the other flags: 32
    // bytes per vertex, as before it.
    bool clipped = false;
    double kept = 0;
  };
  static_assert(sizeof(CellCert) == 32);
  util::PodVector<CellCert> cell_cert_;
  std::vector<TetId> created_;
  std::vector<OmegaMesh::NewTets> new_at_;  // per cell of 𝒱: what the insertion added to its star
  std::vector<uint32_t> cert_mark_, cert_pos_;
  uint32_t cert_stamp_ = 0;
  std::vector<uint8_t> drop_;          // UpdateLocation: links of a shrunk cell to remove
  // ForceInsertOmega's 𝒱', sizes, exactness and lower balls, and
  // LinkBallToOmega's cells: scratch reused across insertions (neither
  // function is re-entered while it uses them; ForceInsertOmega's only
  // nested insertion, CreateCollar, is its last step).
  std::vector<VertexId> insert_changed_;
  std::vector<CellSize> insert_sizes_;
  std::vector<uint8_t> insert_exact_;
  std::vector<BallId> insert_moved_;
  std::vector<VertexId> link_cells_;
  std::vector<VertexId> cmb_candidates_;  // CellsMeetingBall's search queue
  std::vector<VertexId> cmb_parents_;     // and the cell each was found from
};

absl::Status Refiner::Initialize(std::span<const Vec3> normalised, std::span<const SegmentInput> segments) {
  num_input_ = static_cast<uint32_t>(normalised.size());
  // Exact duplicates are one feature point ("plc" merges them for PLCs; a raw
  // point set may still have them): the copies map to the first one's vertex
  // and get no 0-ball — a copy sitting on a vertex would never be within θr of
  // a Voronoi corner, and refinement would run to the budget.
  duplicate_of_.resize(num_input_);
  {
    std::vector<uint32_t> order(num_input_);
    for (uint32_t i = 0; i < num_input_; ++i) order[i] = i;
    auto key = [&](uint32_t i) {
      const Vec3& p = normalised[i];
      return std::make_tuple(p.x, p.y, p.z, i);
    };
    std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return key(a) < key(b); });
    for (size_t k = 0; k < order.size(); ++k) {
      const uint32_t i = order[k];
      duplicate_of_[i] =
          (k > 0 && normalised[order[k - 1]] == normalised[i]) ? duplicate_of_[order[k - 1]] : i;
    }
  }
  // The feature complex of points + free segments (superfeature lists). The
  // refiner keeps it: Setup points complex_ at it for the whole run (a local
  // here had left complex_ dangling once Initialize returned; session 50's
  // budget message read it, caught by ASan in RefinerTest.BudgetAndCancellation).
  plc::FeatureComplex& complex = own_complex_;
  complex = plc::FeatureComplex{};
  complex.points.resize(num_input_);
  for (size_t s = 0; s < segments.size(); ++s) {
    const uint32_t a = segments[s].a, b = segments[s].b;
    if (a >= num_input_ || b >= num_input_) {
      return absl::InvalidArgumentError(absl::StrCat("segment ", s, ": endpoint out of range"));
    }
    if (duplicate_of_[a] == duplicate_of_[b]) {
      return absl::InvalidArgumentError(absl::StrCat("segment ", s, ": endpoints coincide"));
    }
    plc::FeatureSegment fs;
    fs.a = duplicate_of_[a];
    fs.b = duplicate_of_[b];
    fs.is_free = true;
    complex.segments.push_back(fs);
  }
  // Two segments meeting at a point at less than 90° make that point a crease
  // (Definitions 4–5): without collars (stage (d)) refinement around it would
  // never stop, so such inputs are refused rather than run to the budget.
  {
    std::vector<std::vector<uint32_t>> other_end(num_input_);
    for (const plc::FeatureSegment& fs : complex.segments) {
      other_end[fs.a].push_back(fs.b);
      other_end[fs.b].push_back(fs.a);
    }
    for (uint32_t o = 0; o < num_input_; ++o) {
      const auto& ends = other_end[o];
      for (size_t i = 0; i < ends.size(); ++i) {
        for (size_t j = i + 1; j < ends.size(); ++j) {
          if (geom::DotSign(normalised[o], normalised[ends[i]], normalised[o], normalised[ends[j]]) > 0) {
            return absl::UnimplementedError(absl::StrCat(
                "SVRC: segments at point ", o, " meet at an acute angle (a crease); collars are not implemented yet"));
          }
        }
      }
    }
  }
  return Setup(complex, normalised);
}

absl::Status Refiner::Setup(const plc::FeatureComplex& complex, std::span<const Vec3> normalised) {
  num_input_ = static_cast<uint32_t>(normalised.size());
  if (duplicate_of_.size() != num_input_) {
    duplicate_of_.resize(num_input_);
    for (uint32_t i = 0; i < num_input_; ++i) duplicate_of_[i] = i;
  }
  features_ = FeatureTable::Build(complex);
  seg_mesh0_ = complex.segments.empty() ? 0 : features_.OfSegment(0).value();
  facet_mesh0_ = complex.facets.empty() ? 0 : features_.OfFacet(0).value();
  // The default guard: 2000 vertices per input point, at least 10^6. 1000 per
  // point (until session 15) stopped bunny.off's collar stage 6% short (it
  // needs ~3.7 M vertices in M_Ω and the facet meshes for 3,485 points).
  budget_ = options_.max_vertices != 0 ? options_.max_vertices
                                       : std::max<uint64_t>(1'000'000, 2000ull * num_input_);
  // Global ids = SoS priorities: inputs first (in input order), then corners.
  complex_ = &complex;
  {
    std::vector<Vec3> input(complex.points.size());
    for (size_t i = 0; i < input.size(); ++i) input[i] = complex.points[i].p;
    on_plane_tol_ = std::ldexp(mesh::OnFeatureTolerance(input), -norm_.exponent);
  }
  for (uint32_t i = 0; i < num_input_; ++i) {
    points_.Add(normalised[i], features_.OfPoint(i), kCdInputVertex, options_.collars && complex.points[i].crease);
  }
  point_segments_.assign(num_input_, {});
  for (uint32_t s = 0; s < complex.segments.size(); ++s) {
    point_segments_[complex.segments[s].a].push_back(s);
    point_segments_[complex.segments[s].b].push_back(s);
  }
  std::array<PointId, 8> corners;
  for (int i = 0; i < 8; ++i) corners[i] = points_.Add(omega_.Corner(i), FeatureTable::Omega(), kCdSpace);
  omega_.SeedCorners(corners);
  for (int i = 0; i < 8; ++i) points_.SetVertex(corners[i], kOmegaMesh, i);

  // Facet meshes (Definition 35): M_F in F's normalised frame inside the
  // square Ω_F, seeded with its 4 corners (global points of CD (2,3) that are
  // never in F, so they get no 0-ball and never reach M_Ω).
  point_facets_.assign(num_input_, {});
  seg_facets_.assign(complex.segments.size(), {});
  for (uint32_t s = 0; s < complex.segments.size(); ++s) seg_facets_[s] = complex.segments[s].facets;
  std::vector<PointId> ids(num_input_);
  for (uint32_t i = 0; i < num_input_; ++i) ids[i] = PointId(i);
  facets_.reserve(complex.facets.size());
  for (uint32_t f = 0; f < complex.facets.size(); ++f) {
    plc::FacetFrame frame;
    FacetRegion region = BuildFacetRegion(complex, f, norm_, ids, &frame);
    const uint32_t next = points_.size();
    const std::array<PointId, 4> cids{PointId(next), PointId(next + 1), PointId(next + 2), PointId(next + 3)};
    facets_.emplace_back(std::move(region), cids);
    frames_.push_back(frame);
    facet_input_.push_back(complex.facets[f].input_facet);
    facet_marker_.push_back(complex.facets[f].marker);
    for (int i = 0; i < 4; ++i) {
      const PointId c = points_.Add(frame.ToSpace(facets_.back().QuadCorner(i)), features_.OfFacet(f), kCdFacet);
      points_.SetVertex(c, FacetMeshId(f), i);
    }
    double flat = 0;
    for (PointId p : facets_.back().region().all_points) {
      if (p.value() < num_input_) point_facets_[p.value()].push_back(f);
      flat = std::max(flat, std::fabs(geom::Dot(points_.Xyz(p) - frame.origin, frame.normal)));
    }
    facet_plane_tol_.push_back(2 * flat);
  }

  // Figure 3.3: UpdateLocation(∅, M_F, F) for every feature, lowest dimension
  // first. A point feature's mesh is {p}: one 0-ball, propagated to its
  // superfeatures. It is a vertex of its segments' meshes from the start
  // (their seeds), so only M_Ω and the facet meshes have it unresolved.
  for (uint32_t i = 0; i < num_input_; ++i) {
    if (duplicate_of_[i] != i) {
      ++stats_.duplicates;
      continue;
    }
    const FeatureId f = features_.OfPoint(i);
    const BallId b = balls_.AddVertexBall(PointId(i), normalised[i], f, MeshId(f.value()), kCdInputVertex);
    SetVertexBall(PointId(i), b);
    for (uint32_t fc : point_facets_[i]) LinkVertexBallToFacet(b, fc, TriId2());
    LinkVertexBallToOmega(b, VertexId(0));
  }
  // Segment meshes, seeded with their endpoints (Ω_s = s); their pieces'
  // diametral ConfBalls go to the facets containing them and to M_Ω. The
  // endpoints' 0-balls are the point features' (one ball per global point;
  // guide §7).
  for (uint32_t s = 0; s < complex.segments.size(); ++s) {
    const PointId a(complex.segments[s].a), b(complex.segments[s].b);
    segs_.emplace_back(a, b, points_.Xyz(a), points_.Xyz(b));
    seg_input_a_.push_back(a.value());
    points_.SetVertex(a, SegMesh(s), 0);
    points_.SetVertex(b, SegMesh(s), 1);
    SegmentMesh& m = segs_.back();
    m.VertexBall(0) = VertexBallOf(a);
    m.VertexBall(1) = VertexBallOf(b);
    const BallId piece = balls_.AddPieceBall(a, b, points_.Xyz(a), points_.Xyz(b), features_.OfSegment(s), SegMesh(s));
    m.PieceBall(0) = piece;
    if (piece_vertex_.size() <= piece.value()) {
      piece_vertex_.resize(piece.value() + 1);
      piece_seg_.resize(piece.value() + 1);
    }
    piece_vertex_[piece.value()] = 0;
    piece_seg_[piece.value()] = s;
    for (uint32_t fc : seg_facets_[s]) LinkPieceToFacet(piece, fc, TriId2());
    LinkBallToOmega(piece, VertexId(0));
  }
  // The seed triangles of each M_F that are in F (they contain it) get
  // triangle ConfBalls, linked into M_Ω.
  for (uint32_t f = 0; f < facets_.size(); ++f) {
    facets_[f].CreateAllTriangleBalls(frames_[f], features_.OfFacet(f), FacetMeshId(f), &balls_);
    const std::vector<TriId2> tris = facets_[f].dt().Triangles();
    AdoptTriangleBalls(f, tris, VertexId(0));
  }
  for (uint32_t v = 0; v < omega_.NumVertices(); ++v) RefreshEvents(VertexId(v));
  for (uint32_t s = 0; s < segs_.size(); ++s) {
    for (uint32_t v = 0; v < segs_[s].NumVertices(); ++v) RefreshSegmentEvents(s, v);
  }
  for (uint32_t f = 0; f < facets_.size(); ++f) {
    for (uint32_t v = 0; v < facets_[f].NumVertices(); ++v) RefreshFacetEvents(f, VertexId2(v));
  }
  return absl::OkStatus();
}

// ---------------------------------------------------------------- BLG helpers

void Refiner::CellsMeetingBall(const Vec3& c, double r, VertexId w, std::vector<VertexId>* out, bool loose) {
  const delaunay::Delaunay3& dt = omega_.dt();
  const Vec3& pw = dt.Point(w);
  const double wc2 = geom::Dist2(pw, c);
  // V(x) lies in the half-space of points nearer to x than to any y: a cell
  // is admitted when w's bisector allows it (w: the vertex nearest c, or the
  // cell holding c), and kept (output, and searched from) when every
  // Delaunay neighbour's bisector allows it too, V(x) being the intersection
  // of those half-spaces. The cells B truly meets are connected (B is, and
  // they cover it) and all pass, so the search still reaches each of them;
  // measured, 41% of the cells w's test admits fail (cube --max-volume 1e-5,
  // example.poly). The neighbours' test only without collars: the
  // refinement is then the same bit for bit (the no-collar path's links are
  // order-neutral, §8 item 37); with collars FastCollarSize and the event
  // order read the links, and the outputs moved (schonhardt.off 47,338 →
  // 55,851 tets). `loose` (the invariant check) keeps w's test alone.
  const bool tight = !loose && options_.tight_ball_cells && !options_.collars;
  ++stamp_;
  if (mark_.size() < dt.NumVertices()) mark_.resize(dt.NumVertices() + 64, 0);
  out->clear();
  std::vector<VertexId>& cand = cmb_candidates_;
  // cmb_parents_[i]: the kept cell whose neighbour list admitted cand[i].
  std::vector<VertexId>& parent = cmb_parents_;
  cand.clear();
  parent.clear();
  cand.push_back(w);
  parent.push_back(w);
  mark_[w.value()] = stamp_;
  for (size_t i = 0; i < cand.size(); ++i) {
    const VertexId xi = cand[i];
    const Vec3& px = dt.Point(xi);
    double xc2 = 0;
    if (tight && xi != w) {
      // The parent is one of xi's Delaunay neighbours, so its bisector is one
      // of the tests below: asked first, it turns candidates away before
      // their neighbour list is fetched (same cells, same order; the parent
      // w was the admission test). Cube 1e-4: 27% of the fetches saved.
      xc2 = geom::Dist2(px, c);
      const VertexId y = parent[i];
      if (y != w) {
        const Vec3& py = dt.Point(y);
        if (BallBeyondBisectorOf(xc2, geom::Dist2(py, c), px, py, r, wc2)) continue;
      }
    }
    // A view into M_Ω's neighbour cache (no copy); valid until the next
    // vertex query of dt, and the loop body makes none.
    const std::span<const VertexId> nbrs = dt.NeighborsView(xi);
    if (tight && xi != w) {
      bool meets = true;
      for (VertexId y : nbrs) {
        const Vec3& py = dt.Point(y);
        if (BallBeyondBisectorOf(xc2, geom::Dist2(py, c), px, py, r, wc2)) {
          meets = false;
          break;
        }
      }
      if (!meets) continue;
    }
    out->push_back(xi);
    for (VertexId x : nbrs) {
      if (mark_[x.value()] == stamp_) continue;
      mark_[x.value()] = stamp_;
      const Vec3& px2 = dt.Point(x);
      if (!BallBeyondBisectorOf(geom::Dist2(px2, c), wc2, px2, pw, r, wc2)) {
        cand.push_back(x);
        parent.push_back(xi);
      }
    }
  }
}

bool Refiner::Encroaches(BallId b, VertexId x) const {
  // "x inside the diametral ball of piece ab" (Figure 3.10). The closed ball:
  // a vertex exactly on the sphere is counted, because then the empty-sphere
  // witness for ab is decided by the perturbation, which need not favour ab
  // (docs/svrc-design.md §2, §8). The piece's own endpoints are on the sphere
  // by definition and do not count.
  // A triangle ball likewise: the closed diametral ball of abc
  // (InTriangleCircumball3d ≥ 0 on the rounded xyz, design §2), its own
  // vertices excluded.
  const PointId p = omega_.PointOf(x);
  const int n = balls_.NumVertices(b);
  for (int i = 0; i < n; ++i) {
    if (p == balls_.Vertex(b, i)) return false;
  }
  return Inside(b, omega_.dt().Point(x));
}

bool Refiner::Inside(BallId b, const Vec3& px) const {
  if (!DeepInside(balls_.Center(b), balls_.Radius(b), px)) return false;
  if (balls_.NumVertices(b) == 2) {
    return geom::InDiametralSphere(points_.Xyz(balls_.Vertex(b, 0)), points_.Xyz(balls_.Vertex(b, 1)), px) > 0;
  }
  return geom::InTriangleCircumball3d(points_.Xyz(balls_.Vertex(b, 0)), points_.Xyz(balls_.Vertex(b, 1)),
                                      points_.Xyz(balls_.Vertex(b, 2)), px) > 0;
}

Vec2 Refiner::Uv(uint32_t f, PointId p) const {
  const uint32_t v = points_.VertexIn(p, FacetMeshId(f));
  if (v != PointStore::kNoVertex) return facets_[f].dt().Point(VertexId2(v));
  return frames_[f].ToPlane(points_.Xyz(p));
}

bool Refiner::EncroachesInFacet(uint32_t f, BallId b, VertexId2 x) const {
  // A piece ab of a segment of F in M_F: x in the closed diametral disk of
  // ab in uv (§8 item 9), endpoints excluded.
  const FacetMesh& m = facets_[f];
  const PointId p = m.PointOf(x);
  const PointId a = balls_.Vertex(b, 0), c = balls_.Vertex(b, 1);
  if (p == a || p == c) return false;
  const Vec2 ua = Uv(f, a), uc = Uv(f, c), ux = m.dt().Point(x);
  return DeepInside2(Mid2(ua, uc), HalfLen2(ua, uc), ux) && geom::InDiametralCircle(ua, uc, ux) > 0;
}

bool Refiner::EncroachedByPoint(BallId b, PointId p) const {
  const uint32_t x = points_.VertexIn(p, kOmegaMesh);
  if (x != PointStore::kNoVertex && Encroaches(b, VertexId(x))) return true;
  if (balls_.NumVertices(b) == 2 && !facets_.empty()) {
    for (uint32_t f : seg_facets_[piece_seg_[b.value()]]) {
      const uint32_t y = points_.VertexIn(p, FacetMeshId(f));
      if (y != PointStore::kNoVertex && EncroachesInFacet(f, b, VertexId2(y))) return true;
    }
  }
  return false;
}

void Refiner::CellsMeetingDisk(uint32_t f, Vec2 c, double r, VertexId2 w, std::vector<VertexId2>* out) {
  // The 2D twin of CellsMeetingBall (same bisector bound).
  const delaunay::Delaunay2& dt = facets_[f].dt();
  const Vec2 pw = dt.Point(w);
  auto d2 = [](Vec2 a, Vec2 b) { return (a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y); };
  const double wc2 = d2(pw, c);
  auto may_meet = [&](Vec2 px) {
    const double lhs = d2(px, c) - wc2;
    if (lhs <= 1e-12 * wc2) return true;  // the right-hand side is at least that
    return lhs <= 2.0 * r * std::sqrt(d2(px, pw)) * (1 + 1e-9) + 1e-12 * wc2;
  };
  ++stamp2_;
  if (mark2_.size() < dt.NumVertices()) mark2_.resize(dt.NumVertices() + 64, 0);
  out->clear();
  out->push_back(w);
  mark2_[w.value()] = stamp2_;
  for (size_t i = 0; i < out->size(); ++i) {
    dt.Neighbors((*out)[i], &nbrs2_);
    for (VertexId2 x : nbrs2_) {
      if (mark2_[x.value()] == stamp2_) continue;
      mark2_[x.value()] = stamp2_;
      if (may_meet(dt.Point(x))) out->push_back(x);
    }
  }
}

void Refiner::AddFacetPieceLink(uint32_t f, VertexId2 x, BallId b) {
  LinkFacts facts;
  facts.encroaches = EncroachesInFacet(f, b, x);
  const PointId p = facets_[f].PointOf(x);
  facts.native = points_.CdOf(p).dim == 2;  // created in a facet mesh (this one: it is its vertex)
  facts.vertex_point = p;
  const AddLinkResult r = blg_.AddLink(FacetMeshId(f), x.value(), LocationObject::Ball(b), facts, &balls_);
  if (r.encroach == EncroachOutcome::kEnqueue) EnqueueEncroached(b);
  if (r.encroach == EncroachOutcome::kPartial) partial_.push_back({b, balls_.Generation(b)});
}

void Refiner::LinkPieceToFacet(BallId b, uint32_t f, TriId2 hint) {
  const delaunay::Delaunay2& dt = facets_[f].dt();
  const Vec2 a = Uv(f, balls_.Vertex(b, 0)), c = Uv(f, balls_.Vertex(b, 1));
  const Vec2 mid{0.5 * (a.x + c.x), 0.5 * (a.y + c.y)};
  const double r = 0.5 * std::sqrt((a.x - c.x) * (a.x - c.x) + (a.y - c.y) * (a.y - c.y));
  const VertexId2 w = SeedVertex(dt, mid, hint);
  std::vector<VertexId2> cells;
  CellsMeetingDisk(f, mid, r, w, &cells);
  for (VertexId2 x : cells) AddFacetPieceLink(f, x, b);
}

void Refiner::LinkVertexBallToFacet(BallId b, uint32_t f, TriId2 hint) {
  if (Suppressed(balls_.VertexPoint(b))) return;
  const delaunay::Delaunay2& dt = facets_[f].dt();
  const VertexId2 cell = dt.NearestVertex(Uv(f, balls_.VertexPoint(b)), hint);
  LinkFacts facts;
  facts.unresolved = true;
  const AddLinkResult r = blg_.AddLink(FacetMeshId(f), cell.value(), LocationObject::Ball(b), facts, &balls_);
  if (r.cell_became_unresolved) RefreshFacetEvents(f, cell);
}

void Refiner::AdoptTriangleBalls(uint32_t f, std::span<const TriId2> tris, VertexId start) {
  const FacetMesh& m = facets_[f];
  if (tri_of_ball_.size() < balls_.size()) tri_of_ball_.resize(balls_.size() + 64, 0xFFFFFFFFu);
  for (TriId2 t : tris) {
    if (!m.dt().IsAlive(t)) continue;
    const BallId b = m.TriBall(t);
    if (!b.valid() || !balls_.IsAlive(b) || tri_of_ball_[b.value()] == t.value()) continue;
    tri_of_ball_[b.value()] = t.value();
    LinkBallToOmega(b, start);
  }
}

void Refiner::EnqueueEncroached(BallId b) {
  if (balls_.EncroachQueued(b)) return;
  const int dim = features_.Dim(balls_.Feature(b));
  WorkEvent e{EventType::kEncroached, static_cast<uint8_t>(dim), balls_.Mesh(b), b.value(),
              balls_.Generation(b), balls_.Radius(b)};
  if (queues_.Enqueue(e).valid()) balls_.SetEncroachQueued(b, true);
}

void Refiner::AddBallLink(VertexId x, BallId b) {
  LinkFacts facts;
  facts.encroaches = Encroaches(b, x);
  const PointId p = omega_.PointOf(x);
  facts.native = points_.CdOf(p).dim == 3;  // CD(x) = dim Ω: created in M_Ω
  facts.vertex_point = p;
  const AddLinkResult r = blg_.AddLink(kOmegaMesh, x.value(), LocationObject::Ball(b), facts, &balls_);
  if (r.encroach == EncroachOutcome::kEnqueue) EnqueueEncroached(b);
  if (r.encroach == EncroachOutcome::kPartial) partial_.push_back({b, balls_.Generation(b)});
}

void Refiner::LinkBallToOmega(BallId b, VertexId start) {
  const delaunay::Delaunay3& dt = omega_.dt();
  const VertexId w = SeedVertex(balls_.Center(b), dt.VertexTet(start));
  std::vector<VertexId>& cells = link_cells_;
  CellsMeetingBall(balls_.Center(b), balls_.Radius(b), w, &cells);
  for (VertexId x : cells) AddBallLink(x, b);
}

void Refiner::LinkVertexBallToOmega(BallId b, VertexId start) {
  if (Suppressed(balls_.VertexPoint(b))) return;
  AddPending(b);
  const delaunay::Delaunay3& dt = omega_.dt();
  const VertexId cell = dt.NearestVertex(balls_.Center(b), dt.VertexTet(start));
  LinkFacts facts;
  facts.unresolved = true;
  const AddLinkResult r = blg_.AddLink(kOmegaMesh, cell.value(), LocationObject::Ball(b), facts, &balls_);
  if (r.cell_became_unresolved) RefreshEvents(cell);
}

// ---------------------------------------------------------------- events

void Refiner::RefreshEvents(VertexId v, const CellSize* size) {
  const CellSize s = size != nullptr ? *size : omega_.Size(v);
  const uint32_t gen = omega_.CellGeneration(v);
  // Unresolved: the cell holds a 0-ball whose point is not yet in M_Ω. Built
  // as the gap ball ⟨(farthest corner, R_v), Ω⟩ (guide §3 on Figure 3.11).
  EventHandle& u = omega_.UnresolvedEvent(v);
  if (blg_.NumUnresolved(kOmegaMesh, v.value()) > 0) {
    if (queues_.IsQueued(u)) {
      queues_.Refresh(u, gen, s.outradius);
    } else {
      u = queues_.Enqueue({EventType::kUnresolved, 3, kOmegaMesh, v.value(), gen, s.outradius});
    }
  } else if (queues_.IsQueued(u)) {
    queues_.Remove(u);
  }
  // Skinny: R_v/r_v > τ (Figure 3.5), or a size event (R_v above the cell's
  // max_volume target); gap ball at the farthest corner.
  EventHandle& k = omega_.SkinnyEvent(v);
  if (IsBad(v, s)) {
    if (queues_.IsQueued(k)) {
      queues_.Refresh(k, gen, s.kept_outradius);
    } else {
      k = queues_.Enqueue({EventType::kSkinny, 3, kOmegaMesh, v.value(), gen, s.kept_outradius});
    }
  } else if (queues_.IsQueued(k)) {
    queues_.Remove(k);
  }
}

void Refiner::RefreshSegmentEvents(uint32_t seg, uint32_t v) {
  SegmentMesh& m = segs_[seg];
  const SegmentMesh::Size1 s = m.Size(v);
  EventHandle& k = m.SkinnyEvent(v);
  if (IsSkinny(s)) {
    if (queues_.IsQueued(k)) {
      queues_.Refresh(k, m.CellGeneration(v), s.outradius);
    } else {
      k = queues_.Enqueue({EventType::kSkinny, 1, SegMesh(seg), v, m.CellGeneration(v), s.outradius});
    }
  } else if (queues_.IsQueued(k)) {
    queues_.Remove(k);
  }
}

void Refiner::RefreshFacetEvents(uint32_t f, VertexId2 v, const CellSize2* size) {
  FacetMesh& m = facets_[f];
  const CellSize2 s = size != nullptr ? *size : m.Size(v);
  const uint32_t gen = m.CellGeneration(v);
  const MeshId mesh = FacetMeshId(f);
  EventHandle& u = m.UnresolvedEvent(v);
  if (blg_.NumUnresolved(mesh, v.value()) > 0) {
    if (queues_.IsQueued(u)) {
      queues_.Refresh(u, gen, s.outradius);
    } else {
      u = queues_.Enqueue({EventType::kUnresolved, 2, mesh, v.value(), gen, s.outradius});
    }
  } else if (queues_.IsQueued(u)) {
    queues_.Remove(u);
  }
  EventHandle& k = m.SkinnyEvent(v);
  if (IsSkinny(s)) {
    if (queues_.IsQueued(k)) {
      queues_.Refresh(k, gen, s.outradius);
    } else {
      k = queues_.Enqueue({EventType::kSkinny, 2, mesh, v.value(), gen, s.outradius});
    }
  } else if (queues_.IsQueued(k)) {
    queues_.Remove(k);
  }
}

bool Refiner::IsLive(const WorkEvent& e) {
  if (e.type == EventType::kEncroached) {
    const BallId b(e.object);
    // A stale event must not clear the flag of a ball that took over its
    // record (BallStore recycling).
    if (balls_.Generation(b) != e.generation) return false;
    balls_.SetEncroachQueued(b, false);
    return balls_.IsAlive(b);
  }
  if (IsFacetMesh(e.mesh)) {
    const uint32_t f = FacetIndex(e.mesh);
    FacetMesh& m = facets_[f];
    const VertexId2 v(e.object);
    if (m.CellGeneration(v) != e.generation) return false;
    if (e.type == EventType::kUnresolved && blg_.NumUnresolved(e.mesh, v.value()) == 0) return false;
    last_size2_ = m.Size(v);
    last_size2_facet_ = f;
    last_size2_vertex_ = v;
    last_size2_gen_ = m.CellGeneration(v);
    if (e.type == EventType::kSkinny) return IsSkinny(last_size2_);
    return true;
  }
  if (!IsOmega(e.mesh)) {
    SegmentMesh& m = segs_[SegIndex(e.mesh)];
    return m.CellGeneration(e.object) == e.generation && IsSkinny(m.Size(e.object));
  }
  if (e.type == EventType::kSkinny && (e.object & kTetEvent) != 0) {
    const delaunay::Delaunay3& dt = omega_.dt();
    const TetId t(e.object & ~kTetEvent);
    return t.value() < dt.TetCapacity() && dt.IsAlive(t) && dt.Generation(t) == e.generation;
  }
  const VertexId v(e.object);
  if (omega_.CellGeneration(v) != e.generation) return false;
  if (e.type == EventType::kUnresolved) return blg_.NumUnresolved(kOmegaMesh, v.value()) > 0;
  last_size_ = omega_.Size(v);
  last_size_vertex_ = v;
  last_size_gen_ = omega_.CellGeneration(v);
  if (e.type == EventType::kSkinny) return IsBad(v, last_size_);
  return true;
}

// Adds the seconds of its scope to *sum (a phase's time in RefineStats).
class AddSeconds {
 public:
  explicit AddSeconds(double* sum) : sum_(sum), start_(std::chrono::steady_clock::now()) {}
  ~AddSeconds() { *sum_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }
  AddSeconds(const AddSeconds&) = delete;
  AddSeconds& operator=(const AddSeconds&) = delete;

 private:
  double* sum_;
  std::chrono::steady_clock::time_point start_;
};

void Refiner::CountEventTime(double seconds) {
  int kind = -1;
  if (event_kinds_ & (1u << kSegmentMesh)) {
    kind = kSegmentMesh;
  } else if (event_kinds_ & (1u << kFacetMesh)) {
    kind = kFacetMesh;
  } else if (event_insertions_ == 1) {
    kind = std::countr_zero(event_kinds_);
  }
  if (kind >= 0) {
    stats_.seconds_by_kind[kind] += seconds;
    ++stats_.events_by_kind[kind];
  } else {
    stats_.seconds_other_events += seconds;
    ++stats_.other_events;
  }
}

void Refiner::RecycleBalls() {
  // Between events: Destroy's insertions unlinked every ball they killed
  // (ForceInsertFacet, ForceInsertSegment); the only list that keeps dead
  // balls, partial_, holds their generations. A ball some link still names
  // is never recycled.
  balls_.TakeDying(&dying_scratch_);
  for (BallId b : dying_scratch_) {
    if (blg_.NumObjectLinks(LocationObject::Ball(b)) != 0) continue;
    const uint32_t i = b.value();
    if (i < tri_of_ball_.size()) tri_of_ball_[i] = 0xFFFFFFFFu;
    if (i < ball_mark_.size()) ball_mark_[i] = 0;
    if (i < known_present_.size()) known_present_[i] = 0;
    if (i < piece_vertex_.size()) piece_vertex_[i] = 0;
    if (i < piece_seg_.size()) piece_seg_[i] = 0;
    balls_.Recycle(b);
    ++stats_.balls_recycled;
  }
}

absl::Status Refiner::Run() {
  const auto start = std::chrono::steady_clock::now();
  const geom::PredicateStats pred0 = geom::GetPredicateStats();
  auto live = [this](const WorkEvent& e) { return IsLive(e); };
  uint64_t destroys = 0;
  while (true) {
  auto tick = std::chrono::steady_clock::now();
  while (std::optional<WorkEvent> event = queues_.DequeueLive(live)) {
    if (TotalVertices() >= budget_) {
      return absl::ResourceExhaustedError(absl::StrCat("SVRC: vertex budget of ", budget_, " reached with ",
                                                       queues_.size(), " events pending", BudgetHint()));
    }
    if (absl::Status s = PollAt(destroys, event->radius); !s.ok()) return s;
    ++destroys;
    event_kinds_ = 0;
    event_insertions_ = 0;
    absl::Status s = Destroy(*event);
    if (!s.ok()) return s;
    RecycleBalls();
    const auto now = std::chrono::steady_clock::now();
    CountEventTime(std::chrono::duration<double>(now - tick).count());
    tick = now;
    if (options_.validate_every > 0 && destroys % options_.validate_every == 0) {
      s = CheckInvariants(false);
      if (!s.ok()) return s;
    }
  }
  // The queues ran dry. A ball encroached only by one lower-dimensional
  // vertex (PartiallyEncroached, Figure 3.10) waits for a second encroacher;
  // if none came, its piece is still not a Delaunay edge of M_Ω — the
  // thesis' "unresolved ConfBall" (Figure 3.9) — so destroy it now
  // (docs/svrc-design.md §8 item 8).
  std::vector<std::pair<BallId, uint32_t>> partial;
  partial.swap(partial_);
  bool more = false;
  for (const auto& [b, gen] : partial) {
    if (!balls_.IsAlive(b) || balls_.Generation(b) != gen) continue;
    if (EncroachedByPoint(b, balls_.FirstEncroacher(b))) {
      EnqueueEncroached(b);
      more = true;
    }
  }
  if (!more) more = EnqueueMissing();
  if (!more) break;
  }
  const geom::PredicateStats& pred = geom::GetPredicateStats();
  stats_.predicate_calls += pred.TotalCalls() - pred0.TotalCalls();
  stats_.predicate_exact += pred.TotalExact() - pred0.TotalExact();
  stats_.predicate_sos += pred.TotalSos() - pred0.TotalSos();
  stats_.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return absl::OkStatus();
}

// ---------------------------------------------------------------- Destroy

absl::Status Refiner::Destroy(const WorkEvent& event) {
  if (event.type == EventType::kEncroached) return DestroyBall(BallId(event.object));
  if (IsFacetMesh(event.mesh)) {
    const uint32_t f = FacetIndex(event.mesh);
    const VertexId2 v(event.object);
    const CellSize2 s = (last_size2_facet_ == f && last_size2_vertex_ == v &&
                         last_size2_gen_ == facets_[f].CellGeneration(v))
                            ? last_size2_
                            : facets_[f].Size(v);
    return DestroyFacet(f, s.corner, s.outradius, s.hint);
  }
  if (!IsOmega(event.mesh)) {
    const uint32_t seg = SegIndex(event.mesh);
    return DestroySegmentPiece(seg, segs_[seg].Size(event.object).piece);
  }
  if (event.type == EventType::kSkinny && (event.object & kTetEvent) != 0) {
    // The tet is the one EnqueueTetIfBad measured (its generation held at
    // pop), so its circumcentre is the centre computed then, bit for bit.
    const TetId t(event.object & ~kTetEvent);
    Vec3 cc;
    if (!omega_.PlainCorner(t, &cc)) {
      return absl::InternalError(absl::StrCat("SVRC: tet ", t.value(), " of a Skinny event has no circumcentre"));
    }
    return DestroyOmegaAt(cc, event.radius, t, omega_.dt().TetVertex(t, 0));
  }
  return DestroyOmega(VertexId(event.object), event.type == EventType::kSkinny);
}

absl::Status Refiner::DestroyBall(BallId b) {
  if (balls_.NumVertices(b) == 2) return DestroySegmentPiece(piece_seg_[b.value()], piece_vertex_[b.value()]);
  // A triangle of M_F: its circumdisk is a gap ball of M_F (the triangle is
  // Delaunay), centred at a Voronoi vertex; the triangle itself conflicts.
  const uint32_t f = FacetIndex(balls_.Mesh(b));
  const TriId2 t(tri_of_ball_[b.value()]);
  const FacetMesh& m = facets_[f];
  const delaunay::Delaunay2& dt = m.dt();
  Vec2 c = dt.Circumcenter(t);
  double r = dt.Circumradius(t);
  // A triangle reaching the quadrilateral's corners can have its circumcentre
  // outside Ω_F. Its disk meets F (the triangle does), hence Ω_F's interior,
  // so the nearest point of Ω_F to c is strictly inside the disk: the gap
  // ball B(clamp(c), r − |c − clamp(c)|) ⊂ the disk is empty and inserting its
  // centre destroys t — the clipped-Voronoi reading of Definition 11.
  const Vec2 cc{std::clamp(c.x, m.SquareLo().x, m.SquareHi().x), std::clamp(c.y, m.SquareLo().y, m.SquareHi().y)};
  if (cc.x != c.x || cc.y != c.y) {
    r -= std::hypot(c.x - cc.x, c.y - cc.y);
    c = cc;
  }
  return DestroyFacet(f, c, r, t, t);
}

absl::Status Refiner::DestroyFacet(uint32_t f, Vec2 c, double r, TriId2 hint, TriId2 tri, Cd cd_ball, bool jitter) {
  // Figure 3.4 in M_F. 𝒱: cells meeting B (from the nearest vertex to c);
  // 𝓑: balls linked to them — 0-balls of F's points and segment points
  // (warp targets, CD < (2,3)) and piece balls of F's segments (yields).
  FacetMesh& m = facets_[f];
  const MeshId mesh = FacetMeshId(f);
  const double theta_r2 = (options_.theta * r) * (options_.theta * r);
  // Destroying a triangle, the disk whose interior points destroy it is its
  // circumdisk. DestroyBall clamps a circumcentre outside Ω_F into the square
  // and shrinks r, so (c, r) can be a small part of that disk, while a
  // straddled piece is split towards its crossing anywhere in the triangle.
  // Warps are tested against the whole circumdisk (measured: f_real/hinge.stl,
  // facet 459, a triangle of side 2.4 clamped to r = 0.40: its crossing
  // segment was halved uniformly for 100,000 yields, every new point outside
  // the clamped disk, for minutes). Otherwise warp targets lie within θr
  // of c.
  Vec2 wc = c;
  double warp_r2 = theta_r2;
  if (tri.valid()) {
    wc = m.dt().Circumcenter(tri);
    const double wr = m.dt().Circumradius(tri);
    warp_r2 = wr * wr * (1 - 1e-9);
  }
  for (int attempt = 0;; ++attempt) {
    if (attempt > 100000) return absl::InternalError("SVRC: Destroy (facet) yielded without end");
    if (absl::Status polled = PollInDestroy(attempt); !polled.ok()) return polled;
    // Each yield inserts into a segment mesh: the budget bounds the chain.
    if (TotalVertices() >= budget_) {
      return absl::ResourceExhaustedError(absl::StrCat("SVRC: vertex budget of ", budget_, " reached", BudgetHint()));
    }
    const VertexId2 w = SeedVertex(m.dt(), c, hint);
    CellsMeetingDisk(f, c, r, w, &bfs2_);
    stats_.destroy_cells_visited += bfs2_.size();
    BallId warp, yield;
    double warp_d2 = 0;
    GatherBalls(mesh, bfs2_, &gathered_);
    for (BallId b : gathered_) {
      if (!(balls_.CdOf(b) < cd_ball) || !balls_.IsAlive(b)) continue;
      if (balls_.IsVertexBall(b)) {
        const PointId p = balls_.VertexPoint(b);
        if (points_.InMesh(p, mesh) || Suppressed(p)) continue;
        const Vec2 q = Uv(f, p);
        const double d2 = (q.x - c.x) * (q.x - c.x) + (q.y - c.y) * (q.y - c.y);
        // Destroying a triangle's disk, any unresolved lower point strictly
        // inside it destroys the triangle: warp within r, not θr. A
        // straddled piece is split towards the crossing until its new
        // point falls inside the triangle; with θr, a crossing near the
        // disk's rim was never reached (halving to the last ulp; measured
        // on knife_edge.poly refined through its creases).
        if ((q.x - wc.x) * (q.x - wc.x) + (q.y - wc.y) * (q.y - wc.y) > warp_r2) continue;
        if (PreferWarp(b, d2, warp, warp_d2)) {
          warp = b;
          warp_d2 = d2;
        }
      } else if (balls_.NumVertices(b) == 2) {
        const Vec2 ua = Uv(f, balls_.Vertex(b, 0)), ub = Uv(f, balls_.Vertex(b, 1));
        // Yield when c is deeply inside the piece's disk, or when the
        // triangle being destroyed straddles the piece: such a triangle is
        // "in F" only until the piece conforms (guide §5 item 4), and
        // splitting it while the piece is not an edge of M_F refines the
        // wrong side of the segment against the neighbouring facet's points
        // (measured: box_internal_facet ran to the vertex budget).
        // Inside the collars a facet need not conform to a non-crease
        // segment (its points there are suppressed, Figure 3.9): no straddle
        // yield (measured: crease_pair_30 split such a piece without end).
        // The straddle is decided as InFacet decides it, with the vertices
        // known to lie on the segment: a triangle with an edge on the
        // segment's line does not straddle its pieces, although their
        // rounded points zigzag across that edge by 1e-17 (measured:
        // f_real/hinge.stl at radius_edge 1.414, facet 480: every piece of
        // segment 223 under the edge (10858, 187) was split again and again,
        // 28,000 yields in one Destroy down to pieces of 3e-12, for the
        // whole 900 s of the bench's timeout).
        const bool straddles = tri.valid() && m.dt().IsAlive(tri) && !PieceInCollars(b) &&
                               !TriangleInCollars(m, tri) && TriangleStraddlesPiece(m, tri, b, ua, ub);
        if (straddles) ++stats_.straddle_yields;
        if (!straddles && (!DeepInside2(Mid2(ua, ub), HalfLen2(ua, ub), c) || geom::InDiametralCircle(ua, ub, c) <= 0)) {
          continue;
        }
        if (PreferYield(b, yield)) yield = b;
      }
    }
    if (warp.valid()) {
      ++stats_.warps;
      const PointId p = balls_.VertexPoint(warp);
      std::vector<uint32_t> cells;
      blg_.CellsOf(LocationObject::Ball(warp), mesh, &cells);
      const TriId2 h = cells.empty() ? hint : m.dt().VertexTri(VertexId2(cells[0]));
      return ForceInsertFacet(f, p, Uv(f, p), h);
    }
    if (!yield.valid()) {
      if (!(c.x >= m.SquareLo().x && c.x <= m.SquareHi().x && c.y >= m.SquareLo().y && c.y <= m.SquareHi().y)) {
        return absl::InternalError(absl::StrCat("SVRC: facet ", f, " gap ball centre (", c.x, ", ", c.y, ") r=", r, " outside its square Ω_F [", m.SquareLo().x, ",", m.SquareHi().x, "]x[", m.SquareLo().y, ",", m.SquareHi().y, "]"));
      }
      const uint64_t id = points_.size();
      Vec2 cj = jitter ? Vec2{c.x + kJitter * r * Jitter(id, 1), c.y + kJitter * r * Jitter(id, 2)} : c;
      if (!(cj.x >= m.SquareLo().x && cj.x <= m.SquareHi().x && cj.y >= m.SquareLo().y && cj.y <= m.SquareHi().y)) {
        cj = c;  // a corner on ∂Ω_F stays on it
      }
      const PointId p = points_.Add(frames_[f].ToSpace(cj), features_.OfFacet(f), cd_ball);
      return ForceInsertFacet(f, p, cj, hint);
    }
    ++stats_.yields;
    stats_.max_yield_chain = std::max<uint64_t>(stats_.max_yield_chain, attempt + 1);
    absl::Status st = DestroySegmentPiece(piece_seg_[yield.value()], piece_vertex_[yield.value()]);
    if (!st.ok()) return st;
  }
}

absl::Status Refiner::DestroySegmentPiece(uint32_t seg, uint32_t u) {
  // Figure 3.4 in M_s for the gap ball centred at the piece's midpoint. Warp
  // (𝒲) and yield (𝒴) look at balls linked to M_s's cells, i.e. balls of its
  // subfeatures: a free segment's subfeatures are its endpoints, vertices of
  // M_s from the start, so 𝒲 = 𝒴 = ∅ until collar points (1,2) exist
  // (stage (d)). Line 11: insert the centre.
  SegmentMesh& m = segs_[seg];
  const double t = 0.5 * (m.T(u) + m.T(m.Next(u))) +
                   0.5 * kJitter * (m.T(m.Next(u)) - m.T(u)) * Jitter(points_.size(), 3);
  if (!(t > m.T(u) && t < m.T(m.Next(u)))) {
    return absl::InternalError(absl::StrCat("SVRC: segment ", seg, " piece too short to split (t = ", t, ")"));
  }
  return ForceInsertSegment(seg, u, t);
}

absl::Status Refiner::DestroyOmega(VertexId v, bool skinny) {
  // Line 1 (stale test) was done at Dequeue. The gap ball is rebuilt from the
  // cell: ⟨(farthest corner of V(v) ∩ Ω, R_v), Ω⟩; CD(B) = CD(c) = (3,3).
  const CellSize s = (last_size_vertex_ == v && last_size_gen_ == omega_.CellGeneration(v)) ? last_size_
                                                                                           : omega_.Size(v);
  if (skinny) return DestroyOmegaAt(s.kept_corner, s.kept_outradius, s.kept_hint, v);
  // Unresolved (RefineOptions::unresolved_kept_warp): both balls are empty
  // circumballs of tets at v, gap balls of V(v); Destroy of either warps to
  // a pending 0-ball within θ·r of its centre (lowest CD, nearest, lowest
  // id). When the farthest corner's ball has none, Destroy would insert that
  // corner, outside the output for a cell next to its boundary; when that
  // corner is more than 16 times as far as the kept one (the cell's extent
  // is its exterior part) and the kept corner's ball has a target, the point
  // is resolved now. The factor, measured (session 42): without one,
  // fan_6x60deg at radius_edge 1.414 went from 1,433 tets to 2,529 (an input
  // whose count moves between 848 and 8,600 over bounds 1.40 to 1.5), with
  // 2 to 1,645; from 4 on it meshes as before at every bound from 1.40 to
  // 1.5. Below 16 the convex hull of CreaseMesh.MildCreasesLeavingBadTetsTake
  // Collars meshes differently on its first, collar-free run (at 2 it ran
  // into the vertex budget, 0.9 → 2.1 s; at 4 and 8 it met the bounds
  // without collars). Cube 1e-6 keeps 83 of the 89 warps a factor of 4 makes.
  constexpr double kExteriorExtent = 16;
  if (options_.unresolved_kept_warp && !options_.collars && s.outside_tets && s.kept_outradius > 0 &&
      s.outradius > kExteriorExtent * s.kept_outradius && HasWarpTarget(s.kept_corner, s.kept_outradius) &&
      !HasWarpTarget(s.corner, s.outradius)) {
    ++stats_.unresolved_kept_warps;
    return DestroyOmegaAt(s.kept_corner, s.kept_outradius, s.kept_hint, v);
  }
  return DestroyOmegaAt(s.corner, s.outradius, s.hint, v);
}

bool Refiner::WarpTargetWithin(BallId b, const Vec3& c, double theta_r2, double* d2) {
  const PointId p = balls_.VertexPoint(b);
  if (points_.InMesh(p, kOmegaMesh) || Suppressed(p)) return false;
  *d2 = geom::Dist2(balls_.Center(b), c);
  return !(*d2 > theta_r2);
}

bool Refiner::HasWarpTarget(const Vec3& c, double r) {
  // DestroyOmegaAt's warp test for a ball of CD 3, over the pending index
  // (the 0-balls linked unresolved into M_Ω, all of lower CD).
  const double theta_r2 = (options_.theta * r) * (options_.theta * r);
  warp_probe_.clear();
  pending_.Near(c, options_.theta * r, &warp_probe_);
  for (uint32_t id : warp_probe_) {
    double d2;
    if (balls_.CdOf(BallId(id)) < kCdSpace && WarpTargetWithin(BallId(id), c, theta_r2, &d2)) return true;
  }
  return false;
}

absl::Status Refiner::DestroyOmegaAt(const Vec3& c_in, double r, TetId cell_hint, VertexId v, Cd cd_ball) {
  // A centre within a few ulps of a face of Ω goes onto it. A circumcentre
  // of a tet on ∂Ω can be rounded just inside (clipped corners are on it
  // exactly): the point then makes a tet with three points of that face,
  // positive by rounding and flat, which keep_bounding_box returns
  // (segment_fan.poly --keep-bounding-box, session 35: a point 1 ulp below
  // the top face, refused by the checker's flat_tet).
  Vec3 c = c_in;
  {
    const geom::Box3& box = omega_.cube();
    for (int k = 0; k < 3; ++k) {
      const double tol = 8 * 0x1p-52 * std::max(std::fabs(box.lo[k]), std::fabs(box.hi[k]));
      if (std::fabs(c[k] - box.lo[k]) <= tol) c[k] = box.lo[k];
      if (std::fabs(c[k] - box.hi[k]) <= tol) c[k] = box.hi[k];
    }
  }
  struct {
    TetId hint;
  } s{cell_hint};
  const double theta_r2 = (options_.theta * r) * (options_.theta * r);
  for (int attempt = 0;; ++attempt) {
    if (attempt > 100000) return absl::InternalError("SVRC: Destroy yielded without end");
    if (absl::Status polled = PollInDestroy(attempt); !polled.ok()) return polled;
    if (TotalVertices() >= budget_) {
      return absl::ResourceExhaustedError(absl::StrCat("SVRC: vertex budget of ", budget_, " reached", BudgetHint()));
    }
    if (blg_.NumLinks() == 0) {
      // 𝓑 = ∅: nothing to warp or yield to.
      return ForceInsertOmega(points_.Add(c, FeatureTable::Omega(), cd_ball), s.hint);
    }
    // Line 2: 𝒱 = cells meeting B (v is nearest to c: c is its corner).
    // Lines 3–9 read only two kinds of balls of 𝒱: 0-balls not yet in M_Ω
    // within θr of c (warp targets; each is linked, unresolved, to the one
    // cell holding its point, which meets B), and lower balls with c strictly
    // inside (yields; such a ball meets V(v) ∋ c, so it is linked to v). When
    // few cells of M_Ω hold unresolved 0-balls, 𝒱 = {v} ∪ those cells gives
    // the same 𝒲 and 𝒴 without the search of the cells meeting B (12% of
    // the CPU of cube.poly --max-volume 1e-5 before session 9; the output is
    // byte-identical).
    const std::vector<uint32_t>& unresolved_cells = blg_.UnresolvedCells(kOmegaMesh);
    if (options_.destroy_index) {
      // §8 item 41: v's balls and the pending points within θr of c, which
      // are exactly the warp targets the cells would give (a 0-ball linked
      // unresolved into M_Ω and not yet in it is in the index).
      bfs_.assign(1, v);
      ++stats_.destroys_local;
      near_pending_.clear();
      stats_.destroy_index_visited += pending_.Near(c, options_.theta * r, &near_pending_);
    } else if (unresolved_cells.size() <= options_.local_destroy_cells) {
      bfs_.assign(1, v);
      for (uint32_t u : unresolved_cells) {
        if (u != v.value()) bfs_.push_back(VertexId(u));
      }
      ++stats_.destroys_local;
    } else {
      CellsMeetingBall(c, r, v, &bfs_);
    }
    stats_.destroy_cells_visited += bfs_.size();
    stats_.max_destroy_cells = std::max<uint64_t>(stats_.max_destroy_cells, bfs_.size());
    // Line 3: 𝓑 = ∪ Balls_Ω(u). Line 4: 𝒲 = 0-balls not yet in M_Ω within θr
    // of c with CD(p) < CD(B) (the printed inequality is reversed by OCR;
    // guide §3). Line 9: 𝒴 = lower-CD balls with c strictly inside.
    BallId warp, yield;
    double warp_d2 = 0;
    if (options_.destroy_index) {
      GatherIndexedDestroyBalls(v, &gathered_);
    } else if (options_.destroy_gather_all) {
      GatherBalls(kOmegaMesh, bfs_, &gathered_);
    } else {
      GatherDestroyBalls(v, bfs_, &gathered_);
    }
    stats_.destroy_balls_read += gathered_.size();
    for (BallId b : gathered_) {
      if (!(balls_.CdOf(b) < cd_ball)) continue;
      if (balls_.IsVertexBall(b)) {
        double d2;
        if (!WarpTargetWithin(b, c, theta_r2, &d2)) continue;
        // Line 6: lowest CD, then nearest to c, then lowest id (determinism).
        if (PreferWarp(b, d2, warp, warp_d2)) {
          warp = b;
          warp_d2 = d2;
        }
      } else if (balls_.IsAlive(b)) {
        // Strict interior: c on the sphere does not force a yield.
        if (!Inside(b, c)) continue;
        // Lowest CD, then the largest ball, then the one made first.
        if (PreferYield(b, yield)) yield = b;
      }
    }
    if (warp.valid()) {
      ++stats_.warps;
      std::vector<uint32_t> cells;
      blg_.CellsOf(LocationObject::Ball(warp), kOmegaMesh, &cells);
      const TetId hint = cells.empty() ? s.hint : omega_.dt().VertexTet(VertexId(cells[0]));
      return ForceInsertOmega(balls_.VertexPoint(warp), hint);
    }
    if (!yield.valid()) {
      // Line 11: insert the centre. A clipped corner on ∂Ω is a rounded
      // intersection; it can be bit-identical to a vertex already inserted
      // there from a neighbouring cell whose exact cell kept it (so v's cell
      // did not change and its event came back). The gap ball is then not
      // empty: nothing to destroy.
      if (omega_.dt().VertexAt(c, s.hint).valid()) {
        ++stats_.phantom_corners;
        return absl::OkStatus();
      }
      return ForceInsertOmega(points_.Add(c, FeatureTable::Omega(), cd_ball), s.hint);
    }
    // Lines 13–14: destroy the lower ball first (one insertion into M_s), then
    // start over: the new segment point may now be a warp target. M_Ω did not
    // change, so the gap ball is still ours.
    ++stats_.yields;
    stats_.max_yield_chain = std::max<uint64_t>(stats_.max_yield_chain, attempt + 1);
    absl::Status st = DestroyBall(yield);
    if (!st.ok()) return st;
  }
}

// ---------------------------------------------------------------- ForceInsert

absl::Status Refiner::InsertCreaseVertices() {
  TetId hint;
  for (uint32_t i = 0; i < num_input_; ++i) {
    const PointId p(i);
    if (duplicate_of_[i] != i || !points_.IsCrease(p) || points_.InMesh(p, kOmegaMesh)) continue;
    absl::Status st = ForceInsertOmega(p, hint);
    if (!st.ok()) return st;
    const uint32_t v = points_.VertexIn(p, kOmegaMesh);
    if (v != PointStore::kNoVertex) hint = omega_.dt().VertexTet(VertexId(v));
  }
  return absl::OkStatus();
}

absl::Status Refiner::ForceInsertOmega(PointId p, TetId hint) {
  const int cd = points_.CdOf(p).dim;
  LinkChangeCount count(this, cd < 3 ? cd : kOmegaCd3Linked);
  delaunay::Delaunay3& dt = omega_.dt();
  const Vec3 pos = points_.Xyz(p);
  const auto result = dt.Insert(pos, p.value(), hint);
  if (result.outcome != delaunay::Delaunay3::InsertOutcome::kInserted) {
    // Duplicate input points were merged at Initialize and a warp target lying
    // in B is warped to rather than inserted next to, so a coincidence is a bug.
    const PointId q = omega_.PointOf(result.vertex);
    const Vec3 at = norm_.Backward(pos);
    return absl::InternalError(absl::StrCat("SVRC: point ", p.value(), " (CD ", CdToString(points_.CdOf(p)), ", feature ",
                                            points_.Parent(p).value(), ") coincides with point ", q.value(), " (CD ",
                                            CdToString(points_.CdOf(q)), ", feature ", points_.Parent(q).value(),
                                            ") of M_Ω at (", at.x, ", ", at.y, ", ", at.z, ")"));
  }
  ++stats_.insertions;
  // Before any new tet (some in these slots) is tested and enqueued.
  if (!tet_event_.empty()) DropDeadTetEvents(result.destroyed);
  const VertexId nv = result.vertex;
  omega_.AddVertex(nv, p);
  points_.SetVertex(p, kOmegaMesh, nv.value());
  // The point's own 0-ball is resolved in M_Ω: drop its links there.
  const BallId own = VertexBallOf(p);
  if (own.valid()) {
    blg_.RemoveObjectLinks(LocationObject::Ball(own), kOmegaMesh, nullptr);
    ErasePending(own);
  }
  // 𝒱 = cavity vertices, 𝒱' = 𝒱 ∪ {p}. Copy: the span points into Delaunay3
  // scratch, which later queries reuse.
  std::vector<VertexId>& changed = insert_changed_;
  changed.assign(result.cavity_vertices.begin(), result.cavity_vertices.end());
  changed.push_back(nv);
  for (VertexId u : changed) omega_.BumpCell(u);
  if (!tet_labels_.empty()) PropagateSizeTargets(result);

  // R_v, r_v of 𝒱' (Figure 3.5's loop), or a certificate that V(u) is
  // still good, without a star walk. cell_cert_[u] (set from u's last
  // Size()) says: every tet t of u's star has |cc(t) − u| ≤ τ·r_u and ≤ u's
  // size target (IsBad's test, which reads their maximum R_u), and R_u ≤ R.
  // After p's insertion V(u) only shrank (R_u ≤ R still; no vertex leaves
  // M_Ω), r_u = min(r_u, |up|/2) exactly (Lemma 3: the nearest point is a
  // Delaunay neighbour), the tets u kept passed the test with the old r_u,
  // and the new tets at u are p's (`created`). So V(u) is still good if
  // every new tet at u passes with the new r_u and, when r_u shrank,
  // R ≤ τ·r_u. The verdict is Size()'s own, bit for bit (the same doubles
  // |cc − u| and r_u), so the output does not change. Every other cell
  // gets Size(); a certified cell's links read R_u through bounds
  // (largest |cc − u| of its new tets ≤ R_u ≤ R) and fall back to Size()
  // only when the bounds do not decide a link.
  const std::span<const TetId> created_span = result.created;
  created_.assign(created_span.begin(), created_span.end());
  ++cert_stamp_;
  const size_t nvert = dt.NumVertices();
  if (cert_mark_.size() < nvert) {
    cert_mark_.resize(nvert + nvert / 2 + 16, 0);
    cert_pos_.resize(cert_mark_.size(), 0);
  }
  if (cell_cert_.size() < nvert) util::GrowExactly(cell_cert_, nvert + nvert / 2 + 16);
  for (size_t i = 0; i + 1 < changed.size(); ++i) {
    cert_mark_[changed[i].value()] = cert_stamp_;
    cert_pos_[changed[i].value()] = static_cast<uint32_t>(i);
  }
  // The new tets at each old cavity vertex u: their largest |cc − u| (+inf
  // if one of them is a ghost, flat, or has its circumcentre outside Ω), and
  // whether some / every one lies outside the output (labelled M_Ω, §8 item
  // 33): one voids u's certificate and memo, all keep u outside.
  new_at_.assign(changed.size(), OmegaMesh::NewTets{});
  for (TetId t : created_) {
    Vec3 cc;
    const bool plain = !dt.IsGhost(t) && omega_.PlainCorner(t, &cc);
    const bool outside = omega_.KnownOutside(t);
    for (int k = 0; k < 4; ++k) {
      const VertexId u = dt.TetVertex(t, k);
      if (u == nv || !u.valid() || u.value() >= nvert || cert_mark_[u.value()] != cert_stamp_) continue;
      new_at_[cert_pos_[u.value()]].Add(plain ? geom::Dist(cc, dt.Point(u)) : HUGE_VAL, outside);
    }
  }
  std::vector<CellSize>& sizes = insert_sizes_;
  sizes.assign(changed.size(), CellSize{});
  std::vector<uint8_t>& exact = insert_exact_;
  exact.assign(changed.size(), 1);
  auto set_size = [&](size_t i) {
    const VertexId u = changed[i];
    exact[i] = 1;
    const bool good = !sizes[i].saw_flat && !IsBad(u, sizes[i]);
    const bool plain = !sizes[i].clipped && good;
    // A clipped cell whose kept corner comes from plain kept tets is
    // certified over them as an unclipped one (cube --max-volume 1e-4: 3,319
    // clipped Size() calls, 258 cells next to the output's boundary whose
    // exterior tets reach past Ω, degree ~12).
    const bool kept_plain = !sizes[i].clipped || sizes[i].kept_from_star;
    cell_cert_[u.value()] = {sizes[i].inradius,
                             sizes[i].outradius,
                             plain && !sizes[i].outside_tets,
                             sizes[i].outside_tets && sizes[i].kept_outradius == 0,
                             good && kept_plain && sizes[i].outside_tets && sizes[i].kept_outradius > 0,
                             sizes[i].clipped,
                             sizes[i].kept_outradius};
  };
  auto exact_size = [&](size_t i) {
    sizes[i] = omega_.Size(changed[i]);
    set_size(i);
  };
  for (size_t i = 0; i < changed.size(); ++i) {
    const VertexId u = changed[i];
    if (i + 1 < changed.size() && options_.certify_cells) {
      // Exact without a star walk when u's farthest corner survived (this
      // also keeps u's memo current for the next insertion next to it).
      if (omega_.ShrunkSize(u, pos, new_at_[i], &sizes[i])) {
        set_size(i);
        continue;
      }
      CellCert& cert = cell_cert_[u.value()];
      const double r = std::min(cert.inradius, 0.5 * std::sqrt(geom::Dist2(dt.Point(u), pos)));
      // A cell outside the output stays outside while its new tets are: it
      // is never bad (IsBad reads the kept corners), and its links read R_u
      // through the bounds (its last R_u ≥ R_u now). Sizing it exactly would
      // clip its Voronoi cell, and the cells next to ∂Ω have hundreds of
      // neighbours (cube 1e-5: degree up to 1261; 40% of the CPU).
      if (cert.exterior && new_at_[i].all_outside) {
        cert.inradius = r;
        exact[i] = 0;
        ++stats_.sizes_outside;
        continue;
      }
      if (cert.valid && !new_at_[i].outside) {
        const double m = new_at_[i].corner;
        if (!(m > CellTau() * r) && !AboveSizeTarget(u, m) &&
            (r == cert.inradius || !(cert.outradius > CellTau() * r))) {
          cert.inradius = r;
          exact[i] = 0;
          ++stats_.sizes_certified;
          continue;
        }
      }
      // A cell next to the output's boundary (some star tets outside it,
      // some not): the same certificate over its kept tets. Its kept tets
      // are the survivors not known outside (|cc − u| ≤ cert.kept) and the
      // new ones not known outside (≤ kept_corner), so its kept corner is
      // at most their maximum m, and V(u) is good if m passes IsBad's test.
      // Every new tet plain and within R keeps R_u ≤ R and the cell
      // unclipped and without flat tets, as Size() would find it; a kept new
      // tet keeps the cell from turning exterior (cert.exterior is only
      // ever Size()'s). On cube --max-volume 1e-4 these were 12,980 of the
      // 16,581 Size() calls for old cavity vertices (session 41).
      // A clipped cell: V(u) ∩ Ω only shrank (R_u ≤ R whatever the new tets);
      // a new tet outside keeps its kept corner read from its kept tets, and
      // a kept new tet that is not plain makes m infinite.
      if (cert.partial && !new_at_[i].all_outside &&
          (cert.clipped ? new_at_[i].outside : new_at_[i].corner <= cert.outradius)) {
        const double m = std::max(cert.kept, new_at_[i].kept_corner);
        if (!(m > CellTau() * r) && !AboveSizeTarget(u, m)) {
          cert.inradius = r;
          cert.kept = m;
          exact[i] = 0;
          ++stats_.sizes_certified;
          ++stats_.sizes_certified_partial;
          if (cert.clipped) ++stats_.sizes_certified_clipped;
          continue;
        }
      }
    }
    exact_size(i);
  }
  // UpdateLocation (3.6) for F = Ω: no new ConfBalls; re-intersect the lower
  // ConfBalls of the old cells with the new cells. A point in V_old(u) is in
  // V_new(u) or V_new(p): one exact distance comparison (ties: the lower
  // global id, as the perturbation). A ball of radius r meets V(x) only if
  // |xc| ≤ r + R_x (V(x) ⊂ B(x, R_x)): a conservative test over 𝒱'.
  ++ball_stamp_;
  if (ball_mark_.size() < balls_.size()) ball_mark_.resize(balls_.size() + 64, 0);
  // The old cells only shrink (V_new(u) ⊂ V_old(u)), so their links are
  // filtered in place: a 0-ball whose point is now nearer to p moves to p's
  // cell, a lower ball that no longer passes the test goes; the others stay
  // (before session 9 every link of every changed cell was removed and added
  // again: ~140 link operations per insertion on cube.poly --max-volume 1e-5).
  // V(p) ⊂ ∪ V_old(u), so every ball meeting V(p) was linked to some u: p's
  // cell gets the lower balls of 𝒱 that pass the test.
  std::vector<BallId>& moved_pieces = insert_moved_;
  moved_pieces.clear();
  // Not on the collar path: its outputs follow the order of the Encroached
  // events closely (§8 item 37), and that path keeps its measured order.
  const bool bisector_filter = options_.bisector_link_filter && !options_.collars;
  for (size_t i = 0; i + 1 < changed.size(); ++i) {
    const VertexId u = changed[i];
    const Vec3& pu = dt.Point(u);
    // V_new(u) lies in the half-space of points nearer to u than to the new
    // point, which B(c, r) meets only if the signed distance from c to their
    // bisector, (|uc|² − |pc|²) / (2|up|), is at most r: a ball the insertion
    // put wholly on the new point's side leaves u whatever R_u is (cells
    // reaching into Ω's coarse exterior keep R_u large; §8 item 37). The
    // slack keeps rounding on the side of keeping the link, as
    // CellsMeetingBall's.
    const double up = bisector_filter ? geom::Dist(pu, pos) : 0;
    auto beyond_bisector = [&](BallId b) {
      const Vec3& c = balls_.Center(b);
      const double uc2 = geom::Dist2(pu, c);
      return BallBeyondBisector(uc2, geom::Dist2(pos, c), up, balls_.Radius(b), uc2);
    };
    auto piece_meets = [&](BallId b) {
      if (bisector_filter && beyond_bisector(b)) return false;
      const double d = geom::Dist(pu, balls_.Center(b));
      if (!exact[i]) {
        // Certified cell: new_at_[i].corner ≤ R_u ≤ cell_cert_[u].outradius
        // (a clipped one: the plain new corners ≤ R_u).
        const CellCert& cert = cell_cert_[u.value()];
        const double lower = cert.partial && cert.clipped ? new_at_[i].plain_corner : new_at_[i].corner;
        if (d <= (balls_.Radius(b) + lower) * (1 + 1e-9)) return true;
        if (!(d <= (balls_.Radius(b) + cell_cert_[u.value()].outradius) * (1 + 1e-9))) return false;
        // Outside the output: keep the link (location may be inflated,
        // guide §3) rather than clip the cell.
        if (cell_cert_[u.value()].exterior) return true;
        exact_size(i);
        ++stats_.sizes_uncertified;
      }
      return d <= (balls_.Radius(b) + sizes[i].outradius) * (1 + 1e-9);
    };
    auto nearer_to_new = [&](BallId b) {
      const int cmp = geom::CompareDistance(balls_.Center(b), pu, pos);  // > 0: u is farther
      return cmp > 0 || (cmp == 0 && p.value() < omega_.PointOf(u).value());
    };
    FilterShrunkCell(kOmegaMesh, u.value(), nv.value(), &moved_pieces, piece_meets, nearer_to_new);
  }
  const size_t inew = changed.size() - 1;
  // With the filter, newest ball first (descending BallStore::Seq): the new cell's links
  // (and the Encroached events AddBallLink enqueues, FIFO in their bucket)
  // then come in an order that does not depend on which old cells still
  // held each ball. Of the orders measured, newest first gave the fewest
  // tets (§8 item 37).
  if (bisector_filter) {
    std::sort(moved_pieces.begin(), moved_pieces.end(),
              [this](BallId a, BallId b) { return balls_.Seq(b) < balls_.Seq(a); });
  }
  // V(p) is the intersection of the half-spaces nearer to p than to each
  // cavity vertex (its Delaunay neighbours): a ball beyond one of those
  // bisectors misses it (§8 item 57; without collars, as CellsMeetingBall).
  const bool tight = options_.tight_ball_cells && !options_.collars;
  auto misses_new_cell = [&](BallId b) {
    const Vec3& c = balls_.Center(b);
    const double pc2 = geom::Dist2(pos, c);
    for (size_t i = 0; i < inew; ++i) {
      const Vec3& pu = dt.Point(changed[i]);
      if (BallBeyondBisectorOf(pc2, geom::Dist2(pu, c), pos, pu, balls_.Radius(b), pc2)) return true;
    }
    return false;
  };
  for (BallId b : moved_pieces) {
    if (geom::Dist(pos, balls_.Center(b)) <= (balls_.Radius(b) + sizes[inew].outradius) * (1 + 1e-9) &&
        !(tight && misses_new_cell(b))) {
      AddBallLink(nv, b);
    }
  }
  // Figure 3.5's loop over 𝒱': DecreaseSize / enqueue Skinny and Unresolved.
  // A certified cell gets no event (any queued one is stale: BumpCell above).
  // A certified cell still holding an unresolved 0-ball needs its exact
  // farthest corner and R_v for the Unresolved event.
  for (size_t i = 0; i < changed.size(); ++i) {
    if (!exact[i] && blg_.NumUnresolved(kOmegaMesh, changed[i].value()) > 0) {
      exact_size(i);
      ++stats_.sizes_uncertified;
    }
    if (exact[i]) {
      RefreshEvents(changed[i], &sizes[i]);
    } else {
      // RefreshEvents of a good cell without unresolved 0-balls: its queued
      // events go (a stale handle left queued would be refreshed in place
      // later and keep its old place in its bucket; measured with the
      // Unresolved event on segment_fan.poly, CollarRefine test).
      EventHandle& ue = omega_.UnresolvedEvent(changed[i]);
      if (queues_.IsQueued(ue)) queues_.Remove(ue);
      EventHandle& ke = omega_.SkinnyEvent(changed[i]);
      if (queues_.IsQueued(ke)) queues_.Remove(ke);
    }
  }
  if (tet_mode_ && !skinny_deferred_ && (collar_tets_ || !tet_labels_.empty())) {
    for (TetId t : created_) EnqueueTetIfBad(t);
  }
  // Figure 3.5 lines 5–7: a crease point from a lower feature gets its collar.
  if (options_.collars && points_.IsCrease(p) && points_.CdOf(p).dim < 3) return CreateCollar(p, nv);
  return absl::OkStatus();
}

bool Refiner::TetBad(TetId t, Vec3* cc, double* radius) const {
  const delaunay::Delaunay3& dt = omega_.dt();
  if (dt.IsGhost(t)) return false;
  const TetLabel* lab = LiveLabel(t);
  // The unlabelled collar path tests every tet, except those next to a
  // crease (a crease vertex) and those the stitch replaces (below).
  const bool unlabelled = collar_tets_ && lab == nullptr;
  if (unlabelled) {
    for (int k = 0; k < 4; ++k) {
      if (points_.IsCrease(omega_.PointOf(dt.TetVertex(t, k)))) return false;
    }
  } else if (lab == nullptr || !lab->kept()) {
    return false;
  }
  if (!omega_.PlainCorner(t, cc)) return false;
  // RipStitchCollar empties the tets whose circumcentre is strictly inside
  // the collars (rip_stitch.h, step 1); every other tet stays in its output.
  if (unlabelled && collars_.StrictlyInside(*cc)) return false;
  std::array<Vec3, 4> q;
  for (int k = 0; k < 4; ++k) q[k] = dt.Point(dt.TetVertex(t, k));
  const double r = geom::Dist(*cc, q[0]);
  double l2 = HUGE_VAL;
  for (int a = 0; a < 4; ++a) {
    for (int b = a + 1; b < 4; ++b) l2 = std::min(l2, geom::Dist2(q[a], q[b]));
  }
  *radius = r;
  const double rho = 0.5 * options_.tau;
  if (r * r > rho * rho * l2) return true;
  if (!tet_sizes_) return false;  // never set on the collar path (SetSizeTargets)
  if (options_.tet_volumes) {
    // The bound itself, with a relative margin of 1e-9 for the rounding of
    // this determinant and of the back map to input coordinates (the
    // output's volumes are computed there).
    const double volume = ClassOf(*lab).volume;
    if (volume == HUGE_VAL) return false;
    return Volume6(q) > 6.0 * volume * (1 - 1e-9);
  }
  return r > ClassOf(*lab).target;
}

std::optional<uint32_t> Refiner::LabelClassOf(double target, double volume) {
  const auto it = label_class_index_.find({target, volume});
  if (it != label_class_index_.end()) return it->second;
  if (label_classes_.size() > TetLabel::kClassMask) return std::nullopt;
  const uint32_t c = static_cast<uint32_t>(label_classes_.size());
  label_classes_.push_back({target, volume});
  label_class_index_.emplace(std::make_pair(target, volume), c);
  return c;
}

bool Refiner::EnqueueTetIfBad(TetId t) {
  Vec3 cc;
  double r = 0;
  if (!TetBad(t, &cc, &r)) return false;
  const EventHandle h =
      queues_.Enqueue({EventType::kSkinny, 3, kOmegaMesh, t.value() | kTetEvent, omega_.dt().Generation(t), r});
  if (h.valid() && options_.drop_dead_tet_events) {
    util::GrowExactly(tet_event_, omega_.dt().TetCapacity(), kNoTetEvent);  // one per slot, as the tets
    tet_event_[t.value()] = h.id.value();
  }
  return true;
}

void Refiner::DropDeadTetEvents(std::span<const TetId> destroyed) {
  for (TetId d : destroyed) {
    if (d.value() >= tet_event_.size() || tet_event_[d.value()] == kNoTetEvent) continue;
    queues_.RemoveObjectEvent(EventId(tet_event_[d.value()]), kOmegaMesh, d.value() | kTetEvent);
    tet_event_[d.value()] = kNoTetEvent;
  }
}

// max_volume between size rounds: without it a vertex inserted after a
// round's labelling has no target until the next round labels it, and the
// rounds refine in waves (cube.poly --max-volume 1e-5: 6 labellings of the
// whole M_Ω, each finding the previous round's new vertices). The mesh
// conforms to the facets between insertions, so every tet lies in one
// region, and a new tet lies on the same side of every facet as the
// destroyed tet whose cavity-boundary face it was built on (it is that
// face's cone from the new point, inside the cavity): it gets that tet's
// region target, and its vertices the smallest target of their new tets
// (SetSizeTargets' rule). A tet built on a tet without a label (a ghost, or
// one built on such a tet since) gets none, and the next round labels it.
// The rounds still end only when a labelling finds no vertex above its
// target, so this changes how fast they converge, not what they guarantee.
void Refiner::PropagateSizeTargets(const delaunay::Delaunay3::InsertResult& inserted) {
  const delaunay::Delaunay3& dt = omega_.dt();
  const size_t n = inserted.created.size();
  if (inserted.created_on.size() != n) return;
  // Read every base before writing: the new tets reuse the cavity's slots.
  created_labels_.assign(n, TetLabel{});
  for (size_t k = 0; k < n; ++k) {
    const TetId d(inserted.created_on[k] >> 2);
    // Freed once by this insertion: Generation moved one past its live value.
    if (d.value() < tet_labels_.size() && tet_labels_[d.value()].gen != 0 &&
        tet_labels_[d.value()].gen == dt.Generation(d)) {
      created_labels_[k] = tet_labels_[d.value()];
    }
  }
  if (tet_labels_.size() < dt.TetCapacity()) util::GrowExactly(tet_labels_, dt.TetCapacity());
  if (size_target_.size() < dt.NumVertices()) util::GrowExactly(size_target_, dt.NumVertices() + dt.NumVertices() / 2 + 16, HUGE_VAL);
  for (size_t k = 0; k < n; ++k) {
    const TetId c = inserted.created[k];
    const bool known = created_labels_[k].gen != 0;
    const double target = ClassOf(created_labels_[k]).target;
    tet_labels_[c.value()] = TetLabel::Make(known ? dt.Generation(c) + 1 : 0, created_labels_[k].kept(),
                                            created_labels_[k].label_class());
    if (!known || target == HUGE_VAL || dt.IsGhost(c) || tet_sizes_) continue;
    for (int i = 0; i < 4; ++i) {
      const uint32_t v = dt.TetVertex(c, i).value();
      if (target < size_target_[v]) {
        size_target_[v] = target;
        // A certificate proved the old star within the old target only.
        if (v < cell_cert_.size()) cell_cert_[v].valid = cell_cert_[v].partial = false;
        ++stats_.size_targets_propagated;
      }
    }
  }
}

absl::Status Refiner::ForceInsertSegment(uint32_t seg, uint32_t u, double t, Cd cd) {
  LinkChangeCount count(this, kSegmentMesh);
  SegmentMesh& m = segs_[seg];
  const uint32_t w = m.Next(u);
  const FeatureId f = features_.OfSegment(seg);
  const MeshId mesh = SegMesh(seg);
  const PointId p = points_.Add(m.PointAt(t), f, cd, options_.collars && complex_->segments[seg].crease);
  const uint32_t mid = m.Split(u, t, p);
  points_.SetVertex(p, mesh, mid);
  ++stats_.segment_vertices;
  // UpdateLocation (3.6) in M_s: the old piece uw dies (its links in M_Ω go),
  // the new simplices at 𝒱' = {u, mid, w} with |T| = dim F + 1 = 2 (pieces)
  // or |T| = 1 (mid's 0-ball) become ConfBalls (the endpoints' 0-balls do not
  // change: one ball per global point).
  const BallId old_piece = m.PieceBall(u);
  std::vector<uint32_t> old_cells;
  balls_.Kill(old_piece);
  std::vector<TriId2> facet_hint(seg_facets_[seg].size());
  for (size_t i = 0; i < seg_facets_[seg].size(); ++i) {
    const uint32_t fc = seg_facets_[seg][i];
    blg_.RemoveObjectLinks(LocationObject::Ball(old_piece), FacetMeshId(fc), &old_cells);
    if (!old_cells.empty()) facet_hint[i] = facets_[fc].dt().VertexTri(VertexId2(old_cells[0]));
    old_cells.clear();
  }
  blg_.RemoveObjectLinks(LocationObject::Ball(old_piece), kOmegaMesh, &old_cells);
  const BallId left = balls_.AddPieceBall(m.PointOf(u), p, points_.Xyz(m.PointOf(u)), points_.Xyz(p), f, mesh);
  const BallId right = balls_.AddPieceBall(p, m.PointOf(w), points_.Xyz(p), points_.Xyz(m.PointOf(w)), f, mesh);
  const BallId vb = balls_.AddVertexBall(p, points_.Xyz(p), f, mesh, cd);
  m.PieceBall(u) = left;
  m.PieceBall(mid) = right;
  m.VertexBall(mid) = vb;
  SetVertexBall(p, vb);
  if (piece_vertex_.size() < balls_.size()) {
    piece_vertex_.resize(balls_.size());
    piece_seg_.resize(balls_.size());
  }
  piece_vertex_[left.value()] = u;
  piece_vertex_[right.value()] = mid;
  piece_seg_[left.value()] = piece_seg_[right.value()] = seg;
  // PropagateLocation (3.9) to the superfeatures: the facets containing the
  // segment, then M_Ω. New objects are located by a search from the old
  // piece's cells.
  for (size_t i = 0; i < seg_facets_[seg].size(); ++i) {
    const uint32_t fc = seg_facets_[seg][i];
    LinkPieceToFacet(left, fc, facet_hint[i]);
    LinkPieceToFacet(right, fc, facet_hint[i]);
    LinkVertexBallToFacet(vb, fc, facet_hint[i]);
  }
  const VertexId start = old_cells.empty() ? VertexId(0) : VertexId(old_cells[0]);
  LinkBallToOmega(left, start);
  LinkBallToOmega(right, start);
  LinkVertexBallToOmega(vb, start);
  // 𝒱 = {u, w} changed, 𝒱' = {u, mid, w}: Skinny₁ refresh (Figure 3.5).
  m.BumpCell(u);
  m.BumpCell(w);
  RefreshSegmentEvents(seg, u);
  RefreshSegmentEvents(seg, mid);
  RefreshSegmentEvents(seg, w);
  return absl::OkStatus();
}

absl::Status Refiner::ForceInsertFacet(uint32_t f, PointId p, Vec2 uv, TriId2 hint) {
  LinkChangeCount count(this, kFacetMesh);
  FacetMesh& m = facets_[f];
  const MeshId mesh = FacetMeshId(f);
  const delaunay::Delaunay2::InsertResult r = m.Insert(uv, p, hint);
  if (r.outcome != delaunay::Delaunay2::InsertOutcome::kInserted) {
    std::string detail = " (outside Ω_F)";
    if (r.outcome == delaunay::Delaunay2::InsertOutcome::kDuplicate) {
      const PointId q = m.PointOf(m.dt().NearestVertex(uv, hint));
      detail = absl::StrCat(" (coincides with point ", q.value(), "; CD ", points_.CdOf(p).dim, ",",
                            points_.CdOf(p).collar, " and ", points_.CdOf(q).dim, ",", points_.CdOf(q).collar,
                            ", parents ", points_.Parent(p).value(), " and ", points_.Parent(q).value(), ")");
    }
    // With collars, a facet refined next to a crease down to the resolution
    // of doubles (two gap-ball centres rounding to one point; measured on
    // wedge-1.smesh, 1°) is a limit of this implementation, not a bug.
    if (options_.collars && r.outcome == delaunay::Delaunay2::InsertOutcome::kDuplicate) {
      return absl::FailedPreconditionError(absl::StrCat("SVRC: facet mesh ", f, " was refined to the resolution of ",
                                                        "doubles next to a crease", detail));
    }
    return absl::InternalError(
        absl::StrCat("SVRC: point ", p.value(), " could not be inserted into facet mesh ", f, detail));
  }
  const bool steiner = points_.Parent(p) == features_.OfFacet(f);  // created by this mesh
  if (steiner) ++stats_.facet_vertices;
  const VertexId2 nv = r.vertex;
  points_.SetVertex(p, mesh, nv.value());
  // A segment point: tell M_F which of its segments it lies on (InFacet).
  if (features_.Dim(points_.Parent(p)) == 1) {
    const uint32_t seg = features_.Index(points_.Parent(p));
    const auto& ids = m.region().segment_ids;
    for (size_t k = 0; k < ids.size(); ++k) {
      if (ids[k] == seg) m.SetOnSegment(nv, static_cast<int32_t>(k));
    }
  }
  // Copies: the spans point into Delaunay2 scratch.
  std::vector<VertexId2> changed(r.cavity_vertices.begin(), r.cavity_vertices.end());
  changed.push_back(nv);
  const std::vector<TriId2> created(r.created.begin(), r.created.end());
  // UpdateLocation (3.6) (b)/(d): the triangle balls of destroyed in-facet
  // triangles die (unlinked from M_Ω), the new in-facet triangles get balls.
  std::vector<BallId> killed;
  m.SyncTriangleBalls(r, frames_[f], features_.OfFacet(f), mesh, &balls_, nullptr, &killed);
  std::vector<uint32_t> omega_cells;
  for (BallId b : killed) blg_.RemoveObjectLinks(LocationObject::Ball(b), kOmegaMesh, omega_cells.empty() ? &omega_cells : nullptr);
  // p's own 0-ball is resolved in M_F.
  const BallId own = VertexBallOf(p);
  if (own.valid()) blg_.RemoveObjectLinks(LocationObject::Ball(own), mesh, nullptr);
  std::vector<CellSize2> sizes(changed.size());
  for (size_t i = 0; i < changed.size(); ++i) sizes[i] = m.Size(changed[i]);
  // (c): re-link the lower balls of the old cells to the new cells.
  ++ball_stamp_;
  if (ball_mark_.size() < balls_.size()) ball_mark_.resize(balls_.size() + 64, 0);
  // As in ForceInsertOmega: the shrunk old cells keep their surviving links
  // in place; the new cell gets the 0-balls now nearer to p and the pieces
  // of 𝒱 that pass the test.
  std::vector<BallId> moved_pieces;
  const delaunay::Delaunay2& dt = m.dt();
  auto piece_meets = [&](BallId b, const Vec2& x, double outradius) {
    const Vec2 a = Uv(f, balls_.Vertex(b, 0)), c = Uv(f, balls_.Vertex(b, 1));
    const Vec2 mid{0.5 * (a.x + c.x), 0.5 * (a.y + c.y)};
    const double rad = 0.5 * std::hypot(a.x - c.x, a.y - c.y);
    return std::hypot(x.x - mid.x, x.y - mid.y) <= (rad + outradius) * (1 + 1e-9);
  };
  for (size_t i = 0; i + 1 < changed.size(); ++i) {
    const VertexId2 u = changed[i];
    const Vec2 pu = dt.Point(u);
    FilterShrunkCell(
        mesh, u.value(), nv.value(), &moved_pieces, [&](BallId b) { return piece_meets(b, pu, sizes[i].outradius); },
        [&](BallId b) {
          const int cmp = geom::CompareDistance(Uv(f, balls_.VertexPoint(b)), pu, uv);  // > 0: u is farther
          return cmp > 0 || (cmp == 0 && p.value() < m.PointOf(u).value());
        });
  }
  const size_t inew = changed.size() - 1;
  for (BallId b : moved_pieces) {
    if (piece_meets(b, dt.Point(nv), sizes[inew].outradius)) AddFacetPieceLink(f, nv, b);
  }
  const VertexId start = omega_cells.empty() ? VertexId(0) : VertexId(omega_cells[0]);
  // (b): a point M_F created inside (the closure of) F gets a 0-ball, which
  // PropagateLocation hands to M_Ω, where it is unresolved until inserted;
  // points of Ω_F outside F stay scaffolding of M_F (Figure 3.6, "kept if
  // dim(T ∩ F) = dim T").
  if (steiner && m.region().Locate(uv) != FacetRegion::Where::kOutside) {
    const BallId vb = balls_.AddVertexBall(p, points_.Xyz(p), features_.OfFacet(f), mesh, points_.CdOf(p));
    SetVertexBall(p, vb);
    LinkVertexBallToOmega(vb, start);
  }
  AdoptTriangleBalls(f, created, start);
  // Figure 3.5's loop over 𝒱'.
  for (size_t i = 0; i < changed.size(); ++i) RefreshFacetEvents(f, changed[i], &sizes[i]);
  return absl::OkStatus();
}

// ---------------------------------------------------------------- collars

bool Refiner::FeatureContains(FeatureId f, PointId p) const {
  const int d = features_.Dim(f);
  if (d == 3) return true;
  const uint32_t idx = features_.Index(f);
  const FeatureId parent = points_.Parent(p);
  const int pd = features_.Dim(parent);
  if (pd == 0) {
    const uint32_t i = features_.Index(parent);
    if (d == 0) return idx == i;
    if (d == 1) return complex_->segments[idx].a == i || complex_->segments[idx].b == i;
    const auto& fs = point_facets_[i];
    return std::find(fs.begin(), fs.end(), idx) != fs.end();
  }
  if (pd == 1) {
    const uint32_t sg = features_.Index(parent);
    if (d == 1) return idx == sg;
    if (d == 2) {
      const auto& fs = seg_facets_[sg];
      return std::find(fs.begin(), fs.end(), idx) != fs.end();
    }
    return false;
  }
  if (pd == 2) return d == 2 && features_.Index(parent) == idx;
  return false;
}

double Refiner::FeatureDistance(FeatureId f, PointId p, const Vec3& x) const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const int d = features_.Dim(f);
  if (d == 3 || FeatureContains(f, p)) return kInf;
  const uint32_t idx = features_.Index(f);
  if (d == 0) return geom::Dist(x, points_.Xyz(PointId(idx)));
  if (d == 1) {
    const plc::FeatureSegment& sg = complex_->segments[idx];
    return plc::PointSegmentDistance(x, points_.Xyz(PointId(sg.a)), points_.Xyz(PointId(sg.b)));
  }
  return FacetDistance(idx, x);
}

double Refiner::FacetDistance(uint32_t idx, const Vec3& x) const {
  // Its plane if x projects into the facet, else its nearest segment (every
  // polygon edge is a segment of the complex).
  const plc::FacetFrame& fr = frames_[idx];
  if (facets_[idx].region().Locate(fr.ToPlane(x)) != FacetRegion::Where::kOutside) {
    return std::abs(geom::Dot(x - fr.origin, fr.normal));
  }
  double best = std::numeric_limits<double>::infinity();
  for (uint32_t sg : complex_->facets[idx].segments) {
    const plc::FeatureSegment& fs = complex_->segments[sg];
    best = std::min(best, plc::PointSegmentDistance(x, points_.Xyz(PointId(fs.a)), points_.Xyz(PointId(fs.b))));
  }
  return best;
}

double Refiner::FacetGapOnSphere(const Vec3& x, uint32_t ball) const {
  // How far apart the facets through the ball's centre are at x (on its
  // sphere): the sum of x's two smallest distances to them (x's own facet
  // counts 0); infinity with fewer than two.
  double d0 = std::numeric_limits<double>::infinity(), d1 = d0;
  for (uint32_t idx : FacetsThrough(collar_centre_[ball])) {
    const double d = FacetDistance(idx, x);
    if (d < d0) {
      d1 = d0;
      d0 = d;
    } else if (d < d1) {
      d1 = d;
    }
  }
  return d0 + d1;
}

bool Refiner::Suppressed(PointId p) {
  if (!options_.collars || collars_.size() == 0 || points_.IsCrease(p)) return false;
  if (points_.CdOf(p).collar < 3) return false;  // constructed on S: resolved (Definition 37)
  if (p.value() < suppressed_.size() && suppressed_[p.value()]) return true;
  if (!collars_.StrictlyInside(points_.Xyz(p))) return false;
  if (suppressed_.size() <= p.value()) suppressed_.resize(p.value() + 1024, 0);
  suppressed_[p.value()] = 1;
  ++stats_.suppressed_points;
  return true;
}

bool Refiner::InsideCollars(std::span<const PointId> verts) const {
  if (collars_.size() == 0) return false;
  Vec3 c{0, 0, 0};
  for (PointId v : verts) {
    const Vec3& x = points_.Xyz(v);
    // A point constructed on S (collar dimension < 3) is on S even when its
    // rounding put it strictly inside.
    if (points_.CdOf(v).collar == 3 && collars_.StrictlyInside(x)) return true;
    c = c + x;
  }
  return collars_.StrictlyInside(c * (1.0 / static_cast<double>(verts.size())));
}

absl::Status Refiner::CreateCollar(PointId p, VertexId nv) {
  if (has_collar_.size() <= p.value()) has_collar_.resize(p.value() + 1024, 0);
  if (has_collar_[p.value()]) return absl::OkStatus();  // one collar per point (guide §7)
  has_collar_[p.value()] = 1;
  const delaunay::Delaunay3& dt = omega_.dt();
  const Vec3 pos = points_.Xyz(p);
  // A crease point strictly inside a collar (of its own crease, Lemma 13) is
  // already protected; a ball of its own would sit inside that one, off the
  // collar surface, and break the chain of consecutive balls RipStitchCollar
  // builds books from (measured on crease_pair_30: the vertex collar crossed
  // the ball of a non-adjacent crease point).
  const bool point_12 = points_.CdOf(p).dim == 1 && points_.CdOf(p).collar == 2;
  if (!(p.value() < neck_point_.size() && neck_point_[p.value()]) && collars_.StrictlyInside(pos)) {
    ++stats_.collars_skipped_inside;
    if (point_12) {
      // On a vertex collar's sphere by construction: inside another ball
      // means two creases' balls overlap (Lemma 13 broken by the estimate).
      ++stats_.points_12_without_ball;
      if (std::getenv("SVRC_COLLAR_DEBUG") != nullptr) {
        const uint32_t in = collars_.FindContaining(pos);
        const FeatureId fi = points_.Parent(collar_centre_[in]);
        std::fprintf(stderr,
                     "(1,2) point %u (segment %u) at (%.17g %.17g %.17g) strictly inside ball %u (dim %d idx %u, "
                     "centre (%.17g %.17g %.17g) r %.17g): no ball\n",
                     p.value(), features_.Index(points_.Parent(p)), pos.x, pos.y, pos.z, in, features_.Dim(fi),
                     features_.Index(fi), collars_.ball(in).center.x, collars_.ball(in).center.y,
                     collars_.ball(in).center.z, collars_.ball(in).radius);
      }
    }
    return absl::OkStatus();
  }
  // Figure 3.8 over M_Ω (guide: only M_Ω sees every feature's balls). A
  // cell's features: those of its linked ConfBalls (pieces, triangles,
  // unresolved points) and its own vertex's feature (resolved points have no
  // links left in M_Ω).
  std::vector<BallId> cell_balls;
  auto cell_features = [&](VertexId u, std::vector<uint32_t>* out) {
    cell_balls.clear();
    blg_.BallsOf(kOmegaMesh, u.value(), &cell_balls);
    for (BallId b : cell_balls) out->push_back(balls_.Feature(b).value());
    const FeatureId own = points_.Parent(omega_.PointOf(u));
    if (features_.Dim(own) < 3) out->push_back(own.value());
  };
  auto feature_distance = [&](uint32_t f, const Vec3& x) { return FeatureDistance(FeatureId(f), p, x); };
  const CollarSizeResult g = FastCollarSize(dt, pos, nv, cell_features, feature_distance);
  stats_.collar_cells_explored += g.cells_explored;
  stats_.max_collar_cells = std::max<uint64_t>(stats_.max_collar_cells, g.cells_explored);
  if (!std::isfinite(g.radius) || !(g.radius > 0)) {
    if (point_12) ++stats_.points_12_without_ball;
    return absl::OkStatus();
  }
  // The cells the ball may reach (a little beyond g/3: see the shell below).
  std::vector<VertexId> cells;
  CellsMeetingBall(pos, g.radius * (1 + kCollarShellGap), nv, &cells);
  std::vector<std::pair<uint32_t, std::vector<VertexId2>>> facet_cells;
  for (uint32_t f : FacetsThrough(p)) {
    const Vec2 uv = Uv(f, p);
    const VertexId2 w = facets_[f].dt().NearestVertex(uv);
    facet_cells.emplace_back(f, std::vector<VertexId2>());
    CellsMeetingDisk(f, uv, g.radius * (1 + kCollarShellGap), w, &facet_cells.back().second);
  }
  // No vertex within kCollarShellGap·ρ of the new sphere: the radius steps
  // down from g/3 until none is (Lemma 13 only needs ρ <= g/3). A vertex
  // that close to S makes the COLLAR rounds chase RepBalls far below the
  // collar's radius. It happens by construction, not by chance: a neck
  // split's ball has its neighbours' radius, and its centre (their
  // midpoint) lies where an earlier segment vertex's Voronoi edge put an
  // arc point of one neighbour's sphere on a facet, so the new sphere passed
  // 1.4e-7 ρ from that arc point; facet refinement then split the two down
  // to 1e-7 ρ and the rounds stopped at the RepBall floor (random_plcs.py
  // prism 19 and 23).
  std::vector<double> shell;  // |x - centre| / (g/3) of the vertices near the sphere
  auto consider = [&](const Vec3& x) {
    const double s = geom::Dist(x, pos) / g.radius;
    if (std::abs(s - 1) < (kCollarShellSteps + 1) * kCollarShellGap) shell.push_back(s);
  };
  for (VertexId u : cells) consider(dt.Point(u));
  for (const auto& [f, fc] : facet_cells) {
    for (VertexId2 u : fc) consider(points_.Xyz(facets_[f].PointOf(u)));
  }
  double rho = g.radius;
  for (int k = 0; k <= kCollarShellSteps; ++k) {
    const double s0 = 1 - k * kCollarShellGap;
    if (std::all_of(shell.begin(), shell.end(), [&](double s) { return std::abs(s - s0) >= kCollarShellGap; })) {
      rho = g.radius * s0;
      if (k > 0) ++stats_.collar_radii_stepped;
      break;
    }
  }
  collars_.Add(CollarBall{pos, rho});
  collar_centre_.push_back(p);
  ++stats_.collars;
  const bool vertex_collar = features_.Dim(points_.Parent(p)) == 0;
  if (vertex_collar) ++stats_.vertex_collars;

  // Figure 3.9: unresolved points now strictly inside the collar are dropped
  // (their links go; Suppressed() keeps them out from now on). M_Ω first.
  // Unlinks the 0-balls of cell u of `mesh` that are now suppressed; returns
  // whether any was (the cell's events need a refresh).
  std::vector<LocationObject> objs;
  auto drop_suppressed = [&](MeshId mesh, uint32_t u) {
    objs.clear();
    blg_.ObjectsOf(mesh, u, &objs);
    bool changed = false;
    for (const LocationObject& o : objs) {
      if (o.kind != ObjectKind::kBall || !balls_.IsVertexBall(BallId(o.id))) continue;
      const PointId q = balls_.VertexPoint(BallId(o.id));
      if (points_.InMesh(q, mesh) || !Suppressed(q)) continue;
      blg_.RemoveLink(mesh, u, o);
      changed = true;
    }
    return changed;
  };
  for (VertexId u : cells) {
    if (drop_suppressed(kOmegaMesh, u.value())) RefreshEvents(u);
  }
  // The facets through p: the collar's disk in each facet mesh.
  for (const auto& [f, fc] : facet_cells) {
    for (VertexId2 u : fc) {
      if (drop_suppressed(FacetMeshId(f), u.value())) RefreshFacetEvents(f, u);
    }
  }
  // Figure 3.7 line 10: every segment at a vertex collar gets the (1,2) point
  // where the collar sphere crosses it, inserted into M_s (the Unresolved₁
  // event destroyed at once: M_s has no other work on it).
  if (vertex_collar) {
    const uint32_t i = features_.Index(points_.Parent(p));
    for (uint32_t sg : point_segments_[i]) {
      SegmentMesh& m = segs_[sg];
      const double len = geom::Dist(points_.Xyz(m.PointOf(0)), points_.Xyz(m.PointOf(1)));
      if (!(rho < len)) continue;
      const bool at_a = m.PointOf(0) == p;
      double t = at_a ? rho / len : 1 - rho / len;
      // On the sphere, never strictly inside by rounding: such a (1,2) point
      // got no ball of its own (CreateCollar skips points strictly inside a
      // collar), leaving the vertex ball to meet the next chain ball at a
      // sharp angle, i.e. a collar system that is not smooth (Lemma 17;
      // measured on a flat tetrahedron: 3 of its 6 (1,2) points skipped).
      // t moves away from the vertex by 1, 2, 4, … of its ulps: one ulp of t
      // moves a point of a short segment by far less than an ulp of its
      // coordinates (armadillo.off: 64 single steps left 2 of 155,943 (1,2)
      // points strictly inside their vertex ball; segment 70951 is 0.0032
      // long at coordinates near 0.3).
      t = m.StepOutOfBall(t, /*toward_b=*/at_a, pos, rho);
      uint32_t u = 0;
      while (m.Next(u) != SegmentMesh::kNil && m.T(m.Next(u)) <= t) u = m.Next(u);
      if (m.Next(u) == SegmentMesh::kNil || m.T(u) == t || !(t > m.T(u) && t < m.T(m.Next(u)))) {
        ++stats_.points_12_skipped;
        if (std::getenv("SVRC_COLLAR_DEBUG") != nullptr) {
          std::fprintf(stderr, "(1,2) point of ball %u on segment %u at t %.17g not inserted (piece %.17g..%.17g)\n",
                       collars_.size() - 1, sg, t, m.T(u),
                       m.Next(u) == SegmentMesh::kNil ? -1.0 : m.T(m.Next(u)));
        }
        continue;
      }
      ++stats_.points_12;
      absl::Status st = ForceInsertSegment(sg, u, t, Cd{1, 2});
      if (!st.ok()) return st;
    }
  }
  return absl::OkStatus();
}

// The point of the circle where `ball`'s sphere meets the plane of frame fr
// (S ∩ F for a facet through the centre) radially nearest to uv, in fr's
// coordinates; false when the plane misses the ball or uv is the circle's
// centre.
bool NearestArcPoint(const plc::FacetFrame& fr, const CollarBall& ball, const Vec2& uv, Vec2* q) {
  const Vec2 cuv = fr.ToPlane(ball.center);
  const double hc = geom::Dot(ball.center - fr.origin, fr.normal);
  const double rp2 = ball.radius * ball.radius - hc * hc;
  if (!(rp2 > 0)) return false;
  const double dx = uv.x - cuv.x, dy = uv.y - cuv.y, d = std::hypot(dx, dy);
  if (!(d > 0)) return false;
  *q = Vec2{cuv.x + std::sqrt(rp2) * dx / d, cuv.y + std::sqrt(rp2) * dy / d};
  return true;
}

// CollarRepair::Reason in error messages.
constexpr const char* kCollarRepairName[] = {"topology", "angle", "circle", "size"};

// Smallest RepBall accepted, relative to its collar ball's radius.
constexpr double kMinCollarRepairRatio = 1e-4;

std::vector<Refiner::CreaseBallPair> Refiner::CreaseBallPairs() const {
  std::vector<uint32_t> ball_of(points_.size(), CollarIndex::kNone);
  for (uint32_t i = 0; i < collar_centre_.size(); ++i) ball_of[collar_centre_[i].value()] = i;
  std::vector<CreaseBallPair> out;
  for (uint32_t sg = 0; sg < segs_.size(); ++sg) {
    if (!complex_->segments[sg].crease) continue;
    const SegmentMesh& m = segs_[sg];
    uint32_t prev = SegmentMesh::kNil;  // last vertex with a ball
    for (uint32_t u = 0; u != SegmentMesh::kNil; u = m.Next(u)) {
      // Crease points without a ball are inside a collar (CreateCollar skips
      // them) or outside every collar.
      const uint32_t b = ball_of[m.PointOf(u).value()];
      if (b == CollarIndex::kNone) continue;
      if (prev != SegmentMesh::kNil) out.push_back({sg, prev, u, ball_of[m.PointOf(prev).value()], b});
      prev = u;
    }
  }
  return out;
}

absl::StatusOr<bool> Refiner::SplitCollarNecks() {
  bool any = false;
  // Splitting a piece adds a vertex between u and w; the ids of the other
  // pairs' vertices stay valid.
  for (const CreaseBallPair& pr : CreaseBallPairs()) {
    SegmentMesh& m = segs_[pr.seg];
    const CollarBall& a = collars_.ball(pr.ball_u);
    const CollarBall& b = collars_.ball(pr.ball_w);
    const double d = geom::Dist(a.center, b.center);
    if (!(d < a.radius + b.radius && d * d > a.radius * a.radius + b.radius * b.radius)) continue;
    // The crease point on the neck: where the circle's plane crosses the
    // segment.
    const double x = (d * d + a.radius * a.radius - b.radius * b.radius) / (2 * d);
    const double t = m.T(pr.u) + (m.T(pr.w) - m.T(pr.u)) * (x / d);
    uint32_t v = pr.u;
    while (m.Next(v) != pr.w && m.T(m.Next(v)) <= t) v = m.Next(v);
    if (!(t > m.T(v) && t < m.T(m.Next(v)))) continue;
    const uint32_t np = points_.size();
    if (neck_point_.size() <= np) neck_point_.resize(np + 1024, 0);
    neck_point_[np] = 1;
    absl::Status st = ForceInsertSegment(pr.seg, v, t, kCdSegment);
    if (!st.ok()) return st;
    ++stats_.neck_splits;
    any = true;
  }
  return any;
}

void Refiner::DebugNonSmoothPairs() const {
  std::set<std::pair<uint32_t, uint32_t>> consecutive;
  for (const CreaseBallPair& pr : CreaseBallPairs()) {
    consecutive.insert({std::min(pr.ball_u, pr.ball_w), std::max(pr.ball_u, pr.ball_w)});
  }
  struct Bad {
    double ratio;
    uint32_t a, b;
  };
  std::vector<Bad> bad;
  collars_.ForEachIntersectingPair([&](uint32_t i, uint32_t j, double ratio) {
    if (ratio > 1) bad.push_back({ratio, std::min(i, j), std::max(i, j)});
  });
  // Kinds: "consecutive" = neighbours on a crease segment's chain (a neck
  // split is pending); otherwise by the centres' features.
  std::map<std::string, int> kinds;
  auto kind_of = [&](const Bad& x) {
    if (consecutive.count({x.a, x.b})) return std::string("consecutive on a crease segment");
    const FeatureId fa = points_.Parent(collar_centre_[x.a]), fb = points_.Parent(collar_centre_[x.b]);
    if (fa == fb) return absl::StrCat("same feature, dim ", features_.Dim(fa), ", not consecutive");
    if (features_.Dim(fa) + features_.Dim(fb) == 1) {
      const FeatureId fv = features_.Dim(fa) == 0 ? fa : fb, fs = features_.Dim(fa) == 0 ? fb : fa;
      const plc::FeatureSegment& sg = complex_->segments[features_.Index(fs)];
      const uint32_t vi = features_.Index(fv);
      return absl::StrCat("vertex ball and a ball on a ", sg.crease ? "crease" : "non-crease", " segment ",
                          (sg.a == vi || sg.b == vi) ? "ending there" : "not through it");
    }
    return absl::StrCat("features of dims ", std::min(features_.Dim(fa), features_.Dim(fb)), "/",
                        std::max(features_.Dim(fa), features_.Dim(fb)));
  };
  for (const Bad& x : bad) ++kinds[kind_of(x)];
  std::fprintf(stderr, "collar system: %zu ball pairs meet below pi/2\n", bad.size());
  for (const auto& [k, c] : kinds) std::fprintf(stderr, "  %6d %s\n", c, k.c_str());
  std::sort(bad.begin(), bad.end(), [](const Bad& x, const Bad& y) { return x.ratio > y.ratio; });
  for (size_t k = 0; k < bad.size() && k < 12; ++k) {
    const Bad& x = bad[k];
    const CollarBall& a = collars_.ball(x.a);
    const CollarBall& b = collars_.ball(x.b);
    const FeatureId fa = points_.Parent(collar_centre_[x.a]), fb = points_.Parent(collar_centre_[x.b]);
    std::fprintf(stderr,
                 "  ratio %.4f balls %u (dim %d feature %u, r %.3g at %.6g %.6g %.6g) %u (dim %d feature %u, r %.3g): %s\n",
                 x.ratio, x.a, features_.Dim(fa), features_.Index(fa), a.radius, a.center.x, a.center.y, a.center.z,
                 x.b, features_.Dim(fb), features_.Index(fb), b.radius, kind_of(x).c_str());
  }
}

absl::StatusOr<uint32_t> Refiner::InsertSizePoints() {
  const delaunay::Delaunay3& dt = omega_.dt();
  uint32_t inserted = 0;
  stats_.clipped_size_points += size_points_.size();
  for (const auto& [x, radius] : size_points_) {
    const VertexId v = dt.NearestVertex(x);
    const double r = geom::Dist(dt.Point(v), x);
    // An earlier point of this list may have been put next to it.
    if (!(r > 1e-3 * radius)) continue;
    absl::Status st = DestroyOmegaAt(x, r, dt.VertexTet(v), v);
    if (!st.ok()) return st;
    ++inserted;
  }
  size_points_.clear();
  if (inserted > 0) ClearStitch();
  return inserted;
}

absl::StatusOr<uint32_t> Refiner::RepairStitchFailures() {
  // A T′ face whose star over its ball's centre is inverted lies nearly
  // edge-on to the centre; its Voronoi edge's root x on S is the centre of
  // its empty RepBall, so inserting x destroys the face (as an angle repair
  // would). The COLLAR rounds settled on snapped positions; the stitch sees
  // the unsnapped ones (measured: crease_pair 30° with neck splits, one
  // inverted star at ball 7).
  const delaunay::Delaunay3& dt = omega_.dt();
  uint32_t inserted = 0;
  for (const auto& [x, ball, collar_dim] : stitch_failures_) {
    const VertexId v = dt.NearestVertex(x);
    const double r = geom::Dist(dt.Point(v), x);
    if (!(r > kMinCollarRepairRatio * collars_.ball(ball).radius)) continue;
    absl::Status st = DestroyOmegaAt(x, r, dt.VertexTet(v), v, Cd{3, collar_dim});
    if (!st.ok()) return st;
    ++collar_repairs_;
    ++inserted;
  }
  stitch_failures_.clear();
  if (inserted > 0) ClearStitch();
  return inserted;
}

absl::StatusOr<bool> Refiner::CollarRoundImpl() {
  if (collars_.size() == 0) return false;
  if (options_.split_necks) {
    absl::StatusOr<bool> split = SplitCollarNecks();
    if (!split.ok() || *split) return split;
  }
  const CollarDescription desc = BuildCollarDescription(collars_.balls());
  CollarSurfaceOptions copt;
  copt.topology_summary = false;  // χ and components: diagnostics the rounds do not read
  copt.sigma = options_.max_rep_angle;
  copt.delta = collar_snap_;
  copt.exact_vertex_links = options_.collar_exact_vertex_links;
  copt.exact_sphere_links = options_.collar_exact_sphere_links;
  copt.size_criterion = options_.collar_size_eps > 0;
  if (copt.size_criterion) copt.eps_s = options_.collar_size_eps;
  surface_report_ = CollarSurfaceReport();
  if (!restriction_cache_.generation) {
    restriction_cache_.generation = [this](uint32_t v) { return omega_.CellGeneration(VertexId(v)); };
  }
  CollarRestrictionCache* cache = options_.reuse_round_work ? &restriction_cache_ : nullptr;
  std::vector<RestrictedTriangle> restricted;
  std::vector<CollarRepair> reps = CollarRepairs(omega_.dt(), desc, copt, &surface_report_, cache, &restricted);
  // A crease vertex must be strictly inside the stitched hole (Figure 3.12:
  // its star replaces the inside): every tet around it needs its
  // circumcentre inside the collars. A tet whose circumcentre is outside
  // means the centre's Voronoi cell crosses S there; the point of the
  // centre's sphere towards that circumcentre goes in (CD (3,2)), which cuts
  // the cell back (measured: segment_fan.poly's stitch refused 8 crease
  // vertices on hole-boundary faces).
  {
    const delaunay::Delaunay3& d = omega_.dt();
    std::vector<TetId> star;
    for (uint32_t i = 0; i < collars_.size(); ++i) {
      const PointId c = collar_centre_[i];
      if (!points_.InMesh(c, kOmegaMesh)) continue;
      const VertexId v(points_.VertexIn(c, kOmegaMesh));
      const CollarBall& ball = collars_.ball(i);
      d.Star(v, &star);
      for (TetId t : star) {
        if (d.IsGhost(t)) continue;
        const Vec3 cc = d.Circumcenter(t);
        if (collars_.StrictlyInside(cc)) continue;
        const Vec3 dir = cc - ball.center;
        const double len = geom::Norm(dir);
        if (!(len > 0)) continue;
        CollarRepair r;
        r.x = ball.center + (ball.radius / len) * dir;
        r.ball = i;
        r.collar_dim = 2;
        r.reason = CollarRepair::kTopology;
        if (collars_.FindContaining(r.x) != CollarIndex::kNone) continue;  // not on S
        const VertexId nv = d.NearestVertex(r.x, t);
        r.radius = geom::Dist(r.x, d.Point(nv));
        if (!(r.radius > 0)) continue;
        reps.push_back(r);
        ++centre_repairs_;
      }
    }
  }
  // Largest RepBall first (Figure 3.11's buckets), ties by position.
  std::stable_sort(reps.begin(), reps.end(), [](const CollarRepair& a, const CollarRepair& b) { return a.radius > b.radius; });
  bool any = false;
  const delaunay::Delaunay3& dt = omega_.dt();
  std::vector<std::pair<uint32_t, Vec2>> crossings;  // (facet, arc point uv) of this round
  // The facet-crossing check (below) once the restricted triangulation's
  // topology has held in some round (no topology or circle repair): from
  // then on every round, so its arc points go in with the angle repairs
  // instead of each batch restarting rounds that had settled.
  if (surface_report_.repairs[CollarRepair::kTopology] == 0 && surface_report_.repairs[CollarRepair::kCircle] == 0) {
    topology_held_ = true;
  }
  const bool check_crossings = reps.empty() || (options_.crossings_once_topology_holds && topology_held_);
  if (check_crossings) {
    // Facet-crossing check: RipStitchCollar's fan (centre, a, b) covers a
    // facet F through a collar centre only if T′ meets F along F's own points.
    // A T′ edge of ball i's partial sphere whose ends are strictly on opposite
    // sides of such an F (inside F's region) gets F's arc point nearest to the
    // crossing, CD (2,2) (docs/svrc-collars.md "Wiring status", item 5).
    for (const RestrictedTriangle& t : restricted) {
      const PointId centre = collar_centre_[t.ball];
      const CollarBall& ball = collars_.ball(t.ball);
      for (uint32_t f : FacetsThrough(centre)) {
        const plc::FacetFrame& fr = frames_[f];
        for (int k = 0; k < 3; ++k) {
          const Vec3& pa = dt.Point(t.v[k]);
          const Vec3& pb = dt.Point(t.v[(k + 1) % 3]);
          Vec3 x;
          if (!FacetCrossing(f, pa, pb, 1e-12 * ball.radius, &x)) continue;
          Vec2 q;
          if (!NearestArcPoint(fr, ball, fr.ToPlane(x), &q)) continue;
          if (facets_[f].region().Locate(q) == FacetRegion::Where::kOutside) continue;
          crossings.push_back({f, q});
        }
      }
    }
  }
  // The restricted triangles (64 bytes each, every ball's) are not needed
  // past the check: not held while the repairs go in.
  std::vector<RestrictedTriangle>().swap(restricted);
  // Cancellation and deadlines inside a round, as Run() polls between
  // events: one COLLAR round can insert tens of thousands of points
  // (fandisk.off: 49,892 repairs in round 9; a 900 s deadline ended the job
  // at 963 s when only Run() polled).
  uint64_t round_work = 0;
  if (absl::Status s = PollAt(round_work++, reps.empty() ? 0.0 : reps.front().radius); !s.ok()) return s;
  for (const CollarRepair& r : reps) {
    if (absl::Status s = PollAt(round_work++, r.radius); !s.ok()) return s;
    // A RepBall far below its collar's radius means the sampling of S is
    // chasing a degenerate configuration, not converging (measured on
    // schonhardt.off: ~500 topology repairs per round at radii 1e-7..1e-8
    // for 70+ rounds): stop with a precise error instead of running on.
    const double ball_r = collars_.ball(r.ball).radius;
    // The floor is relative to the ball's radius, or to the gap between the
    // facets through its centre at x when that is smaller: two facets at a
    // dihedral angle θ leave arcs ρθ apart on the sphere, and the sampling
    // of S between them legitimately needs RepBalls of that scale
    // (random_plcs.py tet 20, θ = 0.29°: the fallback to the snap band, and
    // stars of σ 89.6°, came from repairs 9e-5ρ next to a facet's arc).
    if (r.radius < kMinCollarRepairRatio * ball_r &&
        !(r.radius >= kMinCollarRepairRatio * FacetGapOnSphere(r.x, r.ball))) {
      if (collar_snap_ < options_.collar_snap_fallback) {
        // The true angles chase a vertex close to S (RefineOptions::
        // collar_snap): from here on the thesis' snap band; the points of
        // this round stay, the next round tests the snapped angles.
        collar_snap_ = options_.collar_snap_fallback;
        return true;
      }
      const Vec3 at = norm_.Backward(r.x);  // the input's coordinates, as every message gives them
      return absl::FailedPreconditionError(absl::StrCat(
          "SVRC: COLLAR ", kCollarRepairName[r.reason], " repair at (", at.x, ", ",
          at.y, ", ", at.z, ") needs a point ", r.radius / ball_r, " collar radii from the nearest vertex; the ",
          "collar surface sampling does not settle (ball ", r.ball, ", radius ", norm_.ToInputLength(ball_r), ")"));
    }
    const VertexId v = dt.NearestVertex(r.x, r.near.valid() ? dt.VertexTet(r.near) : TetId());
    if (dt.Point(v) == r.x) continue;
    // The RepBall is empty by construction (Definition 38); an earlier repair
    // of this round may have destroyed it.
    if (geom::Dist(dt.Point(v), r.x) < r.radius * (1 - 1e-9)) continue;
    absl::Status st = DestroyOmegaAt(r.x, r.radius, dt.VertexTet(v), v, Cd{3, static_cast<uint8_t>(r.collar_dim)});
    if (!st.ok()) return st;
    ++collar_repairs_;
    ++collar_repairs_by_reason_[r.reason];
    any = true;
  }
  // The 2D collar systems of the facets a collar ball reaches.
  std::vector<CollarBall> near;
  std::vector<uint32_t> cand;
  if (arc_memo_.size() < facets_.size()) arc_memo_.resize(facets_.size());
  if (facet_near_.size() < facets_.size()) facet_near_.resize(facets_.size());
  for (uint32_t f = 0; f < facets_.size(); ++f) {
    FacetMesh& m = facets_[f];
    const plc::FacetFrame& fr = frames_[f];
    FacetNearBalls& fnear = facet_near_[f];
    for (uint32_t i = fnear.scanned; i < collars_.size(); ++i) {
      const CollarBall& b = collars_.ball(i);
      if (std::abs(geom::Dot(b.center - fr.origin, fr.normal)) >= b.radius) continue;
      const Vec2 uv = fr.ToPlane(b.center);
      if (uv.x + b.radius < m.SquareLo().x || uv.x - b.radius > m.SquareHi().x || uv.y + b.radius < m.SquareLo().y ||
          uv.y - b.radius > m.SquareHi().y) {
        continue;
      }
      fnear.ids.push_back(i);
    }
    fnear.scanned = collars_.size();
    if (fnear.ids.empty()) continue;
    const std::vector<uint32_t>& near_ids = fnear.ids;
    // ArcRepairs is a function of the facet mesh (changed only by
    // insertions: same vertex count, same mesh) and of the balls (never
    // changed once added): a facet that had none last round and has had no
    // insertion since, with the same balls, has none again.
    FacetArcMemo& memo = arc_memo_[f];
    std::vector<ArcRepair> ar;
    if (!(options_.reuse_round_work && memo.settled && memo.vertices == m.dt().NumVertices() && memo.near == near_ids)) {
      near.clear();
      for (uint32_t i : near_ids) near.push_back(collars_.ball(i));
      const FacetCollarSystem sys = FacetCollars(fr, near);
      ArcOptions aopt;
      aopt.snap = options_.arc_snap;
      if (options_.loose_arcs) {
        aopt.require_on_arc = false;
        aopt.eps = 0;
      }
      ArcReport arep;
      ar = ArcRepairs(m.dt(), sys, options_.max_rep_angle, &arep, aopt);
      memo.settled = ar.empty();
      memo.vertices = m.dt().NumVertices();
      memo.near = near_ids;
      ++stats_.arc_facets_computed;
      if (std::getenv("SVRC_COLLAR_DEBUG") != nullptr && !ar.empty()) {
        std::fprintf(stderr, "  facet %u: %zu arc repairs: missing21 %d multi %d broken %d empty %d offarc %d angles %d size %d\n", f,
                     ar.size(), arep.missing_points21, arep.multi_crossings, arep.broken_arcs, arep.empty_arcs,
                     arep.off_arc_edges, arep.bad_angles, arep.too_large);
      }
    } else {
      ++stats_.arc_facets_settled;
    }
    std::stable_sort(ar.begin(), ar.end(), [](const ArcRepair& a, const ArcRepair& b) {
      return a.collar_dim < b.collar_dim || (a.collar_dim == b.collar_dim && a.radius > b.radius);
    });
    for (const auto& [cf, q] : crossings) {
      // All of a round's crossings go in together, next to its arc repairs
      // (measured: one facet crossing per round left crease_pair 1° unsettled
      // after 256 rounds with 227 crossings; together, 1° settles and
      // conforms, 10° takes 8 s instead of 21 s).
      if (cf != f) continue;
      ArcRepair r;
      r.x = q;
      r.collar_dim = 2;
      const VertexId2 w = m.dt().NearestVertex(q);
      const Vec2 pw = m.dt().Point(w);
      r.radius = std::hypot(pw.x - q.x, pw.y - q.y);
      // Already sampled there (the crossing is within a tenth of the gap).
      if (!(r.radius > 0)) continue;
      ar.push_back(r);
      ++crossing_count_;
    }
    for (const ArcRepair& r : ar) {
      if (absl::Status s = PollAt(round_work++, r.radius); !s.ok()) return s;
      if (!(r.x.x >= m.SquareLo().x && r.x.x <= m.SquareHi().x && r.x.y >= m.SquareLo().y && r.x.y <= m.SquareHi().y)) continue;
      const VertexId2 w = m.dt().NearestVertex(r.x);
      const Vec2 pw = m.dt().Point(w);
      if (pw.x == r.x.x && pw.y == r.x.y) continue;
      const double d = std::hypot(pw.x - r.x.x, pw.y - r.x.y);
      if (r.collar_dim == 2 && d < r.radius * (1 - 1e-9)) continue;  // destroyed earlier this round
      const TriId2 hint = m.dt().Locate(r.x, m.dt().VertexTri(w));
      absl::Status st = DestroyFacet(f, r.x, std::max(d, r.radius), hint, TriId2(), Cd{2, static_cast<uint8_t>(r.collar_dim)},
                                     /*jitter=*/false);
      if (!st.ok()) return st;
      ++arc_repairs_;
      any = true;
    }
  }
  if (any) ++collar_rounds_;
  return any;
}

void Refiner::ReleaseRefinementState() {
  blg_ = LocationGraph();
  balls_ = BallStore();
  queues_ = WorkQueues();
  restriction_cache_ = CollarRestrictionCache();
  partial_ = {};
  vertex_ball_ = {};
  piece_vertex_ = {};
  piece_seg_ = {};
  tri_of_ball_ = {};
  known_present_ = {};
  arc_memo_ = {};
  facet_near_ = {};
  created_labels_ = {};
  gathered_ = {};
  objects_ = {};
  moves_ = {};
  ball_mark_ = {};
  util::PodVector<CellCert>().swap(cell_cert_);
  util::PodVector<uint32_t>().swap(tet_event_);  // the queues' slots (gone above)
  omega_.ReleaseQueryCaches();
}

std::vector<std::pair<uint32_t, std::array<uint32_t, 3>>> Refiner::StitchedFacetFaces(uint64_t* on_plane) const {
  // Only a face whose three points lie on features can be on a facet
  // (FacetsOfPoint is empty for a point of Ω). Filtering before the sort
  // keeps this list to the faces near the facets: all four faces of every
  // stitched tet were 15% of crease_pair_1deg's peak heap (75 of 506 MB).
  // With stitch_faces_on_plane, faces with one point of Ω go to a second list
  // (that point last), kept only if the point lies on a facet of the other two.
  std::vector<uint8_t> on_feature(points_.size());
  for (uint32_t p = 0; p < points_.size(); ++p) on_feature[p] = points_.Parent(PointId(p)) != FeatureTable::Omega();
  std::vector<std::array<uint32_t, 3>> faces, one_omega;
  for (const auto& t : stitched_) {
    for (int k = 0; k < 4; ++k) {
      std::array<uint32_t, 3> fc{t[(k + 1) % 4], t[(k + 2) % 4], t[(k + 3) % 4]};
      const int omega = !on_feature[fc[0]] + !on_feature[fc[1]] + !on_feature[fc[2]];
      if (omega == 0) {
        std::sort(fc.begin(), fc.end());
        faces.push_back(fc);
      } else if (omega == 1 && options_.stitch_faces_on_plane) {
        std::sort(fc.begin(), fc.end(), [&](uint32_t a, uint32_t b) {
          return on_feature[a] != on_feature[b] ? on_feature[a] > on_feature[b] : a < b;
        });
        one_omega.push_back(fc);
      }
    }
  }
  std::sort(faces.begin(), faces.end());
  faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  std::vector<std::pair<uint32_t, std::array<uint32_t, 3>>> out;
  if (on_plane != nullptr) *on_plane = 0;
  std::vector<uint32_t> fa, fb;
  for (const auto& k : faces) {
    const uint32_t f = FacetOfTriangle({PointId(k[0]), PointId(k[1]), PointId(k[2])}, &fa, &fb);
    if (f != kNoFacet) out.emplace_back(f, k);
  }
  if (one_omega.empty()) return out;
  std::sort(one_omega.begin(), one_omega.end());
  one_omega.erase(std::unique(one_omega.begin(), one_omega.end()), one_omega.end());
  size_t added = 0;
  for (const auto& k : one_omega) {
    const std::array<PointId, 2> on{PointId(k[0]), PointId(k[1])};
    CommonFacets(on, &fa, &fb);
    const Vec3& x = points_.Xyz(PointId(k[2]));
    for (uint32_t f : fa) {
      const plc::FacetFrame& fr = frames_[f];
      if (!(std::fabs(geom::Dot(x - fr.origin, fr.normal)) <= std::max(on_plane_tol_, facet_plane_tol_[f]))) {
        continue;
      }
      if (!CentroidInRegion(f, Uv(f, on[0]), Uv(f, on[1]), fr.ToPlane(x))) continue;
      std::array<uint32_t, 3> sorted = k;
      std::sort(sorted.begin(), sorted.end());
      out.emplace_back(f, sorted);
      ++added;
      break;
    }
  }
  if (on_plane != nullptr) *on_plane = added;
  if (added > 0) {
    std::sort(out.begin(), out.end(), [](const auto& p, const auto& q) {
      return p.second != q.second ? p.second < q.second : p.first < q.first;
    });
  }
  return out;
}

absl::StatusOr<uint32_t> Refiner::RepairStitchedCrossings() {
  // M_Ω conforms to a facet F outside the collars through F's triangles, but
  // not where a triangle of M_F has a corner suppressed inside a collar (M_Ω
  // never gets that corner): there, next to S, M_Ω can cross F outside every
  // ball, and the stitched fan only covers F up to the arc chain (measured on
  // crease_pair 5°: a hole of area 3.3e-6 in a fin at 1.001–1.015 collar
  // radii, crossed by three kept tets). Candidates: final tets with a vertex
  // within 1.5 radii of a collar ball, their edges against the facets
  // through that collar's centre.
  CollarIndex near;
  for (uint32_t i = 0; i < collars_.size(); ++i) {
    CollarBall b = collars_.ball(i);
    b.radius *= 1.5;
    near.Add(b);
  }
  std::vector<std::tuple<uint32_t, double, double, bool>> hits;  // facet, u, v, on an arc
  for (const auto& t : stitched_) {
    uint32_t bi = CollarIndex::kNone;
    for (uint32_t p : t) {
      bi = near.FindContaining(points_.Xyz(PointId(p)));
      if (bi != CollarIndex::kNone) break;
    }
    if (bi == CollarIndex::kNone) continue;
    for (uint32_t f : FacetsThrough(collar_centre_[bi])) {
      const plc::FacetFrame& fr = frames_[f];
      for (int a = 0; a < 4; ++a) {
        for (int b = a + 1; b < 4; ++b) {
          // The edge in one orientation (smaller id first): its tets list it
          // in either, and the two crossings differ in the last bits, so they
          // were two hits, the second inserted ~1e-17 from the first
          // (schonhardt.off with exact vertex-link tests, session 21: M_F then
          // refined to the resolution of doubles).
          const uint32_t ia = std::min(t[a], t[b]), ib = std::max(t[a], t[b]);
          const Vec3& pa = points_.Xyz(PointId(ia));
          const Vec3& pb = points_.Xyz(PointId(ib));
          Vec3 x;
          if (!FacetCrossing(f, pa, pb, 1e-12 * collars_.ball(bi).radius, &x)) continue;
          Vec2 uv = fr.ToPlane(x);
          const uint32_t in = collars_.FindContaining(x);
          if (in != CollarIndex::kNone) {
            // Inside a collar the stars cover F only up to the chords of T′
            // (their faces on F are (centre, a, b) with a, b on F's arc);
            // between a chord and the arc F is covered by kept Delaunay tets,
            // whose circumcentres are outside the balls. Those can cross F
            // there: measured on hinge.stl, an edge pierced facet 149 at
            // 0.99959 collar radii, 0.6% beyond the chord of the two arc
            // points around it, and the facet's coverage came out short by
            // that triangle (the labelling flooded through it). Such a
            // crossing gets F's arc point nearest to it, CD (2,2), which
            // halves the chord, as the COLLAR rounds do for T′ edges.
            const std::span<const uint32_t> through = FacetsThrough(collar_centre_[in]);
            if (!std::binary_search(through.begin(), through.end(), f)) continue;
            if (!NearestArcPoint(fr, collars_.ball(in), uv, &uv)) continue;
            // Not on S when another ball swallows it.
            const uint32_t other = collars_.FindContaining(fr.ToSpace(uv));
            if (other != CollarIndex::kNone && other != in) continue;
          }
          if (facets_[f].region().Locate(uv) != FacetRegion::Where::kInside) continue;
          hits.emplace_back(f, uv.x, uv.y, in != CollarIndex::kNone);
        }
      }
    }
  }
  std::sort(hits.begin(), hits.end());
  hits.erase(std::unique(hits.begin(), hits.end()), hits.end());
  uint32_t inserted = 0;
  for (const auto& [f, u, v, on_arc] : hits) {
    FacetMesh& m = facets_[f];
    const Vec2 c{u, v};
    const VertexId2 w = m.dt().NearestVertex(c);
    const Vec2 pw = m.dt().Point(w);
    const double d = std::hypot(pw.x - c.x, pw.y - c.y);
    if (!(d > 0)) continue;
    const TriId2 hint = m.dt().Locate(c, m.dt().VertexTri(w));
    absl::Status st = DestroyFacet(f, c, d, hint, TriId2(), on_arc ? Cd{2, 2} : kCdFacet, /*jitter=*/false);
    if (!st.ok()) return st;
    ++inserted;
    ++stitched_crossings_;
    if (on_arc) ++stitched_arc_crossings_;
  }
  if (inserted > 0) ClearStitch();
  return inserted;
}

absl::Status Refiner::StitchImpl() {
  const delaunay::Delaunay3& dt = omega_.dt();
  // Crease edges: consecutive collared points along each crease segment.
  // Crease points without a ball between them lie on the book's axis and are
  // removed with the inside; those outside every collar break no pair whose
  // spheres cross (the stitch ignores pairs that do not cross). A ball inside
  // the union of its two chain neighbours is no part of S; it leaves the
  // stitch's balls (its centre is then an inside vertex, removed), and the
  // neighbours' circle is the crease edge (armadillo.off: a neck split's
  // ball of radius 2.81e-4 under the 2.90e-4 circle it split, "spheres of
  // balls 15048 and 26067 cross but are not a crease edge").
  std::vector<std::vector<uint32_t>> chains;
  {
    uint32_t seg = std::numeric_limits<uint32_t>::max();
    for (const CreaseBallPair& pr : CreaseBallPairs()) {
      if (pr.seg != seg || chains.back().back() != pr.ball_u) {
        chains.push_back({pr.ball_u});
        seg = pr.seg;
      }
      chains.back().push_back(pr.ball_w);
    }
  }
  std::vector<uint8_t> hidden(collars_.size(), 0);
  for (std::vector<uint32_t>& chain : chains) {
    for (uint32_t b : PruneHiddenChainBalls(collars_.balls(), &chain)) hidden[b] = 1;
  }
  // Stitch ball k is collar ball collar_of[k].
  std::vector<uint32_t> collar_of, stitch_of(collars_.size(), CollarIndex::kNone);
  std::vector<StitchBall> balls;
  stats_.stitch_hidden_balls = 0;  // of this (the last) stitch
  for (uint32_t i = 0; i < collars_.size(); ++i) {
    if (hidden[i]) {
      ++stats_.stitch_hidden_balls;
      continue;
    }
    stitch_of[i] = static_cast<uint32_t>(balls.size());
    collar_of.push_back(i);
    StitchBall sb;
    sb.ball = collars_.ball(i);
    sb.centre = VertexId(points_.VertexIn(collar_centre_[i], kOmegaMesh));
    balls.push_back(sb);
  }
  std::vector<std::pair<uint32_t, uint32_t>> edges;
  for (const std::vector<uint32_t>& chain : chains) {
    for (size_t k = 1; k < chain.size(); ++k) {
      const uint32_t a = stitch_of[chain[k - 1]], b = stitch_of[chain[k]];
      edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  }
  StitchInput in;
  in.dt = &dt;
  in.balls = balls;
  in.crease_edges = edges;
  // The angle bound is checked by the rounds on snapped positions (Snap,
  // thesis §3.1.2); unsnapped, a face can exceed it (measured on crease_pair
  // 5°: one face above 89°). The stitch verifies its tets exactly either way
  // (positive orientation, every face matched), so its own angle test is off.
  in.options.max_rep_angle = M_PI / 2;
  in.options.max_rep_ratio = 10;
  std::vector<StitchFailure> failures;
  absl::StatusOr<StitchResult> r = RipStitchCollar(in, &failures);
  if (!r.ok() && std::getenv("SVRC_COLLAR_DEBUG") != nullptr) {
    std::map<std::string, int> kinds;
    for (const StitchFailure& f : failures) ++kinds[StitchFailureKindName(f.kind)];
    for (const auto& [k, n] : kinds) std::fprintf(stderr, "stitch failure %s: %d\n", k.c_str(), n);
    for (size_t i = 0; i < failures.size() && i < 5; ++i) std::fprintf(stderr, "  %s\n", failures[i].detail.c_str());
    // Stitch ball k (the failures' numbering) is collar ball collar_of[k].
    for (uint32_t k = 0; k < balls.size(); ++k) {
      const uint32_t i = collar_of[k];
      const FeatureId f = points_.Parent(collar_centre_[i]);
      std::fprintf(stderr, "ball %u (collar %u): feature dim %d idx %u centre (%.17g %.17g %.17g) r %.17g\n", k, i,
                   features_.Dim(f), features_.Index(f), collars_.ball(i).center.x, collars_.ball(i).center.y,
                   collars_.ball(i).center.z, collars_.ball(i).radius);
    }
  }
  stitch_failures_.clear();
  for (const StitchFailure& f : failures) {
    if (f.ball == StitchFailure::kNoBall) continue;
    const uint32_t ball = collar_of[f.ball];
    // A flat star (a T′ face in a facet through its ball's centre, positive
    // by rounding; armadillo.off under the snap band) is repaired as an
    // inverted one: the point at its face's crossing of S removes the face.
    if (f.kind == StitchFailure::Kind::kStarFlat || f.kind == StitchFailure::Kind::kBookFlat) ++stats_.stitch_flat_tets;
    if (f.kind == StitchFailure::Kind::kStarInverted || f.kind == StitchFailure::Kind::kStarFlat) {
      stitch_failures_.push_back({f.where, ball, 2});
    }
    // A flat book (its two T′ points coplanar with the crease edge, as two
    // points of one facet through the crease are): `where` is the crease
    // circle's crossing of their edge's Voronoi facet, so inserting it
    // removes that edge (wedge-1.smesh under collar_tet_quality).
    if (f.kind == StitchFailure::Kind::kBookDegenerate || f.kind == StitchFailure::Kind::kBookFlat) {
      stitch_failures_.push_back({f.where, ball, 1});
    }
    // Folded books: `where` is the crease circle's point nearest the fold's
    // T′ vertex; inserting it splits the fold.
    if (f.kind == StitchFailure::Kind::kBookFold) stitch_failures_.push_back({f.where, ball, 1});
  }
  if (!r.ok()) return r.status();
  // The tets to point ids in place, then moved: stitched_ grown by push_back
  // beside r->tets held both, and a doubling vector's old block at its last
  // growth (268 MB of bunny.off's stitch).
  std::vector<std::array<uint32_t, 4>> tets = std::move(r->tets);
  for (auto& t : tets) {
    for (uint32_t& v : t) v = omega_.PointOf(VertexId(v)).value();
  }
  stitch_report_ = *std::move(r);
  stitched_ = std::move(tets);
  stitched_done_ = true;
  return absl::OkStatus();
}

// ---------------------------------------------------------------- checks

absl::Status Refiner::CheckInvariants(bool final) {
  const delaunay::Delaunay3& dt = omega_.dt();
  // New tets locally Delaunay (hence globally): the kernel's full check.
  absl::Status s = dt.Validate(/*check_empty_sphere=*/true);
  if (!s.ok()) return s;
  if (!blg_.Validate()) return absl::InternalError("SVRC invariant: BLG directions disagree");
  if (!queues_.Validate()) return absl::InternalError("SVRC invariant: work queues corrupt");
  // Links are conservative (guide §3): a lower ball linked in M_Ω is linked
  // to the cell holding its centre and to the cell of every vertex strictly
  // inside it (that vertex's cell meets the ball), whatever filters
  // UpdateLocation applied (§8 item 37). The candidates are the superset
  // CellsMeetingBall finds.
  {
    std::vector<uint32_t> linked;
    std::vector<VertexId> near;
    for (uint32_t i = 0; i < balls_.size(); ++i) {
      const BallId b(i);
      if (!balls_.IsAlive(b) || balls_.IsVertexBall(b)) continue;
      linked.clear();
      blg_.CellsOf(LocationObject::Ball(b), kOmegaMesh, &linked);
      if (linked.empty()) continue;
      std::sort(linked.begin(), linked.end());
      const VertexId w = dt.NearestVertex(balls_.Center(b), dt.VertexTet(VertexId(linked[0])));
      CellsMeetingBall(balls_.Center(b), balls_.Radius(b), w, &near, /*loose=*/true);
      for (VertexId x : near) {
        if (x != w && !Inside(b, dt.Point(x))) continue;
        if (!std::binary_search(linked.begin(), linked.end(), x.value())) {
          return absl::InternalError(absl::StrCat("SVRC invariant: ball ", i, " (", balls_.NumVertices(b),
                                                  " vertices) meets cell ", x.value(), " but is not linked to it"));
        }
      }
    }
  }
  // Every unresolved point (input or segment point) is linked to exactly one
  // cell of M_Ω, that cell contains it, and the cell has an Unresolved event.
  for (uint32_t i = 0; i < points_.size(); ++i) {
    const PointId p(i);
    const BallId b = VertexBallOf(p);
    if (!b.valid() || points_.InMesh(p, kOmegaMesh) || (i < suppressed_.size() && suppressed_[i])) continue;
    if (final) return absl::InternalError(absl::StrCat("SVRC invariant: point ", i, " not in M_Ω"));
    std::vector<uint32_t> cells;
    blg_.CellsOf(LocationObject::Ball(b), kOmegaMesh, &cells);
    if (cells.size() != 1) {
      return absl::InternalError(absl::StrCat("SVRC invariant: point ", i, " linked to ", cells.size(), " cells"));
    }
    const Vec3& q = points_.Xyz(p);
    const Vec3& pu = dt.Point(VertexId(cells[0]));
    for (uint32_t w = 0; w < dt.NumVertices(); ++w) {
      if (geom::CompareDistance(q, pu, dt.Point(VertexId(w))) > 0) {
        return absl::InternalError(absl::StrCat("SVRC invariant: point ", i, " linked to cell ", cells[0],
                                                " but vertex ", w, " is nearer"));
      }
    }
    if (!queues_.IsQueued(omega_.UnresolvedEvent(VertexId(cells[0])))) {
      return absl::InternalError(absl::StrCat("SVRC invariant: cell ", cells[0], " holds unresolved point ", i,
                                              " but has no Unresolved event"));
    }
  }
  // tet_quality: at the end no output tet is bad.
  if (tet_mode_ && final) {
    for (uint32_t i = 0; i < dt.TetCapacity(); ++i) {
      const TetId t(i);
      Vec3 cc;
      double r = 0;
      if (!dt.IsAlive(t) || !TetBad(t, &cc, &r)) continue;
      if (dt.VertexAt(cc, t).valid()) continue;  // a phantom corner
      return absl::InternalError(absl::StrCat("SVRC invariant: tet ", i, " bad at the end: R = ", r));
    }
  }
  // Every τ-skinny cell owns a live Skinny event; at the end there is none.
  for (uint32_t w = 0; w < dt.NumVertices(); ++w) {
    const VertexId v(w);
    const CellSize cs = omega_.Size(v);
    if (!IsBad(v, cs)) continue;
    if (final && dt.Point(dt.NearestVertex(cs.kept_corner, cs.kept_hint)) != cs.kept_corner) {
      return absl::InternalError(absl::StrCat("SVRC invariant: cell ", w, " skinny at the end: R/r = ",
                                              cs.kept_outradius / cs.inradius));
    }
    const EventHandle h = omega_.SkinnyEvent(v);
    const VertexId near = dt.NearestVertex(cs.kept_corner, cs.kept_hint);
    if (dt.Point(near) == cs.kept_corner) continue;  // a phantom corner (DestroyOmega skips it)
    if (!queues_.IsQueued(h) || queues_.Get(h).generation != omega_.CellGeneration(v)) {
      return absl::InternalError(absl::StrCat("SVRC invariant: skinny cell ", w, " has no live Skinny event; corner (",
                                              cs.kept_corner.x, ", ", cs.kept_corner.y, ", ", cs.kept_corner.z,
                                              ") R=", cs.kept_outradius,
                                              " r=", cs.inradius, " clipped=", cs.clipped, " queued=", queues_.IsQueued(h) ? 1 : 0, " evgen=",
                                              queues_.IsQueued(h) ? queues_.Get(h).generation : 0, " cellgen=",
                                              omega_.CellGeneration(v)));
    }
  }
  for (uint32_t sg = 0; sg < segs_.size(); ++sg) {
    SegmentMesh& m = segs_[sg];
    for (uint32_t v = 0; v != SegmentMesh::kNil; v = m.Next(v)) {
      if (IsSkinny(m.Size(v))) {
        if (final || !queues_.IsQueued(m.SkinnyEvent(v))) {
          return absl::InternalError(absl::StrCat("SVRC invariant: segment ", sg, " cell ", v, " skinny without event"));
        }
      }
      if (m.Next(v) == SegmentMesh::kNil) break;
      // Every piece ball with a native M_Ω vertex inside is queued; with only
      // non-native encroachers, the first is recorded (Figure 3.10). At the
      // end no piece ball is encroached and every piece is a Delaunay edge.
      const BallId b = m.PieceBall(v);
      if (!balls_.IsAlive(b)) return absl::InternalError("SVRC invariant: dead piece ball in a segment mesh");
      for (uint32_t w = 0; w < dt.NumVertices(); ++w) {
        const VertexId x(w);
        if (!Encroaches(b, x)) continue;
        if (final) {
          return absl::InternalError(absl::StrCat("SVRC invariant: piece ", v, " of segment ", sg,
                                                  " encroached at the end by vertex ", w));
        }
        const bool native = points_.CdOf(omega_.PointOf(x)).dim == 3;
        if (native && !balls_.EncroachQueued(b)) {
          return absl::InternalError(absl::StrCat("SVRC invariant: piece ", v, " of segment ", sg,
                                                  " encroached by native vertex ", w, " but not queued"));
        }
        if (!native && !balls_.EncroachQueued(b) && !balls_.FirstEncroacher(b).valid()) {
          return absl::InternalError(absl::StrCat("SVRC invariant: piece ", v, " of segment ", sg,
                                                  " encroached by vertex ", w, " but no encroacher recorded"));
        }
      }
    }
  }
  if (final && !queues_.empty()) return absl::InternalError("SVRC invariant: events left at the end");
  return absl::OkStatus();
}

absl::StatusOr<bool> Refiner::SetSizeTargets(const plc::FeatureComplex& complex, double global_max_volume,
                                             bool all_vertices) {
  const AddSeconds timer(&stats_.seconds_labelling);
  // The labelling's arrays are the run's peak (massif, cube 1e-5): the event
  // slots of the Run() before it, all free now, go first (§8 item 52).
  if (queues_.ReleaseIfEmpty()) {
    ++stats_.queue_releases;
    util::PodVector<uint32_t>().swap(tet_event_);  // every slot it names is gone
  }
  // So do M_Ω's circumcentre cache and size memos (32 MiB and 29 MB on cube
  // 1e-6, 0.5 MiB and 0.23 MB on 1e-4): they refill after the labelling's
  // arrays are freed (below). RefineOptions::release_label_caches.
  const bool released = options_.release_label_caches && omega_.ReleaseCaches(options_.release_cache_min_bytes);
  const delaunay::Delaunay3& dt = omega_.dt();
  const uint32_t nv = dt.NumVertices();
  // M_Ω's points and (below) tets are read in place: their copies, 24 bytes
  // per vertex and 16 per tet, were the peak of cube 1e-4 once the
  // circumcentre cache was halved (docs/svrc-design.md §8 item 79).
  const std::span<const Vec3> positions = dt.Points();
  std::vector<std::array<uint32_t, 4>> tets;  // the stitched mesh's (collars)
  std::vector<TetId> tet_ids;  // else M_Ω's tets
  std::vector<ConstrainedFace> faces;
  if (stitched_done_) {
    // After RipStitchCollar (collars): label the stitched mesh, whose facets
    // are sealed, with its faces on the facets (as Output() takes them).
    // M_Ω before the stitch leaks through the collars (measured on
    // knife_edge.poly --max-volume 1e-3: "no tetrahedron is left").
    for (const auto& t : stitched_) {
      std::array<uint32_t, 4> tv;
      for (int k = 0; k < 4; ++k) tv[k] = points_.VertexIn(PointId(t[k]), kOmegaMesh);
      tets.push_back(tv);
    }
    for (const auto& [f, k] : StitchedFacetFaces()) {
      ConstrainedFace cf;
      for (int j = 0; j < 3; ++j) cf.v[j] = points_.VertexIn(PointId(k[j]), kOmegaMesh);
      cf.facet = f;
      faces.push_back(cf);
    }
  } else {
    tet_ids = dt.FiniteTets();
    for (uint32_t f = 0; f < facets_.size(); ++f) {
      for (const auto& tri : facets_[f].InFacetTriangles()) {
        ConstrainedFace cf;
        for (int k = 0; k < 3; ++k) cf.v[k] = points_.VertexIn(tri[k], kOmegaMesh);
        // Inside collars a facet point may be suppressed (never in M_Ω): its
        // triangles are not faces of M_Ω (RipStitchCollar rebuilds them).
        if (cf.v[0] == PointStore::kNoVertex || cf.v[1] == PointStore::kNoVertex ||
            cf.v[2] == PointStore::kNoVertex) {
          continue;
        }
        cf.facet = f;
        faces.push_back(cf);
      }
    }
  }
  std::vector<plc::RegionSeed> seeds = complex.regions;
  for (plc::RegionSeed& sd : seeds) sd.point = norm_.Forward(sd.point);
  std::vector<Vec3> holes;
  for (const Vec3& h : complex.holes) holes.push_back(norm_.Forward(h));
  LabelInput in;
  in.positions = positions;
  in.tets = tets;
  in.constrained_faces = faces;
  in.region_seeds = seeds;
  in.hole_seeds = holes;
  in.keep_bounding_box = options_.keep_bounding_box || facets_.empty();
  // M_Ω's own tets: the adjacency comes from Delaunay3 instead of the
  // labelling's face table (§8 item 43; the same labelling).
  std::vector<uint32_t> compact;
  std::vector<TetId> star;
  const auto omega_tet = [&](size_t i) -> std::array<uint32_t, 4> {
    const TetId t = tet_ids[i];
    return {dt.TetVertex(t, 0).value(), dt.TetVertex(t, 1).value(), dt.TetVertex(t, 2).value(),
            dt.TetVertex(t, 3).value()};
  };
  std::vector<std::array<uint32_t, 4>> copied;  // M_Ω's tets without the adjacency option
  if (!stitched_done_ && !tet_ids.empty() && options_.label_with_adjacency) {
    in.tet_vertices_of = omega_tet;
    in.num_tets = tet_ids.size();
  } else if (!stitched_done_) {
    copied.reserve(tet_ids.size());
    for (size_t i = 0; i < tet_ids.size(); ++i) copied.push_back(omega_tet(i));
    in.tets = copied;
  }
  if (!tet_ids.empty() && options_.label_with_adjacency) {
    compact.assign(dt.TetCapacity(), kNoTet);
    for (uint32_t i = 0; i < tet_ids.size(); ++i) compact[tet_ids[i].value()] = i;
    in.neighbor_slots_of = [&](uint32_t i) {
      const TetId t = tet_ids[i];
      std::array<uint32_t, 4> out;
      for (int f = 0; f < 4; ++f) {
        const TetId n = dt.Neighbor(t, f);
        out[f] = dt.IsGhost(n) ? kNoTet : 4 * compact[n.value()] + dt.NeighborFace(t, f);
      }
      return out;
    };
    in.find_face = [&](uint32_t a, uint32_t b, uint32_t c) -> uint32_t {
      dt.Star(VertexId(a), &star);
      for (TetId t : star) {
        if (dt.IsGhost(t)) continue;
        int other = -1, found = 0;
        for (int k = 0; k < 4; ++k) {
          const uint32_t w = dt.TetVertex(t, k).value();
          if (w == a || w == b || w == c) {
            ++found;
          } else {
            other = k;
          }
        }
        if (found == 3 && other >= 0) return 4 * compact[t.value()] + static_cast<uint32_t>(other);
      }
      return kNoTet;
    };
  }
  absl::StatusOr<Labelling> lab = LabelRegions(in);
  if (!lab.ok()) return lab.status();
  const size_t num_tets = stitched_done_ ? tets.size() : tet_ids.size();
  const auto tet_at = [&](size_t i) -> std::array<uint32_t, 4> {
    return stitched_done_ ? tets[i] : omega_tet(i);
  };
  // Volumes scale by 2^−3e into normalised coordinates (exact).
  const double scale3 = std::ldexp(1.0, -3 * norm_.exponent);
  if (size_target_.size() < nv) size_target_.resize(nv, HUGE_VAL);
  cell_cert_.clear();  // certificates read the size targets
  std::vector<uint8_t> touched(nv, 0);
  // Per-tet targets for PropagateSizeTargets, on M_Ω's own tets only. The
  // labels are rewritten in place: each live finite tet's old label is read
  // before its new one is written (below), and every other slot is reset
  // afterwards, as if the array had been cleared.
  const bool relabel = !tet_ids.empty() && options_.propagate_size_targets;
  const size_t old_labels = relabel && options_.skip_unchanged_tets ? tet_labels_.size() : 0;
  if (relabel) {
    tet_labels_.resize(dt.TetCapacity());
  } else {
    tet_labels_.clear();
  }
  const bool sizes_before = tet_sizes_;
  // Per tet of tet_ids: its label is the one it was tested with when made
  // (or at the last labelling), so EnqueueTetIfBad would find it good.
  std::vector<uint8_t> unchanged(old_labels > 0 ? num_tets : 0, 0);
  // Cells are sized on the output's tets from now on (item 33); the memos
  // of Size() drop.
  omega_.SetLabels(!tet_labels_.empty() && options_.size_kept_tets && !in.keep_bounding_box ? &tet_labels_ : nullptr);
  // The volume bound of each kept component (region), normalised; its size
  // target is the circumradius of a regular tet of that volume (edge a =
  // (6√2·V)^(1/3), circumradius a·√6/4); and the label class of the pair.
  // Components that are not kept have neither (class 0).
  const size_t ncomp = lab->components.size();
  std::vector<double> comp_volume(ncomp, HUGE_VAL), comp_target(ncomp, HUGE_VAL);
  std::vector<uint32_t> comp_class(ncomp, 0);
  bool uniform = true;
  double first_volume = -1;
  for (size_t c = 0; c < ncomp; ++c) {
    if (!lab->components[c].kept) continue;
    double vmax = HUGE_VAL;
    const double region = lab->components[c].max_volume;
    if (region > 0) vmax = region;
    if (global_max_volume > 0) vmax = std::min(vmax, global_max_volume);
    if (vmax != HUGE_VAL) {
      comp_volume[c] = vmax * scale3;  // exact: scale3 is a power of two
      comp_target[c] = std::cbrt(6.0 * std::sqrt(2.0) * comp_volume[c]) * std::sqrt(6.0) / 4.0;
    }
    const std::optional<uint32_t> cls = LabelClassOf(comp_target[c], comp_volume[c]);
    if (!cls) return absl::ResourceExhaustedError("more than 2^30 distinct region volume bounds");
    comp_class[c] = *cls;
    if (first_volume < 0) first_volume = comp_volume[c];
    uniform = uniform && comp_volume[c] == first_volume;
  }
  // With one target for every output tet, "some kept tet at v is above it"
  // is "R_v of v's kept tets is above it": the cell test flags the same tets
  // with one event per cell. With several, a cell takes the smallest target
  // of its tets and refines the coarser region along every interface
  // (nested_boxes_3: 4,290 tets instead of 1,152), so the tets are tested
  // against their own targets (§8 item 34).
  // A volume bound is tested per tet on the volume itself (tet_volumes).
  const bool bounded = !uniform || (first_volume >= 0 && first_volume != HUGE_VAL);
  if (tet_mode_ && !collar_tets_ && (!uniform || options_.tet_sizes || (options_.tet_volumes && bounded))) tet_sizes_ = true;
  for (size_t t = 0; t < num_tets; ++t) {
    const uint32_t c = lab->tet_component[t];
    const bool kept = lab->components[c].kept;
    const double rt = comp_target[c];
    if (!tet_labels_.empty()) {
      const uint32_t slot = tet_ids[t].value();
      // sliver_clear starts clear, as in every new label.
      const TetLabel fresh = TetLabel::Make(dt.Generation(tet_ids[t]) + 1, kept, comp_class[c]);
      if (slot < old_labels) {
        const TetLabel& old = tet_labels_[slot];
        unchanged[t] = old.gen == fresh.gen && old.kept() == fresh.kept() && old.label_class() == fresh.label_class();
        stats_.labels_changed += unchanged[t] == 0;
      }
      tet_labels_[slot] = fresh;
    }
    if (!kept) continue;
    if (comp_volume[c] == HUGE_VAL) continue;
    if (tet_sizes_) continue;
    for (uint32_t v : tet_at(t)) {
      if (rt < size_target_[v]) {
        size_target_[v] = rt;
        touched[v] = 1;
      }
    }
  }
  const size_t delaunay_tets = stitched_done_ ? std::min<size_t>(stitch_report_.outside_tets, num_tets) : num_tets;
  CollectOversizedDelaunayTets(positions, tet_at, delaunay_tets, *lab, comp_volume);
  if (stitched_done_) QueueOversizedStitchRepairs(positions, tets, *lab, comp_volume);
  if (relabel) {
    // The slots of dead and ghost tets hold no label (a stale one would pass
    // PropagateSizeTargets' generation test as its cavity's).
    for (uint32_t i = 0; i < tet_labels_.size(); ++i) {
      const TetId t(i);
      if (i >= dt.TetCapacity() || !dt.IsAlive(t) || dt.IsGhost(t)) tet_labels_[i] = TetLabel{};
    }
  }
  if (released) {
    // The labelling's arrays go before the tests below refill M_Ω's caches
    // (with the caches kept, freeing them early cost 1.2 MB of peak RSS on
    // cube 1e-5: the same glibc threshold).
    lab = absl::StatusOr<Labelling>();
    std::vector<uint32_t>().swap(compact);
    std::vector<ConstrainedFace>().swap(faces);
    std::vector<std::array<uint32_t, 4>>().swap(tets);
    std::vector<std::array<uint32_t, 4>>().swap(copied);
  }
  bool any = false;
  if (tet_mode_) {
    // A tet keeping the label it was tested with was good then (a bad one
    // was enqueued, and Destroy removes it: it warps within θr of the
    // circumcentre or inserts it) and TetBad reads only the tet, its label
    // and tet_sizes_: it is good now unless tet_sizes_ just changed.
    const bool retest_all = tet_sizes_ != sizes_before;
    for (size_t t = 0; t < tet_ids.size(); ++t) {
      if (!retest_all && !unchanged.empty() && unchanged[t]) {
        ++stats_.labels_unchanged;
        continue;
      }
      any = EnqueueTetIfBad(tet_ids[t]) || any;
    }
  }
  for (uint32_t v = 0; v < nv; ++v) {
    if (!touched[v] && !all_vertices) continue;
    const CellSize cs = omega_.Size(VertexId(v));
    if (IsBad(VertexId(v), cs)) {
      RefreshEvents(VertexId(v), &cs);
      any = true;
    }
  }
  return any;
}

// Tet t is in a kept component with a volume bound and its volume is
// above it (normalised coordinates; 1e-9 relative slack downwards, so a
// tet at the bound within rounding counts as above).
bool KeptTetAboveBound(std::span<const Vec3> positions, const std::array<uint32_t, 4>& q, size_t t,
                       const Labelling& lab, std::span<const double> comp_volume) {
  const uint32_t c = lab.tet_component[t];
  if (!lab.components[c].kept || comp_volume[c] == HUGE_VAL) return false;
  const Vec3 &a = positions[q[0]], &b = positions[q[1]], &cc = positions[q[2]], &d = positions[q[3]];
  const double vol = geom::Dot(b - a, geom::Cross(cc - a, d - a)) / 6;
  return vol > comp_volume[c] * (1 - 1e-9);
}

void Refiner::CollectOversizedDelaunayTets(std::span<const Vec3> positions,
                                           absl::FunctionRef<std::array<uint32_t, 4>(size_t)> tet_at,
                                           size_t count, const Labelling& lab,
                                           std::span<const double> comp_volume) {
  // M_Ω's kept tets (the first `count` of `tets`) above their volume bound.
  // The cell test sizes a cell clipped by ∂Ω by its corners in Ω, so the
  // cell can look small while a tet at ∂Ω, its circumcentre outside Ω, is
  // above the bound. keep_bounding_box keeps those tets (as does a PLC
  // without facets): cube.poly --keep-bounding-box --max-volume 1e-2 had a
  // tet of 0.0130, tetra.poly 0.0113, and on the collar path crease_pair_30
  // with 1e-4 was refused for 13 tets above it (session 35). Such a tet
  // gets its circumcentre, or the nearest point of Ω to it; InsertSizePoints
  // inserts them once the cell test finds nothing more.
  size_points_.clear();
  const geom::Box3& cube = omega_.cube();
  for (size_t t = 0; t < count; ++t) {
    const std::array<uint32_t, 4> q = tet_at(t);
    if (!KeptTetAboveBound(positions, q, t, lab, comp_volume)) continue;
    const Vec3 o = geom::TetCircumcenter(positions[q[0]], positions[q[1]], positions[q[2]], positions[q[3]]);
    Vec3 x = o;
    for (int k = 0; k < 3; ++k) x[k] = std::clamp(x[k], cube.lo[k], cube.hi[k]);
    size_points_.emplace_back(x, geom::Dist(o, positions[q[0]]));
  }
  std::sort(size_points_.begin(), size_points_.end(), [](const auto& l, const auto& r) {
    return std::tie(l.first.x, l.first.y, l.first.z) < std::tie(r.first.x, r.first.y, r.first.z);
  });
  size_points_.erase(std::unique(size_points_.begin(), size_points_.end(),
                                 [](const auto& l, const auto& r) { return l.first == r.first; }),
                     size_points_.end());
}

void Refiner::QueueOversizedStitchRepairs(std::span<const Vec3> positions,
                                          std::span<const std::array<uint32_t, 4>> tets, const Labelling& lab,
                                          std::span<const double> comp_volume) {
  // max_volume inside the collars. The stars and books are not refined by
  // size events: M_Ω's cells there still hold the points the stitch
  // removes, so the size rounds see small cells while a star (c, face) has
  // volume ρ·area(face)/3 and a book (v, w, a, b) grows with |ab|. Measured
  // before this (session 35): crease_pair_30deg and knife_edge.poly with
  // --max-volume 1e-5 were refused ("a tet of volume 1.05e-05 next to the
  // creases exceeds max_volume 1e-05"). An oversized star gets the point of
  // its ball's sphere over its face's centroid, a book the point of its
  // circle nearest its T′ edge's midpoint: the face or edge is then split
  // on S, as a COLLAR repair would (RepairStitchFailures inserts them).
  stitch_failures_.clear();
  std::vector<uint32_t> ball_of_vertex(positions.size(), CollarIndex::kNone);
  for (uint32_t i = 0; i < collars_.size(); ++i) {
    const uint32_t v = points_.VertexIn(collar_centre_[i], kOmegaMesh);
    if (v != PointStore::kNoVertex && v < ball_of_vertex.size()) ball_of_vertex[v] = i;
  }
  // FindContaining names the lowest ball with x strictly inside; a point
  // constructed on a sphere or circle can be inside its own ball(s) by
  // rounding, which does not take it off S.
  auto on_s = [&](const Vec3& x, uint32_t i, uint32_t j) {
    const uint32_t o = collars_.FindContaining(x);
    return o == CollarIndex::kNone || o == i || o == j;
  };
  auto circle_point = [&](uint32_t i, uint32_t j, const Vec3& near, Vec3* x) {
    Circle3 circle;
    if (!SphereSphereCircle(collars_.ball(i), collars_.ball(j), &circle)) return false;
    return NearestCirclePoint(circle, near, x) && on_s(*x, i, j);
  };
  for (size_t t = stitch_report_.outside_tets; t < tets.size(); ++t) {
    if (!KeptTetAboveBound(positions, tets[t], t, lab, comp_volume)) continue;
    const auto& q = tets[t];
    std::array<uint32_t, 2> centres{}, others{};
    int nc = 0, no = 0;
    for (uint32_t v : q) {
      const uint32_t ball = ball_of_vertex[v];
      if (ball != CollarIndex::kNone && nc < 2) {
        centres[nc++] = ball;
      } else if (no < 2) {
        others[no++] = v;
      }
    }
    if (nc == 1) {
      // A star: its face's centroid projected from the ball's centre; when
      // that lies in a neighbouring ball, the face is at their circle: its
      // point nearest the centroid.
      const uint32_t i = centres[0];
      const CollarBall& ball = collars_.ball(i);
      Vec3 g(0, 0, 0);
      for (uint32_t v : q) {
        if (ball_of_vertex[v] != i) g = g + positions[v] / 3.0;
      }
      const Vec3 dir = g - ball.center;
      const double len = geom::Norm(dir);
      if (!(len > 0)) continue;
      Vec3 x = ball.center + (ball.radius / len) * dir;
      if (on_s(x, i, i)) {
        stitch_failures_.push_back({x, i, 2});
        continue;
      }
      const uint32_t k = collars_.FindContaining(x);
      if (circle_point(i, k, g, &x)) {
        stitch_failures_.push_back({x, i, 1});
      }
    } else if (nc == 2 && no == 2) {
      // A book: the crease circle's point nearest its T′ edge's midpoint.
      Vec3 x;
      if (circle_point(centres[0], centres[1], 0.5 * (positions[others[0]] + positions[others[1]]), &x)) {
        stitch_failures_.push_back({x, centres[0], 1});
      }
    }
  }
  stats_.stitch_size_repairs += stitch_failures_.size();

  if (std::getenv("SVRC_COLLAR_DEBUG") != nullptr) {
    size_t over = 0, over_out = 0;
    for (size_t t = 0; t < tets.size(); ++t) {
      if (!KeptTetAboveBound(positions, tets[t], t, lab, comp_volume)) continue;
      ++over;
      if (t < stitch_report_.outside_tets) ++over_out;
    }
    std::fprintf(stderr, "size pass: %zu stitched tets over (%zu outside), %zu repairs queued\n", over, over_out,
                 stitch_failures_.size());
  }
}

absl::StatusOr<uint64_t> Refiner::BreakSlivers(double min_deg, bool first) {
  const AddSeconds timer(&stats_.seconds_breaks);
  const delaunay::Delaunay3& dt = omega_.dt();
  struct Sliver {
    TetId t;
    uint32_t gen;
    Vec3 cc;
    double r;
  };
  std::vector<Sliver> slivers;
  // A dihedral angle θ at edge e of faces A1, A2 gives 6|V| = 4·A1·A2·sin θ
  // / |e| ≤ ℓ³·sin θ (each face has area ≤ |e|·ℓ/2, ℓ the longest edge): a
  // tet with 6|V| above ℓ³·sin(min_deg) has no angle below min_deg, and the
  // dihedrals (atan2 per edge) are measured only for the others.
  const double sin_min = std::sin(min_deg * M_PI / 180) * (1 + 1e-6);
  const bool reuse = !first && options_.reuse_round_work;
  // The slots in order, as FiniteTets() lists them. A label marked
  // sliver_clear whose generation is its slot's is a live finite tet (only
  // finite tets' labels are ever marked, below, and a new tet's label starts
  // unmarked), so a later round skips it reading the label and the slot's
  // generation only, not the tet (32 bytes per slot: most of the rounds'
  // memory traffic on cube --max-volume 1e-6, where they skip 5.6 M tets).
  const uint32_t slots = dt.TetCapacity();
  for (uint32_t s = 0; s < slots; ++s) {
    const TetId t(s);
    const TetLabel* lab = LiveLabel(t);
    if (lab == nullptr) continue;  // a free slot, or a tet without a label
    if (reuse && lab->sliver_clear()) {
      ++stats_.sliver_scan_reused;
      continue;
    }
    if (!dt.IsAlive(t) || dt.IsGhost(t)) continue;
    // TetLabel::sliver_clear: set below on every live label a round reads,
    // so the first round leaves none stale; new tets' labels start clear of it.
    TetLabel& label = tet_labels_[t.value()];  // *lab
    label.set_sliver_clear(true);  // until a test below keeps it
    if (!label.kept()) continue;
    std::array<Vec3, 4> x;
    for (int k = 0; k < 4; ++k) x[k] = dt.Point(dt.TetVertex(t, k));
    if (Volume6(x) > LongestEdgeCubed(x) * sin_min) continue;
    if (!(MeasureSliverTet(x[0], x[1], x[2], x[3]).min_dihedral_deg < min_deg)) continue;
    Vec3 cc;
    if (!omega_.PlainCorner(t, &cc)) continue;
    label.set_sliver_clear(false);  // the ball test below may change when balls die
    // Only slivers whose circumcentre would be inserted as is: one inside a
    // lower ball would split that facet triangle or segment piece instead,
    // and such splits next to the features cascade (measured:
    // box_internal_facets_k3 at 1.414 453 → 714 tets, fan_6x60deg 3,179 →
    // 4,973 with them).
    // With candidate points (§8 item 69) the test is made at insertion
    // time, for the point chosen then.
    if (options_.sliver_candidates == 0 && YieldsAt(dt.TetVertex(t, 0), cc)) {
      ++stats_.sliver_yields_skipped;
      continue;
    }
    slivers.push_back({t, dt.Generation(t), cc, geom::Dist(cc, x[0])});
  }
  uint64_t broken = 0;
  for (const Sliver& sl : slivers) {
    // An earlier insertion of this round may have destroyed it.
    if (!dt.IsAlive(sl.t) || dt.Generation(sl.t) != sl.gen) continue;
    Vec3 at = sl.cc;
    VertexId near = dt.TetVertex(sl.t, 0);
    if (options_.sliver_candidates > 0 && !PickSliverPoint(sl.t, sl.cc, sl.r, min_deg, &at, &near)) {
      ++stats_.sliver_yields_skipped;
      continue;
    }
    absl::Status st = DestroyOmegaAt(at, sl.r, sl.t, near);
    if (!st.ok()) return st;
    ++stats_.slivers_broken;
    ++broken;
  }
  if (broken > 0) ++stats_.sliver_rounds;
  return broken;
}

bool Refiner::YieldsAt(VertexId v, const Vec3& q) const {
  // DestroyOmegaAt's line 9 for a point of V(v): a lower ball (linked to v's
  // cell, as every ball meeting V(v) is) with q strictly inside.
  bool yields = false;
  blg_.ForEachBall(kOmegaMesh, v.value(), [&](BallId b) {
    if (!yields && !balls_.IsVertexBall(b) && balls_.IsAlive(b) && Inside(b, q)) yields = true;
  });
  return yields;
}

double Refiner::NewTetsMinDihedral(const Vec3& q, TetId t) {
  // Bowyer–Watson's cavity of q as Insert would find it (q's id as the
  // perturbation's), and the smallest dihedral angle of the tets q would
  // make with its boundary faces; nothing is changed.
  const delaunay::Delaunay3& dt = omega_.dt();
  constexpr size_t kMaxCavity = 512;
  if (!dt.CavityBoundary(q, points_.size(), t, kMaxCavity, &cavity_faces_)) return -1;
  double worst = 180;
  for (uint32_t slot : cavity_faces_) {
    const TetId c(slot / 4);
    std::array<Vec3, 3> face;
    for (int k = 0, j = 0; k < 4; ++k) {
      if (k != static_cast<int>(slot % 4)) face[j++] = dt.Point(dt.TetVertex(c, k));
    }
    worst = std::min(worst, MeasureSliverTet(face[0], face[1], face[2], q).min_dihedral_deg);
  }
  return worst;
}

bool Refiner::PickSliverPoint(TetId t, const Vec3& cc, double r, double min_deg, Vec3* at, VertexId* near) {
  // §8 item 69. The candidates: the circumcentre, then K points of the ball
  // B(cc, ρ·r), ρ = sliver_pick_radius < 1, so each is strictly inside the
  // sliver's circumsphere (q in conflict with t, which q's insertion then
  // destroys). Fixed points, not random ones: outputs stay the same on
  // every run. Point k: radius ρ·r·cbrt((k + ½)/K) (uniform in volume), on
  // the golden-angle spiral of directions.
  const delaunay::Delaunay3& dt = omega_.dt();
  const geom::Box3& cube = omega_.cube();
  const int n = options_.sliver_candidates;
  double best = -2;
  bool found = false;
  for (int k = -1; k < n; ++k) {
    Vec3 q = cc;
    if (k >= 0) {
      const double z = 1 - (2.0 * k + 1) / n;
      const double s = std::sqrt(std::max(0.0, 1 - z * z));
      const double phi = k * 2.399963229728653;  // π(3 − √5)
      const double rad = options_.sliver_pick_radius * r * std::cbrt((k + 0.5) / n);
      q = cc + Vec3{rad * s * std::cos(phi), rad * s * std::sin(phi), rad * z};
      bool inside = true;
      for (int a = 0; a < 3; ++a) inside = inside && q[a] > cube.lo[a] && q[a] < cube.hi[a];
      if (!inside) continue;
    }
    const double score = NewTetsMinDihedral(q, t);
    if (!(score > best)) continue;
    const VertexId v = k < 0 ? dt.TetVertex(t, 0) : dt.NearestVertex(q, t);
    if (!options_.sliver_yield && YieldsAt(v, q)) continue;
    best = score;
    *at = q;
    *near = v;
    found = true;
    if (k < 0 && score >= min_deg) break;  // the circumcentre is good enough
  }
  if (found && !(*at == cc)) ++stats_.sliver_picks_off_centre;
  return found;
}

absl::StatusOr<bool> Refiner::BreakFlatTets() {
  const AddSeconds timer(&stats_.seconds_breaks);
  const delaunay::Delaunay3& dt = omega_.dt();
  const geom::Box3& cube = omega_.cube();
  auto on_box = [&](const Vec3& p, int axis, int side) { return p[axis] == (side ? cube.hi[axis] : cube.lo[axis]); };
  // The facets a point lies on (input points, segment points, facet points).
  auto facets_of = [&](PointId p, std::vector<uint32_t>* out) {
    out->clear();
    const FeatureId parent = points_.Parent(p);
    if (p.value() < num_input_) {
      *out = point_facets_[p.value()];
    } else if (features_.Dim(parent) == 1) {
      *out = seg_facets_[features_.Index(parent)];
    } else if (features_.Dim(parent) == 2) {
      out->push_back(features_.Index(parent));
    }
  };
  std::vector<Vec3> centroids;
  std::vector<BallId> balls;
  std::vector<uint32_t> fa, fb;
  for (TetId t : dt.FiniteTets()) {
    std::array<Vec3, 4> x;
    for (int k = 0; k < 4; ++k) x[k] = dt.Point(dt.TetVertex(t, k));
    if (Volume6(x) > 1e-6 * LongestEdgeCubed(x)) continue;
    std::array<PointId, 4> q;
    for (int k = 0; k < 4; ++k) q[k] = omega_.PointOf(dt.TetVertex(t, k));
    bool boxed = false;
    for (int axis = 0; axis < 3 && !boxed; ++axis) {
      for (int side = 0; side < 2 && !boxed; ++side) {
        boxed = on_box(x[0], axis, side) && on_box(x[1], axis, side) && on_box(x[2], axis, side) &&
                on_box(x[3], axis, side);
      }
    }
    if (boxed) continue;
    // A facet containing all four points?
    facets_of(q[0], &fa);
    for (int k = 1; k < 4 && !fa.empty(); ++k) {
      facets_of(q[k], &fb);
      std::vector<uint32_t> both;
      for (uint32_t f : fa) {
        if (std::find(fb.begin(), fb.end(), f) != fb.end()) both.push_back(f);
      }
      fa.swap(both);
    }
    if (fa.empty()) {
      centroids.push_back(0.25 * (x[0] + x[1] + x[2] + x[3]));
      continue;
    }
    const uint32_t f = fa.front();
    const FacetMesh& m = facets_[f];
    for (int skip = 0; skip < 4; ++skip) {
      std::array<uint32_t, 3> k;
      int n = 0;
      bool ok = true;
      for (int i = 0; i < 4; ++i) {
        if (i == skip) continue;
        const uint32_t v2 = points_.VertexIn(q[i], FacetMeshId(f));
        ok = ok && v2 != PointStore::kNoVertex;
        k[n++] = v2;
      }
      if (!ok) continue;
      std::vector<TriId2> star;
      m.dt().Star(VertexId2(k[0]), &star);
      for (TriId2 tri : star) {
        int hits = 0;
        for (int e = 0; e < 3; ++e) {
          const uint32_t w = m.dt().TriVertex(tri, e).value();
          hits += (w == k[1]) + (w == k[2]);
        }
        if (hits == 2 && m.TriBall(tri).valid()) balls.push_back(m.TriBall(tri));
      }
    }
  }
  bool any = false;
  for (BallId b : balls) {
    if (!balls_.IsAlive(b)) continue;
    EnqueueEncroached(b);
    ++stats_.flat_tets_broken;
    any = true;
  }
  for (const Vec3& c : centroids) {
    const VertexId near = dt.NearestVertex(c);
    const double r = geom::Dist(dt.Point(near), c);
    if (!(r > 0)) continue;
    absl::Status s = DestroyOmegaAt(c, r, dt.VertexTet(near), near);
    if (!s.ok()) return s;
    ++stats_.flat_tets_broken;
    any = true;
  }
  return any;
}

bool Refiner::OmegaHasEdge(PointId a, PointId b) const {
  const uint32_t va = points_.VertexIn(a, kOmegaMesh), vb = points_.VertexIn(b, kOmegaMesh);
  if (va == PointStore::kNoVertex || vb == PointStore::kNoVertex) return false;
  for (VertexId x : omega_.dt().NeighborsView(VertexId(va))) {
    if (x.value() == vb) return true;
  }
  return false;
}

bool Refiner::OmegaHasFace(PointId a, PointId b, PointId c) const {
  const uint32_t va = points_.VertexIn(a, kOmegaMesh), vb = points_.VertexIn(b, kOmegaMesh),
                 vc = points_.VertexIn(c, kOmegaMesh);
  if (va == PointStore::kNoVertex || vb == PointStore::kNoVertex || vc == PointStore::kNoVertex) return false;
  const delaunay::Delaunay3& dt = omega_.dt();
  for (TetId t : dt.StarView(VertexId(va))) {
    int hits = 0;
    for (int k = 0; k < 4; ++k) {
      const uint32_t w = dt.TetVertex(t, k).value();
      hits += (w == vb) + (w == vc);
    }
    if (hits == 2) return true;
  }
  return false;
}

bool Refiner::FacetHasEdge(uint32_t f, PointId a, PointId b) {
  const MeshId mesh = FacetMeshId(f);
  const uint32_t va = points_.VertexIn(a, mesh), vb = points_.VertexIn(b, mesh);
  if (va == PointStore::kNoVertex || vb == PointStore::kNoVertex) return false;
  facets_[f].dt().Neighbors(VertexId2(va), &nbrs2_);
  for (VertexId2 x : nbrs2_) {
    if (x.value() == vb) return true;
  }
  return false;
}

bool Refiner::EnqueueMissing() {
  // Local tests (O(degree) each) instead of sorting every simplex of M_Ω:
  // this runs whenever the queues run dry (once per size round and once per
  // COLLAR round too). A simplex found in M_Ω (and in its facets' meshes)
  // stays there until an insertion destroys a tet holding it, which bumps
  // the cell generation of each of its vertices; one found inside the
  // collars stays inside (balls are only added). Both are remembered per
  // ball (ids are never reused), so only simplices whose vertices changed
  // are tested again. The enqueue order is that of the full scan.
  constexpr uint64_t kInside = ~uint64_t{0};
  if (!options_.reuse_round_work) known_present_.clear();
  if (known_present_.size() < balls_.size()) known_present_.resize(balls_.size() + balls_.size() / 2, 0);
  // 1 + Σ generations of the vertices in M_Ω (generations only grow, so an
  // equal sum means none moved), or 0 if one is not in M_Ω.
  auto key_of = [&](std::span<const PointId> verts) -> uint64_t {
    uint64_t key = 1;
    for (PointId p : verts) {
      const uint32_t v = points_.VertexIn(p, kOmegaMesh);
      if (v == PointStore::kNoVertex) return 0;
      key += omega_.CellGeneration(VertexId(v));
    }
    return key;
  };
  // Whether ball b's simplex is known inside the collars, or known in M_Ω
  // with the same key; *key receives the current key unless inside.
  auto known = [&](BallId b, std::span<const PointId> verts, uint64_t* key) {
    const uint64_t k = known_present_[b.value()];
    if (k == kInside) return true;
    *key = key_of(verts);
    return *key != 0 && k == *key;
  };
  bool more = false;
  for (uint32_t sg = 0; sg < segs_.size(); ++sg) {
    SegmentMesh& m = segs_[sg];
    for (uint32_t v = 0; m.Next(v) != SegmentMesh::kNil; v = m.Next(v)) {
      const PointId a = m.PointOf(v), b = m.PointOf(m.Next(v));
      const BallId piece = m.PieceBall(v);
      const std::array<PointId, 2> ends{a, b};
      // Facet meshes change without M_Ω: the key covers M_Ω only, so a
      // segment of facets is always tested.
      const bool cacheable = piece.valid() && seg_facets_[sg].empty();
      uint64_t key = 0;
      if (cacheable && known(piece, ends, &key)) continue;
      if (options_.collars && InsideCollars(ends)) {
        if (cacheable) known_present_[piece.value()] = kInside;
        continue;
      }
      bool missing = !OmegaHasEdge(a, b);
      for (uint32_t fc : seg_facets_[sg]) missing = missing || !FacetHasEdge(fc, a, b);
      if (missing) {
        ++stats_.tied_balls;
        EnqueueEncroached(piece);
        more = true;
      } else if (cacheable) {
        known_present_[piece.value()] = key;
      }
    }
  }
  for (uint32_t f = 0; f < facets_.size(); ++f) {
    const delaunay::Delaunay2& dt = facets_[f].dt();
    for (TriId2 t : dt.Triangles()) {
      const BallId b = facets_[f].TriBall(t);
      if (!b.valid()) continue;
      const std::array<PointId, 3> verts{balls_.Vertex(b, 0), balls_.Vertex(b, 1), balls_.Vertex(b, 2)};
      uint64_t key = 0;
      if (known(b, verts, &key)) continue;
      if (options_.collars && InsideCollars(verts)) {
        known_present_[b.value()] = kInside;
        continue;
      }
      if (!OmegaHasFace(verts[0], verts[1], verts[2])) {
        ++stats_.tied_balls;
        EnqueueEncroached(b);
        more = true;
      } else {
        known_present_[b.value()] = key;
      }
    }
  }
  return more;
}

absl::Status Refiner::VerifyConformity() const {
  for (uint32_t sg = 0; sg < segs_.size(); ++sg) {
    const SegmentMesh& m = segs_[sg];
    for (uint32_t v = 0; m.Next(v) != SegmentMesh::kNil; v = m.Next(v)) {
      std::array<uint32_t, 2> e{m.PointOf(v).value(), m.PointOf(m.Next(v)).value()};
      std::sort(e.begin(), e.end());
      if (options_.collars && InsideCollars(std::array<PointId, 2>{PointId(e[0]), PointId(e[1])})) continue;
      if (!OmegaHasEdge(PointId(e[0]), PointId(e[1]))) {
        return absl::InternalError(absl::StrCat("SVRC: piece (", e[0], ", ", e[1], ") of segment ", sg,
                                                " is not an edge of M_Ω"));
      }
    }
  }
  for (uint32_t f = 0; f < facets_.size(); ++f) {
    for (const auto& tri : facets_[f].InFacetTriangles()) {
      std::array<uint32_t, 3> k{tri[0].value(), tri[1].value(), tri[2].value()};
      std::sort(k.begin(), k.end());
      if (options_.collars && InsideCollars(std::array<PointId, 3>{PointId(k[0]), PointId(k[1]), PointId(k[2])})) {
        continue;
      }
      if (!OmegaHasFace(PointId(k[0]), PointId(k[1]), PointId(k[2]))) {
        return absl::InternalError(absl::StrCat("SVRC: in-facet triangle (", k[0], ", ", k[1], ", ", k[2],
                                                ") of facet ", f, " is not a face of M_Ω"));
      }
    }
  }
  return absl::OkStatus();
}

void Refiner::FillCounters(RefineStats* out) const {
  RefineStats& st = *out;
  st.vertices = omega_.dt().NumVertices();
  // Inputs in M_Ω: all but the duplicates at the end, fewer in a failed run.
  st.input_vertices = 0;
  for (uint32_t i = 0; i < num_input_; ++i) st.input_vertices += points_.InMesh(PointId(i), kOmegaMesh);
  // Created points (after the inputs and Ω's corners). Segment points in M_Ω:
  // all at the end (conformity), fewer in a failed run.
  uint64_t segment_in_omega = 0;
  st.facet_vertices_in_omega = st.segment_vertices_in_collars = st.facet_vertices_in_collars = 0;
  for (uint32_t i = num_input_ + 8; i < points_.size(); ++i) {
    const PointId p(i);
    const Cd cd = points_.CdOf(p);
    const bool on_feature = points_.Parent(p) != FeatureTable::Omega();
    segment_in_omega += cd.dim == 1 && points_.InMesh(p, kOmegaMesh);
    st.facet_vertices_in_omega += cd == kCdFacet && on_feature && points_.InMesh(p, kOmegaMesh);
    if (collars_.size() > 0 && (cd.dim == 1 || cd.dim == 2) && on_feature && collars_.StrictlyInside(points_.Xyz(p))) {
      ++(cd.dim == 1 ? st.segment_vertices_in_collars : st.facet_vertices_in_collars);
    }
  }
  st.collar_rounds = collar_rounds_;
  st.collar_balls_computed = restriction_cache_.balls_computed;
  st.collar_balls_reused = restriction_cache_.balls_reused;
  st.collar_owners_computed = restriction_cache_.owners_computed;
  st.collar_owners_reused = restriction_cache_.owners_reused;
  st.collar_circle_owners_computed = restriction_cache_.circle_owners_computed;
  st.collar_circle_owners_reused = restriction_cache_.circle_owners_reused;
  st.collar_repairs = collar_repairs_;
  st.collar_repairs_by_reason = collar_repairs_by_reason_;
  st.arc_repairs = arc_repairs_;
  st.stitched_arc_crossings = stitched_arc_crossings_;
  st.stitched_crossings = stitched_crossings_;
  st.steiner_vertices = st.vertices - 8 - st.input_vertices - segment_in_omega - st.facet_vertices_in_omega;
  const WorkQueues::Stats& q = queues_.stats();
  for (int i = 0; i < kNumEventTypes; ++i) {
    st.events_pushed[i] = q.pushed[i];
    st.events_popped[i] = q.popped[i];
    st.events_stale[i] = q.stale[i];
    st.events_removed_dead[i] = q.removed_dead[i];
  }
  st.ball_records = balls_.size();
  st.balls_alive = balls_.NumAlive();
  st.buckets_walked = q.buckets_walked;
  st.max_bucket_walk = q.max_walk_one_op;
  st.links_added = blg_.stats().links_added;
  st.links_removed = blg_.stats().links_removed;
  st.link_changes_by_kind = stats_.link_changes_by_kind;
  st.insertions_by_kind = stats_.insertions_by_kind;
  st.seconds_by_kind = stats_.seconds_by_kind;
  st.events_by_kind = stats_.events_by_kind;
  st.seconds_other_events = stats_.seconds_other_events;
  st.other_events = stats_.other_events;
  st.clipped_cells = omega_.stats().clipped_queries;
  st.sizes_shrunk = omega_.stats().shrunk_sizes;
  st.size_queries = omega_.stats().size_queries;
  st.sizes_computed = omega_.stats().computed_sizes;
  st.circumcentres = omega_.stats().circumcentres;
  st.neighbor_cache_flushes = omega_.dt().neighbor_cache_flushes();
}

PointSetRefinement Refiner::Output(std::span<const Vec3> input) {
  const delaunay::Delaunay3& dt = omega_.dt();
  PointSetRefinement out;
  RefineStats& st = stats_;
  FillCounters(&st);
  ReleaseRefinementState();
  for (uint32_t i = 0; i < collars_.size(); ++i) {
    const FeatureId f = points_.Parent(collar_centre_[i]);
    out.collars.push_back({collar_centre_[i].value(), features_.Dim(f), features_.Index(f), collars_.ball(i).center,
                           collars_.ball(i).radius});
  }
  out.num_input = num_input_;
  out.positions.resize(points_.size());
  out.normalised_positions.resize(points_.size());
  for (uint32_t i = 0; i < points_.size(); ++i) {
    out.normalised_positions[i] = points_.Xyz(PointId(i));
    // Inputs come back bit-exactly from the original array; Steiner points
    // through the exact-scale, one-rounding back map.
    out.positions[i] = i < num_input_ ? input[i] : norm_.Backward(points_.Xyz(PointId(i)));
  }
  if (options_.collars) {
    out.point_cd.resize(points_.size());
    for (uint32_t i = 0; i < points_.size(); ++i) {
      const Cd cd = points_.CdOf(PointId(i));
      out.point_cd[i] = static_cast<uint8_t>(10 * cd.dim + cd.collar);
    }
  }
  out.input_vertex.resize(num_input_);
  for (uint32_t i = 0; i < num_input_; ++i) out.input_vertex[i] = duplicate_of_[i];
  if (stitched_done_) {
    // Moved into out.tets at the end (StitchedFacetFaces reads stitched_).
  } else {
    const bool labelled = !tet_labels_.empty();
    const std::vector<TetId> finite = dt.FiniteTets();
    out.tets.resize(finite.size());
    // With the adjacency in the same order (the index of a slot in `finite`;
    // ghosts are the hull), when asked for.
    const bool neighbors = options_.output_tet_neighbors;
    if (neighbors) out.tet_neighbors.resize(finite.size());
    if (labelled) out.tet_outside.reserve(finite.size());
    // `finite` is in slot order, so a slot's index is its rank among the
    // finite slots: a bit per slot and a count per 64 (cube 1e-6: 0.36 MB,
    // in cache) instead of an index per slot (7.6 MB read at random, +0.1 s).
    std::vector<uint64_t> is_finite(neighbors ? (size_t{dt.TetCapacity()} + 63) / 64 : 0, 0);
    for (const TetId t : finite) {
      if (neighbors) is_finite[t.value() >> 6] |= uint64_t{1} << (t.value() & 63);
    }
    std::vector<uint32_t> finite_before(is_finite.size());
    for (uint32_t w = 0, count = 0; w < is_finite.size(); ++w) {
      finite_before[w] = count;
      count += static_cast<uint32_t>(std::popcount(is_finite[w]));
    }
    for (uint32_t i = 0; i < finite.size(); ++i) {
      const TetId t = finite[i];
      for (int k = 0; k < 4; ++k) {
        out.tets[i][k] = omega_.PointOf(dt.TetVertex(t, k)).value();
        if (!neighbors) continue;
        // A finite tet's neighbour is alive: a ghost unless its bit is set
        // (dt.IsGhost would read the neighbour's row, a cache miss each).
        const uint32_t s = dt.Neighbor(t, k).value();
        const uint64_t word = is_finite[s >> 6], bit = uint64_t{1} << (s & 63);
        out.tet_neighbors[i][k] =
            (word & bit) == 0 ? 0xFFFFFFFFu
                              : finite_before[s >> 6] + static_cast<uint32_t>(std::popcount(word & (bit - 1)));
      }
      if (labelled) {
        const TetLabel* lab = LiveLabel(t);
        out.tet_outside.push_back(lab != nullptr && !lab->kept() ? 1 : 0);
      }
    }
  }
  std::vector<uint8_t> in_stitched;
  if (stitched_done_) {
    in_stitched.assign(points_.size(), 0);
    for (const auto& t : stitched_) {
      for (uint32_t p : t) in_stitched[p] = 1;
    }
  }
  out.normalisation_translation = norm_.translation;
  out.normalisation_exponent = norm_.exponent;
  out.omega.Add(norm_.Backward(omega_.cube().lo));
  out.omega.Add(norm_.Backward(omega_.cube().hi));
  for (uint32_t sg = 0; sg < segs_.size(); ++sg) {
    const SegmentMesh& m = segs_[sg];
    std::vector<uint32_t> chain;
    for (uint32_t v = 0; v != SegmentMesh::kNil; v = m.Next(v)) chain.push_back(m.PointOf(v).value());
    if (chain.front() != seg_input_a_[sg]) std::reverse(chain.begin(), chain.end());
    if (stitched_done_) {
      // Crease points without a ball lie inside a collar, on a book's axis,
      // and RipStitchCollar removed them: the segment's pieces are the
      // axis edges between the points that remain (measured on
      // knife_edge.poly: the sliver pass found chain edge (12, 1096) missing).
      std::erase_if(chain, [&](uint32_t p) { return !in_stitched[p]; });
    }
    out.segment_chains.push_back(std::move(chain));
  }

  if (!stitched_done_) {
    for (uint32_t f = 0; f < facets_.size(); ++f) {
      std::vector<std::array<uint32_t, 3>> tris;
      for (const auto& tri : facets_[f].InFacetTriangles()) tris.push_back({tri[0].value(), tri[1].value(), tri[2].value()});
      out.facet_triangles.push_back(std::move(tris));
    }
  } else {
    // After RipStitchCollar the final mesh's faces on a facet are no longer
    // all triangles of its facet mesh: M_F keeps the points suppressed inside
    // the collars (Figure 3.9), which never reached M_Ω, so its triangles that
    // straddle the collar surface are not faces of the final tets (measured on
    // crease_pair 30°: 2179 such M_F triangles on one wall, and the facets'
    // covered area stopped at 0.249969 of 0.25). The faces of the final tets
    // are what the labelling and the checker see: a face is on facet f when
    // its three vertices lie on f's feature and its centroid is in f's region
    // (a triangle with its corners on a non-convex outline can span a notch or
    // a hole). Outside the collars these are exactly M_F's triangles (the
    // conformity of §3.2.2); inside, the stitched fans (Theorem 4's proof).
    out.facet_triangles.assign(facets_.size(), {});
    for (const auto& [f, k] : StitchedFacetFaces(&st.stitch_faces_on_plane)) out.facet_triangles[f].push_back(k);
  }
  // The degrees from one pass over the tets (Euler's formula on each link),
  // not a star walk per vertex (1.4% of cube --max-volume 1e-5's
  // instructions, session 25).
  for (uint32_t d : dt.Degrees()) st.max_degree = std::max(st.max_degree, d);
  // Under tet_quality the cells' aspect is not what bounds the output (the
  // tets' radius-edge is; the quality report has it), and sizing every cell
  // once more was 3% of cube 1e-4's instructions: max_aspect stays 0.
  for (uint32_t w = 0; w < dt.NumVertices() && !tet_mode_; ++w) {
    const CellSize cs = omega_.Size(VertexId(w));
    if (cs.inradius > 0) st.max_aspect = std::max(st.max_aspect, cs.kept_outradius / cs.inradius);
  }
  if (stitched_done_) out.tets = std::move(stitched_);
  out.stats = st;
  return out;
}

}  // namespace

void RefineStats::ExportTo(mesh::MeshStats* out) const {
  static const char* kTypes[] = {"skinny", "encroached", "unresolved", "collar"};
  out->Set("svrc.vertices", static_cast<double>(vertices));
  out->Set("svrc.vertices_dim0", static_cast<double>(input_vertices));
  out->Set("svrc.vertices_dim1", static_cast<double>(segment_vertices));
  out->Set("svrc.vertices_dim2", static_cast<double>(facet_vertices_in_omega));
  out->Set("svrc.facet_mesh_vertices", static_cast<double>(facet_vertices));
  if (collars > 0) {
    out->Set("svrc.segment_vertices_in_collars", static_cast<double>(segment_vertices_in_collars));
    out->Set("svrc.facet_vertices_in_collars", static_cast<double>(facet_vertices_in_collars));
  }
  out->Set("svrc.vertices_dim3", static_cast<double>(steiner_vertices));
  out->Set("svrc.insertions", static_cast<double>(insertions));
  out->Set("svrc.sizes_certified", static_cast<double>(sizes_certified));
  out->Set("svrc.sizes_certified_partial", static_cast<double>(sizes_certified_partial));
  out->Set("svrc.sizes_certified_clipped", static_cast<double>(sizes_certified_clipped));
  out->Set("svrc.unresolved_kept_warps", static_cast<double>(unresolved_kept_warps));
  out->Set("svrc.sizes_uncertified", static_cast<double>(sizes_uncertified));
  out->Set("svrc.sizes_shrunk", static_cast<double>(sizes_shrunk));
  out->Set("svrc.size_queries", static_cast<double>(size_queries));
  out->Set("svrc.sizes_computed", static_cast<double>(sizes_computed));
  out->Set("svrc.circumcentres", static_cast<double>(circumcentres));
  out->Set("svrc.neighbor_cache_flushes", static_cast<double>(neighbor_cache_flushes));
  out->Set("svrc.size_targets_propagated", static_cast<double>(size_targets_propagated));
  out->Set("svrc.sizes_outside", static_cast<double>(sizes_outside));
  out->Set("svrc.sizes_clipped", static_cast<double>(clipped_cells));
  out->Set("svrc.destroys_local", static_cast<double>(destroys_local));
  out->Set("svrc.destroy_cells_visited", static_cast<double>(destroy_cells_visited));
  out->Set("svrc.destroy_index_visited", static_cast<double>(destroy_index_visited));
  out->Set("svrc.max_destroy_cells", static_cast<double>(max_destroy_cells));
  out->Set("svrc.destroy_balls_read", static_cast<double>(destroy_balls_read));
  out->Set("svrc.warps", static_cast<double>(warps));
  out->Set("svrc.yields", static_cast<double>(yields));
  out->Set("svrc.max_yield_chain", static_cast<double>(max_yield_chain));
  for (int i = 0; i < 4; ++i) {
    out->Set(absl::StrCat("svrc.events_pushed.", kTypes[i]), static_cast<double>(events_pushed[i]));
    out->Set(absl::StrCat("svrc.events_popped.", kTypes[i]), static_cast<double>(events_popped[i]));
    out->Set(absl::StrCat("svrc.events_stale.", kTypes[i]), static_cast<double>(events_stale[i]));
    out->Set(absl::StrCat("svrc.events_removed_dead.", kTypes[i]), static_cast<double>(events_removed_dead[i]));
  }
  out->Set("svrc.buckets_walked", static_cast<double>(buckets_walked));
  out->Set("svrc.size_rounds", static_cast<double>(size_rounds));
  out->Set("svrc.queue_releases", static_cast<double>(queue_releases));
  out->Set("svrc.labels_unchanged", static_cast<double>(labels_unchanged));
  out->Set("svrc.labels_changed", static_cast<double>(labels_changed));
  out->Set("svrc.flat_tets_broken", static_cast<double>(flat_tets_broken));
  out->Set("svrc.slivers_broken", static_cast<double>(slivers_broken));
  out->Set("svrc.sliver_rounds", static_cast<double>(sliver_rounds));
  out->Set("svrc.sliver_picks_off_centre", static_cast<double>(sliver_picks_off_centre));
  out->Set("svrc.sliver_yields_skipped", static_cast<double>(sliver_yields_skipped));
  out->Set("svrc.sliver_scan_reused", static_cast<double>(sliver_scan_reused));
  out->Set("svrc.tied_balls", static_cast<double>(tied_balls));
  out->Set("svrc.ball_records", static_cast<double>(ball_records));
  out->Set("svrc.balls_alive", static_cast<double>(balls_alive));
  out->Set("svrc.balls_recycled", static_cast<double>(balls_recycled));
  out->Set("svrc.phantom_corners", static_cast<double>(phantom_corners));
  out->Set("svrc.straddle_yields", static_cast<double>(straddle_yields));
  out->Set("svrc.links_added", static_cast<double>(links_added));
  out->Set("svrc.links_removed", static_cast<double>(links_removed));
  for (int k = 0; k < kNumLinkChangeKinds; ++k) {
    out->Set(absl::StrCat("svrc.link_changes.", kLinkChangeKindName[k]), static_cast<double>(link_changes_by_kind[k]));
    out->Set(absl::StrCat("svrc.insertions.", kLinkChangeKindName[k]), static_cast<double>(insertions_by_kind[k]));
    out->Set(absl::StrCat("svrc.seconds.", kLinkChangeKindName[k]), seconds_by_kind[k]);
    out->Set(absl::StrCat("svrc.events.", kLinkChangeKindName[k]), static_cast<double>(events_by_kind[k]));
  }
  out->Set("svrc.seconds.other_events", seconds_other_events);
  out->Set("svrc.other_events", static_cast<double>(other_events));
  out->Set("svrc.max_degree", max_degree);
  out->Set("svrc.max_aspect", max_aspect);
  out->Set("svrc.predicate_calls", static_cast<double>(predicate_calls));
  out->Set("svrc.predicate_exact", static_cast<double>(predicate_exact));
  out->Set("svrc.predicate_sos", static_cast<double>(predicate_sos));
  out->Set("svrc.collars", static_cast<double>(collars));
  out->Set("svrc.vertex_collars", static_cast<double>(vertex_collars));
  out->Set("svrc.collars_skipped_inside", static_cast<double>(collars_skipped_inside));
  out->Set("svrc.collar_radii_stepped", static_cast<double>(collar_radii_stepped));
  out->Set("svrc.points_12", static_cast<double>(points_12));
  out->Set("svrc.points_12_skipped", static_cast<double>(points_12_skipped));
  out->Set("svrc.points_12_without_ball", static_cast<double>(points_12_without_ball));
  out->Set("svrc.stitch_hidden_balls", static_cast<double>(stitch_hidden_balls));
  out->Set("svrc.stitch_flat_tets", static_cast<double>(stitch_flat_tets));
  out->Set("svrc.stitch_size_repairs", static_cast<double>(stitch_size_repairs));
  out->Set("svrc.clipped_size_points", static_cast<double>(clipped_size_points));
  out->Set("svrc.neck_splits", static_cast<double>(neck_splits));
  out->Set("svrc.collar_rounds", static_cast<double>(collar_rounds));
  if (collars > 0) {
    out->Set("svrc.collar_balls_computed", static_cast<double>(collar_balls_computed));
    out->Set("svrc.collar_balls_reused", static_cast<double>(collar_balls_reused));
    out->Set("svrc.collar_owners_computed", static_cast<double>(collar_owners_computed));
    out->Set("svrc.collar_owners_reused", static_cast<double>(collar_owners_reused));
    out->Set("svrc.collar_circle_owners_computed", static_cast<double>(collar_circle_owners_computed));
    out->Set("svrc.collar_circle_owners_reused", static_cast<double>(collar_circle_owners_reused));
    out->Set("svrc.arc_facets_computed", static_cast<double>(arc_facets_computed));
    out->Set("svrc.arc_facets_settled", static_cast<double>(arc_facets_settled));
  }
  out->Set("svrc.collar_repairs", static_cast<double>(collar_repairs));
  if (collars > 0) {
    for (int k = 0; k < 4; ++k) {
      out->Set(absl::StrCat("svrc.collar_repairs.", kCollarRepairName[k]),
               static_cast<double>(collar_repairs_by_reason[k]));
    }
  }
  out->Set("svrc.arc_repairs", static_cast<double>(arc_repairs));
  if (collars > 0) out->Set("svrc.stitched_arc_crossings", static_cast<double>(stitched_arc_crossings));
  if (collars > 0) out->Set("svrc.stitch_faces_on_plane", static_cast<double>(stitch_faces_on_plane));
  if (collars > 0) out->Set("svrc.stitched_crossings", static_cast<double>(stitched_crossings));
  out->Set("svrc.collar_pairs", static_cast<double>(collar_pairs));
  out->Set("svrc.collar_pairs_not_smooth", static_cast<double>(collar_pairs_not_smooth));
  out->Set("svrc.collar_worst_smoothness", collar_worst_smoothness);
  if (stitch_stars + stitch_books > 0) {
    out->Set("svrc.stitch_stars", static_cast<double>(stitch_stars));
    out->Set("svrc.stitch_books", static_cast<double>(stitch_books));
    out->Set("svrc.star_sigma_max_deg", stitch.star_sigma_max_deg);
    out->Set("svrc.star_eps_max", stitch.star_eps_max);
    out->Set("svrc.star_gamma_max_deg", stitch.star_gamma_max_deg);
    out->Set("svrc.max_star_base_deg", stitch.max_star_base_deg);
    out->Set("svrc.max_star_radial_deg", stitch.max_star_radial_deg);
    out->Set("svrc.book_sigma_max_deg", stitch.book_sigma_max_deg);
    out->Set("svrc.book_eps_max", stitch.book_eps_max);
    out->Set("svrc.book_alpha_max_deg", stitch.book_alpha_max_deg);
    out->Set("svrc.max_book_ab_deg", stitch.max_book_ab_deg);
    out->Set("svrc.max_book_side_deg", stitch.max_book_side_deg);
    out->Set("svrc.collar_snap", collar_snap);
    out->Set("svrc.stitch_bounded", static_cast<double>(stitch.bounded()));
    out->Set("svrc.stitch_violations", static_cast<double>(stitch.violations()));
    out->Set("svrc.max_bounded_dihedral_deg", stitch.max_bounded_dihedral_deg);
    out->Set("svrc.max_unbounded_dihedral_deg", stitch.max_unbounded_dihedral_deg);
  }
  out->Set("svrc.seconds_refine", seconds);
  out->Set("svrc.seconds_labelling", seconds_labelling);
  out->Set("svrc.seconds_breaks", seconds_breaks);
}

// The input's exact normalisation (§1) and Ω: a cube of side 3·diam centred
// on the normalised input's box (Definition 35); a single point gets a unit cube.
struct NormalisedInput {
  Normalization norm;
  std::vector<Vec3> points;
  Vec3 center;
  double half = 0;
};
absl::StatusOr<NormalisedInput> NormaliseInput(std::span<const Vec3> points) {
  absl::StatusOr<Normalization> norm = ChooseNormalization(points);
  if (!norm.ok()) return norm.status();
  NormalisedInput out;
  out.norm = *norm;
  out.points.resize(points.size());
  geom::Box3 box;
  for (size_t i = 0; i < points.size(); ++i) {
    out.points[i] = norm->Forward(points[i]);
    box.Add(out.points[i]);
  }
  const double diam = box.Diagonal();
  out.half = diam > 0 ? 1.5 * diam : 0.5;
  out.center = box.Center();
  return out;
}

absl::StatusOr<PointSetRefinement> RefinePointsAndSegments(std::span<const Vec3> points,
                                                           std::span<const SegmentInput> segments,
                                                           const RefineOptions& options) {
  if (!(options.tau > 0) || !(options.theta > 0 && options.theta < 1)) {
    return absl::InvalidArgumentError("SVRC: need tau > 0 and 0 < theta < 1");
  }
  absl::StatusOr<NormalisedInput> in = NormaliseInput(points);
  if (!in.ok()) return in.status();
  Refiner refiner(options, in->norm, in->center, in->half);
  absl::Status s = refiner.Initialize(in->points, segments);
  if (!s.ok()) return s;
  s = refiner.Run();
  if (!s.ok()) return s;
  if (options.validate_every > 0) {
    s = refiner.CheckInvariants(/*final=*/true);
    if (!s.ok()) return s;
  }
  return refiner.Output(points);
}

namespace {
absl::StatusOr<PointSetRefinement> RefinePlcImpl(const plc::FeatureComplex& complex, const RefineOptions& options,
                                                 std::optional<RefineStats>* counters);
}  // namespace

absl::StatusOr<PointSetRefinement> RefinePlc(const plc::FeatureComplex& complex, const RefineOptions& options) {
  std::optional<RefineStats> counters;  // set when a run failed after its refiner was built
  absl::StatusOr<PointSetRefinement> out = RefinePlcImpl(complex, options, &counters);
  if (!out.ok() && counters.has_value()) {
    mesh::MeshStats stats;
    counters->ExportTo(&stats);
    absl::Status st = out.status();
    mesh::AttachStats(stats, &st);
    return st;
  }
  return out;
}

namespace {
absl::StatusOr<PointSetRefinement> RefinePlcImpl(const plc::FeatureComplex& complex, const RefineOptions& options,
                                                 std::optional<RefineStats>* counters) {
  if (!(options.tau > 0) || !(options.theta > 0 && options.theta < 1)) {
    return absl::InvalidArgumentError("SVRC: need tau > 0 and 0 < theta < 1");
  }
  if (complex.points.empty()) return absl::InvalidArgumentError("SVRC: the PLC has no points");
  // Creases (Definitions 4–5) need collars (issue #6): refuse them up front,
  // naming the first, rather than refine towards the budget.
  const bool creases_ok = options.attempt_creases || options.collars;
  for (uint32_t s = 0; s < complex.segments.size() && !creases_ok; ++s) {
    const plc::FeatureSegment& fs = complex.segments[s];
    if (fs.crease) {
      return absl::FailedPreconditionError(absl::StrCat("SVRC: crease at ", complex.SegmentName(s),
                                                        ": features meet at ", fs.min_angle * 180 / M_PI,
                                                        " degrees < 90; creases need collars, not implemented yet"));
    }
  }
  for (uint32_t i = 0; i < complex.points.size() && !creases_ok; ++i) {
    if (complex.points[i].crease) {
      return absl::FailedPreconditionError(absl::StrCat("SVRC: crease at ", complex.PointName(i),
                                                        ": features meet below 90 degrees; creases need collars, "
                                                        "not implemented yet"));
    }
  }
  std::vector<Vec3> input(complex.points.size());
  for (size_t i = 0; i < input.size(); ++i) input[i] = complex.points[i].p;
  absl::StatusOr<NormalisedInput> in = NormaliseInput(input);
  if (!in.ok()) return in.status();
  Refiner refiner(options, in->norm, in->center, in->half);
  // On every failed exit: how far the run got (RefinePlc attaches it to the
  // status). Cancelled on success, where Output() reports the counters.
  absl::Cleanup report_counters = [&] {
    RefineStats st = refiner.stats();
    refiner.FillCounters(&st);
    *counters = st;
  };
  absl::Status s = refiner.Setup(complex, in->points);
  if (!s.ok()) return s;
  if (options.collars && options.early_crease_vertices) {
    s = refiner.InsertCreaseVertices();
    if (!s.ok()) return s;
  }
  // The per-tet test needs an output volume bounded by facets.
  const bool faceted = !options.keep_bounding_box && !complex.facets.empty();
  const bool eligible = !options.collars && faceted && options.propagate_size_targets;
  const bool collar_tets = options.collars && options.collar_tet_quality && faceted;
  const bool tet_quality = (eligible && options.tet_quality) || collar_tets;
  const bool features_first = tet_quality || (eligible && options.features_first);
  if (features_first) refiner.skinny_deferred_ = true;
  refiner.tet_mode_ = tet_quality;
  refiner.collar_tets_ = collar_tets;
  // Skinny₃ buckets newest first (docs/svrc-design.md §8 item 52).
  if (tet_quality && options.newest_first_tets) refiner.ServeSkinnyTetsNewestFirst();

  s = refiner.Run();
  if (!s.ok()) return s;
  if (collar_tets) {
    refiner.skinny_deferred_ = false;
    refiner.EnqueueBadTets();
    s = refiner.Run();
    if (!s.ok()) return s;
  } else if (features_first) {
    refiner.skinny_deferred_ = false;
    // Every cell's Skinny test resumes on its kept tets (features_first alone);
    // under tet_quality the cells only carry size targets, which the
    // labelling enqueues itself.
    absl::StatusOr<bool> more = refiner.SetSizeTargets(complex, options.max_volume, /*all_vertices=*/!tet_quality);
    if (!more.ok()) return more.status();
    bool volumes = options.max_volume > 0;
    for (const plc::RegionSeed& sd : complex.regions) volumes = volumes || sd.max_volume > 0;
    if (volumes) refiner.CountSizeRound();
    s = refiner.Run();
    if (!s.ok()) return s;
  }
  // Size events (max_volume): label the conforming mesh, enqueue the cells
  // above their region's target, refine again; targets carry over to new
  // vertices, so a round converges and a few rounds settle region borders.
  bool any_volume = options.max_volume > 0;
  for (const plc::RegionSeed& sd : complex.regions) any_volume = any_volume || sd.max_volume > 0;
  // The rounds label M_Ω by flooding across non-facet faces, which leaks
  // through the collars until RipStitchCollar rebuilds them: stage (d) alone
  // applies no max_volume (measured: example.poly flooded to "no tet left"),
  // and with the collar surface the size rounds run after the stitch, on the
  // stitched mesh's labelling (below).
  if (options.collars && !options.collar_surface) any_volume = false;
  const bool sizes_after_stitch = any_volume && options.collars && options.collar_surface && refiner.collars().size() > 0;
  for (int round = 0; any_volume && !sizes_after_stitch && round < 64; ++round) {
    absl::StatusOr<bool> more = refiner.SetSizeTargets(complex, options.max_volume);
    if (!more.ok()) return more.status();
    if (!*more) {
      // What the cell test missed (CollectOversizedDelaunayTets).
      absl::StatusOr<uint32_t> size_points = refiner.InsertSizePoints();
      if (!size_points.ok()) return size_points.status();
      if (*size_points == 0) break;
    }
    refiner.CountSizeRound();
    s = refiner.Run();
    if (!s.ok()) return s;
  }
  if (options.validate_every > 0) {
    s = refiner.CheckInvariants(/*final=*/true);
    if (!s.ok()) return s;
  }
  // Near-flat tets the flip pass cannot remove (BreakFlatTets), a few rounds.
  for (int round = 0; round < 8; ++round) {
    absl::StatusOr<bool> more = refiner.BreakFlatTets();
    if (!more.ok()) return more.status();
    if (!*more) break;
    s = refiner.Run();
    if (!s.ok()) return s;
  }
  // Slivers of the per-tet mode's output (§8 item 38), a few rounds, until
  // one breaks none. With candidate points (min_dihedral, §8 item 69) the
  // target rises in steps of sliver_ramp_deg from min(15°, D) to D, each
  // level's rounds until one breaks none; a level that stops gaining ends
  // them all: 4 rounds without a new fewest slivers broken, or 1.5× (+1000)
  // the vertices the rounds started with, or half the budget. Measured:
  // below ~25° the count falls every round or nearly (cube --max-volume 1e-5
  // at 22° straight: 8,237, 916, 201, 75, 14, 8, 6, 0, +5% vertices); at 28°
  // it stops falling after 9 rounds and grows (2,740 → 4,471 by round 30,
  // the vertices 47 k → 124 k). Straight to an unreachable target, the last
  // round's new slivers could leave the smallest angle below the default's
  // (example.poly at 35°: 7.57° against 9.96°); the levels keep what the
  // last level reached.
  const uint64_t sliver_start = refiner.Vertices();
  const bool ramp = options.sliver_candidates > 0 && options.sliver_ramp_deg > 0;
  double level = ramp ? std::min(15.0, options.sliver_break_deg) : options.sliver_break_deg;
  double reached = 0;  // the last level whose rounds ended breaking none
  bool cleanup = false;
  int rounds = 0;
  for (bool gaining = true; tet_quality && !collar_tets && options.sliver_break_deg > 0;) {
    uint64_t fewest = UINT64_MAX;
    int since_fewest = 0;
    for (int round = 0; rounds < options.sliver_break_rounds; ++round, ++rounds) {
      // A new level re-reads the tets an earlier one found clear.
      absl::StatusOr<uint64_t> broken = refiner.BreakSlivers(level, /*first=*/round == 0);
      if (!broken.ok()) return broken.status();
      if (*broken == 0) break;
      s = refiner.Run();
      if (!s.ok()) return s;
      if (options.sliver_candidates > 0) {
        if (*broken < fewest) {
          fewest = *broken;
          since_fewest = 0;
        } else if (++since_fewest >= 4) {
          gaining = false;
          break;
        }
        const uint64_t v = refiner.Vertices();
        if (2 * v > 3 * sliver_start + 2000 || 2 * v > refiner.VertexBudget()) {
          gaining = false;
          break;
        }
      }
    }
    if (!ramp || rounds >= options.sliver_break_rounds || cleanup) break;
    if (!gaining) {
      // The level that stopped gaining left new slivers below the last level
      // reached: its rounds again (they ended breaking none once).
      if (reached == 0) break;
      level = reached;
      cleanup = true;
      gaining = true;
      continue;
    }
    reached = level;
    if (level >= options.sliver_break_deg) break;
    level = std::min(level + options.sliver_ramp_deg, options.sliver_break_deg);
  }
  int crossing_passes = 0, size_passes = 0, stitch_repair_passes = 0;
  for (int stitch_pass = 0;; ++stitch_pass) {
  if (options.collars && options.collar_surface) {
    // COLLAR events, then RipStitchCollar (Figure 3.2's last line).
    // Each round ends with Run(), so the queues are empty between rounds.
    // Measured: crease_pair 30° settles in 16 rounds, 10° in 104, 5° in 87.
    constexpr int kMaxCollarRounds = 256;
    bool settled = false;
    refiner.EnterPhase(refine_phase::kCollar);
    for (int round = 0; round < kMaxCollarRounds; ++round) {
      absl::StatusOr<bool> more = refiner.CollarRound();
      if (!more.ok()) {
        // The collar system's smoothness (Lemma 14) in the message: every
        // input that stopped here so far had balls meeting below π/2.
        const CollarIndex::Smoothness sm = refiner.collars().MeasureSmoothness();
        if (std::getenv("SVRC_COLLAR_DEBUG") != nullptr) refiner.DebugNonSmoothPairs();
        if (sm.not_smooth == 0) return more.status();
        return absl::Status(more.status().code(),
                            absl::StrCat(more.status().message(), "; the collar system is not smooth: ", sm.not_smooth,
                                         " of ", sm.intersecting, " intersecting ball pairs meet below 90 degrees ",
                                         "(worst |c1c2|^2/(r1^2+r2^2) = ", sm.worst, ", Lemma 14)"));
      }
      if (std::getenv("SVRC_COLLAR_DEBUG") != nullptr) {
        const CollarSurfaceReport& r = refiner.surface_report_;
        std::fprintf(stderr, "collar round %d: repairs topo %d angle %d circle %d size %d; bad roots %d facets %d links %d spherelinks %d empty %d circles %d bound %d angles %d; total 3D %u arcs %u crossings %u centres %u\n",
                     round, r.repairs[0], r.repairs[1], r.repairs[2], r.repairs[3], r.bad_roots, r.bad_facets, r.bad_links,
                     r.bad_sphere_links, r.empty_spheres, r.bad_circles, r.bad_boundaries, r.bad_angles,
                     refiner.collar_repairs_, refiner.arc_repairs_, refiner.crossing_count_, refiner.centre_repairs_);
      }
      if (!*more) {
        settled = true;
        break;
      }
      s = refiner.Run();
      if (!s.ok()) return s;
    }
    if (!settled && refiner.collars().size() > 0) {
      return absl::ResourceExhaustedError(absl::StrCat(
          "SVRC: the collar surface did not settle in ", kMaxCollarRounds, " rounds of COLLAR events (",
          refiner.collar_repairs_, " points on S, ", refiner.arc_repairs_, " on facet arcs, ",
          refiner.crossing_count_, " facet crossings)"));
    }
  }
  s = refiner.VerifyConformity();
  if (!s.ok()) return s;
  if (!(options.collars && options.collar_surface && refiner.collars().size() > 0)) break;
  refiner.EnterPhase(refine_phase::kStitch);
  s = refiner.Stitch();
  if (!s.ok()) {
    refiner.EnterPhase(refine_phase::kStitchRepair);
    absl::StatusOr<uint32_t> fixed = refiner.RepairStitchFailures();
    if (!fixed.ok()) return fixed.status();
    if (std::getenv("SVRC_COLLAR_DEBUG") != nullptr) {
      std::fprintf(stderr, "stitch failed (%s): %u inverted stars repaired\n", std::string(s.message()).c_str(),
                   *fixed);
    }
    if (*fixed == 0 || ++stitch_repair_passes == 8) return s;
    s = refiner.Run();
    if (!s.ok()) return s;
    continue;
  }
  absl::StatusOr<uint32_t> crossings = refiner.RepairStitchedCrossings();
  if (!crossings.ok()) return crossings.status();
  if (std::getenv("SVRC_COLLAR_DEBUG") != nullptr) {
    std::fprintf(stderr, "stitch pass %d: %u facet crossings (%u arc points so far)\n", stitch_pass, *crossings,
                 refiner.stitched_arc_crossings_);
  }
  if (*crossings > 0) {
    refiner.EnterPhase(refine_phase::kStitchRepair);
    if (++crossing_passes == 8) {
      return absl::ResourceExhaustedError(absl::StrCat("SVRC: the stitched mesh still crosses the facets next to "
                                                       "the collars after 8 passes (", *crossings, " crossings left)"));
    }
    s = refiner.Run();
    if (!s.ok()) return s;
    continue;
  }
  if (!sizes_after_stitch) break;
  // Size events on the stitched mesh's labelling; new points, then the
  // rounds and the stitch again. Converges like the rounds above (targets
  // carry over); 64 passes at most.
  absl::StatusOr<bool> more = refiner.SetSizeTargets(complex, options.max_volume);
  if (!more.ok()) return more.status();
  // Stars and books above the bound (QueueOversizedStitchRepairs): points
  // on S.
  absl::StatusOr<uint32_t> size_repairs = refiner.RepairStitchFailures();
  if (!size_repairs.ok()) return size_repairs.status();
  // The kept Delaunay tets the cell test missed (clipped cells), once it
  // finds nothing more: while it does, most tets above the bound are its
  // own work (inserting every one's circumcentre as well ran crease_pair_30
  // --keep-bounding-box --max-volume 1e-4 into the vertex budget).
  absl::StatusOr<uint32_t> size_points = *more ? absl::StatusOr<uint32_t>(0) : refiner.InsertSizePoints();
  if (!size_points.ok()) return size_points.status();
  if (!*more && *size_repairs == 0 && *size_points == 0) break;
  if (++size_passes == 64) {
    return absl::ResourceExhaustedError("SVRC: max_volume next to the collars did not settle in 64 passes");
  }
  refiner.CountSizeRound();
  refiner.ClearStitch();
  refiner.EnterPhase(refine_phase::kRefine);
  s = refiner.Run();
  if (!s.ok()) return s;
  }
  std::move(report_counters).Cancel();
  PointSetRefinement out = refiner.Output(input);
  const CollarIndex::Smoothness sm = refiner.collars().MeasureSmoothness();
  out.stats.collar_pairs = sm.intersecting;
  out.stats.collar_pairs_not_smooth = sm.not_smooth;
  out.stats.collar_worst_smoothness = sm.worst;
  // The last stitch, which succeeded.
  out.stats.stitch_stars = refiner.stitch_report_.stars;
  out.stats.stitch_books = refiner.stitch_report_.books;
  out.stats.stitch = refiner.stitch_report_.shape;
  out.stats.collar_snap = refiner.collar_snap_;
  return out;
}
}  // namespace

std::vector<ConstrainedFace> ConstrainedFacesOf(const PointSetRefinement& refined,
                                                const plc::FeatureComplex& complex) {
  std::vector<ConstrainedFace> faces;
  for (uint32_t f = 0; f < refined.facet_triangles.size(); ++f) {
    for (const auto& t : refined.facet_triangles[f]) {
      ConstrainedFace cf;
      cf.v = t;
      cf.marker = complex.facets[f].marker;
      cf.facet = complex.facets[f].input_facet;
      faces.push_back(cf);
    }
  }
  return faces;
}

CoordinateMap CoordinateMapOf(const PointSetRefinement& refined) {
  CoordinateMap map;
  map.translation = refined.normalisation_translation;
  map.exponent = refined.normalisation_exponent;
  return map;
}

absl::StatusOr<PointSetRefinement> RefinePointSet(std::span<const Vec3> points,
                                                  const RefineOptions& options) {
  return RefinePointsAndSegments(points, {}, options);
}

}  // namespace svrc::refine
