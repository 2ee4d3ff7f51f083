#include "core/svrc/collar_surface.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <limits>
#include <tuple>
#include <utility>

#include "core/geometry/predicates.h"
#include "core/svrc/ball_grid.h"

namespace svrc::refine {

using delaunay::Delaunay3;
using delaunay::TetId;
using delaunay::VertexId;

namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;

Vec3 Unit(const Vec3& v) {
  const double n = geom::Norm(v);
  return n > 0 ? v / n : v;
}

uint64_t EdgeKey(uint32_t a, uint32_t b) {
  if (a > b) std::swap(a, b);
  return (static_cast<uint64_t>(a) << 32) | b;
}

// Sorts `items` by `less`, a total order whose first key is the vertex
// `bucket(item)` < num_buckets: a stable radix sort by that vertex (16 bits
// per pass), then each run of one vertex by `less`. The same sequence as
// std::sort(less) (the items are distinct under it) in linear time plus small
// sorts: the COLLAR rounds sort every restricted triangle's entries, edges
// and link tuples each round, and those std::sorts were ~7% of a fandisk.off
// run and ~12% of wedge-1.smesh's. The counts are 2^16 entries whatever the
// vertex count (a counting sort over every vertex id allocated and zeroed two
// arrays of 23 M entries per call on armadillo.off: most of a tail round's
// page zeroing, docs/svrc-collars.md "Session 19").
template <class T, class Bucket, class Less>
void SortByVertex(std::vector<T>* items, size_t num_buckets, Bucket bucket, Less less) {
  constexpr int kBits = 16;
  constexpr size_t kRadix = size_t{1} << kBits;
  std::vector<T> tmp(items->size());
  std::vector<uint32_t> count(kRadix);
  const int passes = num_buckets <= kRadix ? 1 : 2;
  for (int pass = 0; pass < passes; ++pass) {
    const int shift = pass * kBits;
    std::fill(count.begin(), count.end(), 0);
    for (const T& x : *items) ++count[(bucket(x) >> shift) & (kRadix - 1)];
    uint32_t sum = 0;
    for (uint32_t& c : count) {
      const uint32_t n = c;
      c = sum;
      sum += n;
    }
    for (const T& x : *items) tmp[count[(bucket(x) >> shift) & (kRadix - 1)]++] = x;
    items->swap(tmp);
  }
  std::vector<T>& out = *items;
  for (size_t i = 0; i < out.size();) {
    size_t j = i + 1;
    const uint32_t b = bucket(out[i]);
    while (j < out.size() && bucket(out[j]) == b) ++j;
    if (j - i > 1) std::sort(out.begin() + i, out.begin() + j, less);
    i = j;
  }
}

// V(u) ⊂ B(u, R_u) (R_u = the farthest Voronoi corner; +∞ on the hull, which
// OutRadius returns when a star tet is a ghost: |uc| − ∞ passes), so V(u) can
// meet B(c, ρ) only if |uc| − R_u ≤ ρ. Conservative by a relative 1e-9 (R_u
// and |uc| are rounded).
bool CellMayMeetBall(const Delaunay3& dt, VertexId u, double r, const CollarBall& b) {
  return geom::Dist(dt.Point(u), b.center) - r <= b.radius * (1 + 1e-9) + 1e-9 * r;
}

// The owners a reused ball or circle must compute again because their
// neighbourhood's membership changed: the vertices that entered or left its
// member list (candidates, or `both` for a circle) since its last
// computation, and their Delaunay neighbours (the owners of the faces and
// edges they are in). A byte per vertex, cleared after each list.
class ChangedOwners {
 public:
  void Mark(const Delaunay3& dt, const std::vector<uint32_t>& before, const std::vector<uint32_t>& now) {
    if (dirty_.size() < dt.NumVertices()) dirty_.resize(dt.NumVertices(), 0);
    changed_.clear();
    std::set_symmetric_difference(before.begin(), before.end(), now.begin(), now.end(), std::back_inserter(changed_));
    for (uint32_t w : changed_) {
      Set(w);
      dt.Neighbors(VertexId(w), &nbr_);
      for (VertexId u : nbr_) Set(u.value());
    }
  }
  bool Has(uint32_t v) const { return v < dirty_.size() && dirty_[v] != 0; }
  void Clear() {
    for (uint32_t u : set_) dirty_[u] = 0;
    set_.clear();
  }

