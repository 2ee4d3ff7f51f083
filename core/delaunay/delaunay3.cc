// Incremental 3D Delaunay (Bowyer–Watson) — see delaunay3.h for the layout.
//
// Insertion of p: find one tet in conflict with p (the caller's hint if it
// conflicts, else a visibility walk), grow the cavity (all tets whose
// perturbed circumsphere strictly contains p) by a depth-first search over
// faces, then replace it by the star of p: one new tet per cavity boundary
// face, tet = the cavity tet's vertices with the one opposite that face
// replaced by p (so orientation is inherited, and the ghost vertex stays at
// position 3). New tets are glued to each other through the cavity-boundary
// edge they share, found in a small stamped hash table.
#include "core/delaunay/delaunay3.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "absl/strings/str_cat.h"
#include "core/geometry/predicates.h"
#include "core/util/grow.h"

namespace svrc::delaunay {
namespace {

constexpr uint32_t kInf = kInfiniteVertex.value();

// Face f of a tet consists of the vertices at kFaceVertices[f][0..2].
constexpr int kFaceVertices[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};

// kEdge[a][i]: for a tet whose apex (the vertex shared by all new tets) is at
// position a, the face opposite position i != a contains the apex and the
// edge between positions kEdge[a][i][0] and kEdge[a][i][1].
constexpr uint8_t kEdge[4][4][2] = {
    {{0, 0}, {2, 3}, {1, 3}, {1, 2}},
    {{2, 3}, {0, 0}, {0, 3}, {0, 2}},
    {{1, 3}, {0, 3}, {0, 0}, {0, 1}},
    {{1, 2}, {0, 2}, {0, 1}, {0, 0}},
};

inline uint64_t EdgeKey(uint32_t a, uint32_t b) {
  return a < b ? (static_cast<uint64_t>(a) << 32) | b : (static_cast<uint64_t>(b) << 32) | a;
}
inline uint32_t HashKey(uint64_t k) {
  k *= 0x9E3779B97F4A7C15ull;
  return static_cast<uint32_t>(k >> 40);
}

// Exactly collinear: every component of (b−a)×(c−a) is zero.
bool Collinear(const Vec3& a, const Vec3& b, const Vec3& c) {
  for (int axis = 0; axis < 3; ++axis) {
    if (geom::Orient2dProjected(a, b, c, axis) != 0) return false;
  }
  return true;
}

}  // namespace

Delaunay3::Delaunay3() = default;

void Delaunay3::ReserveVertex() {
  // Per-vertex arrays grow by a quarter, not double (std::vector's push_back):
  // on cube --max-volume 1e-6 the points' array held 2^19 slots for 330 k
  // vertices (session 29).
  util::ReserveForAppend(points_);
  util::ReserveForAppend(global_ids_);
  util::ReserveForAppend(vertex_tet_);
  util::ReserveForAppend(star_version_);
}

void Delaunay3::Reserve(size_t num_vertices) {
  points_.reserve(num_vertices);
  global_ids_.reserve(num_vertices);
  vertex_tet_.reserve(num_vertices);
  star_version_.reserve(num_vertices);
  const size_t tets = num_vertices * 7 + 64;
  tets_.reserve(8 * tets);
  tet_gen_.reserve(tets);
  tet_bits_.reserve(tets / 64 + 1);
  outside_bits_.reserve(tets / 64 + 1);
}

// ---------------------------------------------------------------------------
// Tet slots.

inline uint32_t Delaunay3::NewTet() {
  if (free_head_ == kFreeSlot) GrowTets();
  const uint32_t t = free_head_;
  free_head_ = tets_[8 * t + 4];
  ++num_live_tets_;
  return t;
}

// Appends a batch of free slots (lowest id first on the free list), so the
// arrays grow in bulk rather than per tet.
void Delaunay3::GrowTets() {
  const uint32_t old_cap = TetCapacity();
  const uint32_t add = std::max<uint32_t>(64, old_cap / 4);
  const size_t cap = size_t{old_cap} + add;
  util::GrowExactly(tets_, 8 * cap, kFreeSlot);
  util::GrowExactly(tet_gen_, cap, 0u);
  tet_bits_.resize(cap / 64 + 1, 0);
  outside_bits_.resize(cap / 64 + 1, 0);
  for (uint32_t t = static_cast<uint32_t>(cap); t-- > old_cap;) {
    tets_[8 * t + 4] = free_head_;
    free_head_ = t;
  }
}

inline void Delaunay3::FreeTet(uint32_t t) {
  if (tets_[8 * t + 3] == kInf) --num_ghost_tets_;
  tets_[8 * t] = kFreeSlot;
  tets_[8 * t + 4] = free_head_;
  free_head_ = t;
  ++tet_gen_[t];
  --num_live_tets_;
}

// ---------------------------------------------------------------------------
// Predicates on tets.

// Conflict of tet t with p. Sets *sos_used when the decision needed the
// symbolic perturbation (an exactly cospherical / coplanar configuration).
[[gnu::always_inline]] inline bool Delaunay3::ConflictRaw(uint32_t t, const Vec3& p, uint32_t gid,
                                   uint32_t* sos_used) const {
  const uint32_t* v = &tets_[8 * t];
  if (v[3] != kInf) {
    const int s = geom::InSphere(points_[v[0]], points_[v[1]], points_[v[2]], points_[v[3]], p);
    if (s != 0) return s > 0;
  }
  return ConflictSlow(t, p, gid, sos_used);
}

bool Delaunay3::ConflictSlow(uint32_t t, const Vec3& p, uint32_t gid, uint32_t* sos_used) const {
  const uint32_t* v = &tets_[8 * t];
  if (v[3] != kInf) {
    // The exact in-sphere value is 0 (ConflictRaw ran it).
    *sos_used = 1;
    return geom::internal::InSphereSoSTail(points_[v[0]], points_[v[1]], points_[v[2]],
                                           points_[v[3]], p, global_ids_[v[0]], global_ids_[v[1]],
                                           global_ids_[v[2]], global_ids_[v[3]], gid) > 0;
  }
  // Ghost (a,b,c,∞): conflict iff p is strictly beyond the hull face, or on
  // its plane and inside its circumcircle. The perturbed in-circle test equals
  // the perturbed in-sphere test of the finite tet behind the face: the sphere
  // meets the plane in the face's circumcircle, and under the lifting
  // perturbation the opposite vertex's term has coefficient Orient3d(a,b,c,p) = 0.
  const int o = geom::Orient3d(points_[v[0]], points_[v[1]], points_[v[2]], p);
  if (o != 0) return o > 0;
  return ConflictRaw(tets_[8 * t + 4 + 3] >> 2, p, gid, sos_used);
}

bool Delaunay3::InConflict(TetId t, const Vec3& p, uint32_t global_id) const {
  uint32_t sos = 0;
  return ConflictRaw(t.value(), p, global_id, &sos);
}

// Visibility walk (Devillers–Pion–Teillaud "Walking in a triangulation"):
// from a finite tet, cross a face whose outer side holds p until none does.
// The face order rotates by a fixed xorshift sequence so the walk cannot
// cycle in practice and is still deterministic. Returns a finite tet whose
// closure contains p, or the ghost tet across the hull face p is beyond.
uint32_t Delaunay3::WalkRaw(const Vec3& p, uint32_t t, uint32_t* steps) const {
  if (tets_[8 * t + 3] == kInf) t = tets_[8 * t + 4 + 3] >> 2;
  uint32_t rng = 0x2545F491u;
  uint32_t from = 4;  // face we entered through (skip it)
  for (;;) {
    const uint32_t* v = &tets_[8 * t];
    rng ^= rng << 13;
    rng ^= rng >> 17;
    rng ^= rng << 5;
    const uint32_t r = rng & 3;
    bool moved = false;
    const Vec3& a = points_[v[0]];
    const Vec3& b = points_[v[1]];
    const Vec3& c = points_[v[2]];
    const Vec3& d = points_[v[3]];
    for (uint32_t k = 0; k < 4; ++k) {
      const uint32_t f = (r + k) & 3;
      if (f == from) continue;
      // Orientation with vertex f replaced by p: < 0 iff p is beyond face f.
      int o;
      switch (f) {
        case 0: o = geom::Orient3d(p, b, c, d); break;
        case 1: o = geom::Orient3d(a, p, c, d); break;
        case 2: o = geom::Orient3d(a, b, p, d); break;
        default: o = geom::Orient3d(a, b, c, p); break;
      }
      if (o < 0) {
        const uint32_t n = tets_[8 * t + 4 + f];
        t = n >> 2;
        from = n & 3;
        ++*steps;
        if (tets_[8 * t + 3] == kInf) return t;
        moved = true;
        break;
      }
    }
    if (!moved) return t;
  }
}

TetId Delaunay3::Locate(const Vec3& p, TetId hint) const {
  if (!Is3d()) return kNoneTet;
  uint32_t start = hint.valid() && hint.value() < TetCapacity() && IsAlive(hint) ? hint.value()
                                                                                  : last_tet_;
  uint32_t steps = 0;
  return TetId(WalkRaw(p, start, &steps));
}

// ---------------------------------------------------------------------------
// Insertion.

Delaunay3::InsertResult Delaunay3::Insert(const Vec3& p, uint32_t global_id, TetId hint) {
  destroyed_.clear();
  created_.clear();
  cavity_vertices_.clear();
  if (!Is3d()) return InsertPending(p, global_id);

  uint32_t start = kFreeSlot;
  uint32_t sos = 0;  // the hint's conflict needed the perturbation
  if (hint.valid() && hint.value() < TetCapacity() && IsAlive(hint) &&
      ConflictRaw(hint.value(), p, global_id, &sos)) {
    start = hint.value();
  } else {
    uint32_t from = hint.valid() && hint.value() < TetCapacity() && IsAlive(hint) ? hint.value()
                                                                                  : last_tet_;
    uint32_t steps = 0;
    start = WalkRaw(p, from, &steps);
    stats_.walk_steps += steps;
    // A finite tet whose closure holds p conflicts with p (p is strictly
    // inside its circumsphere) unless p is one of its vertices.
    if (tets_[8 * start + 3] != kInf) {
      for (int i = 0; i < 4; ++i) {
        if (points_[tets_[8 * start + i]] == p) {
          ++stats_.duplicates;
          InsertResult r;
          r.outcome = InsertOutcome::kDuplicate;
          r.vertex = VertexId(tets_[8 * start + i]);
          return r;
        }
      }
    }
  }
  const uint32_t v = static_cast<uint32_t>(points_.size());
  ReserveVertex();
  points_.push_back(p);
  global_ids_.push_back(global_id);
  vertex_tet_.push_back(kFreeSlot);
  star_version_.push_back(0);
  InsertResult r = InsertVertex(v, start, sos);
  if (r.outcome == InsertOutcome::kDuplicate) {
    points_.pop_back();
    global_ids_.pop_back();
    vertex_tet_.pop_back();
    star_version_.pop_back();
  }
  return r;
}

// Bowyer–Watson step for the already stored vertex v, from a tet known to
// conflict with it.
template <class Conflict>
void Delaunay3::FloodCavity(uint32_t start, Conflict&& conflict, std::vector<TetId>* cavity,
                            std::vector<uint32_t>* boundary) const {
  // Marks: tet_bits_ = in the cavity, outside_bits_ = tested, not in
  // conflict. One bit per slot (the sets stay in cache; 32-bit stamps over
  // millions of tets did not), all cleared again below from the lists.
  uint64_t* in_cavity = tet_bits_.data();
  uint64_t* outside = outside_bits_.data();
  auto test = [](const uint64_t* bits, uint32_t t) { return (bits[t >> 6] >> (t & 63)) & 1; };
  auto set = [](uint64_t* bits, uint32_t t) { bits[t >> 6] |= uint64_t{1} << (t & 63); };

  cavity->clear();
  boundary->clear();
  stack_.clear();
  stack_.push_back(start);
  set(in_cavity, start);
  while (!stack_.empty()) {
    const uint32_t t = stack_.back();
    stack_.pop_back();
    cavity->push_back(TetId(t));
    for (uint32_t f = 0; f < 4; ++f) {
      const uint32_t n = tets_[8 * t + 4 + f];
      const uint32_t u = n >> 2;
      if (test(in_cavity, u)) continue;
      if (!test(outside, u)) {
        if (conflict(u)) {
          set(in_cavity, u);
          stack_.push_back(u);
          continue;
        }
        set(outside, u);
      }
      boundary->push_back(4 * t + f);
    }
  }
  // Every marked tet is in the cavity or across one of its boundary faces;
  // set bits belong to this flood only, so whole words can be zeroed.
  for (TetId d : *cavity) in_cavity[d.value() >> 6] = 0;
  for (uint32_t bf : *boundary) outside[tets_[NRef(bf)] >> 8] = 0;
}

bool Delaunay3::CavityBoundary(const Vec3& p, uint32_t global_id, TetId start, size_t max_tets,
                               std::vector<uint32_t>* boundary) const {
  if (!Is3d() || !start.valid() || start.value() >= TetCapacity() || !IsAlive(start) ||
      !InConflict(start, p, global_id)) {
    return false;
  }
  // Past max_tets the flood takes no more tets (a conflict then reads as
  // none), so it ends within the tets it has and their neighbours.
  bool ghost = IsGhost(start), overflow = false;
  size_t taken = 1;
  uint32_t sos = 0;
  FloodCavity(
      start.value(),
      [&](uint32_t u) {
        if (overflow || !ConflictRaw(u, p, global_id, &sos)) return false;
        if (++taken > max_tets) {
          overflow = true;
          return false;
        }
        ghost = ghost || tets_[8 * u + 3] == kInf;
        return true;
      },
      &dry_cavity_, boundary);
  return !overflow && !ghost;
}

Delaunay3::InsertResult Delaunay3::InsertVertex(uint32_t v, uint32_t start, uint32_t sos) {
  const Vec3 p = points_[v];
  const uint32_t gid = global_ids_[v];
  FloodCavity(start, [&](uint32_t u) { return ConflictRaw(u, p, gid, &sos); }, &destroyed_, &boundary_);
  auto test = [](const uint64_t* bits, uint32_t t) { return (bits[t >> 6] >> (t & 63)) & 1; };
  auto set = [](uint64_t* bits, uint32_t t) { bits[t >> 6] |= uint64_t{1} << (t & 63); };

  // An exact duplicate only ever conflicts through the perturbation (p lies
  // on, never strictly inside, the spheres of the tets around its twin).
  if (sos) {
    for (TetId dt : destroyed_) {
      const uint32_t t = dt.value();
      for (int i = 0; i < 4; ++i) {
        const uint32_t w = tets_[8 * t + i];
        if (w != kInf && w != v && points_[w] == p) {
          ++stats_.duplicates;
          // Nothing was modified (the marks are already cleared).
          destroyed_.clear();
          InsertResult r;
          r.outcome = InsertOutcome::kDuplicate;
          r.vertex = VertexId(w);
          return r;
        }
      }
    }
  }

  // New tets: record (vertices, outer neighbour) per boundary face before the
  // cavity's slots are recycled.
  const size_t nb = boundary_.size();
  new_v_.resize(4 * nb);
  new_outer_.resize(nb);
  for (size_t k = 0; k < nb; ++k) {
    const uint32_t bf = boundary_[k];
    const uint32_t t = bf >> 2;
    std::copy_n(&tets_[8 * t], 4, &new_v_[4 * k]);
    new_v_[4 * k + (bf & 3)] = v;
    new_outer_[k] = tets_[NRef(bf)];
  }
  for (TetId dt : destroyed_) FreeTet(dt.value());

  // Create them and glue them: the face opposite position i != f of new tet k
  // goes through p and the edge kEdge[f][i] of the boundary face; the other
  // new tet on that edge is found in a stamped hash table.
  const uint32_t mask = EdgeTableFor(nb);
  EdgeSlot* table = edge_table_.data();
  const uint32_t epoch = edge_epoch_;
  created_.resize(nb);
  for (size_t k = 0; k < nb; ++k) {
    const uint32_t t = NewTet();
    created_[k] = TetId(t);
    uint32_t* tv = &tets_[8 * t];
    std::copy_n(&new_v_[4 * k], 4, tv);
    if (tv[3] == kInf) ++num_ghost_tets_;
    const uint32_t f = boundary_[k] & 3;
    const uint32_t o = new_outer_[k];
    tets_[8 * t + 4 + f] = o;
    tets_[NRef(o)] = 4 * t + f;
    for (uint32_t i = 0; i < 4; ++i) {
      if (i == f) continue;
      const uint64_t key = EdgeKey(tv[kEdge[f][i][0]], tv[kEdge[f][i][1]]);
      uint32_t h = HashKey(key) & mask;
      for (;;) {
        EdgeSlot& e = table[h];
        if (e.stamp != epoch) {
          e.stamp = epoch;
          e.key = key;
          e.val = 4 * t + i;
          break;
        }
        if (e.key == key) {
          tets_[8 * t + 4 + i] = e.val;
          tets_[NRef(e.val)] = 4 * t + i;
          break;
        }
        h = (h + 1) & mask;
      }
    }
    // Vertex → tet for p and the boundary face's vertices; their stars
    // changed, so do their cached neighbour lists.
    for (int i = 0; i < 4; ++i) {
      if (tv[i] != kInf) {
        vertex_tet_[tv[i]] = t;
        ++star_version_[tv[i]];
        if (cache_neighbors_) InvalidateAdj(tv[i]);
      }
    }
  }

  cavity_vertices_.clear();
  if (report_cavity_vertices_) {
    if (vertex_bits_.size() * 64 < points_.size()) {
      vertex_bits_.resize(points_.size() / 64 + points_.size() / 128 + 1, 0);
    }
    uint64_t* seen = vertex_bits_.data();
    for (TetId ct : created_) {
      const uint32_t* tv = &tets_[8 * ct.value()];
      for (int i = 0; i < 4; ++i) {
        const uint32_t w = tv[i];
        if (w == kInf || w == v || test(seen, w)) continue;
        set(seen, w);
        cavity_vertices_.push_back(VertexId(w));
      }
    }
    for (VertexId w : cavity_vertices_) seen[w.value() >> 6] = 0;
  }
  last_tet_ = created_.back().value();
  ++stats_.inserted;
  stats_.tets_created += created_.size();
  stats_.tets_destroyed += destroyed_.size();

  InsertResult r;
  r.outcome = InsertOutcome::kInserted;
  r.vertex = VertexId(v);
  r.destroyed = destroyed_;
  r.created = created_;
  r.created_on = boundary_;
  r.cavity_vertices = cavity_vertices_;
  return r;
}

// Glues the tets in created_ to each other. Every created tet contains the
// apex vertex `apex`; its faces through the apex are matched through the edge
// they share with the other face: the pair of vertices other than the apex
// and the vertex opposite the face. Each such edge is shared by exactly two
// created tets (the cavity boundary is a closed surface).
void Delaunay3::LinkAroundApex(uint32_t apex) {
  const uint32_t mask = EdgeTableFor(created_.size());
  for (TetId ct : created_) {
    const uint32_t t = ct.value();
    const uint32_t* tv = &tets_[8 * t];
    int a = 0;
    while (tv[a] != apex) ++a;
    for (int i = 0; i < 4; ++i) {
      if (i == a) continue;
      const uint64_t key = EdgeKey(tv[kEdge[a][i][0]], tv[kEdge[a][i][1]]);
      uint32_t h = HashKey(key) & mask;
      for (;;) {
        EdgeSlot& e = edge_table_[h];
        if (e.stamp != edge_epoch_) {
          e = {key, 4 * t + i, edge_epoch_};
          break;
        }
        if (e.key == key) {
          tets_[8 * t + 4 + i] = e.val;
          tets_[NRef(e.val)] = 4 * t + i;
          break;
        }
        h = (h + 1) & mask;
      }
    }
  }
}

// Makes the edge table large enough for the edges of num_tets new tets (3/2
// per tet, load <= 1/4) and starts a new epoch; returns the index mask.
uint32_t Delaunay3::EdgeTableFor(size_t num_tets) {
  const size_t need = 6 * num_tets + 16;
  if (edge_table_.size() < need) {
    size_t sz = 64;
    while (sz < need) sz *= 2;
    edge_table_.assign(sz, EdgeSlot{0, 0, 0});
    edge_epoch_ = 0;
  }
  if (++edge_epoch_ == 0) {
    for (auto& e : edge_table_) e.stamp = 0;
    edge_epoch_ = 1;
  }
  return static_cast<uint32_t>(edge_table_.size() - 1);
}

// Before the first tetrahedron: keep points, track the affine hull of the
// points so far through a basis (up to three of them), and build the first
// tetrahedralization when a point leaves the basis's plane.
Delaunay3::InsertResult Delaunay3::InsertPending(const Vec3& p, uint32_t global_id) {
  InsertResult r;
  for (uint32_t w : pending_) {
    if (points_[w] == p) {
      ++stats_.duplicates;
      r.outcome = InsertOutcome::kDuplicate;
      r.vertex = VertexId(w);
      return r;
    }
  }
  const uint32_t v = static_cast<uint32_t>(points_.size());
  ReserveVertex();
  points_.push_back(p);
  global_ids_.push_back(global_id);
  vertex_tet_.push_back(kFreeSlot);
  star_version_.push_back(0);
  pending_.push_back(v);
  r.vertex = VertexId(v);
  r.outcome = InsertOutcome::kPending;
  if (basis_.size() < 2) {
    basis_.push_back(v);  // distinct from basis_[0]: not a duplicate
    return r;
  }
  if (basis_.size() == 2) {
    if (!Collinear(points_[basis_[0]], points_[basis_[1]], p)) basis_.push_back(v);
    return r;
  }
  if (geom::Orient3d(points_[basis_[0]], points_[basis_[1]], points_[basis_[2]], p) == 0) {
    return r;
  }
  // Full-dimensional: the first tet, then the other pending points in order.
  BuildFirstTet(basis_[0], basis_[1], basis_[2], v);
  std::vector<uint32_t> rest;
  for (uint32_t w : pending_) {
    if (w != basis_[0] && w != basis_[1] && w != basis_[2] && w != v) rest.push_back(w);
  }
  pending_.clear();
  pending_.shrink_to_fit();
  Stats before = stats_;
  for (uint32_t w : rest) {
    uint32_t steps = 0;
    const uint32_t start = WalkRaw(points_[w], last_tet_, &steps);
    // Pending points are pairwise distinct, so no duplicate can occur.
    InsertVertex(w, start, 0);
  }
  stats_.inserted = before.inserted + 1 + rest.size();
  destroyed_.clear();
  created_.clear();
  cavity_vertices_.clear();
  for (uint32_t t = 0; t < TetCapacity(); ++t) {
    if (IsAlive(TetId(t))) created_.push_back(TetId(t));
  }
  for (uint32_t w = 0; w < v; ++w) cavity_vertices_.push_back(VertexId(w));
  r.outcome = InsertOutcome::kInserted;
  r.created = created_;
  r.cavity_vertices = cavity_vertices_;
  return r;
}

void Delaunay3::BuildFirstTet(uint32_t a, uint32_t b, uint32_t c, uint32_t d) {
  if (geom::Orient3d(points_[a], points_[b], points_[c], points_[d]) < 0) std::swap(a, b);
  const uint32_t t0 = NewTet();
  const uint32_t tv[4] = {a, b, c, d};
  for (int i = 0; i < 4; ++i) tets_[8 * t0 + i] = tv[i];
  created_.clear();
  for (int f = 0; f < 4; ++f) {
    // Replacing vertex f by ∞ gives a negatively oriented ghost; one
    // transposition moving ∞ to position 3 fixes the orientation.
    uint32_t g[4] = {a, b, c, d};
    g[f] = kInf;
    if (f != 3) std::swap(g[f], g[3]);
    else std::swap(g[0], g[1]);
    const uint32_t t = NewTet();
    for (int i = 0; i < 4; ++i) tets_[8 * t + i] = g[i];
    ++num_ghost_tets_;
    tets_[8 * t + 4 + 3] = 4 * t0 + f;
    tets_[8 * t0 + 4 + f] = 4 * t + 3;
    created_.push_back(TetId(t));
  }
  LinkAroundApex(kInf);
  for (int i = 0; i < 4; ++i) {
    vertex_tet_[tv[i]] = t0;
    ++star_version_[tv[i]];
  }
  last_tet_ = t0;
}

// ---------------------------------------------------------------------------
// Queries.

std::vector<TetId> Delaunay3::FiniteTets() const {
  std::vector<TetId> out;
  out.reserve(NumFiniteTets());
  for (uint32_t t = 0; t < TetCapacity(); ++t) {
    if (tets_[8 * t] != kFreeSlot && tets_[8 * t + 3] != kInf) out.push_back(TetId(t));
  }
  return out;
}

// ---------------------------------------------------------------------------
// The star walk.

// Breadth-first over the tets around v: from each tet, cross its three faces
// that contain v. The order (queue order, faces 0..3) is what Star has always
// returned; the neighbours come out in order of first appearance in it.
template <bool kNeighbors>
uint32_t Delaunay3::WalkStar(uint32_t v, uint32_t* num_neighbors) const {
  uint32_t n = 0, m = 0;
  const uint32_t t0 = vertex_tet_[v];
  if (t0 == kFreeSlot) {
    if (num_neighbors != nullptr) *num_neighbors = 0;
    return 0;
  }
  if (star_buf_.size() < 64) star_buf_.resize(64);
  if (kNeighbors && nbr_buf_.size() < 64) {
    nbr_buf_.resize(64);
    nbr_tet_buf_.resize(64);
  }
  // Visited bits, all zero between walks (cleared from the lists at the end):
  // 1 bit per tet slot keeps the set in L1/L2, unlike 32-bit stamps.
  if (tet_bits_.size() * 64 < TetCapacity()) tet_bits_.resize(TetCapacity() / 64 + 1, 0);
  if (kNeighbors && vertex_bits_.size() * 64 < points_.size()) {
    vertex_bits_.resize(points_.size() / 64 + 1, 0);
  }
  // Raw pointers and capacities in locals: the loop's stores cannot then
  // make the compiler reload the vectors' internals.
  uint64_t* tbits = tet_bits_.data();
  uint64_t* vbits = vertex_bits_.data();
  const uint32_t* tets = tets_.data();
  TetId* star = star_buf_.data();
  size_t star_cap = star_buf_.size();
  VertexId* nbr = nbr_buf_.data();
  TetId* nbr_tet = nbr_tet_buf_.data();
  size_t nbr_cap = nbr_buf_.size();
  star[n++] = TetId(t0);
  tbits[t0 >> 6] |= uint64_t{1} << (t0 & 63);
  for (uint32_t k = 0; k < n; ++k) {
    const uint32_t t = star[k].value();
    const uint32_t* tv = &tets[8 * t];
    // Room for the (at most 3) tets and (at most 3) vertices this tet adds.
    if (n + 3 > star_cap) [[unlikely]] {
      star_buf_.resize(2 * star_cap);
      star = star_buf_.data();
      star_cap = star_buf_.size();
    }
    if (kNeighbors && m + 3 > nbr_cap) [[unlikely]] {
      nbr_buf_.resize(2 * nbr_cap);
      nbr_tet_buf_.resize(nbr_buf_.size());
      nbr = nbr_buf_.data();
      nbr_tet = nbr_tet_buf_.data();
      nbr_cap = nbr_buf_.size();
    }
    // Branch-free appends: whether a tet or vertex is new is data-dependent
    // (a star tet is reached over three faces, once first), so the entry is
    // always written at the end and the count moves on only when it was new.
    for (int f = 0; f < 4; ++f) {
      const uint32_t w = tv[f];
      if (w == v) continue;  // the face opposite v does not contain v
      if (kNeighbors && w != kInf) {
        uint64_t& word = vbits[w >> 6];
        const uint64_t bit = uint64_t{1} << (w & 63);
        const uint32_t fresh = (word & bit) == 0;
        word |= bit;
        nbr[m] = VertexId(w);
        nbr_tet[m] = TetId(t);
        m += fresh;
      }
      const uint32_t u = tv[4 + f] >> 2;
      uint64_t& word = tbits[u >> 6];
      const uint64_t bit = uint64_t{1} << (u & 63);
      const uint32_t fresh = (word & bit) == 0;
      word |= bit;
      __builtin_prefetch(&tets[8 * u]);
      star[n] = TetId(u);
      n += fresh;
    }
  }
  for (uint32_t k = 0; k < n; ++k) tbits[star[k].value() >> 6] = 0;
  if (kNeighbors) {
    for (uint32_t k = 0; k < m; ++k) vbits[nbr[k].value() >> 6] = 0;
  }
  if (num_neighbors != nullptr) *num_neighbors = m;
  return n;
}

void Delaunay3::Star(VertexId v, std::vector<TetId>* out) const {
  const uint32_t n = WalkStar<false>(v.value(), nullptr);
  out->assign(star_buf_.begin(), star_buf_.begin() + n);
}

void Delaunay3::Neighbors(VertexId v, std::vector<VertexId>* out) const {
  const std::span<const VertexId> n = NeighborsView(v);
  out->assign(n.begin(), n.end());
}

std::span<const TetId> Delaunay3::StarView(VertexId v) const {
  const uint32_t n = WalkStar<false>(v.value(), nullptr);
  return {star_buf_.data(), n};
}

void Delaunay3::set_cache_neighbors(bool on) {
  cache_neighbors_ = on;
  adj_.clear();
  adj_.shrink_to_fit();
  adj_pool_.clear();
  adj_pool_.shrink_to_fit();
  adj_stored_.clear();
  adj_live_ = 0;
}

// Appends nbr_buf_[0, m) to the pool as v's list. The vertices stored since
// the last flush are listed (adj_stored_). When the pool is full it is
// packed in place to its live lists, with room for half as many again:
// copying is amortised over at least live/2 appends, and the pool never
// holds more than ~1.5× the most lists live at once (session 49: no second
// pool while packing). With
// a limit (adj_limit_ != 0), when the live lists would pass it every list on
// the list is dropped instead (a flush). Both cost what the stores since the
// last rebuild did, not a pass over every vertex (a run with 10^7 vertices
// had held ~10^8 entries: 10^3 passes over 10^7 vertices).
void Delaunay3::StoreAdj(uint32_t v, uint32_t m) const {
  if (adj_.size() <= v) util::GrowExactly(adj_, points_.size() + points_.size() / 2 + 16);
  if (adj_pool_.size() + m > adj_pool_.capacity()) {
    if (adj_limit_ != 0 && adj_live_ + m > adj_limit_) {
      for (uint32_t w : adj_stored_) adj_[w].size = kNoAdj;
      adj_stored_.clear();
      adj_pool_.clear();
      adj_live_ = 0;
      ++adj_flushes_;
    } else {
      // Packed in place, without a second pool (which had been the heap
      // peak of cube --max-volume 1e-4's refinement: the old pool and the
      // new one at once, +115 KB). A vertex may be listed twice (stored,
      // invalidated, stored again); its live list is the one of its latest
      // listing, and those come in the order of their offsets (each store
      // appends), so one forward pass of memmoves moves every live list
      // down. A backward pass first blanks every listing but the latest
      // (kSeen marks the vertices met).
      constexpr uint32_t kSeen = 0x80000000u;
      constexpr uint32_t kBlank = 0xFFFFFFFFu;
      for (size_t i = adj_stored_.size(); i-- > 0;) {
        AdjEntry& e = adj_[adj_stored_[i]];
        if (e.size == kNoAdj || (e.size & kSeen) != 0) {
          adj_stored_[i] = kBlank;
        } else {
          e.size |= kSeen;
        }
      }
      VertexId* pool = adj_pool_.data();
      size_t next = 0, kept = 0;
      for (const uint32_t w : adj_stored_) {
        if (w == kBlank) continue;
        AdjEntry& e = adj_[w];
        e.size &= ~kSeen;
        if (e.offset != next) std::memmove(pool + next, pool + e.offset, e.size * sizeof(VertexId));
        e.offset = static_cast<uint32_t>(next);
        next += e.size;
        adj_stored_[kept++] = w;
      }
      adj_stored_.resize(kept);
      adj_pool_.resize(next);
      ++adj_packs_;
      // Room for half as many again: the packing stays amortised over at
      // least live/2 appends.
      if (adj_pool_.capacity() < next + next / 2 + m + 1024) adj_pool_.reserve(next + next / 2 + m + 1024);
    }
  }
  adj_stored_.push_back(v);
  AdjEntry& e = adj_[v];
  e.offset = static_cast<uint32_t>(adj_pool_.size());
  e.size = m;
  adj_pool_.insert(adj_pool_.end(), nbr_buf_.begin(), nbr_buf_.begin() + m);
  adj_live_ += m;
}

std::span<const VertexId> Delaunay3::NeighborsView(VertexId v) const {
  const uint32_t i = v.value();
  if (cache_neighbors_ && i < adj_.size() && adj_[i].size != kNoAdj) {
    return {adj_pool_.data() + adj_[i].offset, adj_[i].size};
  }
  uint32_t m = 0;
  WalkStar<true>(i, &m);
  if (cache_neighbors_ && vertex_tet_[i] != kFreeSlot) StoreAdj(i, m);
  return {nbr_buf_.data(), m};
}

Delaunay3::StarAndNeighbors Delaunay3::StarAndNeighborsView(VertexId v) const {
  const uint32_t i = v.value();
  uint32_t m = 0;
  const uint32_t n = WalkStar<true>(i, &m);
  if (cache_neighbors_ && vertex_tet_[i] != kFreeSlot && (i >= adj_.size() || adj_[i].size == kNoAdj)) {
    StoreAdj(i, m);
  }
  return {{star_buf_.data(), n}, {nbr_buf_.data(), m}, {nbr_tet_buf_.data(), m}};
}

std::vector<uint32_t> Delaunay3::Degrees() const {
  std::vector<uint32_t> out;
  if (!Is3d()) return out;
  // F per vertex (tets at v, ghosts included) and whether one is a ghost
  // (h); the finite neighbours are V − h = 2 + F/2 − h.
  out.assign(points_.size(), 0);
  std::vector<uint8_t> hull(points_.size(), 0);
  for (uint32_t t = 0; t < TetCapacity(); ++t) {
    const uint32_t* tv = &tets_[8 * t];
    if (tv[0] == kFreeSlot) continue;
    const bool ghost = tv[3] == kInf;
    for (int k = 0; k < 4; ++k) {
      if (tv[k] == kInf) continue;
      ++out[tv[k]];
      hull[tv[k]] |= static_cast<uint8_t>(ghost);
    }
  }
  for (size_t v = 0; v < out.size(); ++v) {
    if (out[v] != 0) out[v] = 2 + out[v] / 2 - hull[v];
  }
  return out;
}

bool Delaunay3::IsHullVertex(VertexId v) const {
  for (TetId t : StarView(v)) {
    if (tets_[8 * t.value() + 3] == kInf) return true;
  }
  return false;
}

void Delaunay3::VoronoiCorners(VertexId v, std::vector<Vec3>* out) const {
  out->clear();
  for (TetId t : StarView(v)) {
    if (tets_[8 * t.value() + 3] != kInf) out->push_back(Circumcenter(t));
  }
}

double Delaunay3::OutRadius(VertexId v, Vec3* farthest_corner) const {
  const Vec3& pv = points_[v.value()];
  double best = -1;
  Vec3 corner;
  for (TetId t : StarView(v)) {
    if (tets_[8 * t.value() + 3] == kInf) {
      if (farthest_corner) *farthest_corner = Vec3(HUGE_VAL, HUGE_VAL, HUGE_VAL);
      return std::numeric_limits<double>::infinity();
    }
    const Vec3 c = Circumcenter(t);
    const double d = geom::Dist(c, pv);
    if (d > best) {
      best = d;
      corner = c;
    }
  }
  if (farthest_corner) *farthest_corner = corner;
  return best;
}

double Delaunay3::InRadius(VertexId v) const {
  const Vec3& pv = points_[v.value()];
  double best = std::numeric_limits<double>::infinity();
  for (VertexId w : NeighborsView(v)) best = std::min(best, geom::Dist2(points_[w.value()], pv));
  return 0.5 * std::sqrt(best);
}

VertexId Delaunay3::NearestVertex(const Vec3& p, TetId hint) const {
  if (!Is3d()) return kNoneVertex;
  const uint32_t t = Locate(p, hint).value();
  uint32_t best = kFreeSlot;
  auto consider = [&](uint32_t w) {
    if (w == best) return false;
    if (best != kFreeSlot) {
      // > 0: the current best is farther than w.
      const int c = geom::CompareDistance(p, points_[best], points_[w]);
      if (c < 0 || (c == 0 && best < w)) return false;
    }
    best = w;
    return true;
  };
  for (int i = 0; i < 4; ++i) {
    if (tets_[8 * t + i] != kInf) consider(tets_[8 * t + i]);
  }
  // Greedy descent: in a Delaunay graph, a vertex that is not nearest to p
  // has a neighbour strictly nearer (the Delaunay graph contains the nearest
  // neighbour's Voronoi adjacency along the segment to p).
  for (;;) {
    bool improved = false;
    for (VertexId w : NeighborsView(VertexId(best))) improved |= consider(w.value());
    if (!improved) return VertexId(best);
  }
}

VertexId Delaunay3::NearVertex(const Vec3& p, TetId hint) const {
  if (!Is3d()) return kNoneVertex;
  const uint32_t t = Locate(p, hint).value();
  uint32_t best = kFreeSlot;
  double best_d2 = 0;
  for (int i = 0; i < 4; ++i) {
    const uint32_t w = tets_[8 * t + i];
    if (w == kInf) continue;
    const double d = geom::Dist2(p, points_[w]);
    if (best == kFreeSlot || d < best_d2 || (d == best_d2 && w < best)) {
      best = w;
      best_d2 = d;
    }
  }
  for (bool moved = true; moved;) {
    moved = false;
    for (VertexId w : NeighborsView(VertexId(best))) {  // the list of the vertex the pass began at
      const double d = geom::Dist2(p, points_[w.value()]);
      if (d < best_d2) {  // strictly nearer: the descent ends
        best = w.value();
        best_d2 = d;
        moved = true;
      }
    }
  }
  return VertexId(best);
}

VertexId Delaunay3::VertexAt(const Vec3& p, TetId hint) const {
  if (!Is3d()) return kNoneVertex;
  // Locate returns a finite tet whose closure holds p, or the ghost whose
  // hull face p is strictly beyond (then no vertex is at p; its finite
  // vertices are checked anyway).
  const uint32_t t = Locate(p, hint).value();
  for (int i = 0; i < 4; ++i) {
    const uint32_t w = tets_[8 * t + i];
    if (w != kInf && points_[w] == p) return VertexId(w);
  }
  return kNoneVertex;
}

Vec3 Delaunay3::Circumcenter(TetId t, TetShape* shape) const {
  const uint32_t* v = &tets_[8 * t.value()];
  const Vec3 a = points_[v[0]];
  const Vec3 b = points_[v[1]] - a, c = points_[v[2]] - a, d = points_[v[3]] - a;
  // Relative to a: x = (|b|²(c×d) + |c|²(d×b) + |d|²(b×c)) / (2 b·(c×d)).
  const Vec3 cd = geom::Cross(c, d), db = geom::Cross(d, b), bc = geom::Cross(b, c);
  const double det = geom::Dot(b, cd);
  const double den = 2.0 * det;
  const double b2 = geom::Norm2(b), c2 = geom::Norm2(c), d2 = geom::Norm2(d);
  const Vec3 num = b2 * cd + c2 * db + d2 * bc;
  if (shape != nullptr) {
    shape->det = det;
    shape->longest2 = std::max({b2, c2, d2, geom::Dist2(b, c), geom::Dist2(b, d), geom::Dist2(c, d)});
  }
  return a + num / den;
}

double Delaunay3::Circumradius(TetId t) const {
  return geom::Dist(Circumcenter(t), points_[tets_[8 * t.value()]]);
}

// ---------------------------------------------------------------------------
// Validation.

absl::Status Delaunay3::Validate(bool check_empty_sphere) const {
  const uint32_t cap = TetCapacity();
  uint32_t live = 0, ghosts = 0;
  for (uint32_t t = 0; t < cap; ++t) {
    const uint32_t* v = &tets_[8 * t];
    if (v[0] == kFreeSlot) continue;
    ++live;
    for (int i = 0; i < 4; ++i) {
      if (v[i] == kInf) {
        if (i != 3) return absl::InternalError(absl::StrCat("tet ", t, ": ghost vertex at position ", i));
        continue;
      }
      if (v[i] >= points_.size()) return absl::InternalError(absl::StrCat("tet ", t, ": vertex id out of range"));
      for (int j = 0; j < i; ++j) {
        if (v[j] == v[i]) return absl::InternalError(absl::StrCat("tet ", t, ": repeated vertex ", v[i]));
      }
    }
    const bool ghost = v[3] == kInf;
    if (ghost) ++ghosts;
    if (!ghost && geom::Orient3d(points_[v[0]], points_[v[1]], points_[v[2]], points_[v[3]]) <= 0) {
      return absl::InternalError(absl::StrCat("tet ", t, " (", v[0], ",", v[1], ",", v[2], ",", v[3],
                                              ") is not positively oriented"));
    }
    for (int f = 0; f < 4; ++f) {
      const uint32_t n = tets_[8 * t + 4 + f];
      const uint32_t u = n >> 2, g = n & 3;
      if (u >= cap || tets_[8 * u] == kFreeSlot) {
        return absl::InternalError(absl::StrCat("tet ", t, " face ", f, ": neighbour ", u, " is not alive"));
      }
      if (tets_[NRef(n)] != 4 * t + f) {
        return absl::InternalError(absl::StrCat("tet ", t, " face ", f, ": neighbour ", u, " face ", g,
                                                " does not point back"));
      }
      // Same vertex set, opposite orientation: the even permutation taking
      // the face of t to the face of u must reverse the cyclic order.
      const int* fa = kFaceVertices[f];
      const int* fb = kFaceVertices[g];
      uint32_t A[3] = {v[fa[0]], v[fa[1]], v[fa[2]]};
      uint32_t B[3] = {tets_[8 * u + fb[0]], tets_[8 * u + fb[1]], tets_[8 * u + fb[2]]};
      // Orientation of a face listed by kFaceVertices[f] flips with the
      // parity of f (faces 0 and 2 are listed negatively w.r.t. the outward
      // normal, 1 and 3 positively), so normalise to outward order.
      if ((f & 1) == 0) std::swap(A[0], A[1]);
      if ((g & 1) == 0) std::swap(B[0], B[1]);
      // Outward orders of the shared face in t and u must be reverses.
      bool ok = false;
      for (int s = 0; s < 3 && !ok; ++s) {
        ok = A[0] == B[(s + 0) % 3] && A[1] == B[(s + 2) % 3] && A[2] == B[(s + 1) % 3];
      }
      if (!ok) {
        return absl::InternalError(absl::StrCat("tet ", t, " face ", f, " and tet ", u, " face ", g,
                                                ": faces do not match with opposite orientation"));
      }
      if (ghost && u == t) return absl::InternalError("self-neighbour");
    }
    if (tet_gen_.size() != cap || tets_.size() != 8 * size_t{cap}) return absl::InternalError("array sizes");
  }
  if (live != num_live_tets_ || ghosts != num_ghost_tets_) {
    return absl::InternalError(absl::StrCat("tet counts: found ", live, " live / ", ghosts,
                                            " ghost, recorded ", num_live_tets_, " / ", num_ghost_tets_));
  }
  uint32_t free_count = 0;
  for (uint32_t t = free_head_; t != kFreeSlot; t = tets_[8 * t + 4]) {
    if (t >= cap || tets_[8 * t] != kFreeSlot || ++free_count > cap) {
      return absl::InternalError("free list corrupt");
    }
  }
  if (free_count + live != cap) return absl::InternalError("free list does not cover dead slots");
  if (Is3d()) {
    for (uint32_t w = 0; w < points_.size(); ++w) {
      const uint32_t t = vertex_tet_[w];
      if (t == kFreeSlot) continue;  // a rejected duplicate never gets here; pending only before 3D
      if (t >= cap || tets_[8 * t] == kFreeSlot) {
        return absl::InternalError(absl::StrCat("vertex ", w, ": incident tet ", t, " not alive"));
      }
      const uint32_t* v = &tets_[8 * t];
      if (v[0] != w && v[1] != w && v[2] != w && v[3] != w) {
        return absl::InternalError(absl::StrCat("vertex ", w, ": tet ", t, " does not contain it"));
      }
    }
    for (uint32_t w = 0; w < points_.size(); ++w) {
      if (vertex_tet_[w] == kFreeSlot) {
        return absl::InternalError(absl::StrCat("vertex ", w, " is in no tet"));
      }
    }
  }
  // Convex hull: for ghost (a,b,c,∞), the finite vertex d of a neighbouring
  // ghost must not be strictly beyond abc.
  for (uint32_t t = 0; t < cap; ++t) {
    const uint32_t* v = &tets_[8 * t];
    if (v[0] == kFreeSlot || v[3] != kInf) continue;
    for (int f = 0; f < 3; ++f) {
      const uint32_t n = tets_[8 * t + 4 + f];
      const uint32_t d = tets_[8 * (n >> 2) + (n & 3)];
      if (d == kInf) return absl::InternalError("ghost neighbour opposite ∞");
      const int o = geom::Orient3d(points_[v[0]], points_[v[1]], points_[v[2]], points_[d]);
      if (o > 0) {
        return absl::InternalError(absl::StrCat("hull not convex at ghost ", t, ": vertex ", d,
                                                " beyond face (", v[0], ",", v[1], ",", v[2], ")"));
      }
      if (check_empty_sphere && o == 0) {
        uint32_t sos = 0;
        if (ConflictRaw(t, points_[d], global_ids_[d], &sos)) {
          return absl::InternalError(absl::StrCat("hull face (", v[0], ",", v[1], ",", v[2],
                                                  ") not Delaunay: coplanar vertex ", d, " in its circle"));
        }
      }
    }
  }
  if (check_empty_sphere) {
    for (uint32_t t = 0; t < cap; ++t) {
      const uint32_t* v = &tets_[8 * t];
      if (v[0] == kFreeSlot || v[3] == kInf) continue;
      for (int f = 0; f < 4; ++f) {
        const uint32_t n = tets_[8 * t + 4 + f];
        const uint32_t u = n >> 2;
        if (tets_[8 * u + 3] == kInf) continue;
        const uint32_t d = tets_[8 * u + (n & 3)];
        uint32_t sos = 0;
        if (ConflictRaw(t, points_[d], global_ids_[d], &sos)) {
          return absl::InternalError(absl::StrCat("face ", f, " of tet ", t, " (", v[0], ",", v[1], ",",
                                                  v[2], ",", v[3], ") not locally Delaunay: vertex ",
                                                  d, " inside"));
        }
      }
    }
  }
  return absl::OkStatus();
}

}  // namespace svrc::delaunay
