#include "tests/mesh/mesh_test_util.h"

#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <map>

#include "absl/strings/str_cat.h"

namespace svrc::mesh::testing {

plc::Plc BoxPlc(Vec3 lo, Vec3 hi, bool split) {
  plc::Plc p;
  p.source_name = "<box>";
  for (int k = 0; k < 2; ++k) {
    for (int j = 0; j < 2; ++j) {
      for (int i = 0; i < 2; ++i) {
        p.vertices.push_back(Vec3(i ? hi.x : lo.x, j ? hi.y : lo.y, k ? hi.z : lo.z));
      }
    }
  }
  auto quad = [&](std::vector<uint32_t> v, int32_t marker) {
    plc::Facet f;
    f.polygons.push_back({std::move(v)});
    f.marker = marker;
    p.facets.push_back(std::move(f));
  };
  quad({0, 2, 6, 4}, 1);  // x = lo
  quad({1, 3, 7, 5}, 2);  // x = hi
  quad({0, 1, 5, 4}, 3);  // y = lo
  quad({2, 3, 7, 6}, 4);  // y = hi
  quad({0, 1, 3, 2}, 5);  // z = lo
  quad({4, 5, 7, 6}, 6);  // z = hi
  if (split) {
    const double mx = 0.5 * (lo.x + hi.x);
    p.vertices.push_back(Vec3(mx, lo.y, lo.z));
    p.vertices.push_back(Vec3(mx, hi.y, lo.z));
    p.vertices.push_back(Vec3(mx, hi.y, hi.z));
    p.vertices.push_back(Vec3(mx, lo.y, hi.z));
    quad({8, 9, 10, 11}, 7);
  }
  return p;
}

TetMesh KuhnBoxMesh(const plc::Plc& box_plc, int n) {
  const Vec3 lo = box_plc.vertices[0], hi = box_plc.vertices[7];
  TetMesh m;
  m.positions = box_plc.vertices;
  m.num_input_vertices = static_cast<uint32_t>(box_plc.vertices.size());
  auto coord = [&](int i, int j, int k) {
    return Vec3(lo.x + (hi.x - lo.x) * i / n, lo.y + (hi.y - lo.y) * j / n,
                lo.z + (hi.z - lo.z) * k / n);
  };
  std::map<std::array<int, 3>, uint32_t> id;
  for (int k = 0; k <= n; ++k) {
    for (int j = 0; j <= n; ++j) {
      for (int i = 0; i <= n; ++i) {
        const Vec3 p = coord(i, j, k);
        auto it = std::find(box_plc.vertices.begin(), box_plc.vertices.end(), p);
        if (it != box_plc.vertices.end()) {
          id[{i, j, k}] = static_cast<uint32_t>(it - box_plc.vertices.begin());
        } else {
          id[{i, j, k}] = static_cast<uint32_t>(m.positions.size());
          m.positions.push_back(p);
        }
      }
    }
  }
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = 0; k < n; ++k) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        for (const auto& perm : perms) {
          std::array<int, 3> c = {i, j, k};
          std::array<uint32_t, 4> t;
          t[0] = id[c];
          for (int s = 0; s < 3; ++s) {
            ++c[perm[s]];
            t[s + 1] = id[c];
          }
          const Vec3 a = m.positions[t[0]];
          const double det = geom::Dot(m.positions[t[1]] - a,
                                       geom::Cross(m.positions[t[2]] - a, m.positions[t[3]] - a));
          if (det < 0) std::swap(t[2], t[3]);
          m.tets.push_back(t);
          m.tet_region.push_back(0);
        }
      }
    }
  }
  m.regions.resize(1);
  AssignBoxTriangles(box_plc, &m);
  return m;
}