 private:
  void Set(uint32_t u) {
    if (!dirty_[u]) {
      dirty_[u] = 1;
      set_.push_back(u);
    }
  }
  std::vector<uint8_t> dirty_;
  std::vector<uint32_t> set_, changed_;
  std::vector<VertexId> nbr_;
};

// Vertices whose Voronoi cell may meet ball b, ascending. The cells that do
// meet the ball cover it, and the ball is connected, so they form a connected
// set of Voronoi neighbours containing the cell of the centre: a walk from
// the centre's nearest vertex through CellMayMeetBall vertices reaches them
// all. `seen` is zero scratch of NumVertices() entries, left zero.
// `touched` receives every vertex read (the candidates and their neighbours:
// the cache's dependency set).
// `out_radius(u)` is R_u (Delaunay3::OutRadius, possibly memoised).
template <typename OutRadiusFn>
std::vector<uint32_t> CandidateVertices(const Delaunay3& dt, const CollarBall& b, bool local,
                                        TetId hint, std::vector<uint8_t>* seen, VertexId* center_vertex,
                                        std::vector<uint32_t>* touched_out, OutRadiusFn&& out_radius) {
  std::vector<uint32_t> out;
  touched_out->clear();
  if (!local) {
    for (uint32_t v = 0; v < dt.NumVertices(); ++v) {
      if (dt.VertexTet(VertexId(v)).valid()) out.push_back(v);
    }
    return out;
  }
  const VertexId s = dt.NearestVertex(b.center, hint);
  *center_vertex = s;
  if (!s.valid()) return out;
  std::vector<uint32_t>& touched = *touched_out;
  touched.push_back(s.value());
  std::vector<uint32_t> queue = {s.value()};
  (*seen)[s.value()] = 1;
  std::vector<VertexId> nb;
  for (size_t qi = 0; qi < queue.size(); ++qi) {
    const VertexId v(queue[qi]);
    out.push_back(v.value());
    dt.Neighbors(v, &nb);
    for (VertexId u : nb) {
      if ((*seen)[u.value()]) continue;
      (*seen)[u.value()] = 1;
      touched.push_back(u.value());
      // A vertex in the closed ball passes the test whatever R_u is (and
      // R_u may cost a star walk): the same answer without it.
      if (geom::Dist(dt.Point(u), b.center) <= b.radius || CellMayMeetBall(dt, u, out_radius(u), b)) {
        queue.push_back(u.value());
      }
    }
  }
  for (uint32_t v : touched) (*seen)[v] = 0;
  std::sort(out.begin(), out.end());
  return out;
}

// Restricted triangles of sphere `ball` among triangles whose three vertices
// are candidates (a restricted triangle's rep point lies in its three cells,
// which therefore meet the ball). Same constructions as
// RestrictedSphereTriangles; the angle uses each vertex snapped to this
// sphere (Snap, §3.1.2).
// The restricted triangles of sphere `ball` owned by candidate vi (its
// smallest vertex): a function of vi's star (its tets, their circumcentres
// and vertices), of which star vertices are candidates, and of the balls.
void OwnedSphereTriangles(const Delaunay3& dt, std::span<const CollarBall> balls, const BallGrid& grid,
                          uint32_t ball, uint32_t vi, const std::vector<uint8_t>& is_cand, double delta,
                          std::vector<TetId>* star_scratch, std::vector<RestrictedTriangle>* out) {
  const CollarBall& b = balls[ball];
  std::vector<TetId>& star = *star_scratch;
  {
    const VertexId v(vi);
    dt.Star(v, &star);
    for (TetId t : star) {
      if (dt.IsGhost(t)) continue;
      for (int f = 0; f < 4; ++f) {
        if (dt.TetVertex(t, f) == v) continue;  // the face must contain v
        VertexId tri[3];
        bool ok = true;
        for (int k = 0, m = 0; k < 4; ++k) {
          if (k == f) continue;
          tri[m++] = dt.TetVertex(t, k);
        }
        for (int k = 0; k < 3; ++k) {
          // v is the smallest vertex of the face: each face from one star.
          ok = ok && is_cand[tri[k].value()] && tri[k].value() >= vi;
        }
        if (!ok) continue;
        const TetId u = dt.Neighbor(t, f);
        const bool hull = dt.IsGhost(u);
        if (!hull && u.value() < t.value()) continue;  // the smaller slot owns it
        const Vec3 ct = dt.Circumcenter(t);
        const Vec3& p0 = dt.Point(tri[0]);
        Vec3 end;
        if (hull) {
          Vec3 n = geom::Cross(dt.Point(tri[1]) - p0, dt.Point(tri[2]) - p0);
          if (geom::Dot(n, dt.Point(dt.TetVertex(t, f)) - p0) > 0) n = -1.0 * n;
          end = ct + (2 * (geom::Dist(ct, b.center) + b.radius) + 1) * Unit(n);
        } else {
          end = dt.Circumcenter(u);
        }
        double s[2];
        const int nr = SegmentSphere(ct, end, b, s);
        if (nr == 0) continue;
        Vec3 sp[3];
        for (int k = 0; k < 3; ++k) sp[k] = SnapToSphere(dt.Point(tri[k]), b, delta);
        const Vec3 nrm = geom::Cross(sp[1] - sp[0], sp[2] - sp[0]);
        RestrictedTriangle rt;
        int kept = 0;
        for (int k = 0; k < nr; ++k) {
          const Vec3 x = ct + s[k] * (end - ct);
          if (grid.StrictlyInside(x, ball)) continue;
          const double ang = RepresentationAngle(nrm, x, b.center);
          if (kept == 0 || ang > rt.angle) {
            rt.x = x;
            rt.angle = ang;
          }
          ++kept;
        }
        if (kept == 0) continue;
        std::sort(tri, tri + 3, [](VertexId a, VertexId c) { return a.value() < c.value(); });
        for (int k = 0; k < 3; ++k) rt.v[k] = tri[k];
        rt.ball = ball;
        rt.num_roots = kept;
        rt.rep_radius = geom::Dist(rt.x, dt.Point(tri[0]));
        out->push_back(rt);
      }
    }
  }
}

void SphereTriangles(const Delaunay3& dt, std::span<const CollarBall> balls, const BallGrid& grid, uint32_t ball,
                     std::span<const uint32_t> cand, const std::vector<uint8_t>& is_cand,
                     double delta, std::vector<RestrictedTriangle>* out) {
  std::vector<TetId> star;
  for (uint32_t vi : cand) OwnedSphereTriangles(dt, balls, grid, ball, vi, is_cand, delta, &star, out);
}

double CircleParam(const Circle3& c, const Vec3& x) {
  Vec3 u, w;
  CircleFrame(c, &u, &w);
  double t = std::atan2(geom::Dot(x - c.center, w), geom::Dot(x - c.center, u));
  if (t < 0) t += kTwoPi;
  return t;
}

// Snap (§3.1.2) for circle angles: p onto the circle when within δ·r of it.
Vec3 SnapToCircle(const Vec3& p, const Circle3& c, double delta) {
  const Vec3 d = p - c.center;
  const double h = geom::Dot(d, c.normal);
  const Vec3 inplane = d - h * c.normal;
  const double r = geom::Norm(inplane);
  if (r == 0) return p;
  const double dist = std::hypot(h, r - c.radius);
  if (dist > delta * c.radius) return p;
  return c.center + (c.radius / r) * inplane;
}

std::vector<CollarBall> OtherBalls(std::span<const CollarBall> balls, uint32_t a, uint32_t b) {
  std::vector<CollarBall> out;
  for (uint32_t j = 0; j < balls.size(); ++j) {
    if (j != a && j != b) out.push_back(balls[j]);
  }
  return out;
}

// Restricted edges of one circle among Delaunay edges with both ends in
// `both` (candidates of both of its balls). Same construction and
// nearest-vertex acceptance as RestrictedCircleEdges.
// The edges owned by ia (their smaller vertex): a function of ia's star,
// of which of its neighbours are in `both`, and of the circle (a root is
// accepted iff it lies in ia's Voronoi cell, up to the tolerance below).
void OwnedCircleEdges(const Delaunay3& dt, const CollarCircle& cc, const BallGrid& grid,
                      std::span<const uint32_t> both, double delta, uint32_t ia, const Vec3& u, const Vec3& w,
                      std::vector<VertexId>* nb_scratch, std::vector<VertexId>* nbb_scratch, VertexId* nbb_of_io,
                      std::vector<RestrictedEdge>* out) {
  const Circle3& circle = cc.circle;
  std::vector<VertexId>& nb = *nb_scratch;
  std::vector<VertexId>& nbb = *nbb_scratch;  // neighbours of nbb_of, fetched once per edge
  VertexId& nbb_of = *nbb_of_io;
  {
    const VertexId va(ia);
    dt.Neighbors(va, &nb);
    for (VertexId vb : nb) {
      if (vb.value() <= ia || !std::binary_search(both.begin(), both.end(), vb.value())) continue;
      const Vec3& a = dt.Point(va);
      const Vec3& b = dt.Point(vb);
      const Vec3 n = b - a;
      const Vec3 mid = 0.5 * (a + b);
      const double A = circle.radius * geom::Dot(n, u);
      const double B = circle.radius * geom::Dot(n, w);
      const double D = geom::Dot(n, mid - circle.center);
      const double amp = std::hypot(A, B);
      if (!(amp > std::fabs(D))) continue;
      const double phi = std::atan2(B, A), half = std::acos(D / amp);
      for (double t : {phi - half, phi + half}) {
        const Vec3 x = circle.center + circle.radius * (std::cos(t) * u + std::sin(t) * w);
        if (grid.StrictlyInside(x, cc.a, cc.b)) continue;
        // Most roots of the bisector plane are not on the Voronoi facet of
        // (a, b): a neighbour w of a or b nearer to x than both by a margin
        // shows it, and then the nearest vertex is nearer still, neither a
        // nor b, and nearer than da·(1 − 1e−12): the test below would drop
        // x too. This saves the walk (measured on hinge.stl: these walks
        // were 18% of the run). The margin 2e−12 covers the rounding of the
        // distances, so the accepted roots are exactly those of the walk.
        const double cut = std::min(geom::Dist(x, a), geom::Dist(x, b)) * (1 - 2e-12);
        auto any_nearer = [&](std::span<const VertexId> ns, VertexId other) {
          return std::any_of(ns.begin(), ns.end(),
                             [&](VertexId vw) { return vw != other && geom::Dist(x, dt.Point(vw)) < cut; });
        };
        if (any_nearer(nb, vb)) continue;
        if (nbb_of != vb) {
          dt.Neighbors(vb, &nbb);
          nbb_of = vb;
        }
        if (any_nearer(nbb, va)) continue;
        const VertexId nv = dt.NearestVertex(x, dt.VertexTet(va));
        if (nv != va && nv != vb) {
          const double dn = geom::Dist(x, dt.Point(nv)), da = geom::Dist(x, a);
          if (dn < da * (1 - 1e-12)) continue;
        }
        RestrictedEdge e;
        e.v[0] = va;
        e.v[1] = vb;
        e.x = x;
        e.angle = CircleRepresentationAngle(SnapToCircle(a, circle, delta),
                                            SnapToCircle(b, circle, delta), circle, x);
        out->push_back(e);
      }
    }
  }
}

void CircleEdges(const Delaunay3& dt, const CollarCircle& cc, const BallGrid& grid,
                 std::span<const uint32_t> both, double delta, std::vector<RestrictedEdge>* out) {
  Vec3 u, w;
  CircleFrame(cc.circle, &u, &w);
  std::vector<VertexId> nb, nbb;
  VertexId nbb_of;
  for (uint32_t ia : both) OwnedCircleEdges(dt, cc, grid, both, delta, ia, u, w, &nb, &nbb, &nbb_of, out);
}

// Ball b's term of css(x) (CollarSurfaceSize): ρ + max(0, |x c| − ρ).
double CollarSizeTerm(const Vec3& x, const CollarBall& b) {
  return b.radius + std::max(0.0, geom::Dist(x, b.center) - b.radius);
}

// Union-find over small dense ids.
struct Dsu {
  std::vector<uint32_t> p;
  explicit Dsu(size_t n) : p(n) {
    for (size_t i = 0; i < n; ++i) p[i] = static_cast<uint32_t>(i);
  }
  uint32_t Find(uint32_t x) {
    while (p[x] != x) x = p[x] = p[p[x]];
    return x;
  }
  void Join(uint32_t a, uint32_t b) {
    a = Find(a);
    b = Find(b);
    if (a != b) p[std::max(a, b)] = std::min(a, b);
  }
};

// V − E + F of a set of triangles (vertex triples).
int Euler(const std::vector<std::array<uint32_t, 3>>& tris) {
  std::vector<uint32_t> vs;
  std::vector<uint64_t> es;
  for (const auto& t : tris) {
    vs.insert(vs.end(), t.begin(), t.end());
    es.push_back(EdgeKey(t[0], t[1]));
    es.push_back(EdgeKey(t[0], t[2]));
    es.push_back(EdgeKey(t[1], t[2]));
  }
  std::sort(vs.begin(), vs.end());
  vs.erase(std::unique(vs.begin(), vs.end()), vs.end());
  std::sort(es.begin(), es.end());
  es.erase(std::unique(es.begin(), es.end()), es.end());
  return static_cast<int>(vs.size()) - static_cast<int>(es.size()) + static_cast<int>(tris.size());
}

}  // namespace

