// Feature meshes of SVRC (thesis §3.1, §3.2.1): M_Ω, the 3D Delaunay/Voronoi
// mesh of a bounding cube Ω (Definition 35) seeded with its 8 corners, with
// Voronoi cells clipped to Ω (Definition 11; docs/svrc-design.md §3), per-cell
// generations (stale-event test) and the per-cell event handles ForceInsert
// refreshes with DecreaseSize (Figure 3.5). The 1D/2D meshes come with stage (b)/(c).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/delaunay/delaunay3.h"
#include "core/geometry/vec3.h"
#include "core/svrc/ids.h"
#include "core/svrc/work_queue.h"
#include "core/util/pod_vector.h"

namespace svrc::refine {

using delaunay::TetId;
using delaunay::VertexId;

// R_v of a cell clipped to Ω, the corner achieving it, and a tet near that
// corner (a hint for Bowyer–Watson: the tet whose circumcentre it is when the
// corner is a Voronoi vertex inside Ω).
struct CellSize {
  double outradius = 0;   // R_v (clipped)
  double inradius = 0;    // r_v = half the shortest incident edge (Lemma 3)
  geom::Vec3 corner;      // farthest corner of V(v) ∩ Ω
  TetId hint;
  bool clipped = false;   // the cell reached ∂Ω or infinity and was clipped
  bool saw_flat = false;  // a flat tet of the star was left out of R_v
  // The same over the star's tets the last labelling keeps
  // (OmegaMesh::SetLabels; docs/svrc-design.md §8 item 33): the circumcentres
  // of the output's tets at v. Equal to the fields above while M_Ω is not
  // labelled or no star tet is known to lie outside the output; 0 (and v)
  // when every star tet does. The Skinny and size tests read these.
  double kept_outradius = 0;
  geom::Vec3 kept_corner;
  TetId kept_hint;
  bool outside_tets = false;  // a star tet is known to lie outside the output
  // Clipped cells only: the kept_* fields came from the star's kept tets,
  // every one of them plain (not a ghost or flat, circumcentre inside Ω).
  bool kept_from_star = false;
};
static_assert(sizeof(CellSize) == 88);  // the size memo's records (kept_from_star fills padding)

// Per M_Ω tet slot: its label class (the region's size target and volume
// bound, in the refiner's table of classes: one per distinct pair, so a run
// has one per region volume) and whether the output keeps it, from the
// refiner's last labelling and carried to new tets (refiner.cc
// PropagateSizeTargets). Valid while gen == Generation + 1 (a live tet) or
// gen == Generation (a tet just freed by an insertion). 8 bytes: it held the
// two doubles itself until session 29 (24 bytes, 69 MB of cube
// --max-volume 1e-6's 419 MB heap during its refinement).
struct TetLabel {
  static constexpr uint32_t kClassMask = (uint32_t{1} << 30) - 1;
  static constexpr uint32_t kKept = uint32_t{1} << 30;
  // Refiner::BreakSlivers: a round found this tet clear for good (not kept,
  // no angle below the bound, no plain circumcentre: what the tet alone
  // decides), so the next round of the series skips it. Clear in every label
  // written for a new tet.
  static constexpr uint32_t kSliverClear = uint32_t{1} << 31;
  uint32_t gen = 0;
  uint32_t bits = 0;  // class (bits 0–29) | kKept | kSliverClear; class 0: no target, no bound

  static TetLabel Make(uint32_t gen, bool kept, uint32_t label_class) {
    return {gen, label_class | (kept ? kKept : 0)};
  }
  bool kept() const { return (bits & kKept) != 0; }
  uint32_t label_class() const { return bits & kClassMask; }
  bool sliver_clear() const { return (bits & kSliverClear) != 0; }
  void set_sliver_clear(bool clear) { bits = clear ? bits | kSliverClear : bits & ~kSliverClear; }
};
static_assert(sizeof(TetLabel) == 8);  // one per M_Ω tet slot

// Clips the convex polygon `poly` (its vertices in order) to the box in
// place, Sutherland–Hodgman against lo_k <= x_k and x_k <= hi_k in the order
// x lo, x hi, y lo, ..., z hi; crossing points take the plane's coordinate
// exactly. `scratch` is working space. A plane no vertex is outside of is
// skipped: the same polygon, bit for bit, as passing all six.
void ClipPolygonToBox(const geom::Box3& box, std::vector<geom::Vec3>* poly, std::vector<geom::Vec3>* scratch);

class OmegaMesh {
 public:
  // Ω = the axis-aligned cube with this centre and half side.
  OmegaMesh(const geom::Vec3& center, double half_side);

