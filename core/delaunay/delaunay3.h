// Incremental 3D Delaunay triangulation (Bowyer–Watson) with ghost tets on the
// convex hull, symbolic perturbation by caller-supplied global ids, and the
// Voronoi queries SVRC needs on M_Ω (thesis §3.2, Definition 12, Lemma 3).
//
// Storage follows Geogram/HXT: flat struct-of-arrays with 32-bit indices.
//   tets_[8t+i]    vertex i of tet t (i < 4); kInfinite for the ghost vertex, which is
//                 always at position 3 of a ghost tet.
//   tets_[8t+4+f]  the neighbour across face f (the face opposite vertex f),
//                 encoded 4t'+f' where f' is the same face seen from t'.
// Every live tet is positively oriented: Orient3d(v0,v1,v2,v3) > 0. A ghost
// tet (a,b,c,∞) has its finite face abc on the hull, oriented so that the
// outside is on the positive side: Orient3d(a,b,c,q) > 0 for q beyond the hull.
// Free tet slots form a free list; every slot carries a generation counter
// that changes whenever the tet in it is destroyed, so (TetId, generation)
// identifies one tet for good (SVRC's stale-event test).
//
// Degeneracies: orientation tests are exact (no perturbation: no flat tets,
// ever); in-sphere tests are exact with simulation of simplicity by global id,
// so cospherical and grid inputs give one reproducible triangulation that
// does not depend on the insertion order. Global ids must be distinct.
//
// Not thread-safe, not even the const queries (they share scratch marks).
#pragma once

#include <compare>
#include <cstdint>
#include <span>
#include <vector>

#include "absl/status/status.h"
#include "core/geometry/vec3.h"
#include "core/util/pod_vector.h"

namespace svrc::delaunay {

using geom::Vec3;

// A 32-bit index with a type, so that vertex and tet ids do not mix.
// Default-constructed ids are kNone.
template <typename Tag>
class TypedId {
 public:
  static constexpr uint32_t kNoneValue = 0xFFFFFFFFu;
  constexpr TypedId() = default;
  constexpr explicit TypedId(uint32_t value) : value_(value) {}
  constexpr uint32_t value() const { return value_; }
  constexpr bool valid() const { return value_ != kNoneValue; }
  friend constexpr bool operator==(TypedId, TypedId) = default;
  friend constexpr auto operator<=>(TypedId, TypedId) = default;

 private:
  uint32_t value_ = kNoneValue;
};

using VertexId = TypedId<struct VertexIdTag>;
using TetId = TypedId<struct TetIdTag>;

inline constexpr VertexId kNoneVertex{};
inline constexpr TetId kNoneTet{};
// The ghost vertex "at infinity" (never a valid index into vertex arrays).
inline constexpr VertexId kInfiniteVertex{0xFFFFFFFEu};

class Delaunay3 {
 public:
  enum class InsertOutcome : uint8_t {
    kInserted,   // a new vertex; destroyed/created/cavity_vertices describe the change
    kDuplicate,  // exactly equal to an existing vertex; nothing changed, `vertex` is that one
    kPending,    // stored, but all vertices so far are coplanar: no tets yet
  };

  // What one insertion did. The spans point into the triangulation's scratch
  // buffers and stay valid until the next mutating call.
  struct InsertResult {
    InsertOutcome outcome = InsertOutcome::kInserted;
    VertexId vertex;
    // Tets destroyed (their generation has been bumped) and created. Slots of
    // destroyed tets are reused, so an id can appear in both lists: compare
    // generations. Both lists include ghost tets.
    std::span<const TetId> destroyed;
    std::span<const TetId> created;
    // Per created tet (same index): 4·d + f, where d is the destroyed tet
    // whose face f (on the cavity boundary) it was built on. Empty when the
    // insertion made the first tets.
    std::span<const uint32_t> created_on;
    // Finite vertices on the cavity boundary (whose Voronoi cells changed),
    // excluding `vertex`, each once, in a deterministic order.
    std::span<const VertexId> cavity_vertices;
  };

  Delaunay3();
  Delaunay3(const Delaunay3&) = default;
  Delaunay3& operator=(const Delaunay3&) = default;
  Delaunay3(Delaunay3&&) = default;
  Delaunay3& operator=(Delaunay3&&) = default;

