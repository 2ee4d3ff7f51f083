// Incremental 2D Delaunay triangulation (Bowyer–Watson) of a facet's points in
// the facet's 2D frame, inside a bounding convex quadrilateral (the square Ω_F
// of thesis Definition 35), with the Voronoi queries SVRC needs on facet meshes
// (thesis §3.1, Definition 12, Lemma 3; implementer's guide §2).
//
// Storage (Triangle/Geogram style, flat struct-of-arrays, 32-bit indices):
//   tri_v_[3t+i]  vertex i of triangle t, counter-clockwise:
//                 Orient2d(v0, v1, v2) > 0 for every live triangle;
//   tri_n_[3t+e]  the neighbour across edge e (the edge opposite vertex e,
//                 from v[e+1] to v[e+2]), encoded 3t'+e' with e' the same edge
//                 seen from t'; kNoNeighbor on the outer boundary.
// Free slots form a free list; every slot has a generation counter bumped when
// its triangle is destroyed, so (TriId, generation) names one triangle for
// good (stale work events are detected by comparing generations).
//
// Degeneracies: orientation tests are exact; in-circle tests use simulation of
// simplicity by the caller's global ids (core/geometry/predicates.h, lifting
// perturbation), so cocircular points and grids triangulate to one valid,
// reproducible triangulation that does not depend on insertion order.
// Global ids must be distinct. Not thread-safe (scratch marks are shared).
#pragma once

#include <array>
#include <compare>
#include <cstdint>
#include <span>
#include <vector>

#include "absl/status/status.h"
#include "core/geometry/vec3.h"

namespace svrc::delaunay {

namespace lowdim {
// A 32-bit index with a type tag (same shape as delaunay3.h's TypedId; kept
// separate so the 1D/2D and 3D libraries build independently).
template <typename Tag>
class Id {
 public:
  static constexpr uint32_t kNoneValue = 0xFFFFFFFFu;
  constexpr Id() = default;
  constexpr explicit Id(uint32_t value) : value_(value) {}
  constexpr uint32_t value() const { return value_; }
  constexpr bool valid() const { return value_ != kNoneValue; }
  friend constexpr bool operator==(Id, Id) = default;
  friend constexpr auto operator<=>(Id, Id) = default;

 private:
  uint32_t value_ = kNoneValue;
};
}  // namespace lowdim

class Delaunay2 {
 public:
  using Vec2 = geom::Vec2;
  using VertexId = lowdim::Id<struct Delaunay2VertexTag>;
  using TriId = lowdim::Id<struct Delaunay2TriTag>;
  static constexpr VertexId kNoneVertex{};
  static constexpr TriId kNoneTri{};
  static constexpr uint32_t kNoNeighbor = 0xFFFFFFFFu;

  enum class InsertOutcome : uint8_t {
    kInserted,   // a new vertex; the spans describe the change
    kDuplicate,  // equal to an existing vertex (`vertex`); nothing changed
    kOutside,    // not strictly inside the bounding quadrilateral; nothing changed
  };

  struct InsertResult {
    InsertOutcome outcome = InsertOutcome::kInserted;
    VertexId vertex;
    // Triangles destroyed (generations bumped) and created. Slots are reused,
    // so an id may be in both lists (with different generations).
    std::span<const TriId> destroyed;
    std::span<const TriId> created;
    // Vertices of the destroyed triangles, i.e. of the cavity boundary (whose
    // Voronoi cells changed), excluding `vertex`, each once, in boundary order.
    std::span<const VertexId> cavity_vertices;
  };

  // Starts from the bounding quadrilateral `corners` (convex, counter-
  // clockwise, e.g. the square Ω_F), as ordinary vertices 0..3 carrying
  // `corner_ids` (their global ids for SoS). The diagonal is the Delaunay one
  // under SoS. Points must later be inserted strictly inside.
  Delaunay2(std::span<const Vec2, 4> corners, std::span<const uint32_t, 4> corner_ids);
  // Axis-aligned square [lo, hi]² variant: corners lo, (hi.x, lo.y), hi, (lo.x, hi.y).
  static Delaunay2 Square(Vec2 lo, Vec2 hi, std::array<uint32_t, 4> corner_ids);

