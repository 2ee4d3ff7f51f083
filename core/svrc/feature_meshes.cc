// Feature meshes (thesis §3.1–3.2): M_Ω with cells clipped to the cube Ω.
#include "core/svrc/feature_meshes.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include "core/geometry/predicates.h"
#include "core/svrc/balls.h"
#include "core/util/grow.h"

namespace svrc::refine {

using geom::Vec3;

OmegaMesh::OmegaMesh(const Vec3& center, double half_side) : half_side_(half_side) {
  cube_.Add(center - Vec3(half_side, half_side, half_side));
  cube_.Add(center + Vec3(half_side, half_side, half_side));
  // The refiner's cell searches (Destroy's 𝒱, PropagateLocation, nearest
  // vertex) ask for the same cells' neighbours many times between insertions.
  dt_.set_cache_neighbors(true);
}

Vec3 OmegaMesh::Corner(int i) const {
  return {(i & 1) ? cube_.hi.x : cube_.lo.x, (i & 2) ? cube_.hi.y : cube_.lo.y,
          (i & 4) ? cube_.hi.z : cube_.lo.z};
}

void OmegaMesh::SeedCorners(const std::array<PointId, 8>& ids) {
  for (int i = 0; i < 8; ++i) {
    const auto r = dt_.Insert(Corner(i), ids[i].value());
    AddVertex(r.vertex, ids[i]);
  }
}

void OmegaMesh::AddVertex(VertexId v, PointId p) {
  if (point_of_.size() <= v.value()) {
    // A quarter more at a time (resize past the capacity would double it).
    const size_t n = v.value() + 1, extra = n - point_of_.size();
    util::ReserveForAppend(point_of_, extra);
    util::ReserveForAppend(cell_gen_, extra);
    util::ReserveForAppend(skinny_event_, extra);
    util::ReserveForAppend(unresolved_event_, extra);
    point_of_.resize(n);
    cell_gen_.resize(n, 0);
    skinny_event_.resize(n);
    unresolved_event_.resize(n);
  }
  point_of_[v.value()] = p;
  ++cell_gen_[v.value()];
}

bool OmegaMesh::InsideCube(const Vec3& p) const {
  // Exact coordinate comparisons: Orient1d(lo, x) >= 0 and Orient1d(x, hi)
  // >= 0, without its per-call counter (a thread-local increment, six per
  // circumcentre; ~1% of cube --max-volume 1e-5's instructions). Not
  // Box3::Contains: that answers false for a NaN coordinate, Orient1d's test
  // true, and a flat tet's circumcentre may be NaN.
  for (int k = 0; k < 3; ++k) {
    if (p[k] < cube_.lo[k] || p[k] > cube_.hi[k]) return false;
  }
  return true;
}

namespace {
// The table size for `n` keys: the power of two <= n (at least 64), at most
// `limit` (0: no limit). Between a half and one record per key, as the large
// runs' capped tables have: rounding up (of 1.5 records per vertex for the
// memos) gave the small runs up to two or three per key (cube 1e-4: a 1 MiB
// circumcentre table for 22k tets, 16% of the heap's peak; session 44,
// docs/svrc-design.md §8 item 74).
size_t CacheSize(size_t n, uint32_t limit) {
  const size_t want = std::bit_floor(std::max<size_t>(n, 64));
  return limit == 0 ? want : std::min<size_t>(want, limit);
}

// Grows a direct-mapped table to CacheSize(n, limit) records when `key` (the
// index looked up) lies beyond it and that size is larger; the records move to
// their new places (a record's place is its key's low bits; the new places
// of the old records are distinct, each its old place or one beyond the old
// table). key_of(record) is its key, or `none` for an empty record.
template <typename R, typename KeyOf>
void GrowTable(util::PodVector<R>& table, uint32_t key, size_t n, uint32_t limit, uint32_t none, KeyOf key_of) {
  if (table.size() > key || (limit != 0 && table.size() >= limit)) return;
  const size_t old_size = table.size();
  const size_t size = CacheSize(n, limit);
  if (size <= old_size) return;  // keys beyond the table share its records
  table.resize(size, R{});
  const size_t mask = size - 1;
  for (size_t k = 0; k < old_size; ++k) {
    const uint32_t w = key_of(table[k]);
    if (w == none || (w & mask) == k) continue;
    table[w & mask] = table[k];
    table[k] = R{};
  }
}
}  // namespace

OmegaMesh::CcEntry OmegaMesh::ComputeCircumcenter(TetId t) const {
  ++stats_.circumcentres;
  CcEntry e;
  // |b·(c×d)| and the longest squared edge from the circumcentre's own
  // computation (the same doubles as recomputing them from the vertices).
  delaunay::Delaunay3::TetShape shape;
  e.cc = dt_.Circumcenter(t, &shape);
  e.inside = InsideCube(e.cc);
  const Vec3& a = dt_.Point(dt_.TetVertex(t, 0));
  const double vol6 = std::fabs(shape.det);
  const double l2 = shape.longest2;
  double scale = 0;
  for (int k = 0; k < 3; ++k) scale = std::max({scale, std::fabs(a[k]), std::fabs(e.cc[k])});
  e.flat = vol6 <= 1e-9 * l2 * std::sqrt(l2) + 3e-14 * l2 * std::min(scale, 4.0 * half_side_);
  return e;
}

OmegaMesh::CcEntry OmegaMesh::CachedCircumcenterSlow(TetId t) const {
  const uint32_t i = t.value();
  if (i > CcRecord::kSlotMask) [[unlikely]] return ComputeCircumcenter(t);
  // Half a record per tet slot before rounding down: one per slot cost 6% of
  // the heap's peak at every size (cube 1e-4 and 1e-6) for 4–13% fewer
  // circumcentres computed (docs/svrc-design.md §8 item 79).
  GrowTable(cc_, i, (size_t{dt_.TetCapacity()} + 64) / 2, cc_limit_, CcRecord::kSlotMask,
            [](const CcRecord& r) { return r.tag & CcRecord::kSlotMask; });
  const uint32_t g = dt_.Generation(t) + 1;
  CcRecord& r = cc_[i & (cc_.size() - 1)];
  if ((r.tag & CcRecord::kSlotMask) == i && r.gen == g) {
    return {r.cc, (r.tag & CcRecord::kInside) != 0, (r.tag & CcRecord::kFlat) != 0};
  }
  const CcEntry e = ComputeCircumcenter(t);
  r.cc = e.cc;
  r.gen = g;
  r.tag = i | (e.inside ? CcRecord::kInside : 0) | (e.flat ? CcRecord::kFlat : 0);
  return e;
}

Vec3 OmegaMesh::FarPoint(TetId g) const {
  // Ghost (a,b,c,∞): Orient3d(a,b,c,q) > 0 beyond the hull, so the outward
  // normal is (b−a)×(c−a). The Voronoi edge dual to abc is the line through
  // abc's circumcentre along that normal; a point 8 half-sides out is outside
  // Ω, and so is the chord between two such points (docs/svrc-design.md §3).
  const Vec3& a = dt_.Point(dt_.TetVertex(g, 0));
  const Vec3& b = dt_.Point(dt_.TetVertex(g, 1));
  const Vec3& c = dt_.Point(dt_.TetVertex(g, 2));
  const Vec3 n = geom::Cross(b - a, c - a);
  Vec3 m;
  double r;
  TriangleCircumball(a, b, c, &m, &r);
  return m + (8.0 * half_side_ / geom::Norm(n)) * n;
}

void ClipPolygonToBox(const geom::Box3& box, std::vector<Vec3>* poly, std::vector<Vec3>* scratch) {
  // Sutherland–Hodgman against lo_k <= x_k and x_k <= hi_k. A pass against a
  // plane no vertex is outside of copies the polygon unchanged (every vertex
  // kept, in order, no crossing), so only the planes in the polygon's
  // outcode are passed; the outcode is recomputed after each pass that
  // clipped, since its new corners are rounded and may fall outside another
  // plane. Most Voronoi facets of a clipped cell lie inside Ω (outcode 0).
  // Bit 2k + side: some vertex has x_k < lo_k (side 0) or x_k > hi_k (side
  // 1), the negation of `inside` below.
  auto outcode = [&](const std::vector<Vec3>& pts) {
    uint32_t code = 0;
    for (const Vec3& p : pts) {
      for (int k = 0; k < 3; ++k) {
        code |= static_cast<uint32_t>(p[k] < box.lo[k]) << (2 * k);
        code |= static_cast<uint32_t>(p[k] > box.hi[k]) << (2 * k + 1);
      }
    }
    return code;
  };
  uint32_t code = outcode(*poly);
  // Intersection points get the plane's coordinate exactly, so corners on ∂Ω
  // are on ∂Ω.
  for (int k = 0; k < 3 && code != 0; ++k) {
    for (int side = 0; side < 2 && code != 0; ++side) {
      if ((code & (1u << (2 * k + side))) == 0) continue;
      const double bound = side == 0 ? box.lo[k] : box.hi[k];
      auto inside = [&](const Vec3& p) { return side == 0 ? !(p[k] < bound) : !(p[k] > bound); };
      scratch->clear();
      const size_t n = poly->size();
      for (size_t i = 0; i < n; ++i) {
        const Vec3& a = (*poly)[i];
        const Vec3& b = (*poly)[(i + 1) % n];
        const bool ia = inside(a), ib = inside(b);
        if (ia) scratch->push_back(a);
        if (ia != ib) {
          const double s = (bound - a[k]) / (b[k] - a[k]);
          Vec3 q = a + s * (b - a);
          q[k] = bound;
          scratch->push_back(q);
        }
      }
      poly->swap(*scratch);
      code = outcode(*poly);  // 0 when the polygon is gone
    }
  }
}

OmegaMesh::SizeMemo* OmegaMesh::MemoSlot(VertexId v, bool grow) const {
  const uint32_t i = v.value();
  if (grow) {
    GrowTable(size_memo_, i, size_t{dt_.NumVertices()} + 16, memo_limit_, 0xFFFFFFFFu,
              [](const SizeMemo& m) { return m.vertex; });
  } else if (size_memo_.empty()) {
    return nullptr;
  }
  // Keys beyond the table share its records (CacheSize rounds down): the
  // caller checks the record's vertex.
  return &size_memo_[i & (size_memo_.size() - 1)];
}

CellSize OmegaMesh::Size(VertexId v) const {
  ++stats_.size_queries;
  const uint32_t key = dt_.StarVersion(v) + 1;
  const SizeMemo* old = MemoSlot(v, false);
  if (old != nullptr && old->vertex == v.value() && old->key == key) {
    const CellSize& m = old->size;
    if (m.clipped) ++stats_.clipped_queries;
    return m;
  }
  Uniqueness unique;
  ++stats_.computed_sizes;
  const CellSize out = ComputeSize(v, &unique);
  *MemoSlot(v, true) = {v.value(), key, out, out.hint.valid() ? dt_.Generation(out.hint) : 0,
                        out.kept_hint.valid() ? dt_.Generation(out.kept_hint) : 0, unique};
  return out;
}

bool OmegaMesh::ShrunkSize(VertexId v, const Vec3& p, const NewTets& added, CellSize* out) const {
  SizeMemo* slot = MemoSlot(v, false);
  if (slot == nullptr || slot->vertex != v.value()) return false;
  SizeMemo& m = *slot;
  const uint32_t key = dt_.StarVersion(v) + 1;
  if (m.key == 0 || m.key + added.count != key || m.size.clipped || m.size.saw_flat) return false;
  auto survived = [&](TetId t, uint32_t gen) { return t.valid() && dt_.IsAlive(t) && dt_.Generation(t) == gen; };
  // The cell's farthest corner.
  if (!m.unique.corner || !(added.corner < m.size.outradius) || !survived(m.size.hint, m.hint_gen)) return false;
  if (m.size.outside_tets || added.outside) {
    // The kept corner, over the tets not known to lie outside.
    if (m.size.kept_outradius == 0) {
      if (added.kept_corner != 0) return false;  // no kept tet before; one now
    } else if (!m.unique.kept_corner || !(added.kept_corner < m.size.kept_outradius) ||
               !survived(m.size.kept_hint, m.kept_hint_gen)) {
      return false;
    }
    m.size.outside_tets = true;
  }
  ++stats_.size_queries;
  ++stats_.shrunk_sizes;
  m.key = key;
  m.size.inradius = std::min(m.size.inradius, 0.5 * std::sqrt(geom::Dist2(dt_.Point(v), p)));
  *out = m.size;
  return true;
}

// The kept_* fields once the whole cell is measured: the cell's own unless
// they came from the kept tets (`from_kept`, their corner already set), and
// none (0, v) when no star tet is kept.
void OmegaMesh::FinishKept(bool from_kept, double kept_best, const Vec3& pv, CellSize* out) {
  if (!from_kept) {
    out->kept_outradius = out->outradius;
    out->kept_corner = out->corner;
    out->kept_hint = out->hint;
  } else if (kept_best < 0) {
    out->kept_outradius = 0;
    out->kept_corner = pv;
    out->kept_hint = TetId();
  } else {
    out->kept_outradius = kept_best;
  }
}

CellSize OmegaMesh::ComputeSize(VertexId v, Uniqueness* unique) const {
  CellSize out;
  *unique = Uniqueness{};
  const Vec3& pv = dt_.Point(v);
  out.hint = dt_.VertexTet(v);
  // One star walk gives the star, the neighbours and, per neighbour, a tet on
  // the ring around the edge (the first star tet containing it).
  const delaunay::Delaunay3::StarAndNeighbors sn = dt_.StarAndNeighborsView(v);
  // r_v = half the shortest Delaunay edge at v (Lemma 3).
  double shortest2 = HUGE_VAL;
  for (VertexId w : sn.neighbors) shortest2 = std::min(shortest2, geom::Dist2(dt_.Point(w), pv));
  out.inradius = 0.5 * std::sqrt(shortest2);
  bool needs_clip = false;
  double best = -1, kept_best = -1;
  for (TetId t : sn.star) {
    if (dt_.IsGhost(t)) {
      needs_clip = true;
      break;
    }
    const CcEntry e = CachedCircumcenter(t);
    if (e.flat) {
      out.saw_flat = true;
      continue;
    }
    if (!e.inside) {
      needs_clip = true;
      break;
    }
    const double d = geom::Dist(e.cc, pv);
    if (d > best) {
      best = d;
      out.corner = e.cc;
      out.hint = t;
      unique->corner = true;
    } else if (d == best) {
      unique->corner = false;
    }
    if (KnownOutside(t)) {
      out.outside_tets = true;
    } else if (d > kept_best) {
      kept_best = d;
      out.kept_corner = e.cc;
      out.kept_hint = t;
      unique->kept_corner = true;
    } else if (d == kept_best) {
      unique->kept_corner = false;
    }
  }
  if (!needs_clip) {
    out.outradius = best;
    if (!out.outside_tets) unique->kept_corner = unique->corner;
    FinishKept(out.outside_tets, kept_best, pv, &out);
    return out;
  }
  // Clipped (a star tet is a ghost or has its circumcentre outside Ω): the
  // kept tets' corners, unless one of them is itself clipped.
  out.outside_tets = false;
  bool kept_plain = true;
  kept_best = -1;
  for (TetId t : sn.star) {
    if (KnownOutside(t)) {
      out.outside_tets = true;
      continue;
    }
    if (dt_.IsGhost(t)) {
      kept_plain = false;
      continue;
    }
    const CcEntry e = CachedCircumcenter(t);
    if (e.flat) continue;
    if (!e.inside) {
      kept_plain = false;
      continue;
    }
    const double d = geom::Dist(e.cc, pv);
    if (d > kept_best) {
      kept_best = d;
      out.kept_corner = e.cc;
      out.kept_hint = t;
    }
  }
  const bool kept_from_star = out.outside_tets && kept_plain;
  out.kept_from_star = kept_from_star;
  // Clip every Voronoi facet of v (dual to edge vu) to the cube.
  *unique = Uniqueness{};
  ++stats_.clipped_queries;
  out.clipped = true;
  out.hint = dt_.VertexTet(v);
  best = -1;
  for (size_t k = 0; k < sn.neighbors.size(); ++k) {
    const VertexId u = sn.neighbors[k];
    // The ring of tets around edge vu, walked across the faces containing vu.
    const TetId t0 = sn.neighbor_tet[k];
    poly_.clear();
    TetId t = t0, prev;
    for (int guard = 0; guard < 1024; ++guard) {
      if (dt_.IsGhost(t)) {
        poly_.push_back(FarPoint(t));
      } else if (const CcEntry e = CachedCircumcenter(t); !e.flat) {
        poly_.push_back(e.cc);
      }
      // The two faces of t containing v and u are opposite its other two vertices.
      TetId next;
      for (int i = 0; i < 4; ++i) {
        const VertexId w = dt_.TetVertex(t, i);
        if (w == v || w == u) continue;
        const TetId n = dt_.Neighbor(t, i);
        if (n != prev) {
          next = n;
          break;
        }
      }
      prev = t;
      t = next;
      if (t == t0 || !t.valid()) break;
    }
    ClipPolygonToBox(cube_, &poly_, &poly2_);
    for (const Vec3& x : poly_) {
      const double d = geom::Dist(x, pv);
      if (d > best) {
        best = d;
        out.corner = x;
      }
    }
  }
  out.outradius = best < 0 ? 0 : best;
  FinishKept(kept_from_star, kept_best, pv, &out);
  return out;
}

SegmentMesh::SegmentMesh(PointId a, PointId b, const Vec3& pa, const Vec3& pb) : pa_(pa), pb_(pb) {
  const uint32_t va = AddVertex(0.0, a);
  const uint32_t vb = AddVertex(1.0, b);
  next_[va] = vb;
  prev_[vb] = va;
}

uint32_t SegmentMesh::AddVertex(double t, PointId p) {
  const uint32_t v = NumVertices();
  t_.push_back(t);
  point_.push_back(p);
  next_.push_back(kNil);
  prev_.push_back(kNil);
  cell_gen_.push_back(1);
  skinny_event_.emplace_back();
  piece_ball_.push_back(kNoneBall);
  vertex_ball_.push_back(kNoneBall);
  return v;
}

Vec3 SegmentMesh::PointAt(double t) const {
  if (t == 0.0) return pa_;
  if (t == 1.0) return pb_;
  return pa_ + t * (pb_ - pa_);
}

double SegmentMesh::StepOutOfBall(double t, bool toward_b, const Vec3& c, double r) const {
  // 64 single ulps first: the steps of sessions 12–32, so every point they
  // placed stays where it was (the collar path is sensitive to an ulp: on
  // armadillo.off, doubling from the first step moved other (1,2) points and
  // that run ended with two facets over-covered; docs/svrc-collars.md
  // "Session 33").
  int k = 0;
  for (; k < 64 && geom::InBall(PointAt(t), c, r) > 0; ++k) t = std::nextafter(t, toward_b ? 1.0 : 0.0);
  double step = 0;
  for (; k < 1024 && geom::InBall(PointAt(t), c, r) > 0; ++k) {
    const double next = std::nextafter(t, toward_b ? 1.0 : 0.0);
    step = step == 0 ? std::fabs(next - t) : 2 * step;
    t = toward_b ? std::min(1.0, t + step) : std::max(0.0, t - step);
  }
  return t;
}

double SegmentMesh::PieceLength(uint32_t v) const {
  return (t_[next_[v]] - t_[v]) * geom::Dist(pa_, pb_);
}

uint32_t SegmentMesh::Split(uint32_t v, double t, PointId p) {
  const uint32_t w = next_[v];
  const uint32_t m = AddVertex(t, p);
  next_[v] = m;
  prev_[m] = v;
  next_[m] = w;
  prev_[w] = m;
  return m;
}

SegmentMesh::Size1 SegmentMesh::Size(uint32_t v) const {
  Size1 s;
  double lo = HUGE_VAL, hi = -1;
  if (prev_[v] != kNil) {
    const double g = PieceLength(prev_[v]);
    lo = std::min(lo, g);
    if (g > hi) {
      hi = g;
      s.piece = prev_[v];
    }
  }
  if (next_[v] != kNil) {
    const double g = PieceLength(v);
    lo = std::min(lo, g);
    if (g > hi) {
      hi = g;
      s.piece = v;
    }
  }
  s.outradius = 0.5 * hi;
  s.inradius = 0.5 * lo;
  return s;
}

}  // namespace svrc::refine