  const geom::Box3& cube() const { return cube_; }
  geom::Vec3 Corner(int i) const;  // i in [0, 8): bit k selects hi on axis k

  // Inserts the 8 corners with the given global point ids (SoS priorities).
  void SeedCorners(const std::array<PointId, 8>& ids);

  delaunay::Delaunay3& dt() { return dt_; }
  const delaunay::Delaunay3& dt() const { return dt_; }

  // Registers a vertex returned by dt().Insert: its global point and a fresh
  // cell generation.
  void AddVertex(VertexId v, PointId p);
  PointId PointOf(VertexId v) const { return point_of_[v.value()]; }
  uint32_t NumVertices() const { return static_cast<uint32_t>(point_of_.size()); }

  // The cell of v changed (Figure 3.5's 𝒱'): its generation moves on.
  void BumpCell(VertexId v) { ++cell_gen_[v.value()]; }
  uint32_t CellGeneration(VertexId v) const { return cell_gen_[v.value()]; }

  // R_v, r_v and the farthest corner of V(v) ∩ Ω. Cells whose incident tets
  // are all finite with circumcentres in Ω use the circumcentres directly;
  // the others clip each Voronoi facet (dual of an edge vu: the ring of
  // circumcentres around vu, rays of hull faces replaced by far points) to the
  // cube (Sutherland–Hodgman). Corners created on a cube face get that face's
  // coordinate exactly, so they lie on ∂Ω.
  CellSize Size(VertexId v) const;
  // Tet labels for CellSize's kept_* fields (nullptr: none; every tet
  // counts as kept). Drops every memo of Size().
  void SetLabels(const util::PodVector<TetLabel>* labels) {
    labels_ = labels;
    for (SizeMemo& m : size_memo_) m.key = 0;
  }
  // The circumcentre cache and Size()'s memos hold at most 2^cc_log2 and
  // 2^memo_log2 entries, direct-mapped by tet slot and vertex (a miss
  // recomputes; answers do not depend on them). 0: no bound; the tables then
  // grow to a power of two (rounded down) of between a quarter and a half
  // entry per tet slot, and between a half and one per vertex.
  // docs/svrc-design.md §8 items 44, 74, 79.
  // `neighbor_entries` bounds Delaunay3's neighbour lists
  // (set_neighbor_cache_limit).
  void SetCacheLimits(uint32_t cc_log2, uint32_t memo_log2, size_t neighbor_entries) {
    dt_.set_neighbor_cache_limit(neighbor_entries);
    cc_limit_ = cc_log2 == 0 ? 0 : uint32_t{1} << cc_log2;
    memo_limit_ = memo_log2 == 0 ? 0 : uint32_t{1} << memo_log2;
    cc_.clear();
    size_memo_.clear();
  }
  // Frees the circumcentre cache and Size()'s memos when they hold at least
  // `min_bytes` (they refill on use; answers do not depend on them). Before
  // a size labelling, whose arrays are a run's heap peak; SetLabels drops
  // the memos' keys anyway. glibc raises its mmap threshold to the size of
  // a freed mapped block below 32 MiB, and the blocks after it then come
  // from the heap and stay resident: with every table freed (the default
  // since session 44) cube 1e-6's peak RSS is ~3% higher, 1e-4's and 1e-5's
  // lower, and every size's heap peak lower (bench/RESULTS.md "Session 44").
  // Returns whether it freed one.
  bool ReleaseCaches(size_t min_bytes) {
    bool any = false;
    if (!cc_.empty() && cc_.size() * sizeof(CcRecord) >= min_bytes) {
      util::PodVector<CcRecord>().swap(cc_);
      any = true;
    }
    if (!size_memo_.empty() && size_memo_.size() * sizeof(SizeMemo) >= min_bytes) {
      util::PodVector<SizeMemo>().swap(size_memo_);
      any = true;
    }
    return any;
  }
  // After the refinement (Refiner::ReleaseRefinementState): every query
  // cache goes, the neighbour lists included (32 MiB + 29 MB + ~5 MB on cube
  // 1e-6, alive under the output's arrays, the run's heap peak there).
  // Queries still answer, from scratch.
  void ReleaseQueryCaches() {
    ReleaseCaches(0);
    dt_.set_cache_neighbors(false);
  }
  // t (a ghost, or a finite tet with a valid label) lies outside the output.
  bool KnownOutside(TetId t) const {
    if (labels_ == nullptr) return false;
    if (dt_.IsGhost(t)) return true;
    return t.value() < labels_->size() && (*labels_)[t.value()].gen == dt_.Generation(t) + 1 &&
           !(*labels_)[t.value()].kept();
  }
  // What an insertion added to one vertex's star: its new tets, the largest
  // |cc − v| over them (+inf if one is a ghost, flat, or has its
  // circumcentre outside Ω), the same over those not known to lie outside
  // the output (SetLabels), and whether some / all of them do.
  struct NewTets {
    uint32_t count = 0;
    double corner = 0;
    double kept_corner = 0;
    bool outside = false;
    bool all_outside = true;
    // The largest d of the plain new tets (corners of V(v) ∩ Ω, so ≤ R_v
    // also when the cell is clipped).
    double plain_corner = 0;
    // One new tet at v: d = |cc − v|, or +inf when it is not plain.
    void Add(double d, bool tet_outside) {
      ++count;
      corner = std::max(corner, d);
      if (d != HUGE_VAL) plain_corner = std::max(plain_corner, d);
      if (!tet_outside) kept_corner = std::max(kept_corner, d);
      outside = outside || tet_outside;
      all_outside = all_outside && tet_outside;
    }
  };
  // Size(v) right after an insertion next to v, from v's memo of the star
  // before it, without a star walk: when the only change to v's star since
  // the memo is this insertion (`added`), the memo's cell was unclipped with
  // no flat tet and a unique farthest corner whose tet survived, and every
  // new tet at v is plain with |cc − v| < R_v. Then R_v, the corner and the
  // hint stay (V(v) only shrank) and r_v = min(r_v, |vp|/2) (Lemma 3) — the
  // doubles Size() would compute, so the verdicts do not change. False: call
  // Size(). With labels, a cell whose star had or gets tets outside the
  // output keeps its kept corner when that corner's tet survived likewise,
  // and CellSize::outside_tets may then stay set after the last such tet
  // went (it only ever costs a star walk).
  bool ShrunkSize(VertexId v, const geom::Vec3& p, const NewTets& added, CellSize* out) const;
  // The circumcentre of finite tet t as Size() reads it for each vertex of t
  // (R_v is the largest |cc − v| over v's star); false when Size() would not
  // read it plainly: t flat, or its circumcentre outside Ω (clipped cells).
  bool PlainCorner(TetId t, geom::Vec3* cc) const {
    const CcEntry e = CachedCircumcenter(t);
    if (e.flat || !e.inside) return false;
    *cc = e.cc;
    return true;
  }

