#include "core/svrc/restricted_delaunay.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/geometry/predicates.h"

namespace svrc::refine {

using delaunay::Delaunay3;
using delaunay::TetId;
using delaunay::VertexId;

namespace {

Vec3 Unit(const Vec3& v) {
  const double n = geom::Norm(v);
  return n > 0 ? v / n : v;
}

void SortIds(VertexId* v, int n) {
  std::sort(v, v + n, [](VertexId a, VertexId b) { return a.value() < b.value(); });
}

}  // namespace

Vec3 SnapToSphere(const Vec3& p, const CollarBall& ball, double delta) {
  const Vec3 d = p - ball.center;
  const double n = geom::Norm(d);
  if (n == 0 || std::fabs(n - ball.radius) > delta * ball.radius) return p;
  return ball.center + (ball.radius / n) * d;
}

std::vector<RestrictedTriangle> RestrictedSphereTriangles(const Delaunay3& dt,
                                                          std::span<const CollarBall> balls,
                                                          uint32_t ball,
                                                          std::span<const Vec3> snapped,
                                                          RestrictedOptions opt) {
  std::vector<RestrictedTriangle> out;
  if (!dt.Is3d() || ball >= balls.size()) return out;
  const CollarBall& b = balls[ball];
  const auto pos = [&](VertexId v) -> const Vec3& {
    return snapped.empty() ? dt.Point(v) : snapped[v.value()];
  };
  for (uint32_t ti = 0; ti < dt.TetCapacity(); ++ti) {
    const TetId t(ti);
    if (!dt.IsAlive(t) || dt.IsGhost(t)) continue;
    const Vec3 ct = dt.Circumcenter(t);
    for (int f = 0; f < 4; ++f) {
      const TetId u = dt.Neighbor(t, f);
      const bool hull = dt.IsGhost(u);
      if (!hull && u.value() < ti) continue;  // each interior triangle once
      VertexId tri[3];
      for (int k = 0, m = 0; k < 4; ++k) {
        if (k != f) tri[m++] = dt.TetVertex(t, k);
      }
      const Vec3& p0 = dt.Point(tri[0]);
      Vec3 end;
      if (hull) {
        // Voronoi ray: from ct away from the tet's fourth vertex, cut long
        // enough to leave every ball.
        Vec3 n = geom::Cross(dt.Point(tri[1]) - p0, dt.Point(tri[2]) - p0);
        if (geom::Dot(n, dt.Point(dt.TetVertex(t, f)) - p0) > 0) n = -1.0 * n;
        double len = opt.ray_length;
        if (len <= 0) len = 2 * (geom::Dist(ct, b.center) + b.radius) + 1;
        end = ct + len * Unit(n);
      } else {
        end = dt.Circumcenter(u);
      }
      double s[2];
      const int nr = SegmentSphere(ct, end, b, s);
      if (nr == 0) continue;
      RestrictedTriangle rt;
      int kept = 0;
      const Vec3 nrm =
          geom::Cross(pos(tri[1]) - pos(tri[0]), pos(tri[2]) - pos(tri[0]));  // ∝ edge direction
      for (int k = 0; k < nr; ++k) {
        const Vec3 x = ct + s[k] * (end - ct);
        if (!OnCollarSurface(x, ball, balls)) continue;
        const double ang = RepresentationAngle(nrm, x, b.center);
        if (kept == 0 || ang > rt.angle) {
          rt.x = x;
          rt.angle = ang;
        }
        ++kept;
      }
      if (kept == 0) continue;
      SortIds(tri, 3);
      for (int k = 0; k < 3; ++k) rt.v[k] = tri[k];
      rt.ball = ball;
      rt.num_roots = kept;
      rt.rep_radius = geom::Dist(rt.x, dt.Point(tri[0]));
      out.push_back(rt);
    }
  }
  return out;
}

std::vector<RestrictedEdge> RestrictedCircleEdges(const Delaunay3& dt, const Circle3& circle,
                                                  std::span<const CollarBall> others) {
  std::vector<RestrictedEdge> out;
  if (!dt.Is3d()) return out;
  // Every finite Delaunay edge once, from the finite tets.
  std::vector<std::pair<uint32_t, uint32_t>> edges;
  for (uint32_t ti = 0; ti < dt.TetCapacity(); ++ti) {
    const TetId t(ti);
    if (!dt.IsAlive(t) || dt.IsGhost(t)) continue;
    for (int i = 0; i < 4; ++i) {
      for (int j = i + 1; j < 4; ++j) {
        uint32_t a = dt.TetVertex(t, i).value(), c = dt.TetVertex(t, j).value();
        if (a > c) std::swap(a, c);
        edges.push_back({a, c});
      }
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  Vec3 u, w;
  CircleFrame(circle, &u, &w);
  for (auto [ia, ib] : edges) {
    const VertexId va(ia), vb(ib);
    const Vec3& a = dt.Point(va);
    const Vec3& b = dt.Point(vb);
    // Bisector plane n·p = e with n = b − a, e = (|b|² − |a|²)/2, on the
    // circle p(t) = k + r(cos t u + sin t w):  r(n·u) cos t + r(n·w) sin t = e − n·k.
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
      if (InsideAnyBall(x, others)) continue;
      const VertexId nv = dt.NearestVertex(x, dt.VertexTet(va));
      if (nv != va && nv != vb) {
        // x is on the bisector (rounded): accept a tie with the nearest vertex.
        const double dn = geom::Dist(x, dt.Point(nv)), da = geom::Dist(x, a);
        if (dn < da * (1 - 1e-12)) continue;
      }
      RestrictedEdge e;
      e.v[0] = va;
      e.v[1] = vb;
      e.x = x;
      e.angle = CircleRepresentationAngle(a, b, circle, x);
      out.push_back(e);
    }
  }
  return out;
}

absl::Status ValidateRestrictedTopology(std::span<const RestrictedTriangle> tris,
                                        std::span<const std::vector<RestrictedEdge>> circle_edges,
                                        TopologyReport* report) {
  TopologyReport r;
  std::string first;
  auto note = [&first](std::string s) {
    if (first.empty()) first = std::move(s);
  };
  // (a)
  for (const RestrictedTriangle& t : tris) {
    if (t.num_roots != 1) {
      ++r.bad_roots;
      note(absl::StrCat("(a) Voronoi edge of triangle ", t.v[0].value(), ",", t.v[1].value(),
                        ",", t.v[2].value(), " meets S ", t.num_roots, " times"));
    }
  }
  // (b) edges → triangle counts; (c) vertex → link edges.
  std::map<std::pair<uint32_t, uint32_t>, int> edge_count;
  std::map<uint32_t, std::vector<std::pair<uint32_t, uint32_t>>> link;
  std::map<uint32_t, int> vertex_seen;
  for (const RestrictedTriangle& t : tris) {
    const uint32_t a = t.v[0].value(), b = t.v[1].value(), c = t.v[2].value();
    ++edge_count[{a, b}];
    ++edge_count[{a, c}];
    ++edge_count[{b, c}];
    link[a].push_back({b, c});
    link[b].push_back({a, c});
    link[c].push_back({a, b});
  }
  for (const auto& [e, n] : edge_count) {
    // A restricted triangle with its Voronoi edge crossing S is one crossing
    // on the boundary of the Voronoi facet of each of its edges.
    // On a partial sphere bounded by circles an edge crossing a circle has one.
    if (n != 2 && !(n == 1 && !circle_edges.empty())) {
      ++r.bad_facets;
      note(absl::StrCat("(b) Voronoi facet of edge ", e.first, ",", e.second, " crossed ", n,
                        " times"));
    }
  }
  for (const auto& [v, edges] : link) {
    // One cycle: every link vertex has degree 2 and the edges are connected.
    std::map<uint32_t, std::vector<uint32_t>> adj;
    for (auto [p, q] : edges) {
      adj[p].push_back(q);
      adj[q].push_back(p);
    }
    // A vertex next to a circle (partial sphere) has a path: two ends.
    bool ok = true;
    int ends = 0;
    uint32_t start = adj.begin()->first;
    for (const auto& [p, nb] : adj) {
      if (nb.size() == 1) {
        if (ends++ == 0) start = p;
      } else if (nb.size() != 2) {
        ok = false;
      }
    }
    if (ends != 0 && (ends != 2 || circle_edges.empty())) ok = false;
    if (ok) {
      // Walk from `start`; one component iff the walk visits every vertex.
      uint32_t prev = start, cur = adj[start][0];
      size_t steps = 1;
      while (cur != start && steps <= adj.size()) {
        const auto& nb = adj[cur];
        if (nb.size() == 1) {
          ++steps;
          break;
        }
        const uint32_t next = nb[0] == prev ? nb[1] : nb[0];
        prev = cur;
        cur = next;
        ++steps;
      }
      ok = steps == adj.size();
    }
    if (!ok) {
      ++r.bad_links;
      note(absl::StrCat("(c) restricted link of vertex ", v, " is not one cycle"));
    }
  }
  // (d)
  if (tris.empty()) {
    r.empty_sphere = true;
    note("(d) no restricted triangle: the partial sphere lies inside one cell");
  }
  // (e)
  for (size_t ci = 0; ci < circle_edges.size(); ++ci) {
    std::map<uint32_t, std::vector<uint32_t>> adj;
    for (const RestrictedEdge& e : circle_edges[ci]) {
      adj[e.v[0].value()].push_back(e.v[1].value());
      adj[e.v[1].value()].push_back(e.v[0].value());
    }
    bool ok = adj.size() >= 3;
    for (const auto& [p, nb] : adj) ok = ok && nb.size() == 2;
    if (ok) {
      uint32_t prev = adj.begin()->first, cur = adj.begin()->second[0];
      size_t steps = 1;
      while (cur != adj.begin()->first && steps <= adj.size()) {
        const auto& nb = adj[cur];
        const uint32_t next = nb[0] == prev ? nb[1] : nb[0];
        prev = cur;
        cur = next;
        ++steps;
      }
      ok = steps == adj.size();
    }
    if (!ok) {
      ++r.bad_circles;
      note(absl::StrCat("(e) restricted edges of circle ", ci, " are not one cycle of >= 3"));
    }
  }
  std::map<uint32_t, int> verts;
  for (const auto& [v, e] : link) verts[v] = 1;
  r.euler = static_cast<int>(verts.size()) - static_cast<int>(edge_count.size()) +
            static_cast<int>(tris.size());
  if (report != nullptr) *report = r;
  if (!first.empty()) return absl::FailedPreconditionError(first);
  return absl::OkStatus();
}

}  // namespace svrc::refine