  Delaunay2(const Delaunay2&) = default;
  Delaunay2& operator=(const Delaunay2&) = default;
  Delaunay2(Delaunay2&&) = default;
  Delaunay2& operator=(Delaunay2&&) = default;

  // Inserts p with SoS priority `global_id`. `hint`: a live triangle near p
  // (kNoneTri: the last created one). If the hint conflicts with p the cavity
  // grows from it directly (SVRC's ForceInsert), else a deterministic
  // visibility walk locates p.
  InsertResult Insert(Vec2 p, uint32_t global_id, TriId hint = kNoneTri);

  // A live triangle whose closure contains p, or kNoneTri if p is outside
  // the bounding quadrilateral. Deterministic.
  TriId Locate(Vec2 p, TriId hint = kNoneTri) const;
  // True iff inserting p (priority global_id) would destroy t.
  bool InConflict(TriId t, Vec2 p, uint32_t global_id) const;

  // --- size and access ----------------------------------------------------
  uint32_t NumVertices() const { return static_cast<uint32_t>(points_.size()); }
  uint32_t NumTriangles() const { return num_live_; }
  uint32_t TriCapacity() const { return static_cast<uint32_t>(tri_gen_.size()); }
  Vec2 Point(VertexId v) const { return points_[v.value()]; }
  uint32_t GlobalId(VertexId v) const { return global_ids_[v.value()]; }
  TriId VertexTri(VertexId v) const { return TriId(vertex_tri_[v.value()]); }
  bool IsAlive(TriId t) const { return tri_v_[3 * t.value()] != kFreeSlot; }
  uint32_t Generation(TriId t) const { return tri_gen_[t.value()]; }
  VertexId TriVertex(TriId t, int i) const { return VertexId(tri_v_[3 * t.value() + i]); }
  // Neighbour across edge e (kNoneTri on the boundary) and its edge index there.
  TriId Neighbor(TriId t, int e) const {
    const uint32_t n = tri_n_[3 * t.value() + e];
    return n == kNoNeighbor ? kNoneTri : TriId(n / 3);
  }
  int NeighborEdge(TriId t, int e) const { return static_cast<int>(tri_n_[3 * t.value() + e] % 3); }
  // Live triangles in slot order.
  std::vector<TriId> Triangles() const;
  // True for the bounding-quadrilateral corners (vertices 0..3).
  bool IsCorner(VertexId v) const { return v.value() < 4; }

  // --- vertex queries -----------------------------------------------------
  // Triangles around v in counter-clockwise order (for a corner: from the
  // boundary on, so the order is a fan).
  void Star(VertexId v, std::vector<TriId>* out) const;
  // Vertices adjacent to v, counter-clockwise (same start as Star).
  void Neighbors(VertexId v, std::vector<VertexId>* out) const;
  // Corners of v's Voronoi cell: circumcentres of the triangles in Star order
  // (for a bounding corner the cell is unbounded; these are its finite corners).
  void VoronoiCorners(VertexId v, std::vector<Vec2>* out) const;
  // R_v: max distance from v to a Voronoi corner (= max circumradius of the
  // incident triangles); +infinity for the 4 bounding corners, whose cells
  // are unbounded. `farthest_corner` (optional) receives the corner achieving
  // it (ties: first in Star order).
  double OutRadius(VertexId v, Vec2* farthest_corner = nullptr) const;
  // r_v: half the shortest Delaunay edge at v (thesis Lemma 3, Definition 12).
  double InRadius(VertexId v) const;
  // Nearest vertex to p (ties: smallest vertex id); walk + greedy descent on
  // the Delaunay graph (exact distance comparisons). p must be inside.
  VertexId NearestVertex(Vec2 p, TriId hint = kNoneTri) const;
  // A vertex nearest to p up to rounding: the same walk and descent on
  // squared distances in doubles, moving only to a strictly nearer vertex.
  // For seeding searches that need a cell meeting a disk around p, not the
  // exact nearest: from a circumcentre, the three corners tie and
  // NearestVertex settles them with exact arithmetic (~700 instructions per
  // comparison, svrc's facet Destroy).
  VertexId NearVertex(Vec2 p, TriId hint = kNoneTri) const;

