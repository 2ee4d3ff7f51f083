// Bowyer–Watson in 2D; see delaunay2.h for the representation and conventions.
#include "core/delaunay/delaunay2.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "absl/strings/str_cat.h"
#include "core/geometry/constructions.h"
#include "core/geometry/predicates.h"
#include "core/util/grow.h"

namespace svrc::delaunay {

namespace {
inline int Next(int i) { return i == 2 ? 0 : i + 1; }
inline int Prev(int i) { return i == 0 ? 2 : i - 1; }
}  // namespace

Delaunay2::Delaunay2(std::span<const Vec2, 4> corners, std::span<const uint32_t, 4> corner_ids) {
  for (int i = 0; i < 4; ++i) {
    points_.push_back(corners[i]);
    global_ids_.push_back(corner_ids[i]);
    vertex_tri_.push_back(kFreeSlot);
  }
  vertex_mark_.assign(4, 0);
  vertex_slot_.assign(4, 0);
  // Diagonal 0–2 unless corner 3 is inside the (perturbed) circle of 0,1,2.
  const auto& c = corners;
  const auto& id = corner_ids;
  const bool flip = geom::InCircleSoS(c[0], c[1], c[2], c[3], id[0], id[1], id[2], id[3]) > 0;
  const uint32_t t0 = NewTri(), t1 = NewTri();
  if (!flip) {
    SetTri(t0, 0, 1, 2);  // edge 1 (2→0) is the diagonal
    SetTri(t1, 0, 2, 3);  // edge 2 (0→2) is the diagonal
    for (int e = 0; e < 3; ++e) tri_n_[3 * t0 + e] = tri_n_[3 * t1 + e] = kNoNeighbor;
    tri_n_[3 * t0 + 1] = 3 * t1 + 2;
    tri_n_[3 * t1 + 2] = 3 * t0 + 1;
  } else {
    SetTri(t0, 0, 1, 3);  // edge 0 (1→3) is the diagonal
    SetTri(t1, 1, 2, 3);  // edge 1 (3→1) is the diagonal
    for (int e = 0; e < 3; ++e) tri_n_[3 * t0 + e] = tri_n_[3 * t1 + e] = kNoNeighbor;
    tri_n_[3 * t0 + 0] = 3 * t1 + 1;
    tri_n_[3 * t1 + 1] = 3 * t0 + 0;
  }
  last_tri_ = t1;
}

Delaunay2 Delaunay2::Square(Vec2 lo, Vec2 hi, std::array<uint32_t, 4> corner_ids) {
  const std::array<Vec2, 4> corners = {lo, Vec2{hi.x, lo.y}, hi, Vec2{lo.x, hi.y}};
  return Delaunay2(std::span<const Vec2, 4>(corners), std::span<const uint32_t, 4>(corner_ids));
}

uint32_t Delaunay2::NewTri() {
  ++num_live_;
  if (free_head_ != kFreeSlot) {
    const uint32_t t = free_head_;
    free_head_ = tri_n_[3 * t];
    return t;
  }
  const uint32_t t = static_cast<uint32_t>(tri_gen_.size());
  // 1.25x growth (insert and push_back double): the facet meshes of a small
  // run held up to half their triangle capacity unused (session 45).
  util::ReserveForAppend(tri_v_, 3);
  util::ReserveForAppend(tri_n_, 3);
  util::ReserveForAppend(tri_gen_);
  util::ReserveForAppend(tri_mark_);
  tri_v_.insert(tri_v_.end(), 3, kFreeSlot);
  tri_n_.insert(tri_n_.end(), 3, kNoNeighbor);
  tri_gen_.push_back(0);
  tri_mark_.push_back(0);
  return t;
}

void Delaunay2::FreeTri(uint32_t t) {
  --num_live_;
  tri_v_[3 * t] = tri_v_[3 * t + 1] = tri_v_[3 * t + 2] = kFreeSlot;
  tri_n_[3 * t] = free_head_;
  tri_n_[3 * t + 1] = tri_n_[3 * t + 2] = kNoNeighbor;
  free_head_ = t;
  ++tri_gen_[t];
}

void Delaunay2::SetTri(uint32_t t, uint32_t a, uint32_t b, uint32_t c) {
  tri_v_[3 * t] = a;
  tri_v_[3 * t + 1] = b;
  tri_v_[3 * t + 2] = c;
  vertex_tri_[a] = vertex_tri_[b] = vertex_tri_[c] = t;
}

uint32_t Delaunay2::FreshTriStamp() const {
  if (++tri_stamp_ == 0) {
    std::fill(tri_mark_.begin(), tri_mark_.end(), 0);
    tri_stamp_ = 1;
  }
  return tri_stamp_;
}

uint32_t Delaunay2::FreshVertexStamp() const {
  if (vertex_mark_.size() < points_.size()) {
    vertex_mark_.reserve(points_.capacity());  // as the points grow, not doubling past them
    vertex_slot_.reserve(points_.capacity());
    vertex_mark_.resize(points_.size(), 0);
    vertex_slot_.resize(points_.size(), 0);
  }
  if (++vertex_stamp_ == 0) {
    std::fill(vertex_mark_.begin(), vertex_mark_.end(), 0);
    vertex_stamp_ = 1;
  }
  return vertex_stamp_;
}

bool Delaunay2::Conflict(uint32_t t, Vec2 p, uint32_t gid) const {
  const uint32_t* v = &tri_v_[3 * t];
  return geom::InCircleSoS(points_[v[0]], points_[v[1]], points_[v[2]], p, global_ids_[v[0]],
                           global_ids_[v[1]], global_ids_[v[2]], gid) > 0;
}

bool Delaunay2::InConflict(TriId t, Vec2 p, uint32_t global_id) const {
  return Conflict(t.value(), p, global_id);
}

// Visibility walk: leave through the first edge (in a fixed rotation starting
// after the entry edge) that has p strictly on its outer side. Acyclic on
// Delaunay (and regular) triangulations (Edelsbrunner 1990); a step budget
// with a deterministic scan guards against misuse anyway.
uint32_t Delaunay2::LocateRaw(Vec2 p, uint32_t start, uint64_t* steps) const {
  uint32_t t = start;
  int entry = -1;
  const uint64_t budget = 4ull * tri_gen_.size() + 16;
  for (uint64_t step = 0; step < budget; ++step) {
    const uint32_t* v = &tri_v_[3 * t];
    int exit_edge = -1;
    for (int k = 0; k < 3; ++k) {
      const int e = entry < 0 ? k : (entry + 1 + k) % 3;
      if (e == entry) continue;
      if (geom::Orient2d(points_[v[Next(e)]], points_[v[Prev(e)]], p) < 0) {
        exit_edge = e;
        break;
      }
    }
    if (exit_edge < 0) {
      if (steps) *steps += step;
      return t;
    }
    const uint32_t n = tri_n_[3 * t + exit_edge];
    if (n == kNoNeighbor) return kFreeSlot;  // outside the bounding quadrilateral
    t = n / 3;
    entry = static_cast<int>(n % 3);
  }
  // Not reached on a valid triangulation: scan every triangle.
  for (uint32_t s = 0; s < tri_gen_.size(); ++s) {
    if (tri_v_[3 * s] == kFreeSlot) continue;
    const uint32_t* v = &tri_v_[3 * s];
    bool inside = true;
    for (int e = 0; e < 3 && inside; ++e) {
      inside = geom::Orient2d(points_[v[Next(e)]], points_[v[Prev(e)]], p) >= 0;
    }
    if (inside) return s;
  }
  return kFreeSlot;
}

Delaunay2::TriId Delaunay2::Locate(Vec2 p, TriId hint) const {
  uint32_t start = last_tri_;
  if (hint.valid() && hint.value() < tri_gen_.size() && IsAlive(hint)) start = hint.value();
  const uint32_t t = LocateRaw(p, start, nullptr);
  return t == kFreeSlot ? kNoneTri : TriId(t);
}

Delaunay2::InsertResult Delaunay2::Insert(Vec2 p, uint32_t global_id, TriId hint) {
  destroyed_.clear();
  created_.clear();
  cavity_vertices_.clear();
  InsertResult result;
  result.outcome = InsertOutcome::kOutside;
  if (!std::isfinite(p.x) || !std::isfinite(p.y)) return result;

  uint32_t start = last_tri_;
  if (hint.valid() && hint.value() < tri_gen_.size() && IsAlive(hint)) start = hint.value();
  const uint32_t t0 = LocateRaw(p, start, &stats_.walk_steps);
  if (t0 == kFreeSlot) return result;
  {
    const uint32_t* v = &tri_v_[3 * t0];
    for (int i = 0; i < 3; ++i) {
      if (points_[v[i]] == p) {
        ++stats_.duplicates;
        result.outcome = InsertOutcome::kDuplicate;
        result.vertex = VertexId(v[i]);
        return result;
      }
    }
    // On the outer boundary: the new triangle there would be flat.
    for (int e = 0; e < 3; ++e) {
      if (tri_n_[3 * t0 + e] == kNoNeighbor &&
          geom::Orient2d(points_[v[Next(e)]], points_[v[Prev(e)]], p) == 0) {
        return result;
      }
    }
  }

  // The new vertex.
  const uint32_t pv = static_cast<uint32_t>(points_.size());
  util::ReserveForAppend(points_);
  util::ReserveForAppend(global_ids_);
  util::ReserveForAppend(vertex_tri_);
  points_.push_back(p);
  global_ids_.push_back(global_id);
  vertex_tri_.push_back(kFreeSlot);

  // Cavity: triangles in conflict, connected to t0 (which contains p, so it
  // is in conflict). Boundary edges are recorded as 3t+e with t inside.
  const uint32_t stamp = FreshTriStamp();
  stack_.clear();
  boundary_.clear();
  std::vector<uint32_t>& cavity = stack_;  // reused: cavity list (BFS queue)
  cavity.push_back(t0);
  tri_mark_[t0] = stamp;
  for (size_t head = 0; head < cavity.size(); ++head) {
    const uint32_t t = cavity[head];
    for (int e = 0; e < 3; ++e) {
      const uint32_t n = tri_n_[3 * t + e];
      if (n == kNoNeighbor) {
        boundary_.push_back(3 * t + e);
        continue;
      }
      const uint32_t u = n / 3;
      if (tri_mark_[u] == stamp) continue;
      if (Conflict(u, p, global_id)) {
        tri_mark_[u] = stamp;
        cavity.push_back(u);
      } else {
        boundary_.push_back(3 * t + e);
      }
    }
  }

  // Read everything we need from the cavity before freeing it.
  std::vector<BoundaryEdge>& edges = edges_;
  edges.clear();
  for (uint32_t be : boundary_) {
    const uint32_t t = be / 3;
    const int e = static_cast<int>(be % 3);
    edges.push_back({tri_v_[3 * t + Next(e)], tri_v_[3 * t + Prev(e)], tri_n_[be]});
  }
  for (uint32_t t : cavity) {
    destroyed_.push_back(TriId(t));
    FreeTri(t);
  }

  // Fan around p: new triangle (a, b, p) per boundary edge a→b; its edge 2
  // faces outward, edge 0 (b→p) meets the fan triangle starting at b (its
  // edge 1, p→b).
  const uint32_t vstamp = FreshVertexStamp();
  for (const BoundaryEdge& be : edges) {
    const uint32_t nt = NewTri();
    SetTri(nt, be.a, be.b, pv);
    tri_n_[3 * nt + 2] = be.outer;
    if (be.outer != kNoNeighbor) tri_n_[be.outer] = 3 * nt + 2;
    vertex_mark_[be.a] = vstamp;
    vertex_slot_[be.a] = nt;
    created_.push_back(TriId(nt));
    cavity_vertices_.push_back(VertexId(be.a));
  }
  for (const TriId& id : created_) {
    const uint32_t nt = id.value();
    const uint32_t b = tri_v_[3 * nt + 1];
    const uint32_t nb = vertex_slot_[b];  // vertex_mark_[b] == vstamp on a valid cavity
    tri_n_[3 * nt + 0] = 3 * nb + 1;
    tri_n_[3 * nb + 1] = 3 * nt + 0;
  }
  (void)vstamp;
  last_tri_ = created_.back().value();

  stats_.inserted++;
  stats_.tris_created += created_.size();
  stats_.tris_destroyed += destroyed_.size();
  result.outcome = InsertOutcome::kInserted;
  result.vertex = VertexId(pv);
  result.destroyed = destroyed_;
  result.created = created_;
  result.cavity_vertices = cavity_vertices_;
  return result;
}

std::vector<Delaunay2::TriId> Delaunay2::Triangles() const {
  std::vector<TriId> out;
  out.reserve(num_live_);
  for (uint32_t t = 0; t < tri_gen_.size(); ++t) {
    if (tri_v_[3 * t] != kFreeSlot) out.push_back(TriId(t));
  }
  return out;
}

void Delaunay2::StarRaw(uint32_t v, std::vector<uint32_t>* out) const {
  out->clear();
  const uint32_t start = vertex_tri_[v];
  auto index_of = [&](uint32_t t) {
    for (int i = 0; i < 3; ++i) {
      if (tri_v_[3 * t + i] == v) return i;
    }
    return -1;
  };
  // Counter-clockwise: across the edge (v, c) opposite b = v[i+1].
  uint32_t t = start;
  bool closed = false;
  while (true) {
    out->push_back(t);
    const uint32_t n = tri_n_[3 * t + Next(index_of(t))];
    if (n == kNoNeighbor) break;
    t = n / 3;
    if (t == start) {
      closed = true;
      break;
    }
  }
  if (closed) return;
  // Open fan (a bounding corner): collect clockwise from start, prepend.
  std::vector<uint32_t> cw;
  t = start;
  while (true) {
    const uint32_t n = tri_n_[3 * t + Prev(index_of(t))];
    if (n == kNoNeighbor) break;
    t = n / 3;
    cw.push_back(t);
  }
  std::reverse(cw.begin(), cw.end());
  cw.insert(cw.end(), out->begin(), out->end());
  *out = std::move(cw);
}

void Delaunay2::Star(VertexId v, std::vector<TriId>* out) const {
  std::vector<uint32_t>& raw = raw_scratch_;
  StarRaw(v.value(), &raw);
  out->clear();
  for (uint32_t t : raw) out->push_back(TriId(t));
}

void Delaunay2::Neighbors(VertexId v, std::vector<VertexId>* out) const {
  std::vector<uint32_t>& raw = raw_scratch_;
  StarRaw(v.value(), &raw);
  out->clear();
  int i = 0;
  for (uint32_t t : raw) {
    for (i = 0; i < 3; ++i) {
      if (tri_v_[3 * t + i] == v.value()) break;
    }
    out->push_back(VertexId(tri_v_[3 * t + Next(i)]));
  }
  // An open fan also ends with the last triangle's third vertex.
  if (!raw.empty() && tri_n_[3 * raw.back() + Next(i)] == kNoNeighbor) {
    out->push_back(VertexId(tri_v_[3 * raw.back() + Prev(i)]));
  }
}

geom::Vec2 Delaunay2::Circumcenter(TriId t) const {
  const uint32_t* v = &tri_v_[3 * t.value()];
  return geom::TriangleCircumcenter2d(points_[v[0]], points_[v[1]], points_[v[2]]);
}

double Delaunay2::Circumradius(TriId t) const {
  const uint32_t* v = &tri_v_[3 * t.value()];
  return geom::TriangleCircumcircle2d(points_[v[0]], points_[v[1]], points_[v[2]]).radius;
}

void Delaunay2::VoronoiCorners(VertexId v, std::vector<Vec2>* out) const {
  std::vector<uint32_t>& raw = raw_scratch_;
  StarRaw(v.value(), &raw);
  out->clear();
  for (uint32_t t : raw) out->push_back(Circumcenter(TriId(t)));
}

double Delaunay2::OutRadius(VertexId v, Vec2* farthest_corner) const {
  std::vector<Vec2> corners;
  VoronoiCorners(v, &corners);
  const Vec2 p = points_[v.value()];
  double best = -1;
  for (const Vec2& c : corners) {
    const double d = std::sqrt(geom::Norm2(c - p));
    if (d > best) {
      best = d;
      if (farthest_corner) *farthest_corner = c;
    }
  }
  if (IsCorner(v)) return std::numeric_limits<double>::infinity();
  return best;
}

double Delaunay2::InRadius(VertexId v) const {
  std::vector<VertexId>& nbrs = nbrs_scratch_;
  Neighbors(v, &nbrs);
  const Vec2 p = points_[v.value()];
  double best = std::numeric_limits<double>::infinity();
  for (VertexId u : nbrs) best = std::min(best, geom::Norm2(points_[u.value()] - p));
  return 0.5 * std::sqrt(best);
}

Delaunay2::VertexId Delaunay2::NearestVertex(Vec2 p, TriId hint) const {
  TriId t = Locate(p, hint);
  if (!t.valid()) t = TriId(last_tri_);
  auto closer = [&](uint32_t u, uint32_t best) {
    const int c = geom::CompareDistance(p, points_[best], points_[u]);
    return c > 0 || (c == 0 && u < best);
  };
  uint32_t best = tri_v_[3 * t.value()];
  for (int i = 1; i < 3; ++i) {
    const uint32_t u = tri_v_[3 * t.value() + i];
    if (closer(u, best)) best = u;
  }
  std::vector<VertexId>& nbrs = nbrs_scratch_;
  bool moved = true;
  while (moved) {
    moved = false;
    Neighbors(VertexId(best), &nbrs);
    for (VertexId u : nbrs) {
      if (closer(u.value(), best)) {
        best = u.value();
        moved = true;
      }
    }
  }
  return VertexId(best);
}

Delaunay2::VertexId Delaunay2::NearVertex(Vec2 p, TriId hint) const {
  TriId t = Locate(p, hint);
  if (!t.valid()) t = TriId(last_tri_);
  auto d2 = [&](uint32_t u) {
    const double dx = points_[u].x - p.x, dy = points_[u].y - p.y;
    return dx * dx + dy * dy;
  };
  uint32_t best = tri_v_[3 * t.value()];
  double best_d2 = d2(best);
  for (int i = 1; i < 3; ++i) {
    const uint32_t u = tri_v_[3 * t.value() + i];
    const double d = d2(u);
    if (d < best_d2 || (d == best_d2 && u < best)) {
      best = u;
      best_d2 = d;
    }
  }
  std::vector<VertexId>& nbrs = nbrs_scratch_;
  for (bool moved = true; moved;) {
    moved = false;
    Neighbors(VertexId(best), &nbrs);
    for (VertexId u : nbrs) {
      const double d = d2(u.value());
      if (d < best_d2) {  // strictly nearer: the descent ends
        best = u.value();
        best_d2 = d;
        moved = true;
      }
    }
  }
  return VertexId(best);
}

absl::Status Delaunay2::Validate(bool check_empty_circle) const {
  const uint32_t nv = static_cast<uint32_t>(points_.size());
  uint32_t live = 0, boundary_edges = 0;
  for (uint32_t t = 0; t < tri_gen_.size(); ++t) {
    const uint32_t* v = &tri_v_[3 * t];
    if (v[0] == kFreeSlot) continue;
    ++live;
    for (int i = 0; i < 3; ++i) {
      if (v[i] >= nv) return absl::InternalError(absl::StrCat("tri ", t, " bad vertex ", v[i]));
    }
    if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) {
      return absl::InternalError(absl::StrCat("tri ", t, " repeats a vertex"));
    }
    if (geom::Orient2d(points_[v[0]], points_[v[1]], points_[v[2]]) <= 0) {
      return absl::InternalError(absl::StrCat("tri ", t, " (", v[0], ",", v[1], ",", v[2],
                                              ") not counter-clockwise"));
    }
    for (int e = 0; e < 3; ++e) {
      const uint32_t n = tri_n_[3 * t + e];
      const uint32_t a = v[Next(e)], b = v[Prev(e)];
      if (n == kNoNeighbor) {
        ++boundary_edges;
        // Outer edges are the quadrilateral's sides i → i+1.
        if (!(a < 4 && b < 4 && b == (a + 1) % 4)) {
          return absl::InternalError(absl::StrCat("tri ", t, " edge ", e, " (", a, ",", b,
                                                  ") has no neighbour but is not a box side"));
        }
        continue;
      }
      const uint32_t u = n / 3, f = n % 3;
      if (u >= tri_gen_.size() || tri_v_[3 * u] == kFreeSlot) {
        return absl::InternalError(absl::StrCat("tri ", t, " edge ", e, " points to dead tri ", u));
      }
      if (tri_n_[n] != 3 * t + e) {
        return absl::InternalError(absl::StrCat("tri ", t, " edge ", e, " -> tri ", u, " edge ", f,
                                                " is not symmetric"));
      }
      const uint32_t* w = &tri_v_[3 * u];
      if (w[Next(f)] != b || w[Prev(f)] != a) {
        return absl::InternalError(absl::StrCat("tri ", t, " edge ", e, " and tri ", u, " edge ", f,
                                                " do not share their vertices"));
      }
      if (check_empty_circle && t < u) {
        const uint32_t d = w[f];
        if (geom::InCircleSoS(points_[v[0]], points_[v[1]], points_[v[2]], points_[d],
                              global_ids_[v[0]], global_ids_[v[1]], global_ids_[v[2]],
                              global_ids_[d]) >= 0) {
          return absl::InternalError(absl::StrCat("edge (", a, ",", b, ") between tris ", t, " and ",
                                                  u, " is not locally Delaunay: vertex ", d,
                                                  " in circle of tri ", t));
        }
      }
    }
  }
  if (live != num_live_) {
    return absl::InternalError(absl::StrCat("live count ", live, " != ", num_live_));
  }
  uint32_t free_count = 0;
  for (uint32_t t = free_head_; t != kFreeSlot; t = tri_n_[3 * t]) {
    if (t >= tri_gen_.size() || tri_v_[3 * t] != kFreeSlot || ++free_count > tri_gen_.size()) {
      return absl::InternalError("free list corrupt");
    }
  }
  if (free_count + live != tri_gen_.size()) {
    return absl::InternalError(absl::StrCat("free ", free_count, " + live ", live, " != slots ",
                                            tri_gen_.size()));
  }
  if (boundary_edges != 4) {
    return absl::InternalError(absl::StrCat(boundary_edges, " boundary edges, expected 4"));
  }
  // Euler: a triangulation of n points with 4 on the hull has 2n − 6 triangles.
  if (live != 2 * nv - 6) {
    return absl::InternalError(absl::StrCat(live, " triangles for ", nv, " vertices, expected ",
                                            2 * nv - 6));
  }
  for (uint32_t v = 0; v < nv; ++v) {
    const uint32_t t = vertex_tri_[v];
    if (t >= tri_gen_.size() || tri_v_[3 * t] == kFreeSlot ||
        (tri_v_[3 * t] != v && tri_v_[3 * t + 1] != v && tri_v_[3 * t + 2] != v)) {
      return absl::InternalError(absl::StrCat("vertex ", v, " -> tri ", t, " not incident"));
    }
  }
  return absl::OkStatus();
}

}  // namespace svrc::delaunay
