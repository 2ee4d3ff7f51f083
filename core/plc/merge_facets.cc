// Surface soups to PLCs: exact vertex merging (STL) and merging of exactly
// (or, within a tolerance, nearly) coplanar edge-adjacent faces with equal
// markers into polygonal facets
// (guide §5 item 7: the STL cube must become six quadrilaterals, not twelve
// triangles whose 45° corners would all be creases).
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <initializer_list>
#include <map>
#include <numeric>
#include <utility>

#include "core/plc/exact.h"
#include "core/plc/polygon2d.h"
#include "core/plc/read_internal.h"

namespace svrc::plc::internal {
namespace {

uint64_t Bits(double d) {
  if (d == 0) d = 0;  // -0.0 and 0.0 are the same point
  return std::bit_cast<uint64_t>(d);
}

struct UnionFind {
  std::vector<uint32_t> parent;
  explicit UnionFind(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  uint32_t Find(uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void Union(uint32_t a, uint32_t b) {
    a = Find(a);
    b = Find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

// Three vertices of a face spanning its plane, or false if all are collinear.
bool PlaneTriple(const std::vector<Vec3>& v, const std::vector<uint32_t>& f, std::array<uint32_t, 3>* t) {
  const uint32_t a = f[0];
  for (size_t i = 1; i < f.size(); ++i) {
    if (v[f[i]] == v[a]) continue;
    for (size_t j = i + 1; j < f.size(); ++j) {
      for (int drop = 0; drop < 3; ++drop) {
        if (Orient2dSign(v[a], v[f[i]], v[f[j]], drop) != 0) {
          *t = {a, f[i], f[j]};
          return true;
        }
      }
    }
  }
  return false;
}

bool OnPlane(const std::vector<Vec3>& v, const std::array<uint32_t, 3>& t, const std::vector<uint32_t>& f) {
  for (uint32_t x : f) {
    if (x == t[0] || x == t[1] || x == t[2]) continue;  // trivially on it
    if (Orient3dSign(v[t[0]], v[t[1]], v[t[2]], v[x]) != 0) return false;
  }
  return true;
}

// Every vertex of f within tol of the plane of triple t.
bool NearPlane(const std::vector<Vec3>& v, const std::array<uint32_t, 3>& t, const std::vector<uint32_t>& f,
               double tol) {
  const Vec3 n = geom::Cross(v[t[1]] - v[t[0]], v[t[2]] - v[t[0]]);
  const double len = geom::Norm(n);
  if (!(len > 0)) return false;
  for (uint32_t x : f) {
    if (!(std::fabs(geom::Dot(n, v[x] - v[t[0]])) <= tol * len)) return false;
  }
  return true;
}

double Diameter(const std::vector<Vec3>& v, std::initializer_list<const std::vector<uint32_t>*> faces) {
  geom::Box3 box;
  for (const std::vector<uint32_t>* f : faces) {
    for (uint32_t x : *f) box.Add(v[x]);
  }
  return geom::Norm(box.hi - box.lo);
}

// A facet merged from nearly coplanar faces is kept only if (1) every vertex of
// its faces is on its boundary loops: an interior vertex (a fan's centre) would
// be left as a point near the facet but not on it, a feature 1e-9 of the size
// away from it; and (2) it passes validation's planarity test with a factor 2
// to spare (prepare.cc: the Newell normal of its largest loop through the
// centroid of its points, every point within planarity_tolerance = 1e-8 of
// the diameter; here within `rel`).
bool NearGroupFacetOk(const std::vector<Vec3>& v, const std::vector<uint32_t>& group,
                      const std::vector<std::vector<uint32_t>>& faces, const Facet& facet, double rel) {
  std::vector<uint32_t> on_loops, in_faces;
  for (const Polygon& poly : facet.polygons) on_loops.insert(on_loops.end(), poly.vertices.begin(), poly.vertices.end());
  for (uint32_t f : group) in_faces.insert(in_faces.end(), faces[f].begin(), faces[f].end());
  std::sort(on_loops.begin(), on_loops.end());
  on_loops.erase(std::unique(on_loops.begin(), on_loops.end()), on_loops.end());
  std::sort(in_faces.begin(), in_faces.end());
  in_faces.erase(std::unique(in_faces.begin(), in_faces.end()), in_faces.end());
  if (in_faces != on_loops) return false;
  Vec3 normal(0, 0, 0);
  double best = -1;
  for (const Polygon& poly : facet.polygons) {
    const Vec3 n = NewellNormal(v, poly.vertices);
    if (geom::Norm(n) > best) best = geom::Norm(n), normal = n;
  }
  if (!(best > 0)) return false;
  normal = normal / best;
  const Vec3& o = v[on_loops[0]];
  Vec3 centroid(0, 0, 0);
  geom::Box3 box;
  for (uint32_t x : on_loops) {
    centroid = centroid + (v[x] - o);
    box.Add(v[x]);
  }
  centroid = o + centroid / static_cast<double>(on_loops.size());
  const double tol = rel * geom::Norm(box.hi - box.lo);
  for (uint32_t x : on_loops) {
    if (!(std::fabs(geom::Dot(v[x] - centroid, normal)) <= tol)) return false;
  }
  return true;
}

}  // namespace

Plc BuildSurfacePlc(SurfaceSoup soup, bool merge_vertices, bool merge_coplanar, double coplanar_tolerance) {
  Plc plc;
  plc.is_surface = true;
  plc.index_base = soup.index_base;
  plc.input_face_count = static_cast<uint32_t>(soup.faces.size());
  plc.marker_names = std::move(soup.marker_names);
  if (merge_vertices) {
    // Exactly equal coordinates -> one vertex; first occurrence order kept.
    std::vector<uint32_t> order(soup.vertices.size());
    std::iota(order.begin(), order.end(), 0u);
    auto key = [&](uint32_t i) {
      const Vec3& p = soup.vertices[i];
      return std::array<uint64_t, 3>{Bits(p.x), Bits(p.y), Bits(p.z)};
    };
    std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return key(a) < key(b); });
    std::vector<uint32_t> rep(soup.vertices.size());
    for (size_t k = 0; k < order.size();) {
      size_t e = k;
      while (e < order.size() && key(order[e]) == key(order[k])) ++e;
      for (size_t q = k; q < e; ++q) rep[order[q]] = order[k];  // smallest index (stable)
      k = e;
    }
    std::vector<uint32_t> new_id(soup.vertices.size(), UINT32_MAX);
    for (uint32_t i = 0; i < soup.vertices.size(); ++i) {
      if (rep[i] == i) {
        new_id[i] = static_cast<uint32_t>(plc.vertices.size());
        plc.vertices.push_back(soup.vertices[i]);
        plc.vertex_lines.push_back(soup.vertex_lines[i]);
        if (!soup.vertex_markers.empty()) plc.vertex_markers.push_back(soup.vertex_markers[i]);
      }
    }
    for (auto& f : soup.faces) {
      for (uint32_t& x : f) x = new_id[rep[x]];
    }
    for (Segment& s : soup.segments) {
      s.a = new_id[rep[s.a]];
      s.b = new_id[rep[s.b]];
    }
  } else {
    plc.vertices = std::move(soup.vertices);
    plc.vertex_lines = std::move(soup.vertex_lines);
    plc.vertex_markers = std::move(soup.vertex_markers);
  }
  plc.segments = std::move(soup.segments);
  const auto& V = plc.vertices;
  const size_t nf = soup.faces.size();

  auto emit_face = [&](uint32_t f) {
    Facet facet;
    facet.polygons.push_back({soup.faces[f]});
    facet.marker = soup.face_markers[f];
    facet.input_faces = {f};
    plc.facets.push_back(std::move(facet));
    plc.facet_lines.push_back(soup.face_lines[f]);
  };
  if (!merge_coplanar) {
    for (uint32_t f = 0; f < nf; ++f) emit_face(f);
    return plc;
  }

  // Planes of faces that are exactly planar and non-degenerate.
  std::vector<std::array<uint32_t, 3>> plane(nf);
  std::vector<bool> mergeable(nf, false);
  for (uint32_t f = 0; f < nf; ++f) {
    const auto& face = soup.faces[f];
    bool distinct = true;  // no repeated vertex in the face
    std::vector<uint32_t> s = face;
    std::sort(s.begin(), s.end());
    distinct = std::adjacent_find(s.begin(), s.end()) == s.end();
    mergeable[f] = distinct && PlaneTriple(V, face, &plane[f]) && OnPlane(V, plane[f], face);
  }
  // Directed edges -> faces. An undirected edge used by exactly two faces, in
  // opposite directions (consistent orientation), joins them if coplanar with
  // equal markers.
  struct E {
    uint32_t lo, hi, face;
    bool forward;
  };
  std::vector<E> edges;
  for (uint32_t f = 0; f < nf; ++f) {
    const auto& face = soup.faces[f];
    for (size_t i = 0; i < face.size(); ++i) {
      const uint32_t a = face[i], b = face[(i + 1) % face.size()];
      if (a == b) continue;
      edges.push_back({std::min(a, b), std::max(a, b), f, a < b});
    }
  }
  std::sort(edges.begin(), edges.end(), [](const E& x, const E& y) {
    return std::tie(x.lo, x.hi, x.face) < std::tie(y.lo, y.hi, y.face);
  });
  // uf: exactly coplanar pairs; near: those and the nearly coplanar ones.
  UnionFind uf(nf), near(nf);
  bool any_near = false;
  for (size_t k = 0; k < edges.size();) {
    size_t e = k;
    while (e < edges.size() && edges[e].lo == edges[k].lo && edges[e].hi == edges[k].hi) ++e;
    if (e - k == 2) {
      const E& x = edges[k];
      const E& y = edges[k + 1];
      if (x.face != y.face && x.forward != y.forward && mergeable[x.face] && mergeable[y.face] &&
          soup.face_markers[x.face] == soup.face_markers[y.face]) {
        const std::vector<uint32_t>& fx = soup.faces[x.face];
        const std::vector<uint32_t>& fy = soup.faces[y.face];
        if (OnPlane(V, plane[x.face], fy)) {
          uf.Union(x.face, y.face);
          near.Union(x.face, y.face);
        } else if (coplanar_tolerance > 0) {
          const double tol = coplanar_tolerance * Diameter(V, {&fx, &fy});
          if (NearPlane(V, plane[x.face], fy, tol) && NearPlane(V, plane[y.face], fx, tol)) {
            near.Union(x.face, y.face);
            any_near = true;
          }
        }
      }
    }
    k = e;
  }
  // Groups in order of their first face (emit_group falls back from a
  // nearly coplanar group to its exactly coplanar subgroups).
  std::map<uint32_t, std::vector<uint32_t>> groups;
  UnionFind& joined = any_near ? near : uf;
  for (uint32_t f = 0; f < nf; ++f) groups[joined.Find(f)].push_back(f);
  std::vector<std::vector<uint32_t>> ordered;
  for (auto& [root, faces] : groups) ordered.push_back(std::move(faces));
  std::sort(ordered.begin(), ordered.end(), [](const auto& a, const auto& b) { return a[0] < b[0]; });

  // Emits the group as one facet if its boundary is a simple polygon with
  // holes; false (nothing emitted) otherwise.
  auto emit_group = [&](const std::vector<uint32_t>& group) -> bool {
    // A group joined by nearly coplanar pairs (not all one exact group).
    bool near_group = false;
    for (uint32_t f : group) near_group = near_group || uf.Find(f) != uf.Find(group[0]);
    // Boundary = directed edges whose reverse is not in the group.
    std::map<std::pair<uint32_t, uint32_t>, int> count;
    for (uint32_t f : group) {
      const auto& face = soup.faces[f];
      for (size_t i = 0; i < face.size(); ++i) {
        const uint32_t a = face[i], b = face[(i + 1) % face.size()];
        ++count[{a, b}];
      }
    }
    std::map<uint32_t, std::vector<uint32_t>> out;  // boundary successor(s)
    bool ok = true;
    size_t nboundary = 0;
    for (const auto& [ab, c] : count) {
      auto rev = count.find({ab.second, ab.first});
      const int r = rev == count.end() ? 0 : rev->second;
      if (c > 1 || r > 1) ok = false;
      if (r == 0) {
        out[ab.first].push_back(ab.second);
        ++nboundary;
      }
    }
    for (const auto& [v, succ] : out) ok = ok && succ.size() == 1;  // no pinch vertices
    std::vector<std::vector<uint32_t>> loops;
    if (ok) {
      std::map<uint32_t, bool> used;
      for (const auto& [start, succ] : out) {
        if (used[start]) continue;
        std::vector<uint32_t> loop;
        uint32_t v = start;
        while (!used[v]) {
          used[v] = true;
          loop.push_back(v);
          auto it = out.find(v);
          if (it == out.end()) {
            ok = false;
            break;
          }
          v = it->second[0];
        }
        if (!ok || v != start || loop.size() < 3) {
          ok = false;
          break;
        }
        loops.push_back(std::move(loop));
      }
    }
    Facet facet;
    int drop = 2;
    if (ok) {
      const auto& t = plane[group[0]];
      const Vec3 n = geom::Cross(V[t[1]] - V[t[0]], V[t[2]] - V[t[0]]);
      drop = DropAxis(n);
      // The group's orientation in the projection: the outer loop turns the
      // same way as its faces, hole loops the other way.
      const int face_orient = LoopOrientation(V, soup.faces[group[0]], drop);
      size_t outer_count = 0;
      for (auto& loop : loops) {
        const int o = LoopOrientation(V, loop, drop);
        if (o == 0) {
          ok = false;
          break;
        }
        if (o == face_orient) {
          ++outer_count;
          facet.polygons.insert(facet.polygons.begin(), Polygon{loop});
        } else {
          Vec3 seed;
          if (!PointInsideLoop(V, loop, drop, &seed)) {
            ok = false;
            break;
          }
          facet.polygons.push_back(Polygon{loop});
          facet.holes.push_back(seed);
        }
      }
      ok = ok && outer_count == 1;
    }
    if (ok && near_group) ok = NearGroupFacetOk(V, group, soup.faces, facet, coplanar_tolerance);
    if (!ok) return false;
    facet.marker = soup.face_markers[group[0]];
    facet.input_faces = group;
    plc.facets.push_back(std::move(facet));
    plc.facet_lines.push_back(soup.face_lines[group[0]]);
    (void)nboundary;
    return true;
  };
  for (const auto& group : ordered) {
    if (group.size() == 1) {
      emit_face(group[0]);
      continue;
    }
    if (emit_group(group)) continue;
    // Not a simple polygon with holes (pinch vertex, inconsistent
    // orientation). A group joined by nearly coplanar pairs falls back to its
    // exactly coplanar subgroups; the faces of any other stay as they are.
    std::map<uint32_t, std::vector<uint32_t>> exact;
    for (uint32_t f : group) exact[uf.Find(f)].push_back(f);
    if (exact.size() == 1) {
      for (uint32_t f : group) emit_face(f);
      continue;
    }
    std::vector<std::vector<uint32_t>> subgroups;
    for (auto& [root, faces] : exact) subgroups.push_back(std::move(faces));
    std::sort(subgroups.begin(), subgroups.end(), [](const auto& a, const auto& b) { return a[0] < b[0]; });
    for (const auto& sub : subgroups) {
      if (sub.size() > 1 && emit_group(sub)) continue;
      for (uint32_t f : sub) emit_face(f);
    }
  }
  return plc;
}

}  // namespace svrc::plc::internal