namespace detail {

// One cycle through every vertex of the graph given by `edges` (pairs), with
// at least `min_vertices` vertices: no repeated edge, every vertex of degree
// exactly 2 (each appears in exactly two edges), connected. With
// exact_degrees false the degree test is an average (as many distinct
// vertices as edges: a connected graph with one cycle, so a "lollipop" with
// degrees 1, 3, 2, 2 passes); until session 21 every caller had that one
// (docs/svrc-collars.md "Session 21").
bool IsOneCycleGeneral(std::vector<std::pair<uint32_t, uint32_t>> edges, size_t min_vertices, bool exact_degrees) {
  if (edges.empty()) return false;
  for (auto& e : edges) {
    if (e.first > e.second) std::swap(e.first, e.second);
  }
  std::sort(edges.begin(), edges.end());
  if (std::adjacent_find(edges.begin(), edges.end()) != edges.end()) return false;
  std::vector<uint32_t> vs;
  for (auto [a, b] : edges) {
    vs.push_back(a);
    vs.push_back(b);
  }
  std::sort(vs.begin(), vs.end());
  std::vector<uint32_t> uniq = vs;
  uniq.erase(std::unique(uniq.begin(), uniq.end()), uniq.end());
  // Every vertex of degree 2 ⇔ each appears exactly twice.
  if (exact_degrees) {
    for (size_t i = 0; i < vs.size(); i += 2) {
      if (vs[i] != vs[i + 1] || (i + 2 < vs.size() && vs[i + 2] == vs[i])) return false;
    }
  }
  if (edges.size() != uniq.size() || uniq.size() < min_vertices) return false;
  Dsu d(uniq.size());
  auto idx = [&](uint32_t v) {
    return static_cast<uint32_t>(std::lower_bound(uniq.begin(), uniq.end(), v) - uniq.begin());
  };
  for (auto [a, b] : edges) d.Join(idx(a), idx(b));
  for (uint32_t i = 0; i < uniq.size(); ++i) {
    if (d.Find(i) != 0) return false;
  }
  return true;
}

// IsOneCycleGeneral without heap allocation for the small graphs of vertex
// links and circles (the same answer: the same tests on arrays; measured on
// wedge-1.smesh, the allocating version with its callers' per-vertex
// vectors was ~3% of the run).
bool IsOneCycle(const std::vector<std::pair<uint32_t, uint32_t>>& in, size_t min_vertices, bool exact_degrees) {
  constexpr size_t kMax = 48;
  const size_t n = in.size();
  if (n == 0) return false;
  if (n > kMax) return IsOneCycleGeneral(in, min_vertices, exact_degrees);
  std::array<std::pair<uint32_t, uint32_t>, kMax> edges;
  for (size_t i = 0; i < n; ++i) edges[i] = std::minmax(in[i].first, in[i].second);
  std::sort(edges.begin(), edges.begin() + n);
  if (std::adjacent_find(edges.begin(), edges.begin() + n) != edges.begin() + n) return false;
  std::array<uint32_t, 2 * kMax> uniq;
  for (size_t i = 0; i < n; ++i) {
    uniq[2 * i] = edges[i].first;
    uniq[2 * i + 1] = edges[i].second;
  }
  std::sort(uniq.begin(), uniq.begin() + 2 * n);
  if (exact_degrees) {
    for (size_t i = 0; i < 2 * n; i += 2) {  // every vertex of degree exactly 2
      if (uniq[i] != uniq[i + 1] || (i + 2 < 2 * n && uniq[i + 2] == uniq[i])) return false;
    }
  }
  const size_t u = static_cast<size_t>(std::unique(uniq.begin(), uniq.begin() + 2 * n) - uniq.begin());
  if (u < min_vertices || u != n) return false;
  std::array<uint32_t, 2 * kMax> parent;
  for (uint32_t i = 0; i < u; ++i) parent[i] = i;
  auto find = [&](uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  auto idx = [&](uint32_t v) {
    return static_cast<uint32_t>(std::lower_bound(uniq.begin(), uniq.begin() + u, v) - uniq.begin());
  };
  for (size_t i = 0; i < n; ++i) {
    const uint32_t a = find(idx(edges[i].first)), b = find(idx(edges[i].second));
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
  for (uint32_t i = 0; i < u; ++i) {
    if (find(i) != 0) return false;
  }
  return true;
}

}  // namespace detail

namespace {

using detail::IsOneCycle;

// One simple path through every vertex of the graph (a vertex link next to a
// circle): no repeated edge, two vertices of degree 1, the rest degree 2,
// connected.
bool IsOnePath(std::vector<std::pair<uint32_t, uint32_t>> edges) {
  if (edges.empty()) return false;
  for (auto& e : edges) {
    if (e.first > e.second) std::swap(e.first, e.second);
  }
  std::sort(edges.begin(), edges.end());
  if (std::adjacent_find(edges.begin(), edges.end()) != edges.end()) return false;
  std::vector<uint32_t> vs;
  for (auto [a, b] : edges) {
    vs.push_back(a);
    vs.push_back(b);
  }
  std::sort(vs.begin(), vs.end());
  std::vector<uint32_t> uniq = vs;
  uniq.erase(std::unique(uniq.begin(), uniq.end()), uniq.end());
  if (edges.size() + 1 != uniq.size()) return false;
  int ends = 0;
  for (uint32_t u : uniq) {
    const auto n = std::upper_bound(vs.begin(), vs.end(), u) - std::lower_bound(vs.begin(), vs.end(), u);
    if (n == 1) {
      ++ends;
    } else if (n != 2) {
      return false;
    }
  }
  if (ends != 2) return false;
  Dsu d(uniq.size());
  auto idx = [&](uint32_t v) {
    return static_cast<uint32_t>(std::lower_bound(uniq.begin(), uniq.end(), v) - uniq.begin());
  };
  for (auto [a, b] : edges) d.Join(idx(a), idx(b));
  for (uint32_t i = 0; i < uniq.size(); ++i) {
    if (d.Find(i) != 0) return false;
  }
  return true;
}

}  // namespace

double CollarSurfaceSize(const Vec3& x, const CollarDescription& collars) {
  double best = std::numeric_limits<double>::infinity();
  for (const CollarBall& b : collars.balls) best = std::min(best, CollarSizeTerm(x, b));
  return best;
}

CollarRestriction ComputeCollarRestriction(const Delaunay3& dt, const CollarDescription& collars,
                                           const CollarSurfaceOptions& opt, CollarRestrictionCache* cache) {
  CollarRestriction r;
  const std::span<const CollarBall> balls(collars.balls);
  const size_t nb = balls.size(), nc = collars.circles.size();
  const BallGrid grid(balls);
  r.candidates_per_ball.assign(nb, 0);
  r.circle_edges.resize(nc);
  r.circle_params.resize(nc);
  r.circle_state.assign(nc, 0);
  r.circle_arcs.resize(nc);
  if (!dt.Is3d()) return r;
  // The cache serves only the same description (balls and circles) and
  // options; otherwise it is rebuilt from this call.
  std::vector<std::pair<uint32_t, uint32_t>> circle_balls(nc);
  for (uint32_t k = 0; k < nc; ++k) circle_balls[k] = {collars.circles[k].a, collars.circles[k].b};
  auto same_ball = [](const CollarBall& x, const CollarBall& y) { return x.center == y.center && x.radius == y.radius; };
  const bool reuse = cache != nullptr && cache->valid && opt.local_search && cache->delta == opt.delta &&
                     cache->balls.size() == nb && cache->circle_balls == circle_balls &&
                     std::equal(balls.begin(), balls.end(), cache->balls.begin(), same_ball);
  std::vector<uint8_t> seen(dt.NumVertices(), 0), is_cand(dt.NumVertices(), 0);
  std::vector<std::vector<uint32_t>> cand(nb);
  std::vector<uint8_t> computed(nb, 1);
  std::vector<uint32_t> touched;
  std::vector<RestrictedTriangle> tris;
  ChangedOwners changed;
  std::vector<TetId> star_scratch;
  std::vector<CollarRestrictionCache::PerBall> per_ball;
  if (cache != nullptr) per_ball.resize(nb);
  r.center_vertex.assign(nb, VertexId());
  // About as many restricted triangles as last round: reserved, not grown by
  // doubling (each growth copies and touches fresh pages).
  if (cache != nullptr && reuse) r.triangles.reserve(cache->last_triangles + cache->last_triangles / 8);
  // R_u, memoised in the cache by u's generation (its star, hence its
  // Voronoi cell, is the same while the generation is).
  auto out_radius = [&](VertexId u) -> double {
    if (cache == nullptr) return dt.OutRadius(u);
    std::vector<CollarRestrictionCache::OutRadiusMemo>& memo = cache->out_radius;
    if (memo.size() <= u.value()) memo.resize(dt.NumVertices() + dt.NumVertices() / 2 + 16);
    CollarRestrictionCache::OutRadiusMemo& m = memo[u.value()];
    const uint32_t g = cache->generation(u.value());
    if (!m.valid || m.generation != g) m = {g, true, dt.OutRadius(u)};
    return m.radius;
  };
  for (uint32_t i = 0; i < nb; ++i) {
    if (reuse) {
      CollarRestrictionCache::PerBall& pb = cache->per_ball[i];
      bool clean = true;
      for (const auto& [v, g] : pb.read) {
        if (cache->generation(v) != g) {
          clean = false;
          break;
        }
      }
      if (clean) {
        computed[i] = 0;
        ++cache->balls_reused;
        cand[i] = pb.cand;
        r.candidates_per_ball[i] = static_cast<uint32_t>(cand[i].size());
        r.center_vertex[i] = pb.center_vertex;
        r.triangles.insert(r.triangles.end(), pb.triangles.begin(), pb.triangles.end());
        per_ball[i] = std::move(pb);
        continue;
      }
    }
    // The walk to the centre starts at this ball's last centre vertex, else
    // at the previous ball's (balls come in creation order, mostly along a
    // crease); the default start, the last inserted tet, may be across M_Ω
    // (measured on hinge.stl: these walks were 30% of the COLLAR rounds).
    // NearestVertex is exact, so the hint changes no result.
    VertexId from;
    if (cache != nullptr && i < cache->per_ball.size()) from = cache->per_ball[i].center_vertex;
    if (!from.valid() && i > 0) from = r.center_vertex[i - 1];
    const TetId hint = from.valid() && from.value() < dt.NumVertices() ? dt.VertexTet(from) : TetId();
    cand[i] = CandidateVertices(dt, balls[i], opt.local_search, hint, &seen, &r.center_vertex[i], &touched,
                                out_radius);
    r.candidates_per_ball[i] = static_cast<uint32_t>(cand[i].size());
    for (uint32_t v : cand[i]) is_cand[v] = 1;
    tris.clear();
    if (cache == nullptr) {
      SphereTriangles(dt, balls, grid, i, cand[i], is_cand, opt.delta, &tris);
    } else {
      // Per owner: the last computation's triangles of a candidate whose
      // star is unchanged (same generation) and none of whose neighbours
      // entered or left the candidates; the others computed. The neighbour
      // test is a guard: with the owner's star unchanged its faces' Voronoi
      // edges are too, and a neighbour whose cell such an edge meets S in
      // stays a candidate unless the search stops reaching it (the unit
      // test's rounds never hit that case; dropping the generation test
      // fails it).
      const CollarRestrictionCache::PerBall* old =
          reuse && i < cache->per_ball.size() && cache->per_ball[i].tri_begin.size() == cache->per_ball[i].cand.size() + 1
              ? &cache->per_ball[i]
              : nullptr;
      if (old != nullptr) changed.Mark(dt, old->cand, cand[i]);
      CollarRestrictionCache::PerBall& pb = per_ball[i];
      pb.cand_gen.clear();
      pb.tri_begin.clear();
      pb.cand_gen.reserve(cand[i].size());
      pb.tri_begin.reserve(cand[i].size() + 1);
      size_t j = 0;  // in old->cand
      for (uint32_t v : cand[i]) {
        const uint32_t g = cache->generation(v);
        pb.tri_begin.push_back(static_cast<uint32_t>(tris.size()));
        pb.cand_gen.push_back(g);
        if (old != nullptr) {
          while (j < old->cand.size() && old->cand[j] < v) ++j;
          if (j < old->cand.size() && old->cand[j] == v && old->cand_gen[j] == g && !changed.Has(v)) {
            tris.insert(tris.end(), old->triangles.begin() + old->tri_begin[j],
                        old->triangles.begin() + old->tri_begin[j + 1]);
            ++cache->owners_reused;
            continue;
          }
        }
        OwnedSphereTriangles(dt, balls, grid, i, v, is_cand, opt.delta, &star_scratch, &tris);
        ++cache->owners_computed;
      }
      pb.tri_begin.push_back(static_cast<uint32_t>(tris.size()));
      changed.Clear();
    }
    for (uint32_t v : cand[i]) is_cand[v] = 0;
    r.triangles.insert(r.triangles.end(), tris.begin(), tris.end());
    if (cache != nullptr) {
      ++cache->balls_computed;
      CollarRestrictionCache::PerBall& pb = per_ball[i];
      pb.cand = cand[i];
      pb.read.clear();
      pb.read.reserve(touched.size());
      for (uint32_t v : touched) pb.read.emplace_back(v, cache->generation(v));
      pb.triangles = tris;
      pb.center_vertex = r.center_vertex[i];
    }
  }
  std::vector<std::vector<uint32_t>> circle_both(cache != nullptr ? nc : 0), circle_both_gen(cache != nullptr ? nc : 0);
  for (uint32_t k = 0; k < nc; ++k) {
    const CollarCircle& cc = collars.circles[k];
    if (reuse && !computed[cc.a] && !computed[cc.b]) {
      if (k < cache->circle_both.size()) {
        circle_both[k] = std::move(cache->circle_both[k]);
        circle_both_gen[k] = std::move(cache->circle_both_gen[k]);
      }
      ++cache->circles_reused;
      r.circle_arcs[k] = cache->last.circle_arcs[k];
      r.circle_state[k] = cache->last.circle_state[k];
      r.circle_edges[k] = cache->last.circle_edges[k];
      r.circle_params[k] = cache->last.circle_params[k];
      continue;
    }
    if (cache != nullptr) ++cache->circles_computed;
    const std::vector<CollarBall> others = OtherBalls(balls, cc.a, cc.b);
    r.circle_arcs[k] = ClipCircleByBalls(cc.circle, others);
    const auto& arcs = r.circle_arcs[k];
    if (arcs.empty()) continue;
    r.circle_state[k] = (arcs.size() == 1 && arcs[0].t0 <= 0 && arcs[0].t1 >= kTwoPi) ? 1 : 2;
    std::vector<uint32_t> both;
    std::set_intersection(cand[cc.a].begin(), cand[cc.a].end(), cand[cc.b].begin(),
                          cand[cc.b].end(), std::back_inserter(both));
    std::vector<RestrictedEdge>& edges = r.circle_edges[k];
    if (cache == nullptr) {
      CircleEdges(dt, cc, grid, both, opt.delta, &edges);
    } else {
      // Per owner, as the balls' triangles: the last computation's edges of
      // an owner with the same generation none of whose neighbours entered
      // or left `both` (the last edges are sorted by their first vertex, the
      // owner). The unit test fails without both tests; in its scenes either
      // one alone catches every change (a new vertex next to a circle is in
      // both lists), while in general each covers a case the other does not
      // (a new neighbour outside `both`; a neighbour joining `both` through
      // a change on its far side).
      const bool have_old = reuse && k < cache->circle_both.size() &&
                            cache->circle_both_gen[k].size() == cache->circle_both[k].size();
      const std::vector<uint32_t>* old_both = have_old ? &cache->circle_both[k] : nullptr;
      const std::vector<RestrictedEdge>* old_edges = have_old ? &cache->last.circle_edges[k] : nullptr;
      if (have_old) changed.Mark(dt, *old_both, both);
      Vec3 fu, fw;
      CircleFrame(cc.circle, &fu, &fw);
      std::vector<VertexId> cnb, cnbb;
      VertexId cnbb_of;
      std::vector<uint32_t>& gens = circle_both_gen[k];
      gens.reserve(both.size());
      size_t j = 0;  // in *old_both
      for (uint32_t ia : both) {
        const uint32_t g = cache->generation(ia);
        gens.push_back(g);
        if (have_old) {
          while (j < old_both->size() && (*old_both)[j] < ia) ++j;
          if (j < old_both->size() && (*old_both)[j] == ia && cache->circle_both_gen[k][j] == g && !changed.Has(ia)) {
            auto lo = std::lower_bound(old_edges->begin(), old_edges->end(), ia,
                                       [](const RestrictedEdge& e, uint32_t v) { return e.v[0].value() < v; });
            for (; lo != old_edges->end() && lo->v[0].value() == ia; ++lo) edges.push_back(*lo);
            ++cache->circle_owners_reused;
            continue;
          }
        }
        OwnedCircleEdges(dt, cc, grid, both, opt.delta, ia, fu, fw, &cnb, &cnbb, &cnbb_of, &edges);
        ++cache->circle_owners_computed;
      }
      changed.Clear();
      circle_both[k] = both;
    }
    std::vector<double> params(edges.size());
    for (size_t e = 0; e < edges.size(); ++e) params[e] = CircleParam(cc.circle, edges[e].x);
    // Sort by (v0, v1, param), keeping params parallel.
    std::vector<size_t> order(edges.size());
    for (size_t e = 0; e < order.size(); ++e) order[e] = e;
    std::sort(order.begin(), order.end(), [&](size_t p, size_t q) {
      return std::tuple(edges[p].v[0].value(), edges[p].v[1].value(), params[p]) <
             std::tuple(edges[q].v[0].value(), edges[q].v[1].value(), params[q]);
    });
    std::vector<RestrictedEdge> se;
    std::vector<double> sp;
    for (size_t e : order) {
      se.push_back(edges[e]);
      sp.push_back(params[e]);
    }
    edges = std::move(se);
    r.circle_params[k] = std::move(sp);
  }
  if (cache != nullptr) {
    cache->valid = opt.local_search;
    cache->delta = opt.delta;
    cache->balls.assign(balls.begin(), balls.end());
    cache->circle_balls = std::move(circle_balls);
    cache->per_ball = std::move(per_ball);
    cache->last_triangles = r.triangles.size();
    cache->last.circle_arcs = r.circle_arcs;
    cache->last.circle_state = r.circle_state;
    cache->last.circle_edges = r.circle_edges;
    cache->last.circle_params = r.circle_params;
    cache->circle_both = std::move(circle_both);
    cache->circle_both_gen = std::move(circle_both_gen);
  }
  return r;
}

std::vector<CollarRepair> CollarRepairs(const Delaunay3& dt, const CollarDescription& collars,
                                        const CollarSurfaceOptions& opt,
                                        CollarSurfaceReport* report, CollarRestrictionCache* cache,
                                        std::vector<RestrictedTriangle>* triangles) {
  if (triangles != nullptr) triangles->clear();
  CollarSurfaceReport rep;
  std::vector<CollarRepair> out;
  const std::span<const CollarBall> balls(collars.balls);
  const uint32_t nb = static_cast<uint32_t>(balls.size());
  const uint32_t nc = static_cast<uint32_t>(collars.circles.size());
  rep.euler_per_ball.assign(nb, 0);
  rep.circles_on_surface_per_ball.assign(nb, 0);
  if (!dt.Is3d() || nb == 0) {
    if (report != nullptr) *report = rep;
    return out;
  }
  CollarRestriction res = ComputeCollarRestriction(dt, collars, opt, cache);
  const BallGrid grid(balls);
  for (uint32_t c : res.candidates_per_ball) rep.candidates += c;
  const std::vector<RestrictedTriangle>& tris = res.triangles;
  auto ball_hint = [&](uint32_t ball) {
    const VertexId c = ball < res.center_vertex.size() ? res.center_vertex[ball] : VertexId();
    return c.valid() ? dt.VertexTet(c) : TetId();
  };

  // Adds a repair after checking that x is on S and not a vertex; the radius
  // is the distance to the nearest vertex (= the RepBall radius for a rep point).
  auto add = [&](const Vec3& x, uint32_t ball, uint32_t circle, CollarRepair::Reason why) {
    CollarRepair cr;
    cr.x = x;
    cr.ball = ball;
    cr.circle = circle;
    cr.collar_dim = circle == CollarRepair::kNoCircle ? 2 : 1;
    cr.reason = why;
    if (circle == CollarRepair::kNoCircle) {
      if (grid.StrictlyInside(x, ball)) return;
    } else {
      const CollarCircle& cc = collars.circles[circle];
      cr.ball = cc.a;
      if (grid.StrictlyInside(x, cc.a, cc.b)) return;
    }
    const VertexId nv = dt.NearestVertex(x, ball_hint(cr.ball));
    if (!nv.valid()) return;
    cr.near = nv;
    cr.radius = geom::Dist(x, dt.Point(nv));
    if (!(cr.radius > 0)) return;  // x is a vertex already
    out.push_back(cr);
  };
  auto circles_on_s = [&](uint32_t i) {
    std::vector<uint32_t> cs;
    for (uint32_t k : collars.circles_of_ball[i]) {
      if (res.circle_state[k] != 0) cs.push_back(k);
    }
    return cs;
  };

  // --- Distinct Delaunay triangles of Del(M)|_S (a triangle may be listed for
  // two spheres when its Voronoi edge crosses S twice near a circle).
  std::vector<uint32_t> order(tris.size());
  for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  auto triple = [&](uint32_t i) {
    return std::array<uint32_t, 3>{tris[i].v[0].value(), tris[i].v[1].value(),
                                   tris[i].v[2].value()};
  };
  const size_t nv = dt.NumVertices();
  SortByVertex(&order, nv, [&](uint32_t p) { return tris[p].v[0].value(); },
               [&](uint32_t p, uint32_t q) { return std::pair(triple(p), p) < std::pair(triple(q), q); });
  struct Unique {
    std::array<uint32_t, 3> v;
    int roots = 0;
    uint32_t best = 0;  // entry with the largest RepBall
  };
  std::vector<Unique> uniq;
  uniq.reserve(order.size());
  for (uint32_t i : order) {
    if (uniq.empty() || uniq.back().v != triple(i)) uniq.push_back(Unique{triple(i), 0, i});
    Unique& u = uniq.back();
    u.roots += tris[i].num_roots;
    if (tris[i].rep_radius > tris[u.best].rep_radius) u.best = i;
  }
  rep.restricted_triangles = static_cast<int>(uniq.size());
  for (const auto& e : res.circle_edges) rep.restricted_circle_edges += static_cast<int>(e.size());
  // The topology tests run in both modes: Lemma 16's "ε-sample ⇒ consistent"
  // assumes M ⊂ S, but M_Ω has vertices off S (inside and outside the
  // balls), and with them the size criterion alone left (a)–(c) violations
  // even at ε_s = 0.07 (docs/svrc-collars.md, stage (e) measurements).
  const bool explicit_tests = !opt.size_criterion;

  // (a) one root per Voronoi edge.
  for (const Unique& u : uniq) {
    if (u.roots == 1) continue;
    ++rep.bad_roots;
    add(tris[u.best].x, tris[u.best].ball, CollarRepair::kNoCircle, CollarRepair::kTopology);
  }
  // (b) every Delaunay edge in 0 or 2 restricted triangles of S.
  std::vector<std::pair<uint64_t, uint32_t>> edge_tri;  // edge → unique index
  edge_tri.reserve(3 * uniq.size());
  for (uint32_t k = 0; k < uniq.size(); ++k) {
    const auto& v = uniq[k].v;
    edge_tri.push_back({EdgeKey(v[0], v[1]), k});
    edge_tri.push_back({EdgeKey(v[0], v[2]), k});
    edge_tri.push_back({EdgeKey(v[1], v[2]), k});
  }
  SortByVertex(&edge_tri, nv, [](const std::pair<uint64_t, uint32_t>& e) { return static_cast<uint32_t>(e.first >> 32); },
               std::less<>());
  for (size_t i = 0; i < edge_tri.size();) {
    size_t j = i;
    uint32_t best = uniq[edge_tri[i].second].best;
    while (j < edge_tri.size() && edge_tri[j].first == edge_tri[i].first) {
      const uint32_t b = uniq[edge_tri[j].second].best;
      if (tris[b].rep_radius > tris[best].rep_radius) best = b;
      ++j;
    }
    if (j - i != 2) {
      ++rep.bad_facets;
      add(tris[best].x, tris[best].ball, CollarRepair::kNoCircle, CollarRepair::kTopology);
    }
    i = j;
  }
  // Circle rep points by vertex, for (c)'s candidates.
  std::vector<std::tuple<uint32_t, uint32_t, uint32_t>> circle_at;  // v, circle, edge
  for (uint32_t k = 0; k < nc; ++k) {
    for (uint32_t e = 0; e < res.circle_edges[k].size(); ++e) {
      circle_at.push_back({res.circle_edges[k][e].v[0].value(), k, e});
      circle_at.push_back({res.circle_edges[k][e].v[1].value(), k, e});
    }
  }
  std::sort(circle_at.begin(), circle_at.end());
  // Repair of a bad link at v (restricted to sphere `only`, or kAll): the
  // point of S ∩ V(v) farthest from v among the rep points of v's triangles
  // (corners of its restricted cell), its circle crossings, and the point of
  // each of its spheres opposite v when that point is in V(v).
  constexpr uint32_t kAll = 0xFFFFFFFFu;
  auto repair_link = [&](uint32_t v, const std::vector<uint32_t>& entries, uint32_t only) {
    const Vec3& pv = dt.Point(VertexId(v));
    Vec3 best_x;
    uint32_t best_ball = 0, best_circle = CollarRepair::kNoCircle;
    double best_d = -1;
    auto consider = [&](const Vec3& x, uint32_t ball, uint32_t circle) {
      const double d = geom::Dist(x, pv);
      if (d > best_d) {
        best_d = d;
        best_x = x;
        best_ball = ball;
        best_circle = circle;
      }
    };
    std::vector<uint32_t> its_balls;
    for (uint32_t e : entries) {
      consider(tris[e].x, tris[e].ball, CollarRepair::kNoCircle);
      its_balls.push_back(tris[e].ball);
    }
    auto ca = std::lower_bound(circle_at.begin(), circle_at.end(),
                               std::tuple<uint32_t, uint32_t, uint32_t>{v, 0, 0});
    for (; ca != circle_at.end() && std::get<0>(*ca) == v; ++ca) {
      const uint32_t k = std::get<1>(*ca);
      if (only != kAll && collars.circles[k].a != only && collars.circles[k].b != only) continue;
      consider(res.circle_edges[k][std::get<2>(*ca)].x, collars.circles[k].a, k);
    }
    std::sort(its_balls.begin(), its_balls.end());
    its_balls.erase(std::unique(its_balls.begin(), its_balls.end()), its_balls.end());
    for (uint32_t bi : its_balls) {
      const Vec3 d = balls[bi].center - pv;
      if (!(geom::Norm(d) > 0)) continue;
      const Vec3 x = balls[bi].center + balls[bi].radius * Unit(d);
      if (grid.StrictlyInside(x, bi)) continue;
      if (dt.NearestVertex(x, dt.VertexTet(VertexId(v))) != VertexId(v)) continue;
      consider(x, bi, CollarRepair::kNoCircle);
    }
    if (best_d > 0) add(best_x, best_ball, best_circle, CollarRepair::kTopology);
  };
  // (c) every vertex's restricted link in S is one cycle.
  {
    std::vector<std::tuple<uint32_t, uint32_t, uint32_t, uint32_t>> link;  // v, a, b, entry
    link.reserve(3 * uniq.size());
    for (const Unique& u : uniq) {
      link.push_back({u.v[0], u.v[1], u.v[2], u.best});
      link.push_back({u.v[1], u.v[0], u.v[2], u.best});
      link.push_back({u.v[2], u.v[0], u.v[1], u.best});
    }
    SortByVertex(&link, nv, [](const std::tuple<uint32_t, uint32_t, uint32_t, uint32_t>& l) { return std::get<0>(l); },
                 std::less<>());
    std::vector<std::pair<uint32_t, uint32_t>> ring;
    std::vector<uint32_t> entries;
    for (size_t i = 0; i < link.size();) {
      const uint32_t v = std::get<0>(link[i]);
      size_t j = i;
      ring.clear();
      entries.clear();
      for (; j < link.size() && std::get<0>(link[j]) == v; ++j) {
        ring.push_back({std::get<1>(link[j]), std::get<2>(link[j])});
        entries.push_back(std::get<3>(link[j]));
      }
      // By default the average-degree test: a vertex link with a vertex x of
      // degree other than 2 has its edge (v, x) in 1 or 3 restricted
      // triangles, which (b) reports and repairs already (with a second
      // repair here, at the far end of v's restricted cell, crease_pair 10°
      // went 44,576 → 53,466 tets; docs/svrc-collars.md "Session 21").
      if (!IsOneCycle(ring, 3, opt.exact_vertex_links)) {
        ++rep.bad_links;
        repair_link(v, entries, kAll);
      }
      i = j;
    }
  }

  // Per partial sphere: its triangles, χ, (d) and (f).
  std::vector<std::vector<uint32_t>> of_ball(nb);
  for (uint32_t i = 0; i < tris.size(); ++i) of_ball[tris[i].ball].push_back(i);
  for (uint32_t bi = 0; bi < nb; ++bi) {
    const std::vector<uint32_t> cs = circles_on_s(bi);
    for (uint32_t k : cs) rep.circles_on_surface_per_ball[bi] += res.circle_state[k] == 1;
    if (opt.topology_summary) {
      std::vector<std::array<uint32_t, 3>> t3;
      for (uint32_t i : of_ball[bi]) t3.push_back(triple(i));
      rep.euler_per_ball[bi] = Euler(t3);
    }
    const CollarBall& b = balls[bi];
    if (of_ball[bi].empty()) {
      // (d) The partial sphere lies inside one cell, or is covered: the
      // farthest from its nearest vertex of 26 sphere directions and the
      // points opposite each crossing ball.
      std::vector<Vec3> dirs;
      for (int dx = -1; dx <= 1; ++dx) {
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dz = -1; dz <= 1; ++dz) {
            if (dx != 0 || dy != 0 || dz != 0) dirs.push_back(Unit(Vec3(dx, dy, dz)));
          }
        }
      }
      for (uint32_t k : collars.circles_of_ball[bi]) {
        const CollarCircle& cc = collars.circles[k];
        const uint32_t other = cc.a == bi ? cc.b : cc.a;
        dirs.push_back(Unit(b.center - balls[other].center));
      }
      double best_d = -1;
      Vec3 best_x;
      for (const Vec3& d : dirs) {
        const Vec3 x = b.center + b.radius * d;
        if (grid.StrictlyInside(x, bi)) continue;
        const VertexId nv = dt.NearestVertex(x, ball_hint(bi));
        const double dist = geom::Dist(x, dt.Point(nv));
        if (dist > best_d) {
          best_d = dist;
          best_x = x;
        }
      }
      if (best_d > 0) {
        ++rep.empty_spheres;
        add(best_x, bi, CollarRepair::kNoCircle, CollarRepair::kTopology);
      }
      continue;
    }
    // (f) boundary of sphere bi's triangles = restricted edges of its circles.
    std::vector<std::pair<uint64_t, uint32_t>> es;  // edge → triangle entry
    for (uint32_t i : of_ball[bi]) {
      const auto v = triple(i);
      es.push_back({EdgeKey(v[0], v[1]), i});
      es.push_back({EdgeKey(v[0], v[2]), i});
      es.push_back({EdgeKey(v[1], v[2]), i});
    }
    std::sort(es.begin(), es.end());
    std::vector<std::pair<uint64_t, uint32_t>> boundary;
    for (size_t i = 0; i < es.size();) {
      size_t j = i;
      while (j < es.size() && es[j].first == es[i].first) ++j;
      if (j - i == 1) boundary.push_back(es[i]);
      i = j;
    }
    std::vector<std::tuple<uint64_t, uint32_t, uint32_t>> ce;  // edge, circle, index
    for (uint32_t k : cs) {
      for (uint32_t e = 0; e < res.circle_edges[k].size(); ++e) {
        const RestrictedEdge& re = res.circle_edges[k][e];
        ce.push_back({EdgeKey(re.v[0].value(), re.v[1].value()), k, e});
      }
    }
    std::sort(ce.begin(), ce.end());
    size_t p = 0, q = 0;
    while (p < boundary.size() || q < ce.size()) {
      const uint64_t kb = p < boundary.size() ? boundary[p].first : ~uint64_t{0};
      const uint64_t kc = q < ce.size() ? std::get<0>(ce[q]) : ~uint64_t{0};
      if (kb == kc) {
        ++p;
        while (q < ce.size() && std::get<0>(ce[q]) == kc) ++q;
      } else if (kb < kc) {
        ++rep.bad_boundaries;
        const RestrictedTriangle& t = tris[boundary[p].second];
        add(t.x, t.ball, CollarRepair::kNoCircle, CollarRepair::kTopology);
        ++p;
      } else {
        ++rep.bad_boundaries;
        const uint32_t k = std::get<1>(ce[q]);
        add(res.circle_edges[k][std::get<2>(ce[q])].x, bi, k, CollarRepair::kCircle);
        while (q < ce.size() && std::get<0>(ce[q]) == kc) ++q;
      }
    }
    // (c) within the partial sphere (Lemma 15: each partial sphere's
    // restricted triangulation is homeomorphic to it): every vertex's link in
    // sphere bi is one cycle, or one path when v is on one of its circles'
    // restricted edges.
    std::vector<std::tuple<uint32_t, uint32_t, uint32_t, uint32_t>> blink;
    for (uint32_t i : of_ball[bi]) {
      const auto v = triple(i);
      blink.push_back({v[0], v[1], v[2], i});
      blink.push_back({v[1], v[0], v[2], i});
      blink.push_back({v[2], v[0], v[1], i});
    }
    std::sort(blink.begin(), blink.end());
    std::vector<uint32_t> on_circle;  // vertices of its circles' restricted edges
    for (const auto& c : ce) {
      on_circle.push_back(static_cast<uint32_t>(std::get<0>(c) >> 32));
      on_circle.push_back(static_cast<uint32_t>(std::get<0>(c) & 0xFFFFFFFFu));
    }
    std::sort(on_circle.begin(), on_circle.end());
    for (size_t i = 0; i < blink.size();) {
      const uint32_t v = std::get<0>(blink[i]);
      size_t j = i;
      std::vector<std::pair<uint32_t, uint32_t>> ring;
      std::vector<uint32_t> entries;
      for (; j < blink.size() && std::get<0>(blink[j]) == v; ++j) {
        ring.push_back({std::get<1>(blink[j]), std::get<2>(blink[j])});
        entries.push_back(std::get<3>(blink[j]));
      }
      const bool ok = std::binary_search(on_circle.begin(), on_circle.end(), v)
                          ? IsOnePath(ring)
                          : IsOneCycle(ring, 3, opt.exact_sphere_links);
      if (!ok) {
        ++rep.bad_sphere_links;
        repair_link(v, entries, bi);
      }
      i = j;
    }
  }

