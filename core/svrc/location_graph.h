// The Bipartite Location Graph (thesis §3.2.3, Figure 3.10): links between
// location objects (balls, collars) and the Voronoi cells of every
// superfeature mesh they intersect. Answers Balls_F(v) and Cells_F'(O) in time
// proportional to the answer, and traps encroachment and unresolved objects as
// links are added (AddLink) so the refiner can enqueue work events.
//
// Representation (guide §2 "BLG"): a pool of link records {object, mesh, cell,
// prev/next in the object's list, prev/next in the cell's list} with a free
// list; both lists are intrusive, doubly linked and append at the tail, so
// iteration order is the order of AddLink calls: deterministic.
#pragma once

#include <cstdint>
#include <vector>

#include "core/svrc/balls.h"
#include "core/svrc/ids.h"

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
  LinkId link;
  EncroachOutcome encroach = EncroachOutcome::kNothing;  // Figure 3.10's trap
  bool cell_became_unresolved = false;  // first unresolved object of this cell
};

class LocationGraph {
 public:
  // AddLink(v, F, O) of Figure 3.10: adds both directions. For a ball with
  // facts.encroaches, records the encroacher in `balls` and reports whether an
  // Encroached event is due. A duplicate (same object, mesh, cell) is refused
  // (returns an invalid link): links are sets (Lemma 36 counts unique pairs).
  AddLinkResult AddLink(MeshId mesh, uint32_t cell, LocationObject object, const LinkFacts& facts,
                        BallStore* balls);
  // RemoveLink: deletes both directions.
  void RemoveLink(LinkId link);
  // Removes the link (mesh, cell, object) if present; returns whether it was.
  bool RemoveLink(MeshId mesh, uint32_t cell, LocationObject object);
  // Removes every link of a cell, appending the objects to `removed` (in link
  // order) when non-null. Used when a cell changes (UpdateLocation).
  void RemoveCellLinks(MeshId mesh, uint32_t cell, std::vector<LocationObject>* removed);
  // Removes every link of an object in `mesh` (all meshes if mesh is kNoneMesh),
  // appending the cells to `cells` when non-null.
  void RemoveObjectLinks(LocationObject object, MeshId mesh, std::vector<uint32_t>* cells);

  // Balls_F(v): balls linked to cell v of mesh F, in link order.
  void BallsOf(MeshId mesh, uint32_t cell, std::vector<BallId>* out) const;
  // All objects linked to cell v of mesh F, in link order.
  void ObjectsOf(MeshId mesh, uint32_t cell, std::vector<LocationObject>* out) const;
  // Cells_F'(O): cells of mesh F' linked to O, in link order.
  void CellsOf(LocationObject object, MeshId mesh, std::vector<uint32_t>* out) const;
  bool IsLinked(MeshId mesh, uint32_t cell, LocationObject object) const;
  // Unresolved objects linked to the cell (LinkFacts::unresolved links).
  uint32_t NumUnresolved(MeshId mesh, uint32_t cell) const;

  uint32_t NumLinks() const { return num_links_; }

  // Both directions agree: every link is in exactly its object's list and its
  // cell's list, prev/next consistent, unresolved counters match, no duplicate
  // (object, mesh, cell). Linear time. For tests and debug builds.
  bool Validate() const;

  struct Stats {
    uint64_t links_added = 0;    // LW-events (Lemma 36), add side
    uint64_t links_removed = 0;  // LW-events, remove side
    uint64_t duplicates_refused = 0;
  };
  const Stats& stats() const { return stats_; }

 private:
  static constexpr uint32_t kNil = 0xFFFFFFFFu;
  struct Link {
    LocationObject object;
    MeshId mesh;
    uint32_t cell = kNil;  // kNil: free slot
    uint32_t prev_obj = kNil, next_obj = kNil;
    uint32_t prev_cell = kNil, next_cell = kNil;
    bool unresolved = false;
  };
  struct List {
    uint32_t head = kNil, tail = kNil;
    uint32_t size = 0;
  };

  List& CellList(MeshId mesh, uint32_t cell);
  const List* FindCellList(MeshId mesh, uint32_t cell) const;
  List& ObjectList(LocationObject object);
  const List* FindObjectList(LocationObject object) const;
  uint32_t Find(MeshId mesh, uint32_t cell, LocationObject object) const;

  std::vector<Link> links_;
  uint32_t free_head_ = kNil;
  uint32_t num_links_ = 0;
  std::vector<std::vector<List>> cell_lists_;  // [mesh][cell]
  std::vector<std::vector<uint32_t>> unresolved_;  // [mesh][cell]
  std::vector<List> ball_lists_;
  std::vector<List> collar_lists_;
  Stats stats_;
};

}  // namespace svrc::refine