  // --- triangle constructions --------------------------------------------
  Vec2 Circumcenter(TriId t) const;
  double Circumradius(TriId t) const;

  // --- checking -----------------------------------------------------------
  // Combinatorics (neighbour symmetry, shared edge vertices, counter-clockwise
  // orientation, vertex→triangle incidence, free list and counts, boundary =
  // the 4 quadrilateral sides) and, if `check_empty_circle`, the locally-
  // Delaunay property of every interior edge under InCircleSoS (which implies
  // the empty-circle property globally). INTERNAL with the offending ids.
  absl::Status Validate(bool check_empty_circle = true) const;

  struct Stats {
    uint64_t inserted = 0;
    uint64_t duplicates = 0;
    uint64_t walk_steps = 0;
    uint64_t tris_created = 0;
    uint64_t tris_destroyed = 0;
  };
  const Stats& stats() const { return stats_; }

 private:
  static constexpr uint32_t kFreeSlot = 0xFFFFFFFFu;

  Delaunay2() = default;
  uint32_t NewTri();
  void FreeTri(uint32_t t);
  bool Conflict(uint32_t t, Vec2 p, uint32_t gid) const;
  uint32_t LocateRaw(Vec2 p, uint32_t start, uint64_t* steps) const;
  void StarRaw(uint32_t v, std::vector<uint32_t>* out) const;
  uint32_t FreshTriStamp() const;
  uint32_t FreshVertexStamp() const;
  void SetTri(uint32_t t, uint32_t a, uint32_t b, uint32_t c);

  std::vector<Vec2> points_;
  std::vector<uint32_t> global_ids_;
  std::vector<uint32_t> vertex_tri_;
  std::vector<uint32_t> tri_v_;
  std::vector<uint32_t> tri_n_;
  std::vector<uint32_t> tri_gen_;
  uint32_t free_head_ = kFreeSlot;  // free list threaded through tri_n_[3t]
  uint32_t num_live_ = 0;
  uint32_t last_tri_ = 0;
  // Scratch of the const star queries (Star, Neighbors, VoronoiCorners,
  // InRadius, NearestVertex), reused instead of a vector per call (300,000
  // allocations on cube.poly --max-volume 1e-4). Each is used within one
  // call and none of those calls another that uses the same buffer; like
  // tri_mark_, it makes concurrent queries of one Delaunay2 unsafe (a job
  // owns its meshes).
  mutable std::vector<uint32_t> raw_scratch_;
  mutable std::vector<VertexId> nbrs_scratch_;
  mutable std::vector<uint32_t> tri_mark_;
  mutable uint32_t tri_stamp_ = 0;
  mutable std::vector<uint32_t> vertex_mark_;
  mutable std::vector<uint32_t> vertex_slot_;  // scratch: new triangle starting at a vertex
  mutable uint32_t vertex_stamp_ = 0;
  // Insertion scratch, reported through InsertResult spans.
  std::vector<TriId> destroyed_;
  std::vector<TriId> created_;
  std::vector<VertexId> cavity_vertices_;
  std::vector<uint32_t> boundary_;  // 3t+e of cavity-boundary edges (t inside)
  std::vector<uint32_t> stack_;
  struct BoundaryEdge {
    uint32_t a, b, outer;  // edge a→b of the cavity boundary, outer neighbour 3t+e
  };
  std::vector<BoundaryEdge> edges_;
  Stats stats_;
};

}  // namespace svrc::delaunay
