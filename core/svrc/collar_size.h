// FastCollarSize (thesis Figure 3.8, Definition 14, Lemma 35; guide
// "FastCollarSize"): g(v) = distance from v to the nearest feature not
// containing v, by a best-first search over Voronoi cells of a Delaunay3 mesh;
// the collar radius is g/3. Plus a brute-force oracle over all features.
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "absl/functional/function_ref.h"
#include "core/delaunay/delaunay3.h"
#include "core/geometry/vec3.h"

namespace svrc::refine {

using geom::Vec3;

struct CollarSizeResult {
  double g = std::numeric_limits<double>::infinity();  // g(v); +inf: no feature found
  double radius = std::numeric_limits<double>::infinity();  // g/3, shrunk by `shrink`
  uint32_t nearest_feature = 0xFFFFFFFFu;  // the caller's feature id achieving g
  uint32_t cells_explored = 0;             // Voronoi cells popped (Lemma 35: O(1))
};

// Callbacks that let the refiner plug in its BLG:
//  * cell_features(u, out): append the ids of the features whose protective
//    balls are linked to cell V(u) — any superset of the features meeting V(u)
//    is correct (only exact distances of reported features enter g);
//  * feature_distance(f, v): the exact distance from v to feature f, or +inf
//    when v ∈ f (Definition 14 / the guide: only features with v ∉ F' count).
using CellFeaturesFn = absl::FunctionRef<void(delaunay::VertexId, std::vector<uint32_t>*)>;
using FeatureDistanceFn = absl::FunctionRef<double(uint32_t, const Vec3&)>;

// Best-first search from q (the vertex whose Voronoi cell contains v; e.g.
// dt.NearestVertex(v)). A frontier cell u is keyed by the lower bound on
// dist(v, V(u)) given by the bisector of q and u:
//   key(u) = max(0, (|uv|² − |qv|²) / (2|uq|))
// (V(u) lies in the half-space closer to u than to q). Stops when the smallest
// key ≥ g: every point within g of v then lies in an explored cell, so g is
// exact. Deterministic (ties by vertex id). radius = g/3·(1 − shrink) (guide §5
// item 9: a too-large g breaks Lemma 13). Infinite vertices are skipped; a hull
// cell is unbounded, so its features are reported by the callback like any cell.
CollarSizeResult FastCollarSize(const delaunay::Delaunay3& dt, const Vec3& v,
                                delaunay::VertexId q, CellFeaturesFn cell_features,
                                FeatureDistanceFn feature_distance, double shrink = 1e-9);

// A PLC feature for the oracle: a segment (kind 1: p[0], p[1]) or a triangle
// (kind 2: p[0..2]); facets are given as their triangles with one id.
struct OracleFeature {
  uint32_t id = 0;
  int kind = 1;
  Vec3 p[3];
};

// Exact-in-double distance from v to one oracle feature.
double OracleFeatureDistance(const OracleFeature& f, const Vec3& v);

// Brute-force g(v): min distance over features whose id is not in `excluded`
// (the features containing v). Linear scan. nearest_feature receives the id.
double BruteForceCollarG(std::span<const OracleFeature> features, const Vec3& v,
                         std::span<const uint32_t> excluded, uint32_t* nearest_feature = nullptr);

}  // namespace svrc::refine
