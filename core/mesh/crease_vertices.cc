#include "core/mesh/crease_vertices.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include "absl/status/statusor.h"
#include "core/mesh/conformity.h"
#include "core/plc/validate.h"

namespace svrc::mesh {

std::vector<uint8_t> CreaseVertexFlags(const plc::Plc& plc, const TetMesh& mesh) {
  std::vector<uint8_t> flag(mesh.positions.size(), 0);
  absl::StatusOr<plc::FeatureComplex> c = plc::PreparePlc(plc, {}, {}, nullptr);
  if (!c.ok()) return flag;
  using Key = std::tuple<double, double, double>;
  std::map<Key, uint32_t> crease_point;  // position -> mesh vertex (kNone until found)
  constexpr uint32_t kNone = ~uint32_t{0};
  for (const plc::FeaturePoint& p : c->points) {
    if (p.crease) crease_point.emplace(Key{p.p.x, p.p.y, p.p.z}, kNone);
  }
  if (crease_point.empty()) return flag;
  for (uint32_t i = 0; i < mesh.positions.size(); ++i) {
    const geom::Vec3& x = mesh.positions[i];
    auto it = crease_point.find(Key{x.x, x.y, x.z});
    if (it == crease_point.end()) continue;
    flag[i] = 1;
    if (it->second == kNone) it->second = i;
  }
  bool any_segment = false;
  for (const plc::FeatureSegment& s : c->segments) any_segment = any_segment || s.crease;
  if (!any_segment) return flag;
  // Vertex neighbours through the tets' edges (CSR, duplicates kept).
  const size_t n = mesh.positions.size();
  std::vector<uint32_t> start(n + 1, 0);
  for (const auto& t : mesh.tets) {
    for (uint32_t v : t) start[v + 1] += 3;
  }
  for (size_t i = 0; i < n; ++i) start[i + 1] += start[i];
  std::vector<uint32_t> nbr(start[n]);
  std::vector<uint32_t> fill(start.begin(), start.end() - 1);
  for (const auto& t : mesh.tets) {
    for (int i = 0; i < 4; ++i) {
      for (int j = 0; j < 4; ++j) {
        if (i != j) nbr[fill[t[i]]++] = t[j];
      }
    }
  }
  const double on_feature_tol = OnFeatureTolerance(plc.vertices);
  for (const plc::FeatureSegment& s : c->segments) {
    if (!s.crease) continue;
    const geom::Vec3 a = c->points[s.a].p, b = c->points[s.b].p;
    const auto ia = crease_point.find(Key{a.x, a.y, a.z});
    const auto ib = crease_point.find(Key{b.x, b.y, b.z});
    if (ia == crease_point.end() || ib == crease_point.end() || ia->second == kNone || ib->second == kNone) continue;
    const geom::Vec3 d = b - a;
    const double dd = geom::Dot(d, d);
    // A chain vertex is on the segment up to rounding: relative to its
    // length, or the conformity checker's on-feature tolerance when that is
    // larger (random_plcs.py hull+far 2: coordinates ~1.2e4, a segment of
    // 1e-2, a chain vertex 9.1e-13 off it; the walk stopped there and the
    // tets past it counted as away from the creases).
    const double tol = std::max(1e-12 * std::sqrt(dd), on_feature_tol);
    uint32_t v = ia->second;
    double tv = 0;
    while (v != ib->second) {
      uint32_t next = kNone;
      double tn = 2;
      for (uint32_t k = start[v]; k < start[v + 1]; ++k) {
        const uint32_t w = nbr[k];
        if (w == ib->second) {
          next = w;
          tn = 1;
          break;
        }
        const geom::Vec3& x = mesh.positions[w];
        const double t = geom::Dot(x - a, d) / dd;
        if (!(t > tv) || !(t < tn) || t >= 1) continue;
        if (geom::Dist(a + t * d, x) <= tol) {
          next = w;
          tn = t;
        }
      }
      if (next == kNone) break;  // not a chain of mesh edges: the conformity checker says so
      flag[next] = 1;
      v = next;
      tv = tn;
    }
  }
  return flag;
}

}  // namespace svrc::mesh
