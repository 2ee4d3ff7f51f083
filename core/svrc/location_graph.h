// The Bipartite Location Graph (thesis §3.2.3, Figure 3.10): links between
// location objects (balls, collars) and the Voronoi cells of every
// superfeature mesh they intersect. Answers Balls_F(v) and Cells_F'(O) in time
// proportional to the answer, and traps encroachment and unresolved objects as
// links are added (AddLink) so the refiner can enqueue work events.
//
// Representation (guide §2 "BLG"; issue #5): contiguous arrays, not linked
// lists. Per (mesh, cell) one array of {object, unresolved} entries (4
// bytes), per object one array of {mesh, cell} entries (8 bytes: the removal
// of a cell's links scans its objects' arrays); each array is a block of a
// shared arena (capacities in classes 2, 3, 4, 6, 8, 12, ..., recycled
// through per-class free lists). Adds
// append at the end and removals shift the tail down by one, so iteration
// order is the order of AddLink calls (deterministic; the refiner's output
// depends on it). A link is its (mesh, cell, object) triple: there is no
// per-link record or id (8 bytes per cell-side entry; the refiner never named
// a link by anything else). A query walks one short array (bounded ply,
// Lemma 6) instead of chasing one pointer per link.
#pragma once

#include <cstdint>
#include <vector>

#include "core/svrc/balls.h"
#include "core/svrc/ids.h"
#include "core/util/pod_vector.h"

namespace svrc::refine {

enum class ObjectKind : uint8_t { kBall = 0, kCollar = 1 };

struct LocationObject {
  ObjectKind kind = ObjectKind::kBall;
  uint32_t id = 0;
  static LocationObject Ball(BallId b) { return {ObjectKind::kBall, b.value()}; }
  static LocationObject Collar(uint32_t c) { return {ObjectKind::kCollar, c}; }
  friend bool operator==(LocationObject, LocationObject) = default;
};

// What the caller (who owns the geometry and the predicates) knows about a new
// link. `encroaches`: the cell's vertex lies strictly inside the ball (decided
// by core/geometry/predicates.h). `native`: CD(vertex) = dim of the mesh.
// `unresolved`: the object is a 0-ball whose point is not (yet) a vertex of this
// mesh and is not collar-suppressed (Figure 3.9).
struct LinkFacts {
  bool encroaches = false;
  bool native = false;
  PointId vertex_point;
  bool unresolved = false;
};

struct AddLinkResult {
  bool added = false;  // false: the link existed (AddLink refuses duplicates)
  EncroachOutcome encroach = EncroachOutcome::kNothing;  // Figure 3.10's trap
  bool cell_became_unresolved = false;  // first unresolved object of this cell
};

class LocationGraph {
 public:
  // AddLink(v, F, O) of Figure 3.10: adds both directions. For a ball with
  // facts.encroaches, records the encroacher in `balls` and reports whether an
  // Encroached event is due. A duplicate (same object, mesh, cell) is refused
  // (added = false): links are sets (Lemma 36 counts unique pairs).
  AddLinkResult AddLink(MeshId mesh, uint32_t cell, LocationObject object, const LinkFacts& facts,
                        BallStore* balls);
  // Removes the link (mesh, cell, object) if present; returns whether it was.
  bool RemoveLink(MeshId mesh, uint32_t cell, LocationObject object);
  // Removes every link of a cell, appending the objects to `removed` (in link
  // order) when non-null. Used when a cell changes (UpdateLocation).
  void RemoveCellLinks(MeshId mesh, uint32_t cell, std::vector<LocationObject>* removed);
  // Removes the links of a cell whose entry i (in link order, as ObjectsOf
  // lists them) has drop[i] != 0; the kept links keep their order.
  // `drop` has one entry per link of the cell. UpdateLocation for a cell that
  // shrank: its surviving links stay in place instead of being removed and
  // added again.
  void RemoveCellLinksWhere(MeshId mesh, uint32_t cell, const std::vector<uint8_t>& drop);
  // Removes every link of an object in `mesh` (all meshes if mesh is kNoneMesh),
  // appending the cells to `cells` when non-null.
  void RemoveObjectLinks(LocationObject object, MeshId mesh, std::vector<uint32_t>* cells);