  // (e) circles: one cycle of ≥ 3 (whole), paths covering every arc (partial).
  for (uint32_t k = 0; k < nc; ++k) {
    if (res.circle_state[k] == 0) continue;
    const Circle3& circle = collars.circles[k].circle;
    const auto& edges = res.circle_edges[k];
    std::vector<std::pair<uint32_t, uint32_t>> pairs;
    for (const RestrictedEdge& e : edges) pairs.push_back({e.v[0].value(), e.v[1].value()});
    std::vector<double> params = res.circle_params[k];
    std::sort(params.begin(), params.end());
    bool ok;
    if (res.circle_state[k] == 1) {
      ok = IsOneCycle(pairs, 3, /*exact_degrees=*/true);
    } else {
      // Partly covered: every arc holds a crossing, no vertex of degree > 2.
      ok = !pairs.empty();
      std::vector<uint32_t> vs;
      for (auto [a, b] : pairs) {
        vs.push_back(a);
        vs.push_back(b);
      }
      std::sort(vs.begin(), vs.end());
      for (size_t i = 0; i + 2 < vs.size(); ++i) ok = ok && vs[i] != vs[i + 2];
      for (const Arc& arc : res.circle_arcs[k]) {
        const auto it = std::lower_bound(params.begin(), params.end(), arc.t0);
        ok = ok && it != params.end() && *it <= arc.t1;
      }
    }
    if (ok) continue;
    ++rep.bad_circles;
    // The gaps between consecutive rep points (or arc ends) along the circle
    // (no rep point on a whole circle: 8 probes); the repair is the gap
    // midpoint farthest from its nearest vertex, i.e. the largest RepBall.
    // Not simply the longest gap: a vertex on the circle whose Voronoi cell
    // is flanked by a collar centre's (equidistant from the whole circle)
    // has its two crossings symmetric about it, so the longest gap's midpoint
    // was that vertex up to rounding and the repair came back every round
    // (measured: a flat tetrahedron, 27° creases, stopped at the RepBall floor
    // with a circle repair 2.8e-17 from vertex 2955).
    std::vector<double> probes;
    if (res.circle_state[k] == 1 && params.empty()) {
      for (int s = 0; s < 8; ++s) probes.push_back(kTwoPi * s / 8);
    } else if (res.circle_state[k] == 1) {
      for (size_t i = 0; i < params.size(); ++i) {
        const double a = params[i];
        const double b = i + 1 < params.size() ? params[i + 1] : params[0] + kTwoPi;
        probes.push_back(0.5 * (a + b));
      }
    } else {
      for (const Arc& arc : res.circle_arcs[k]) {
        double a = arc.t0;
        for (double t : params) {
          if (t < arc.t0 || t > arc.t1) continue;
          probes.push_back(0.5 * (a + t));
          a = t;
        }
        probes.push_back(0.5 * (a + arc.t1));
      }
    }
    Vec3 best_x;
    double best_d = -1;
    for (double t : probes) {
      const Vec3 x = CirclePoint(circle, std::fmod(t, kTwoPi));
      const double d = geom::Dist(x, dt.Point(dt.NearestVertex(x, ball_hint(collars.circles[k].a))));
      if (d > best_d) {
        best_d = d;
        best_x = x;
      }
    }
    add(best_x, collars.circles[k].a, k, CollarRepair::kCircle);
  }