  // Per-cell handles of queued events (Figure 3.5: "if v' is the centre of
  // some work event, DecreaseSize it").
  EventHandle& SkinnyEvent(VertexId v) { return skinny_event_[v.value()]; }
  EventHandle& UnresolvedEvent(VertexId v) { return unresolved_event_[v.value()]; }

  struct Stats {
    uint64_t size_queries = 0;
    uint64_t clipped_queries = 0;
    uint64_t shrunk_sizes = 0;  // ShrunkSize() answers
    uint64_t computed_sizes = 0;  // Size() answers not from the memo
    uint64_t circumcentres = 0;   // circumcentres computed (cc_ misses)
  };
  const Stats& stats() const { return stats_; }

 private:
  bool InsideCube(const geom::Vec3& p) const;
  // Whether no other star tet (no other kept star tet) is as far as the
  // corner's (the kept corner's): ShrunkSize needs it.
  struct Uniqueness {
    bool corner = false;
    bool kept_corner = false;
  };
  // Size() without the memo.
  CellSize ComputeSize(VertexId v, Uniqueness* unique) const;
  static void FinishKept(bool from_kept, double kept_best, const geom::Vec3& pv, CellSize* out);
  // Circumcentre of finite tet t and whether it lies in Ω, cached per (slot,
  // generation): each tet is in four stars and Size() is called for every
  // cavity vertex (Figure 3.5).
  struct CcEntry {
    geom::Vec3 cc;
    bool inside = false;  // InsideCube(cc)
    // Its four vertices are coplanar up to rounding (|volume| at noise level):
    // four cocircular points of one facet, rounded off the plane. Its
    // computed circumcentre is noise along the circle's axis, not a Voronoi
    // vertex of the exact configuration, so R_v ignores it; the cell's
    // corners on that axis are the circumcentres of the tets on either side,
    // which share v (docs/svrc-design.md §10).
    bool flat = false;
  };
  // The cache: a table of 2^k 32-byte records indexed by the slot's low bits
  // (SetCacheLimits), grown with the mesh up to its limit (the tets of the
  // insertions' cavities are what it serves). Slots from 2^30 on are not
  // cached (a billion tets would not fit in memory anyway).
  struct CcRecord {
    static constexpr uint32_t kSlotMask = (uint32_t{1} << 30) - 1;
    static constexpr uint32_t kInside = uint32_t{1} << 30, kFlat = uint32_t{1} << 31;
    geom::Vec3 cc;
    uint32_t tag = kSlotMask;  // the tet slot cached here | kInside | kFlat; kSlotMask: none
    uint32_t gen = 0;          // generation + 1 of the cached value
  };
  static_assert(sizeof(CcRecord) == 32);
  // By value: another tet's lookup may take the same record. Hits inline,
  // at the slot's low bits (5 M lookups on cube --max-volume 1e-5, ~48
  // instructions each through the call; slots past the table's end hit here
  // too since session 44); misses and growth in CachedCircumcenterSlow,
  // which looks the slot up again.
  CcEntry CachedCircumcenter(TetId t) const {
    const uint32_t i = t.value();
    if (!cc_.empty()) {
      const CcRecord& r = cc_[i & (cc_.size() - 1)];
      if ((r.tag & CcRecord::kSlotMask) == i && r.gen == dt_.Generation(t) + 1) {
        return {r.cc, (r.tag & CcRecord::kInside) != 0, (r.tag & CcRecord::kFlat) != 0};
      }
    }
    return CachedCircumcenterSlow(t);
  }
  CcEntry CachedCircumcenterSlow(TetId t) const;
  // A far point on the Voronoi ray of ghost tet g (outside Ω).
  geom::Vec3 FarPoint(TetId ghost) const;