  // Balls_F(v): balls linked to cell v of mesh F, in link order.
  void BallsOf(MeshId mesh, uint32_t cell, std::vector<BallId>* out) const;
  // The same balls, in the same order, passed to f(BallId) without a copy
  // (Destroy's line 3 unions them over 𝒱 at once). f must not change the
  // graph.
  template <typename F>
  void ForEachBall(MeshId mesh, uint32_t cell, F&& f) const {
    const CellSpanT* cs = FindCellSpan(mesh, cell);
    if (cs == nullptr) return;
    const CellEntry* e = cell_arena_.Data(*cs);
    for (uint32_t i = 0, n = cs->size; i < n; ++i) {
      if (e[i].is_ball()) f(BallId(e[i].object_id()));
    }
  }
  // The balls of the cell's unresolved links only (0-balls whose point is
  // not yet in the mesh), in link order; f as in ForEachBall.
  template <typename F>
  void ForEachUnresolvedBall(MeshId mesh, uint32_t cell, F&& f) const {
    const CellSpanT* cs = FindCellSpan(mesh, cell);
    if (cs == nullptr || cs->unresolved == 0) return;
    const CellEntry* e = cell_arena_.Data(*cs);
    for (uint32_t i = 0, n = cs->size; i < n; ++i) {
      if (e[i].unresolved() && e[i].is_ball()) f(BallId(e[i].object_id()));
    }
  }
  // All objects linked to cell v of mesh F, in link order.
  void ObjectsOf(MeshId mesh, uint32_t cell, std::vector<LocationObject>* out) const;
  // Cells_F'(O): cells of mesh F' linked to O, in link order.
  void CellsOf(LocationObject object, MeshId mesh, std::vector<uint32_t>* out) const;
  bool IsLinked(MeshId mesh, uint32_t cell, LocationObject object) const;
  // Unresolved objects linked to the cell (LinkFacts::unresolved links).
  uint32_t NumUnresolved(MeshId mesh, uint32_t cell) const;
  // All links of the cell.
  uint32_t NumCellLinks(MeshId mesh, uint32_t cell) const {
    const CellSpanT* cs = FindCellSpan(mesh, cell);
    return cs == nullptr ? 0 : cs->size;
  }
  // The cells of the mesh with an unresolved link, in no particular (but
  // deterministic) order.
  const std::vector<uint32_t>& UnresolvedCells(MeshId mesh) const {
    static const std::vector<uint32_t> kNone;
    return mesh.value() < unresolved_cells_.size() ? unresolved_cells_[mesh.value()] : kNone;
  }

  uint32_t NumLinks() const { return num_links_; }
  // Links of `object`, in every mesh.
  uint32_t NumObjectLinks(LocationObject object) const;

  // Both directions agree: every link is in exactly its object's array and
  // its cell's array, each entry of either side has its partner on the other
  // side, link ids are distinct, unresolved counters match, no duplicate
  // (object, mesh, cell). Time linear in links × array length (plus a sort of
  // the ids). For tests and debug builds.
  bool Validate() const;

  struct Stats {
    uint64_t links_added = 0;    // LW-events (Lemma 36), add side
    uint64_t links_removed = 0;  // LW-events, remove side
    uint64_t duplicates_refused = 0;
    uint64_t compactions = 0;  // arenas packed (MaybeCompactCells/Objects)
  };
  const Stats& stats() const { return stats_; }
  // Entries the two arenas hold (live, in unused block room, or in free
  // blocks): the graph's storage, for tests of its compaction.
  uint64_t ArenaEntries() const { return cell_arena_.PoolSize() + object_arena_.PoolSize(); }

 private:
  static constexpr uint32_t kNil = 0xFFFFFFFFu;

  // One block of an Arena: entries [offset, offset + size), room for `cap`.
  struct Span {
    uint32_t offset = 0;
    uint32_t size = 0;
    uint32_t cap = 0;  // 0: no block yet; otherwise a class capacity (2, 3, 4, 6, 8, ...)
  };
  // A cell's span also counts its unresolved links (next to its size: one
  // access for both). An object's span is a plain Span (12 bytes per ball).
  struct CellSpanT : Span {
    uint32_t unresolved = 0;
    uint32_t upos = 0;  // unresolved > 0: position in unresolved_cells_
  };
  // Blocks of small arrays in one vector. A full block moves to a block of
  // the next class (taken from that class's free list, else appended); the
  // old block goes to its free list. Blocks of emptied arrays are kept (a cell
  // emptied by UpdateLocation is usually refilled at once) except a dead
  // object's (RemoveObjectLinks): a recycled ball id starts with no block.
  // Blocks of arrays that shrank stay too, until the arena is packed
  // (MaybeCompactCells).
  template <typename Entry>
  class Arena {
   public:
    Entry* Data(const Span& s) { return pool_.data() + s.offset; }
    const Entry* Data(const Span& s) const { return pool_.data() + s.offset; }
    // Appends `e` to the array of `s` (entries keep their order).
    void Append(Span& s, const Entry& e);
    // Removes entry `i` of `s`, shifting the later entries down (order kept).
    void Erase(Span& s, uint32_t i);
    // Returns the block of an empty array to its free list.
    void Release(Span& s);
    // Whether Append(s, ·) would have to enlarge the pool's storage: the
    // array is full, no free block of the next size exists, and the pool has
    // no room left for one.
    bool WouldGrow(const Span& s) const;
    // Packs the blocks of `spans` (every span with a block, sorted by offset)
    // to the front of the pool, each array keeping its entries in order in a
    // block of the smallest class that holds it (an empty array loses its
    // block); the free lists are emptied.
    void Compact(const std::vector<Span*>& spans);
    uint64_t PoolSize() const { return pool_.size(); }