  // Angles (Definition 34, snapped) and sizes (Ch. 6). css(x) for x on
  // ball o's sphere: every ball j contributes ≥ |x c_j|, so with B0 = o's
  // contribution, a ball with |c_j c_o| ≥ 3ρ_o contributes
  // ≥ 3ρ_o − |x c_o| > B0 whenever |x c_o| + B0 < 3ρ_o: the minimum is
  // over o and the balls within 3ρ_o of it (the same value as over all
  // balls; all of them otherwise). The full loop made the size test
  // O(triangles × balls) per round (hinge.stl: 5% of the run).
  // The balls by centre x: ball i's close balls lie within 3ρ_i of it in x
  // (the same set as a scan of all pairs, which was O(balls²) per round:
  // 32 M distances on fandisk.off; css_at takes a min, so order is moot).
  std::vector<std::vector<uint32_t>> close(nb);
  {
    std::vector<std::pair<double, uint32_t>> by_x(nb);
    for (uint32_t j = 0; j < nb; ++j) by_x[j] = {balls[j].center.x, j};
    std::sort(by_x.begin(), by_x.end());
    for (uint32_t i = 0; i < nb; ++i) {
      const double r3 = 3 * balls[i].radius;
      // |Δx| ≤ Dist: every j with a computed Dist < 3ρ_i has its x within
      // 3ρ_i of x_i up to roundings far below the margins (relative to 3ρ_i
      // and to |x_i|).
      const double pad = r3 * (1 + 1e-9) + 1e-15 * std::fabs(balls[i].center.x);
      const double lo = balls[i].center.x - pad, hi = balls[i].center.x + pad;
      auto it = std::lower_bound(by_x.begin(), by_x.end(), std::pair<double, uint32_t>{lo, 0});
      for (; it != by_x.end() && it->first <= hi; ++it) {
        const uint32_t j = it->second;
        if (j != i && geom::Dist(balls[i].center, balls[j].center) < r3) close[i].push_back(j);
      }
    }
  }
  auto css_at = [&](const Vec3& x, uint32_t o) {
    const double b0 = CollarSizeTerm(x, balls[o]);
    if (!(geom::Dist(x, balls[o].center) + b0 < 3 * balls[o].radius * (1 - 1e-9))) return CollarSurfaceSize(x, collars);
    double best = b0;
    for (uint32_t j : close[o]) best = std::min(best, CollarSizeTerm(x, balls[j]));
    return best;
  };
  for (const RestrictedTriangle& t : tris) {
    rep.worst_angle = std::max(rep.worst_angle, t.angle);
    const double css = css_at(t.x, t.ball);
    rep.max_rep_ratio = std::max(rep.max_rep_ratio, t.rep_radius / css);
    if (t.angle > opt.sigma) {
      ++rep.bad_angles;
      if (explicit_tests) add(t.x, t.ball, CollarRepair::kNoCircle, CollarRepair::kAngle);
    }
    if (t.rep_radius > opt.eps_s * css) {
      ++rep.too_big;
      if (opt.size_criterion) add(t.x, t.ball, CollarRepair::kNoCircle, CollarRepair::kSize);
    }
  }
  for (uint32_t k = 0; k < nc; ++k) {
    for (const RestrictedEdge& e : res.circle_edges[k]) {
      rep.worst_circle_angle = std::max(rep.worst_circle_angle, e.angle);
      const double css = css_at(e.x, collars.circles[k].a);
      const double rr = geom::Dist(e.x, dt.Point(e.v[0]));
      rep.max_rep_ratio = std::max(rep.max_rep_ratio, rr / css);
      if (e.angle > opt.sigma) {
        ++rep.bad_angles;
        if (explicit_tests) add(e.x, collars.circles[k].a, k, CollarRepair::kAngle);
      }
      if (rr > opt.eps_s * css) {
        ++rep.too_big;
        if (opt.size_criterion) add(e.x, collars.circles[k].a, k, CollarRepair::kSize);
      }
    }
  }

