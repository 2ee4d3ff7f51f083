// The output of the mesher: a tetrahedral mesh with float64 positions, region
// ids per tetrahedron, and boundary/interface triangles carrying input facet
// markers. Canonical order (DESIGN.md "Result encoding"): input vertices first,
// in input order, then Steiner points in a deterministic spatial order; tets
// sorted. Encoders and writers never reorder.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "core/geometry/vec3.h"

namespace svrc::mesh {

using geom::Vec3;

// Named counters of one meshing run, in a fixed insertion order (so that
// printing them is deterministic): vertices per dimension, warps, yields,
// events by type, predicate filter failures, seconds per phase, ...
struct MeshStats {
  std::vector<std::pair<std::string, double>> counters;

  void Set(const std::string& name, double value) {
    for (auto& [k, v] : counters) {
      if (k == name) { v = value; return; }
    }
    counters.emplace_back(name, value);
  }
  void Add(const std::string& name, double value) {
    for (auto& [k, v] : counters) {
      if (k == name) { v += value; return; }
    }
    counters.emplace_back(name, value);
  }
  // Returns `fallback` when the counter was never set.
  double Get(const std::string& name, double fallback = 0) const {
    for (const auto& [k, v] : counters) {
      if (k == name) return v;
    }
    return fallback;
  }
};

// One region of the output: its id (the index into TetMesh::regions) and the
// attribute of its seed (TetGen's region attribute), 0 when unseeded.
struct Region {
  double attribute = 0;
  double max_volume = 0;
};

// Where a result came from: recorded in every writer's output and the codec.
struct Provenance {
  std::string svrc_version;   // core::Version()
  std::string parameters;     // "radius_edge=2 theta=0.9 ..." in a fixed order
  std::string input_sha256;   // hex sha256 of the input bytes, "" if built in memory
};

struct TetMesh {
  std::vector<Vec3> positions;
  uint32_t num_input_vertices = 0;           // positions[0, n) are the input's
  // Tetrahedra, positively oriented: Orient3d(p0, p1, p2, p3) > 0 in the sense
  // of core/geometry/predicates.h.
  std::vector<std::array<uint32_t, 4>> tets;
  std::vector<int32_t> tet_region;           // one per tet, index into regions
  std::vector<Region> regions;
  // Boundary and interface triangles (faces on input facets), each with the
  // marker of the facet it lies on.
  std::vector<std::array<uint32_t, 3>> triangles;
  std::vector<int32_t> triangle_marker;
  MeshStats stats;
  Provenance provenance;

  size_t num_vertices() const { return positions.size(); }
  size_t num_tets() const { return tets.size(); }
};

}  // namespace svrc::mesh