  // Pre-allocates for about `num_vertices` vertices (tets ≈ 6.7 per vertex).
  void Reserve(size_t num_vertices);

  // Whether Insert fills InsertResult::cavity_vertices (default true). A
  // batch build that does not need them turns this off to save time.
  void set_report_cavity_vertices(bool on) { report_cavity_vertices_ = on; }

  // Whether neighbour lists are cached per vertex (default false). With the
  // cache, Neighbors / NeighborsView (and NearestVertex, InRadius) answer from
  // a compact per-vertex list instead of walking ~25 scattered tets, which
  // pays off when the same cells are asked about repeatedly between
  // insertions (SVRC's cell searches on M_Ω). An insertion invalidates
  // exactly the vertices of the new tets: a vertex in no new tet keeps its
  // star, its VertexTet and hence its answer (same contents, same order).
  // Costs ~8 bytes per vertex plus the lists (and 4 per list stored since
  // the last flush).
  void set_cache_neighbors(bool on);
  // The live lists hold at most this many entries (0: no bound): a full
  // pool is rebuilt with the live lists, and when those would pass the
  // bound every list is dropped instead (the cache starts again; answers do
  // not change). Default 2^20 (4 MB of lists).
  void set_neighbor_cache_limit(size_t entries) { adj_limit_ = entries; }
  // Lists dropped that way (cache flushes), for tests.
  uint64_t neighbor_cache_flushes() const { return adj_flushes_; }
  // Times the neighbour lists were packed in place (StoreAdj).
  uint64_t neighbor_cache_packs() const { return adj_packs_; }

  // Inserts `p` with SoS priority `global_id`. `hint` is any live tet near p
  // (kNoneTet: the last created tet): if it conflicts with p the cavity grows
  // from it directly — SVRC's ForceInsert passes a known conflicting tet and
  // never locates globally — otherwise a deterministic visibility walk from it
  // finds one. While fewer than four affinely independent points have been
  // inserted, points are stored as kPending; the insertion that makes the set
  // 3D builds the tetrahedralization of everything so far and reports all its
  // tets as created. `p` must be finite.
  InsertResult Insert(const Vec3& p, uint32_t global_id, TetId hint = kNoneTet);

  // Locates p: returns a live tet whose closure contains p (a finite tet), or
  // the ghost tet whose hull face sees p (p outside the hull). kNoneTet while
  // there are no tets. Deterministic.
  TetId Locate(const Vec3& p, TetId hint = kNoneTet) const;

  // True iff p (with priority global_id) lies strictly inside the circumsphere
  // of tet t after perturbation, i.e. inserting p would destroy t. For a ghost
  // tet: p strictly beyond its hull face, or on the face's plane and inside its
  // circumcircle (perturbed).
  bool InConflict(TetId t, const Vec3& p, uint32_t global_id) const;

  // The faces on the boundary of the cavity that inserting p (priority
  // global_id) would make, without changing anything: the tets in conflict
  // with p connected to `start` (which must be one), found as Insert finds
  // them, each face as the slot 4t + f (face f, opposite vertex f, of cavity
  // tet t). False when start is not in conflict, a ghost tet is (p beyond the
  // hull), or the cavity passes max_tets tets.
  bool CavityBoundary(const Vec3& p, uint32_t global_id, TetId start, size_t max_tets,
                      std::vector<uint32_t>* boundary) const;

  // --- Size and element access -------------------------------------------------

  // Vertices ever inserted (including pending ones; duplicates get no id).
  uint32_t NumVertices() const { return static_cast<uint32_t>(points_.size()); }
  // Live tets, ghosts included / finite only.
  uint32_t NumTets() const { return num_live_tets_; }
  uint32_t NumFiniteTets() const { return num_live_tets_ - num_ghost_tets_; }
  uint32_t NumGhostTets() const { return num_ghost_tets_; }
  // One past the largest tet slot; iterate slots [0, TetCapacity()) and skip
  // !IsAlive ones.
  uint32_t TetCapacity() const { return static_cast<uint32_t>(tet_gen_.size()); }
  // False before the first full-dimensional tet exists.
  bool Is3d() const { return num_live_tets_ != 0; }

