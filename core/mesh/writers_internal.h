// Per-format text builders behind WriteMesh (writers.cc), exposed to the
// writers' own files only. Each returns (path, contents) pairs.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "core/mesh/tet_mesh.h"

namespace svrc::mesh::internal {

using FileList = std::vector<std::pair<std::string, std::string>>;

FileList FormatTetgen(const TetMesh& mesh, const std::string& node_path);
FileList FormatVtu(const TetMesh& mesh, const std::string& vtu_path);
FileList FormatMsh(const TetMesh& mesh, const std::string& msh_path);
FileList FormatMedit(const TetMesh& mesh, const std::string& mesh_path);

// Region id of tet i (0 when tet_region is missing) and its attribute.
inline int32_t RegionId(const TetMesh& m, size_t i) {
  return i < m.tet_region.size() ? m.tet_region[i] : 0;
}
inline double RegionAttribute(const TetMesh& m, size_t i) {
  const int32_t r = RegionId(m, i);
  return r >= 0 && static_cast<size_t>(r) < m.regions.size() ? m.regions[r].attribute : 0.0;
}
inline int32_t TriangleMarker(const TetMesh& m, size_t i) {
  return i < m.triangle_marker.size() ? m.triangle_marker[i] : 0;
}
// Replaces line breaks by spaces (provenance goes into one-line comments).
inline std::string SingleLine(std::string s) {
  for (char& c : s) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return s;
}

}  // namespace svrc::mesh::internal
