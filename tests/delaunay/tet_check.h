// An independent checker for a tetrahedralization given as a plain tet array
// (does not trust any adjacency of the kernel): positive orientation, every
// triangle in at most two tets with opposite orientations, a convex boundary,
// and every interior face locally Delaunay under the perturbed in-sphere test
// (global id = vertex index) — which together make it the Delaunay
// tetrahedralization of its vertices. Linear time (sort of 4T faces).
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <tuple>
#include <vector>

#include "absl/strings/str_cat.h"
#include "core/geometry/predicates.h"
#include "core/geometry/vec3.h"

namespace svrc::delaunay::testing {

// Returns "" when valid, else a description of the first problem.
inline std::string CheckDelaunayTets(const std::vector<geom::Vec3>& pts,
                                     const std::vector<std::array<uint32_t, 4>>& tets) {
  struct Face {
    std::array<uint32_t, 3> key;  // sorted vertex ids
    uint32_t tet;
    uint8_t opp;
    bool parity;  // orientation of the face relative to its sorted key
  };
  std::vector<Face> faces;
  faces.reserve(4 * tets.size());
  static constexpr int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};  // outward
  for (uint32_t t = 0; t < tets.size(); ++t) {
    const auto& v = tets[t];
    for (int i = 0; i < 4; ++i) {
      if (v[i] >= pts.size()) return absl::StrCat("tet ", t, ": id out of range");
    }
    if (geom::Orient3d(pts[v[0]], pts[v[1]], pts[v[2]], pts[v[3]]) <= 0) {
      return absl::StrCat("tet ", t, " not positively oriented");
    }
    for (int f = 0; f < 4; ++f) {
      std::array<uint32_t, 3> a = {v[kFace[f][0]], v[kFace[f][1]], v[kFace[f][2]]};
      // parity of the sorting permutation
      bool par = false;
      for (int i = 0; i < 3; ++i)
        for (int j = i + 1; j < 3; ++j) par ^= a[i] > a[j];
      std::sort(a.begin(), a.end());
      faces.push_back({a, t, static_cast<uint8_t>(f), par});
    }
  }
  std::sort(faces.begin(), faces.end(), [](const Face& x, const Face& y) {
    return std::tie(x.key, x.tet) < std::tie(y.key, y.tet);
  });
  std::vector<std::array<uint32_t, 3>> hull;  // outward-oriented boundary faces
  for (size_t i = 0; i < faces.size();) {
    size_t j = i + 1;
    while (j < faces.size() && faces[j].key == faces[i].key) ++j;
    if (j - i > 2) return absl::StrCat("face ", faces[i].key[0], ",", faces[i].key[1], ",", faces[i].key[2], " in ", j - i, " tets");
    if (j - i == 2) {
      const Face& a = faces[i];
      const Face& b = faces[i + 1];
      if (a.parity == b.parity) return absl::StrCat("tets ", a.tet, " and ", b.tet, " overlap (same face orientation)");
      const auto& ta = tets[a.tet];
      const uint32_t e = tets[b.tet][b.opp];
      if (geom::InSphereSoS(pts[ta[0]], pts[ta[1]], pts[ta[2]], pts[ta[3]], pts[e], ta[0], ta[1], ta[2],
                            ta[3], e) > 0) {
        return absl::StrCat("face of tets ", a.tet, "/", b.tet, " not locally Delaunay");
      }
    } else {
      const auto& t = tets[faces[i].tet];
      const int f = faces[i].opp;
      hull.push_back({t[kFace[f][0]], t[kFace[f][1]], t[kFace[f][2]]});
    }
    i = j;
  }
  // Convex boundary: at every boundary edge, the third vertex of the other
  // boundary face is not strictly outside this face's plane.
  struct Edge {
    uint32_t a, b, face;
  };
  std::vector<Edge> edges;
  for (uint32_t h = 0; h < hull.size(); ++h) {
    for (int k = 0; k < 3; ++k) edges.push_back({hull[h][k], hull[h][(k + 1) % 3], h});
  }
  std::sort(edges.begin(), edges.end(), [](const Edge& x, const Edge& y) {
    return std::tie(x.a, x.b) < std::tie(y.a, y.b);
  });
  for (const Edge& e : edges) {
    // The twin edge (b, a) in another boundary face.
    auto it = std::lower_bound(edges.begin(), edges.end(), Edge{e.b, e.a, 0},
                               [](const Edge& x, const Edge& y) { return std::tie(x.a, x.b) < std::tie(y.a, y.b); });
    if (it == edges.end() || it->a != e.b || it->b != e.a) return "boundary is not a closed surface";
    const auto& f = hull[e.face];
    const auto& g = hull[it->face];
    uint32_t d = g[0] + g[1] + g[2] - e.a - e.b;
    // Outward face (f0,f1,f2): inside is where Orient3d(f0,f2,f1,x) > 0.
    if (geom::Orient3d(pts[f[0]], pts[f[2]], pts[f[1]], pts[d]) < 0) {
      return absl::StrCat("boundary not convex at edge ", e.a, "-", e.b);
    }
  }
  return "";
}

}  // namespace svrc::delaunay::testing