  const Vec3& Point(VertexId v) const { return points_[v.value()]; }
  // Every vertex's point, by id (valid until the next insertion).
  std::span<const Vec3> Points() const { return points_; }
  uint32_t GlobalId(VertexId v) const { return global_ids_[v.value()]; }
  // One live tet incident to v (kNoneTet while v is pending).
  TetId VertexTet(VertexId v) const { return TetId(vertex_tet_[v.value()]); }
  // Changes whenever v's star changes (v is a vertex of a new tet); while it
  // stays the same, so do VertexTet(v) and every vertex query about v (same
  // results, same order). A key for caching what is computed from the star.
  uint32_t StarVersion(VertexId v) const { return star_version_[v.value()]; }

  bool IsAlive(TetId t) const { return tets_[8 * t.value()] != kFreeSlot; }
  bool IsGhost(TetId t) const { return tets_[8 * t.value() + 3] == kInfiniteVertex.value(); }
  uint32_t Generation(TetId t) const { return tet_gen_[t.value()]; }
  VertexId TetVertex(TetId t, int i) const { return VertexId(tets_[8 * t.value() + i]); }
  // The tet across face f (opposite vertex f) and that face's index there.
  TetId Neighbor(TetId t, int f) const { return TetId(tets_[8 * t.value() + 4 + f] >> 2); }
  int NeighborFace(TetId t, int f) const { return static_cast<int>(tets_[8 * t.value() + 4 + f] & 3); }

  // All live finite tets, in slot order.
  std::vector<TetId> FiniteTets() const;

  // --- Vertex queries (v must not be pending) ----------------------------------

  // Tets incident to v, ghosts included, in a deterministic (BFS) order.
  void Star(VertexId v, std::vector<TetId>* out) const;
  // Finite vertices sharing an edge with v, in a deterministic order: by first
  // appearance in Star order, then by position in the tet.
  void Neighbors(VertexId v, std::vector<VertexId>* out) const;

  // Allocation-free variants (after warm-up): the same contents in the same
  // order as Star / Neighbors, returned as views of scratch owned by the
  // triangulation. A view stays valid until the next vertex query (any
  // function of this section, including the *View ones) or mutation.
  std::span<const TetId> StarView(VertexId v) const;
  std::span<const VertexId> NeighborsView(VertexId v) const;
  // One walk for both: the star (as StarView), the neighbours (as
  // NeighborsView) and, per neighbour, the first tet in star order that
  // contains it (a tet of the ring around the edge v–neighbour).
  struct StarAndNeighbors {
    std::span<const TetId> star;
    std::span<const VertexId> neighbors;
    std::span<const TetId> neighbor_tet;
  };
  StarAndNeighbors StarAndNeighborsView(VertexId v) const;
  // True iff v is on the convex hull (incident to a ghost tet).
  bool IsHullVertex(VertexId v) const;
  // Per vertex, the number of its neighbours (NeighborsView(v).size(); 0 for
  // a pending vertex), from one pass over the tets instead of a star walk
  // per vertex. Once Is3d(), the tets with the ghosts triangulate a 3-sphere,
  // so v's link is a triangulated 2-sphere: V − E + F = 2 with 3F = 2E gives
  // V = 2 + F/2, F = the tets at v (ghosts included), V its link's vertices,
  // the infinite vertex among them when v is on the hull. Empty while !Is3d().
  std::vector<uint32_t> Degrees() const;
  // Circumcentres of the finite tets incident to v (the corners of v's Voronoi
  // cell; for a hull vertex the cell is unbounded and this lists the finite
  // corners only).
  void VoronoiCorners(VertexId v, std::vector<Vec3>* out) const;
  // R_v: max distance from v to a corner of its (unclipped) Voronoi cell;
  // +infinity for a hull vertex. If `farthest_corner` is set it receives the
  // corner achieving R_v (ties: the first in Star order).
  double OutRadius(VertexId v, Vec3* farthest_corner = nullptr) const;
  // r_v: half the length of the shortest Delaunay edge at v (Lemma 3).
  double InRadius(VertexId v) const;
  // The vertex nearest to p (ties: smallest vertex id): walk + greedy descent
  // on the Delaunay graph. kNoneVertex while !Is3d().
  VertexId NearestVertex(const Vec3& p, TetId hint = kNoneTet) const;
  // A vertex nearest to p up to rounding (Delaunay2::NearVertex): for seeding
  // searches that need a cell meeting a ball around p, not the exact nearest.
  VertexId NearVertex(const Vec3& p, TetId hint = kNoneTet) const;
  // The vertex whose point is exactly p, or kNoneVertex (also while
  // !Is3d()): one Locate and coordinate comparisons, no distance predicate.
  // A vertex at p is a vertex of every tet whose closure contains p, so this
  // is NearestVertex(p) when Point(NearestVertex(p)) == p and kNoneVertex
  // otherwise — the cheap form of "is p already a vertex?".
  VertexId VertexAt(const Vec3& p, TetId hint = kNoneTet) const;