   private:
    util::PodVector<Entry> pool_;
    std::vector<uint32_t> free_[64];  // [class of cap] offsets of free blocks
  };

  // The cell side: which object, and whether the link counts as unresolved,
  // in 4 bytes (the object's id in the low 30 bits, its kind in bit 30, the
  // flag in bit 31; §8 item 45). Ids from 2^30 on are refused (AddLink):
  // a billion balls are 64 GB of ball records alone.
  struct CellEntry {
    static constexpr uint32_t kIdMask = (uint32_t{1} << 30) - 1;
    uint32_t bits = 0;
    static CellEntry Make(LocationObject o, bool unresolved) {
      return {o.id | (o.kind == ObjectKind::kCollar ? uint32_t{1} << 30 : 0) | (unresolved ? uint32_t{1} << 31 : 0)};
    }
    uint32_t object_id() const { return bits & kIdMask; }
    ObjectKind kind() const { return (bits >> 30 & 1) != 0 ? ObjectKind::kCollar : ObjectKind::kBall; }
    bool unresolved() const { return (bits >> 31) != 0; }
    bool is_ball() const { return (bits >> 30 & 1) == 0; }
    LocationObject object() const { return {kind(), object_id()}; }
    bool Is(LocationObject o) const { return (bits & ~(uint32_t{1} << 31)) == Make(o, false).bits; }
  };
  static_assert(sizeof(CellEntry) == 4);
  // The object side: which cell of which mesh.
  struct ObjectEntry {
    uint32_t mesh = 0;
    uint32_t cell = 0;
  };

  CellSpanT& CellSpan(MeshId mesh, uint32_t cell);
  const CellSpanT* FindCellSpan(MeshId mesh, uint32_t cell) const {
    if (cell_spans_.size() <= mesh.value() || cell_spans_[mesh.value()].size() <= cell) return nullptr;
    return &cell_spans_[mesh.value()][cell];
  }
  Span& ObjectSpan(LocationObject object);
  const Span* FindObjectSpan(LocationObject object) const;
  // Position of `object` in the cell's array / of (mesh, cell) in the
  // object's array; kNil when absent.
  uint32_t CellPos(const Span& cs, LocationObject object) const;
  uint32_t ObjectPos(const Span& os, MeshId mesh, uint32_t cell) const;
  // The same position, searched from the back: a shrunk cell's links to a
  // ball go in the ball's newer cells more often (cube 1e-5:
  // RemoveCellLinksWhere 175 M → 131 M instructions; design §8 item 54). A (mesh, cell) pair is
  // in an object's list at most once, so both find the same entry.
  uint32_t ObjectPosFromBack(const Span& os, MeshId mesh, uint32_t cell) const;
  // Removes entry `oi` of the object's array and entry `ci` of the cell's
  // array, which must be the same link.
  void RemoveAt(MeshId mesh, CellSpanT& cs, uint32_t ci, Span& os, uint32_t oi);
  void EnterUnresolved(MeshId mesh, uint32_t cell, CellSpanT& cs);
  void LeaveUnresolved(MeshId mesh, CellSpanT& cs);
  // Before an append that would enlarge an arena's storage: when the arrays
  // would fit, packed, in at most 2/3 of the pool (the rest being blocks of
  // emptied or shrunk arrays and free blocks), the arena is packed instead
  // (Arena::Compact; each packing frees a third of the pool, so its linear
  // cost is amortised over the appends that filled that third).
  // A cell's array keeps the block of its largest size until then, so without
  // this the pool kept the high-water mark of every array at once (cube
  // --max-volume 1e-4: 197k cell-side entries for at most 44k live links).
  void MaybeCompactCells();
  void MaybeCompactObjects();
  // The shared step: `spans` are every span of `arena` with a block.
  template <typename Entry>
  void CompactIfSparse(Arena<Entry>& arena, std::vector<Span*>& spans);

  Arena<CellEntry> cell_arena_;
  Arena<ObjectEntry> object_arena_;
  uint32_t num_links_ = 0;
  std::vector<util::PodVector<CellSpanT>> cell_spans_;  // [mesh][cell]
  std::vector<std::vector<uint32_t>> unresolved_cells_;  // [mesh]: cells with unresolved > 0
  util::PodVector<Span> ball_spans_;
  util::PodVector<Span> collar_spans_;
  Stats stats_;
};

}  // namespace svrc::refine