  geom::Box3 cube_;
  double half_side_ = 0;
  delaunay::Delaunay3 dt_;
  std::vector<PointId> point_of_;
  std::vector<uint32_t> cell_gen_;
  std::vector<EventHandle> skinny_event_;
  std::vector<EventHandle> unresolved_event_;
  mutable Stats stats_;
  mutable util::PodVector<CcRecord> cc_;
  CcEntry ComputeCircumcenter(TetId t) const;
  // Size() per vertex, valid while the vertex's star is unchanged
  // (Delaunay3::StarVersion): the event loop asks again for cells that did
  // not change (IsLive, Output, invariant checks).
  // Direct-mapped by the vertex's low bits, like cc_ (SetCacheLimits).
  struct SizeMemo {
    uint32_t vertex = 0xFFFFFFFFu;  // the vertex memoised here
    uint32_t key = 0;  // StarVersion + 1 when computed; 0: none
    CellSize size;
    uint32_t hint_gen = 0;       // Generation(size.hint) when computed
    uint32_t kept_hint_gen = 0;  // Generation(size.kept_hint) when computed
    Uniqueness unique;
  };
  mutable util::PodVector<SizeMemo> size_memo_;
  // The memo of v (its record, possibly another vertex's); nullptr before
  // the table covers v's index, unless `grow`.
  SizeMemo* MemoSlot(VertexId v, bool grow) const;
  uint32_t cc_limit_ = 0;    // 0: unbounded
  uint32_t memo_limit_ = 0;  // 0: unbounded
  const util::PodVector<TetLabel>* labels_ = nullptr;
  // Scratch.
  mutable std::vector<geom::Vec3> poly_, poly2_;
};

// The 1D mesh M_s of a segment s = ab (thesis §3.1: Ω_s = s, seeded with its
// endpoints): vertices ordered by their parameter t ∈ [0, 1] along s (the only
// coordinate M_s reads; docs/svrc-design.md §2), kept as a doubly-linked list
// in arrays. Local vertex ids are dense in creation order (a = 0, b = 1).
class SegmentMesh {
 public:
  static constexpr uint32_t kNil = 0xFFFFFFFFu;