  // --- Tet constructions (finite tets) -----------------------------------------

  // Circumcentre of finite tet t, computed relative to its vertex 0.
  Vec3 Circumcenter(TetId t) const { return Circumcenter(t, nullptr); }
  // The same, and what the computation has at hand for a shape test: with
  // b, c, d the edge vectors from vertex 0, det = b·(c×d) (six times the
  // signed volume) and longest2 the largest of |b|², |c|², |d|², |b − c|²,
  // |b − d|², |c − d|² (OmegaMesh's flatness test, which read them again).
  struct TetShape {
    double det = 0;
    double longest2 = 0;
  };
  Vec3 Circumcenter(TetId t, TetShape* shape) const;
  // Circumradius of finite tet t (distance from the circumcentre to vertex 0).
  double Circumradius(TetId t) const;

  // --- Checking ----------------------------------------------------------------

  // Neighbour symmetry (face vertex sets match, orientations opposite), the
  // ghost vertex at position 3, positive orientation of every finite tet, a
  // convex hull, vertex→tet incidence, the free list, tet counts; with
  // `check_empty_sphere`, every interior face and every hull edge is locally
  // Delaunay under the perturbed in-sphere test (which makes it globally
  // Delaunay). Linear time. INTERNAL with the offending ids on failure.
  absl::Status Validate(bool check_empty_sphere) const;

  // Predicate-level counters of this triangulation's work.
  struct Stats {
    uint64_t inserted = 0;
    uint64_t duplicates = 0;
    uint64_t walk_steps = 0;
    uint64_t tets_created = 0;
    uint64_t tets_destroyed = 0;
  };
  const Stats& stats() const { return stats_; }

 private:
  static constexpr uint32_t kFreeSlot = 0xFFFFFFFFu;
  static constexpr uint32_t kInf = 0xFFFFFFFEu;

  uint32_t NewTet();
  void GrowTets();
  // Room for one more vertex in the per-vertex arrays (a quarter more when full).
  void ReserveVertex();
  void FreeTet(uint32_t t);
  bool ConflictRaw(uint32_t t, const Vec3& p, uint32_t gid, uint32_t* sos_used) const;
  bool ConflictSlow(uint32_t t, const Vec3& p, uint32_t gid, uint32_t* sos_used) const;
  uint32_t WalkRaw(const Vec3& p, uint32_t start, uint32_t* steps) const;
  InsertResult InsertPending(const Vec3& p, uint32_t global_id);
  void BuildFirstTet(uint32_t a, uint32_t b, uint32_t c, uint32_t d);
  InsertResult InsertVertex(uint32_t v, uint32_t start_conflict, uint32_t sos_used);
  // Bowyer–Watson's cavity from `start` (in conflict), depth first:
  // conflict(u) decides each neighbour u once. The cavity's tets go to
  // *cavity, its boundary faces (4t + f) to *boundary, in the order
  // InsertVertex makes the new tets in; the bitsets are left zero.
  template <class Conflict>
  void FloodCavity(uint32_t start, Conflict&& conflict, std::vector<TetId>* cavity,
                   std::vector<uint32_t>* boundary) const;
  void LinkAroundApex(uint32_t apex);
  // The star walk behind every vertex query: fills star_buf_ (BFS order from
  // VertexTet(v)) and, with kNeighbors, nbr_buf_ / nbr_tet_buf_; returns the
  // star size. Visited sets are bitsets over tet slots / vertices, zero
  // between walks (1/32 of the memory of 32-bit stamps, measured no slower;
  // small hash sets were measured slower).
  template <bool kNeighbors>
  uint32_t WalkStar(uint32_t v, uint32_t* num_neighbors) const;