  // Components of S (balls joined by circles on S) and their χ.
  Dsu comp(nb);
  for (uint32_t k = 0; k < nc; ++k) {
    if (res.circle_state[k] != 0) comp.Join(collars.circles[k].a, collars.circles[k].b);
  }
  std::vector<int> comp_id(nb, -1);
  for (uint32_t bi = 0; bi < nb; ++bi) {
    const uint32_t root = comp.Find(bi);
    if (comp_id[root] < 0) comp_id[root] = rep.num_components++;
    comp_id[bi] = comp_id[root];
  }
  if (opt.topology_summary) {
    std::vector<std::vector<std::array<uint32_t, 3>>> comp_tris(rep.num_components);
    for (const Unique& u : uniq) comp_tris[comp_id[tris[u.best].ball]].push_back(u.v);
    for (const auto& ct : comp_tris) rep.euler_per_component.push_back(Euler(ct));
  }
  if (opt.topology_summary) {
    std::vector<uint32_t> vs;
    for (const Unique& u : uniq) vs.insert(vs.end(), u.v.begin(), u.v.end());
    std::sort(vs.begin(), vs.end());
    vs.erase(std::unique(vs.begin(), vs.end()), vs.end());
    Dsu d(vs.size());
    auto idx = [&](uint32_t v) {
      return static_cast<uint32_t>(std::lower_bound(vs.begin(), vs.end(), v) - vs.begin());
    };
    for (const Unique& u : uniq) {
      d.Join(idx(u.v[0]), idx(u.v[1]));
      d.Join(idx(u.v[0]), idx(u.v[2]));
    }
    for (uint32_t i = 0; i < vs.size(); ++i) rep.triangulation_components += d.Find(i) == i;
  }
  rep.consistent = rep.bad_roots == 0 && rep.bad_facets == 0 && rep.bad_links == 0 && rep.bad_sphere_links == 0 &&
                   rep.empty_spheres == 0 && rep.bad_circles == 0 && rep.bad_boundaries == 0;

  // One repair per point (the first proposal, by reason order of discovery),
  // then largest radius first.
  std::stable_sort(out.begin(), out.end(), [](const CollarRepair& a, const CollarRepair& b) {
    return std::tuple(a.x.x, a.x.y, a.x.z) < std::tuple(b.x.x, b.x.y, b.x.z);
  });
  std::vector<CollarRepair> merged;
  for (const CollarRepair& r : out) {
    if (!merged.empty() && merged.back().x.x == r.x.x && merged.back().x.y == r.x.y &&
        merged.back().x.z == r.x.z) {
      ++rep.duplicates;
      continue;
    }
    merged.push_back(r);
  }
  std::sort(merged.begin(), merged.end(), [](const CollarRepair& a, const CollarRepair& b) {
    return std::tuple(-a.radius, a.reason, a.ball, a.x.x, a.x.y, a.x.z) <
           std::tuple(-b.radius, b.reason, b.ball, b.x.x, b.x.y, b.x.z);
  });
  for (const CollarRepair& r : merged) ++rep.repairs[r.reason];
  if (report != nullptr) *report = std::move(rep);
  if (triangles != nullptr) *triangles = std::move(res.triangles);
  return merged;
}

}  // namespace svrc::refine
