// The 1D mesh M_s of an input segment s (thesis §3.1: one mesh per feature,
// starting from the segment's endpoints and only gaining vertices; implementer's
// guide §2 "Segment mesh"). Vertices are kept in order along the segment in a
// doubly linked list over flat arrays; each consecutive pair forms a *piece*
// (the 1D Delaunay simplex, its diametral ball is the piece's ConfBall).
// Pieces live in slots with generation counters, like triangles and tets, so a
// (PieceId, generation) pair detects stale work events.
//
// Order along the segment is decided exactly: q comes after p iff
// DotSign(p, q, a, b) = sign((q − p)·(b − a)) > 0 (core/geometry/predicates.h).
// Points are expected on the segment (the caller constructs them there); a
// point whose projection coincides exactly with a vertex's is a duplicate.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "absl/status/status.h"
#include "core/delaunay/delaunay2.h"  // lowdim::Id
#include "core/geometry/vec3.h"

namespace svrc::delaunay {

class Delaunay1 {
 public:
  using Vec3 = geom::Vec3;
  using VertexId = lowdim::Id<struct Delaunay1VertexTag>;
  using PieceId = lowdim::Id<struct Delaunay1PieceTag>;
  static constexpr VertexId kNoneVertex{};
  static constexpr PieceId kNonePiece{};

  enum class InsertOutcome : uint8_t {
    kInserted,   // split `destroyed` into `created[0]` (left) and `created[1]` (right)
    kDuplicate,  // same position along the segment as `vertex`; nothing changed
    kOutside,    // before the first or after the last endpoint; nothing changed
  };
  struct InsertResult {
    InsertOutcome outcome = InsertOutcome::kInserted;
    VertexId vertex;
    PieceId destroyed;
    std::array<PieceId, 2> created;
    // The destroyed piece's endpoints (their Voronoi cells changed): left, right.
    std::array<VertexId, 2> cavity_vertices;
  };

  // Endpoints a (vertex 0, t = 0) and b (vertex 1, t = 1), a != b.
  Delaunay1(const Vec3& a, const Vec3& b, uint32_t id_a, uint32_t id_b);

  // Inserts p (on the segment) with global id `global_id`, locating its piece
  // by a walk from `hint` (kNonePiece: the last created piece).
  InsertResult Insert(const Vec3& p, uint32_t global_id, PieceId hint = kNonePiece);
  // The piece whose closure contains p's projection (kNonePiece if outside).
  PieceId Locate(const Vec3& p, PieceId hint = kNonePiece) const;

  // --- access -------------------------------------------------------------
  uint32_t NumVertices() const { return static_cast<uint32_t>(points_.size()); }
  uint32_t NumPieces() const { return num_live_; }
  uint32_t PieceCapacity() const { return static_cast<uint32_t>(piece_gen_.size()); }
  const Vec3& Point(VertexId v) const { return points_[v.value()]; }
  uint32_t GlobalId(VertexId v) const { return global_ids_[v.value()]; }
  // Parameter along the segment, (p − a)·(b − a)/|b − a|² (rounded; for
  // display and bucketing — order decisions use the exact predicate).
  double Parameter(VertexId v) const { return t_[v.value()]; }
  // Pieces left/right of v (kNonePiece at the ends) and adjacent vertices.
  PieceId LeftPiece(VertexId v) const { return PieceId(left_[v.value()]); }
  PieceId RightPiece(VertexId v) const { return PieceId(right_[v.value()]); }
  VertexId Prev(VertexId v) const;
  VertexId Next(VertexId v) const;
  bool IsAlive(PieceId p) const { return piece_l_[p.value()] != kFree; }
  uint32_t Generation(PieceId p) const { return piece_gen_[p.value()]; }
  VertexId PieceStart(PieceId p) const { return VertexId(piece_l_[p.value()]); }
  VertexId PieceEnd(PieceId p) const { return VertexId(piece_r_[p.value()]); }
  // Live pieces in order from a to b.
  std::vector<PieceId> Pieces() const;
  // Vertices in order from a to b.
  std::vector<VertexId> Vertices() const;

  // --- Voronoi queries (the domain is the segment itself) -----------------
  // R_v: half the longest incident piece (its midpoint is the farthest corner
  // of v's cell clipped to the segment); r_v: half the shortest.
  double OutRadius(VertexId v, Vec3* farthest_corner = nullptr) const;
  double InRadius(VertexId v) const;
  // Diametral ball of a piece: midpoint and half length.
  Vec3 PieceMidpoint(PieceId p) const;
  double PieceHalfLength(PieceId p) const;
  // The vertex nearest to p (ties: smallest vertex id).
  VertexId NearestVertex(const Vec3& p, PieceId hint = kNonePiece) const;

  // Links, strict exact order along the segment, counts, the free list.
  absl::Status Validate() const;

 private:
  static constexpr uint32_t kFree = 0xFFFFFFFFu;
  static constexpr uint32_t kNone = 0xFFFFFFFFu;
  // sign((q − p)·(b − a)): > 0 iff q comes after p.
  int Order(const Vec3& p, const Vec3& q) const;
  uint32_t NewPiece(uint32_t l, uint32_t r);
  void FreePiece(uint32_t s);

  Vec3 a_, b_;
  std::vector<Vec3> points_;
  std::vector<uint32_t> global_ids_;
  std::vector<double> t_;
  std::vector<uint32_t> left_, right_;  // per vertex: adjacent piece slots
  std::vector<uint32_t> piece_l_, piece_r_, piece_gen_;
  uint32_t free_head_ = kFree;  // threaded through piece_r_
  uint32_t num_live_ = 0;
  uint32_t last_piece_ = 0;
};

}  // namespace svrc::delaunay
