// Internal interfaces between the format readers (read_*.cc) and readers.cc.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/plc/plc.h"
#include "core/plc/readers.h"

namespace svrc::plc::internal {

// Supplies the bytes of the sibling .node file when a .poly/.smesh has none.
using NodeLoader = std::function<absl::StatusOr<std::string>()>;

// .node/.poly/.smesh into `plc` (source_name set by the caller).
absl::Status ReadTetgen(std::string_view bytes, InputFormat format, Plc* plc,
                        const NodeLoader& load_nodes);

// Faces as read from a surface file, before vertex and coplanar merging.
struct SurfaceSoup {
  std::vector<Vec3> vertices;
  std::vector<uint32_t> vertex_lines;
  std::vector<int32_t> vertex_markers;      // empty or one per vertex
  std::vector<std::vector<uint32_t>> faces;  // 0-based, >= 3 vertices
  std::vector<int32_t> face_markers;
  std::vector<uint32_t> face_lines;
  std::vector<Segment> segments;             // OBJ `l`, Medit Edges
  std::vector<std::string> marker_names;
  uint32_t index_base = 0;
};

absl::Status ReadOff(std::string_view bytes, const std::string& name, SurfaceSoup* soup);
absl::Status ReadStl(std::string_view bytes, const std::string& name, SurfaceSoup* soup);
absl::Status ReadObj(std::string_view bytes, const std::string& name, SurfaceSoup* soup);
absl::Status ReadMedit(std::string_view bytes, const std::string& name, SurfaceSoup* soup);

// Merges exactly equal vertices when `merge_vertices` (STL), then, when
// `merge_coplanar`, coplanar edge-adjacent faces with equal markers into
// polygonal facets: exactly coplanar ones, and nearly coplanar ones within
// `coplanar_tolerance` (ReadOptions::coplanar_tolerance; merge_facets.cc).
Plc BuildSurfacePlc(SurfaceSoup soup, bool merge_vertices, bool merge_coplanar, double coplanar_tolerance = 0);

}  // namespace svrc::plc::internal
