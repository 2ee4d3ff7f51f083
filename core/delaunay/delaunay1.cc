// The 1D segment mesh; see delaunay1.h.
#include "core/delaunay/delaunay1.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "core/geometry/predicates.h"

namespace svrc::delaunay {

Delaunay1::Delaunay1(const Vec3& a, const Vec3& b, uint32_t id_a, uint32_t id_b) : a_(a), b_(b) {
  points_ = {a, b};
  global_ids_ = {id_a, id_b};
  t_ = {0.0, 1.0};
  left_ = {kNone, kNone};
  right_ = {kNone, kNone};
  const uint32_t s = NewPiece(0, 1);
  right_[0] = s;
  left_[1] = s;
  last_piece_ = s;
}

int Delaunay1::Order(const Vec3& p, const Vec3& q) const { return geom::DotSign(p, q, a_, b_); }

uint32_t Delaunay1::NewPiece(uint32_t l, uint32_t r) {
  ++num_live_;
  uint32_t s;
  if (free_head_ != kFree) {
    s = free_head_;
    free_head_ = piece_r_[s];
  } else {
    s = static_cast<uint32_t>(piece_gen_.size());
    piece_l_.push_back(kFree);
    piece_r_.push_back(kFree);
    piece_gen_.push_back(0);
  }
  piece_l_[s] = l;
  piece_r_[s] = r;
  return s;
}

void Delaunay1::FreePiece(uint32_t s) {
  --num_live_;
  piece_l_[s] = kFree;
  piece_r_[s] = free_head_;
  free_head_ = s;
  ++piece_gen_[s];
}

Delaunay1::PieceId Delaunay1::Locate(const Vec3& p, PieceId hint) const {
  uint32_t s = last_piece_;
  if (hint.valid() && hint.value() < piece_gen_.size() && IsAlive(hint)) s = hint.value();
  // Walk left or right until the piece's closure contains p (projections).
  while (true) {
    const uint32_t l = piece_l_[s], r = piece_r_[s];
    if (Order(points_[l], p) < 0) {
      if (left_[l] == kNone) return kNonePiece;
      s = left_[l];
    } else if (Order(p, points_[r]) < 0) {
      if (right_[r] == kNone) return kNonePiece;
      s = right_[r];
    } else {
      return PieceId(s);
    }
  }
}

Delaunay1::InsertResult Delaunay1::Insert(const Vec3& p, uint32_t global_id, PieceId hint) {
  InsertResult result;
  result.outcome = InsertOutcome::kOutside;
  if (!geom::IsFinite(p)) return result;
  const PieceId located = Locate(p, hint);
  if (!located.valid()) return result;
  const uint32_t s = located.value();
  const uint32_t l = piece_l_[s], r = piece_r_[s];
  if (Order(points_[l], p) == 0 || Order(p, points_[r]) == 0) {
    result.outcome = InsertOutcome::kDuplicate;
    result.vertex = VertexId(Order(points_[l], p) == 0 ? l : r);
    return result;
  }
  const uint32_t v = static_cast<uint32_t>(points_.size());
  points_.push_back(p);
  global_ids_.push_back(global_id);
  const Vec3 d = b_ - a_;
  t_.push_back(geom::Dot(p - a_, d) / geom::Norm2(d));
  FreePiece(s);
  const uint32_t s1 = NewPiece(l, v), s2 = NewPiece(v, r);
  right_[l] = s1;
  left_[r] = s2;
  left_.push_back(s1);
  right_.push_back(s2);
  last_piece_ = s2;
  result.outcome = InsertOutcome::kInserted;
  result.vertex = VertexId(v);
  result.destroyed = PieceId(s);
  result.created = {PieceId(s1), PieceId(s2)};
  result.cavity_vertices = {VertexId(l), VertexId(r)};
  return result;
}

Delaunay1::VertexId Delaunay1::Prev(VertexId v) const {
  const uint32_t s = left_[v.value()];
  return s == kNone ? kNoneVertex : VertexId(piece_l_[s]);
}

Delaunay1::VertexId Delaunay1::Next(VertexId v) const {
  const uint32_t s = right_[v.value()];
  return s == kNone ? kNoneVertex : VertexId(piece_r_[s]);
}

std::vector<Delaunay1::PieceId> Delaunay1::Pieces() const {
  std::vector<PieceId> out;
  for (uint32_t v = 0; right_[v] != kNone; v = piece_r_[right_[v]]) out.push_back(PieceId(right_[v]));
  return out;
}

std::vector<Delaunay1::VertexId> Delaunay1::Vertices() const {
  std::vector<VertexId> out{VertexId(0)};
  for (uint32_t v = 0; right_[v] != kNone;) {
    v = piece_r_[right_[v]];
    out.push_back(VertexId(v));
  }
  return out;
}

geom::Vec3 Delaunay1::PieceMidpoint(PieceId p) const {
  const Vec3& l = points_[piece_l_[p.value()]];
  const Vec3& r = points_[piece_r_[p.value()]];
  return l + 0.5 * (r - l);
}

double Delaunay1::PieceHalfLength(PieceId p) const {
  return 0.5 * geom::Dist(points_[piece_l_[p.value()]], points_[piece_r_[p.value()]]);
}

double Delaunay1::OutRadius(VertexId v, Vec3* farthest_corner) const {
  double best = -1;
  for (uint32_t s : {left_[v.value()], right_[v.value()]}) {
    if (s == kNone) continue;
    const double h = PieceHalfLength(PieceId(s));
    if (h > best) {
      best = h;
      if (farthest_corner) *farthest_corner = PieceMidpoint(PieceId(s));
    }
  }
  return best;
}

double Delaunay1::InRadius(VertexId v) const {
  double best = HUGE_VAL;
  for (uint32_t s : {left_[v.value()], right_[v.value()]}) {
    if (s != kNone) best = std::min(best, PieceHalfLength(PieceId(s)));
  }
  return best;
}

Delaunay1::VertexId Delaunay1::NearestVertex(const Vec3& p, PieceId hint) const {
  PieceId s = Locate(p, hint);
  uint32_t best;
  if (!s.valid()) {
    // Beyond an end: the nearer endpoint... of the whole chain.
    best = Order(p, a_) >= 0 ? 0 : 1;
  } else {
    const uint32_t l = piece_l_[s.value()], r = piece_r_[s.value()];
    const int c = geom::CompareDistance(p, points_[l], points_[r]);
    best = (c > 0 || (c == 0 && r < l)) ? r : l;
  }
  // Off-segment points may be nearer to a vertex further along: descend.
  bool moved = true;
  while (moved) {
    moved = false;
    for (VertexId u : {Prev(VertexId(best)), Next(VertexId(best))}) {
      if (!u.valid()) continue;
      const int c = geom::CompareDistance(p, points_[best], points_[u.value()]);
      if (c > 0 || (c == 0 && u.value() < best)) {
        best = u.value();
        moved = true;
      }
    }
  }
  return VertexId(best);
}

absl::Status Delaunay1::Validate() const {
  const uint32_t nv = NumVertices();
  if (left_[0] != kNone || right_[1] != kNone) {
    return absl::InternalError("endpoint a must be first and b last");
  }
  std::vector<bool> seen(nv, false);
  uint32_t v = 0, pieces = 0;
  seen[0] = true;
  while (right_[v] != kNone) {
    const uint32_t s = right_[v];
    if (s >= piece_gen_.size() || piece_l_[s] != v) {
      return absl::InternalError(absl::StrCat("piece ", s, " right of vertex ", v, " does not start there"));
    }
    const uint32_t w = piece_r_[s];
    if (w >= nv || left_[w] != s) {
      return absl::InternalError(absl::StrCat("piece ", s, " end ", w, " not linked back"));
    }
    if (Order(points_[v], points_[w]) <= 0) {
      return absl::InternalError(absl::StrCat("vertices ", v, " and ", w, " out of order"));
    }
    if (seen[w]) return absl::InternalError(absl::StrCat("vertex ", w, " visited twice"));
    seen[w] = true;
    ++pieces;
    v = w;
  }
  if (v != 1) return absl::InternalError(absl::StrCat("chain ends at ", v, ", not at b"));
  if (pieces + 1 != nv || pieces != num_live_) {
    return absl::InternalError(absl::StrCat(pieces, " pieces for ", nv, " vertices (live ", num_live_, ")"));
  }
  uint32_t free_count = 0;
  for (uint32_t s = free_head_; s != kFree; s = piece_r_[s]) {
    if (s >= piece_gen_.size() || piece_l_[s] != kFree || ++free_count > piece_gen_.size()) {
      return absl::InternalError("free list corrupt");
    }
  }
  if (free_count + num_live_ != piece_gen_.size()) return absl::InternalError("slot count mismatch");
  return absl::OkStatus();
}

}  // namespace svrc::delaunay