  // Neighbour cache (set_cache_neighbors): per vertex, its list in adj_pool_.
  static constexpr uint32_t kNoAdj = 0xFFFFFFFFu;
  struct AdjEntry {
    uint32_t offset = 0;
    uint32_t size = kNoAdj;
  };
  void InvalidateAdj(uint32_t v) {
    if (v < adj_.size() && adj_[v].size != kNoAdj) {
      adj_live_ -= adj_[v].size;
      adj_[v].size = kNoAdj;
    }
  }
  void StoreAdj(uint32_t v, uint32_t m) const;

  // Vertices.
  std::vector<Vec3> points_;
  std::vector<uint32_t> global_ids_;
  std::vector<uint32_t> vertex_tet_;
  std::vector<uint32_t> star_version_;
  // Tets.
  // Index in tets_ of the neighbour slot named by the encoding 4t+f.
  static constexpr uint32_t NRef(uint32_t n) { return 8 * (n >> 2) + 4 + (n & 3); }
  util::PodVector<uint32_t> tets_;  // per tet: 4 vertices then 4 neighbours (one cache line per 2 tets)
  util::PodVector<uint32_t> tet_gen_;
  uint32_t free_head_ = kFreeSlot;
  uint32_t num_live_tets_ = 0;
  uint32_t num_ghost_tets_ = 0;
  uint32_t last_tet_ = kFreeSlot;
  // While !Is3d(): the vertices inserted so far, in order.
  std::vector<uint32_t> pending_;
  std::vector<uint32_t> basis_;  // affinely independent pending vertices (<= 3)
  // Insertion scratch (reported through InsertResult spans).
  std::vector<TetId> destroyed_;
  std::vector<TetId> created_;
  std::vector<VertexId> cavity_vertices_;
  std::vector<uint32_t> boundary_;  // 4t+f of outer faces of the cavity
  mutable std::vector<uint32_t> stack_;
  mutable std::vector<TetId> dry_cavity_;  // CavityBoundary's cavity
  std::vector<uint32_t> new_v_;      // per boundary face: the new tet's vertices
  std::vector<uint32_t> new_outer_;  // per boundary face: the outer neighbour 4t+f
  struct EdgeSlot {
    uint64_t key;
    uint32_t val;
    uint32_t stamp;
  };
  std::vector<EdgeSlot> edge_table_;  // stamped open addressing: edge → 4t+f
  uint32_t edge_epoch_ = 0;
  uint32_t EdgeTableFor(size_t num_tets);
  // Vertex-query scratch (WalkStar); sizes only grow.
  mutable std::vector<TetId> star_buf_;
  mutable std::vector<VertexId> nbr_buf_;
  mutable std::vector<TetId> nbr_tet_buf_;
  // Scratch bitsets (all zero between calls): tet_bits_ over tet slots (star
  // walks; the cavity during an insertion), outside_bits_ over tet slots
  // (insertion: tested, not in conflict), vertex_bits_ over vertices.
  mutable std::vector<uint64_t> tet_bits_, outside_bits_, vertex_bits_;
  bool cache_neighbors_ = false;
  mutable std::vector<AdjEntry> adj_;
  mutable std::vector<VertexId> adj_pool_;
  mutable size_t adj_live_ = 0;  // entries of adj_pool_ still referenced
  size_t adj_limit_ = size_t{1} << 20;
  mutable std::vector<uint32_t> adj_stored_;  // vertices stored since the last flush (StoreAdj)
  mutable uint64_t adj_flushes_ = 0;
  mutable uint64_t adj_packs_ = 0;
  bool report_cavity_vertices_ = true;
  Stats stats_;
};

}  // namespace svrc::delaunay