  SegmentMesh(PointId a, PointId b, const geom::Vec3& pa, const geom::Vec3& pb);

  uint32_t NumVertices() const { return static_cast<uint32_t>(t_.size()); }
  double T(uint32_t v) const { return t_[v]; }
  PointId PointOf(uint32_t v) const { return point_[v]; }
  uint32_t Next(uint32_t v) const { return next_[v]; }  // kNil at b
  uint32_t Prev(uint32_t v) const { return prev_[v]; }  // kNil at a
  // The point at parameter t: a + t(b − a), exactly a at 0 and b at 1.
  geom::Vec3 PointAt(double t) const;
  // t, or the parameter nearest t towards b (toward_b) or a whose point is
  // not strictly inside B(c, r) (exact InBall): 64 steps of one ulp of t,
  // then steps of 1, 2, 4, … ulps, at most 1024 in all (then the last one
  // tried). One ulp of t moves a point of a short segment by far less than
  // an ulp of its coordinates.
  double StepOutOfBall(double t, bool toward_b, const geom::Vec3& c, double r) const;
  // 3D length of the piece between consecutive vertices v and Next(v).
  double PieceLength(uint32_t v) const;

  // Splits the piece (v, Next(v)) at parameter t (strictly between) with
  // global point p; returns the new local vertex.
  uint32_t Split(uint32_t v, double t, PointId p);

  // 1D Voronoi cell of v clipped to Ω_s = s: R_v = half the longer adjacent
  // piece, r_v = half the shorter (Lemma 3); the farthest corner is the
  // midpoint of the longer piece (an endpoint's cell has one piece).
  struct Size1 {
    double outradius = 0, inradius = 0;
    uint32_t piece = kNil;  // the piece (by its first vertex) whose midpoint is the corner
  };
  Size1 Size(uint32_t v) const;

  void BumpCell(uint32_t v) { ++cell_gen_[v]; }
  uint32_t CellGeneration(uint32_t v) const { return cell_gen_[v]; }
  EventHandle& SkinnyEvent(uint32_t v) { return skinny_event_[v]; }
  // The ConfBall of the piece starting at v (kNoneBall at b), and v's 0-ball.
  BallId& PieceBall(uint32_t v) { return piece_ball_[v]; }
  BallId& VertexBall(uint32_t v) { return vertex_ball_[v]; }

 private:
  uint32_t AddVertex(double t, PointId p);
  geom::Vec3 pa_, pb_;
  std::vector<double> t_;
  std::vector<PointId> point_;
  std::vector<uint32_t> next_, prev_, cell_gen_;
  std::vector<EventHandle> skinny_event_;
  std::vector<BallId> piece_ball_, vertex_ball_;
};

}  // namespace svrc::refine
