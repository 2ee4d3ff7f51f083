#include "tests/svrc/output_test_util.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>

#include "core/geometry/predicates.h"
#include "gtest/gtest.h"

namespace svrc::refine::testing {

Grid ApexFan(int n, std::vector<std::array<uint32_t, 3>>* cone_faces) {
  Grid g;
  g.positions = {{0, 0, 1}};
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    g.positions.push_back({std::cos(a), std::sin(a), 0});
  }
  for (int i = 0; i < n; ++i) {
    const Vec3 p = g.positions[1 + i], q = g.positions[1 + (i + 1) % n];
    g.positions.push_back({0.45 * (p.x + q.x), 0.45 * (p.y + q.y), 0});
  }
  cone_faces->clear();
  for (int i = 0; i < n; ++i) {
    std::array<uint32_t, 4> t = {0, static_cast<uint32_t>(1 + i), static_cast<uint32_t>(1 + (i + 1) % n),
                                 static_cast<uint32_t>(1 + n + i)};
    if (geom::Orient3d(g.positions[t[0]], g.positions[t[1]], g.positions[t[2]], g.positions[t[3]]) < 0) {
      std::swap(t[1], t[2]);
    }
    g.tets.push_back(t);
    cone_faces->push_back({0, t[1], t[2]});
  }
  return g;
}

Grid KuhnGrid(int n) {
  Grid g;
  g.n = n;
  for (int k = 0; k <= n; ++k) {
    for (int j = 0; j <= n; ++j) {
      for (int i = 0; i <= n; ++i) g.positions.push_back({double(i), double(j), double(k)});
    }
  }
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = 0; k < n; ++k) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        for (const auto& p : perms) {
          int c[3] = {i, j, k};
          std::array<uint32_t, 4> t{};
          t[0] = g.Id(c[0], c[1], c[2]);
          for (int s = 0; s < 3; ++s) {
            ++c[p[s]];
            t[s + 1] = g.Id(c[0], c[1], c[2]);
          }
          if (geom::Orient3d(g.positions[t[0]], g.positions[t[1]], g.positions[t[2]],
                             g.positions[t[3]]) < 0) {
            std::swap(t[2], t[3]);
          }
          g.tets.push_back(t);
        }
      }
    }
  }
  return g;
}

namespace {

// Inside or on a convex polygon, for a point coplanar with it.
bool InConvex(const ConvexFacet& f, const Vec3& q, int axis, int orient) {
  const size_t m = f.pts.size();
  for (size_t i = 0; i < m; ++i) {
    const int s = geom::Orient2dProjected(f.pts[i], f.pts[(i + 1) % m], q, axis);
    if (s != 0 && s != orient) return false;
  }
  return true;
}

}  // namespace

std::vector<ConstrainedFace> FacesOnConvexFacets(std::span<const Vec3> pos,
                                                 std::span<const std::array<uint32_t, 4>> tets,
                                                 const std::vector<ConvexFacet>& facets) {
  std::map<std::array<uint32_t, 3>, bool> seen;
  std::vector<ConstrainedFace> out;
  for (const auto& t : tets) {
    for (int f = 0; f < 4; ++f) {
      std::array<uint32_t, 3> k{};
      for (int i = 0, j = 0; i < 4; ++i) {
        if (i != f) k[j++] = t[i];
      }
      std::sort(k.begin(), k.end());
      if (!seen.emplace(k, true).second) continue;
      for (size_t fi = 0; fi < facets.size(); ++fi) {
        const ConvexFacet& F = facets[fi];
        // Three non-collinear polygon points span the plane.
        const Vec3 n = geom::Cross(F.pts[1] - F.pts[0], F.pts[2] - F.pts[0]);
        const int axis = geom::DominantAxis(n);
        const int orient = geom::Orient2dProjected(F.pts[0], F.pts[1], F.pts[2], axis);
        bool on = orient != 0;
        for (int i = 0; on && i < 3; ++i) {
          const Vec3& q = pos[k[i]];
          on = geom::Orient3d(F.pts[0], F.pts[1], F.pts[2], q) == 0 && InConvex(F, q, axis, orient);
        }
        if (on) {
          out.push_back({k, F.marker, F.facet});
          break;
        }
      }
    }
  }
  return out;
}

std::vector<ConvexFacet> ConvexFacetsOf(const plc::Plc& plc, const CoordinateMap& map) {
  std::vector<ConvexFacet> out;
  for (size_t f = 0; f < plc.facets.size(); ++f) {
    ConvexFacet cf;
    for (uint32_t v : plc.facets[f].polygons[0].vertices) cf.pts.push_back(map.ToMesher(plc.vertices[v]));
    cf.marker = plc.facets[f].marker;
    cf.facet = static_cast<uint32_t>(f);
    out.push_back(cf);
  }
  return out;
}

void AddBox(plc::Plc* plc, Vec3 lo, Vec3 hi, int32_t marker) {
  const uint32_t b = static_cast<uint32_t>(plc->vertices.size());
  for (int c = 0; c < 8; ++c) {
    plc->vertices.push_back({(c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z});
  }
  const uint32_t quads[6][4] = {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}};
  for (const auto& q : quads) {
    plc::Facet f;
    f.polygons.push_back({{b + q[0], b + q[1], b + q[2], b + q[3]}});
    f.marker = marker;
    plc->facets.push_back(f);
  }
}

std::vector<uint32_t> GridVertexOf(const plc::Plc& plc, const Grid& grid, const CoordinateMap& map) {
  std::vector<uint32_t> out;
  for (size_t i = 0; i < plc.vertices.size(); ++i) {
    const Vec3 y = map.ToMesher(plc.vertices[i]);
    const int a = static_cast<int>(y.x), b = static_cast<int>(y.y), c = static_cast<int>(y.z);
    const bool ok = a >= 0 && b >= 0 && c >= 0 && a <= grid.n && b <= grid.n && c <= grid.n &&
                    grid.positions[grid.Id(a, b, c)] == y;
    EXPECT_TRUE(ok) << "PLC vertex " << i << " is not a grid vertex";
    out.push_back(ok ? grid.Id(a, b, c) : 0);
  }
  return out;
}

double TetVolume(const mesh::TetMesh& m, size_t t) {
  const auto& v = m.tets[t];
  const Vec3 a = m.positions[v[0]];
  return geom::Dot(geom::Cross(m.positions[v[1]] - a, m.positions[v[2]] - a), m.positions[v[3]] - a) / 6;
}

Vec3 TetCentroid(const mesh::TetMesh& m, size_t t) {
  const auto& v = m.tets[t];
  return (m.positions[v[0]] + m.positions[v[1]] + m.positions[v[2]] + m.positions[v[3]]) / 4.0;
}

bool SameMesh(const mesh::TetMesh& a, const mesh::TetMesh& b) {
  if (a.positions.size() != b.positions.size()) return false;
  if (a.positions.size() != 0 &&
      std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(Vec3)) != 0) {
    return false;
  }
  if (a.regions.size() != b.regions.size()) return false;
  for (size_t i = 0; i < a.regions.size(); ++i) {
    if (std::memcmp(&a.regions[i], &b.regions[i], sizeof(mesh::Region)) != 0) return false;
  }
  return a.num_input_vertices == b.num_input_vertices && a.tets == b.tets &&
         a.tet_region == b.tet_region && a.triangles == b.triangles &&
         a.triangle_marker == b.triangle_marker;
}

}  // namespace svrc::refine::testing
