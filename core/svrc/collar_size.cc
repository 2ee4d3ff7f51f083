#include "core/svrc/collar_size.h"

#include <algorithm>
#include <cmath>
#include <queue>
#include <unordered_set>

#include "core/geometry/constructions.h"

namespace svrc::refine {

using delaunay::Delaunay3;
using delaunay::VertexId;

CollarSizeResult FastCollarSize(const Delaunay3& dt, const Vec3& v, VertexId q,
                                CellFeaturesFn cell_features, FeatureDistanceFn feature_distance,
                                double shrink) {
  CollarSizeResult res;
  if (!dt.Is3d() || !q.valid()) return res;
  struct Item {
    double key;
    uint32_t vertex;
    bool operator>(const Item& o) const {
      return key != o.key ? key > o.key : vertex > o.vertex;
    }
  };
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> frontier;
  // Membership only (never iterated): no order leaks into the result.
  std::unordered_set<uint32_t> seen;
  const Vec3& qp = dt.Point(q);
  const double qv2 = geom::Dist2(qp, v);
  frontier.push({0.0, q.value()});
  seen.insert(q.value());
  std::vector<uint32_t> feats;
  std::vector<VertexId> nbrs;
  while (!frontier.empty()) {
    const Item it = frontier.top();
    if (it.key >= res.g) break;  // B(v, g) ⊆ explored cells
    frontier.pop();
    ++res.cells_explored;
    const VertexId u(it.vertex);
    feats.clear();
    cell_features(u, &feats);
    for (uint32_t f : feats) {
      const double d = feature_distance(f, v);
      if (d < res.g || (d == res.g && f < res.nearest_feature)) {
        res.g = d;
        res.nearest_feature = f;
      }
    }
    dt.Neighbors(u, &nbrs);
    for (VertexId w : nbrs) {
      if (!seen.insert(w.value()).second) continue;
      const Vec3& wp = dt.Point(w);
      const double uq = geom::Dist(wp, qp);
      const double key = uq > 0 ? std::max(0.0, (geom::Dist2(wp, v) - qv2) / (2 * uq)) : 0.0;
      frontier.push({key, w.value()});
    }
  }
  if (std::isfinite(res.g)) res.radius = res.g / 3 * (1 - shrink);
  return res;
}

double OracleFeatureDistance(const OracleFeature& f, const Vec3& v) {
  if (f.kind == 1) return geom::DistancePointSegment(v, f.p[0], f.p[1]);
  return geom::DistancePointTriangle(v, f.p[0], f.p[1], f.p[2]);
}

double BruteForceCollarG(std::span<const OracleFeature> features, const Vec3& v,
                         std::span<const uint32_t> excluded, uint32_t* nearest_feature) {
  double g = std::numeric_limits<double>::infinity();
  uint32_t best = 0xFFFFFFFFu;
  for (const OracleFeature& f : features) {
    if (std::find(excluded.begin(), excluded.end(), f.id) != excluded.end()) continue;
    const double d = OracleFeatureDistance(f, v);
    if (d < g || (d == g && f.id < best)) {
      g = d;
      best = f.id;
    }
  }
  if (nearest_feature != nullptr) *nearest_feature = best;
  return g;
}

}  // namespace svrc::refine