void AssignBoxTriangles(const plc::Plc& box_plc, TetMesh* mesh) {
  TetMesh& m = *mesh;
  const Vec3 lo = box_plc.vertices[0], hi = box_plc.vertices[7];
  m.triangles.clear();
  m.triangle_marker.clear();
  const bool split = box_plc.facets.size() > 6;
  const double mx = 0.5 * (lo.x + hi.x);
  std::map<std::array<uint32_t, 3>, int32_t> tris;
  for (const auto& t : m.tets) {
    for (int skip = 0; skip < 4; ++skip) {
      std::array<uint32_t, 3> f;
      int w = 0;
      for (int v = 0; v < 4; ++v) {
        if (v != skip) f[w++] = t[v];
      }
      auto all = [&](int axis, double value) {
        return m.positions[f[0]][axis] == value && m.positions[f[1]][axis] == value &&
               m.positions[f[2]][axis] == value;
      };
      int32_t marker = 0;
      if (all(0, lo.x)) marker = 1;
      if (all(0, hi.x)) marker = 2;
      if (all(1, lo.y)) marker = 3;
      if (all(1, hi.y)) marker = 4;
      if (all(2, lo.z)) marker = 5;
      if (all(2, hi.z)) marker = 6;
      if (split && all(0, mx)) marker = 7;
      if (marker == 0) continue;
      std::array<uint32_t, 3> key = f;
      std::sort(key.begin(), key.end());
      tris.emplace(key, marker);
    }
  }
  for (const auto& [key, marker] : tris) {
    m.triangles.push_back(key);
    m.triangle_marker.push_back(marker);
  }
}

void AssignAxisAlignedTriangles(const plc::Plc& plc, TetMesh* mesh) {
  TetMesh& m = *mesh;
  std::map<std::array<uint32_t, 3>, int32_t> tris;
  for (const auto& t : m.tets) {
    for (int skip = 0; skip < 4; ++skip) {
      std::array<uint32_t, 3> f;
      int w = 0;
      for (int v = 0; v < 4; ++v) {
        if (v != skip) f[w++] = t[v];
      }
      std::sort(f.begin(), f.end());
      if (tris.count(f)) continue;
      const Vec3 c = (m.positions[f[0]] + m.positions[f[1]] + m.positions[f[2]]) / 3.0;
      for (const auto& facet : plc.facets) {
        geom::Box3 box;
        for (const auto& poly : facet.polygons) {
          for (uint32_t v : poly.vertices) box.Add(plc.vertices[v]);
        }
        int axis = -1;
        for (int a = 0; a < 3; ++a) {
          if (box.lo[a] == box.hi[a]) axis = a;
        }
        if (axis < 0) continue;
        bool on = true;
        for (uint32_t v : f) on = on && m.positions[v][axis] == box.lo[axis];
        for (int a = 0; a < 3; ++a) {
          if (a != axis) on = on && c[a] >= box.lo[a] && c[a] <= box.hi[a];
        }
        if (on) {
          tris.emplace(f, facet.marker);
          break;
        }
      }
    }
  }
  m.triangles.clear();
  m.triangle_marker.clear();
  for (const auto& [key, marker] : tris) {
    m.triangles.push_back(key);
    m.triangle_marker.push_back(marker);
  }
}

bool HaveTool(const std::string& tool) {
  return std::system(absl::StrCat("command -v ", tool, " >/dev/null 2>&1").c_str()) == 0;
}

int RunIn(const std::string& dir, const std::string& cmd, const std::string& log) {
  const std::string full = absl::StrCat("cd '", dir, "' && ", cmd, " > '", log, "' 2>&1");
  const int rc = std::system(full.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : 128 + WTERMSIG(rc);
}

double TotalVolume(const TetMesh& mesh) {
  double v = 0;
  for (const auto& t : mesh.tets) {
    const Vec3 a = mesh.positions[t[0]];
    v += geom::Dot(mesh.positions[t[1]] - a,
                   geom::Cross(mesh.positions[t[2]] - a, mesh.positions[t[3]] - a)) / 6;
  }
  return v;
}

}  // namespace svrc::mesh::testing
