// Readers for the input formats users bring (DESIGN.md "Core pipeline" 1):
// TetGen .poly/.smesh/.node, .off, .stl (ASCII and binary), .obj, Medit .mesh
// surfaces. A reader never crashes or hangs on malformed bytes: it returns
// INVALID_ARGUMENT with file, line and reason.
#pragma once

#include <string>
#include <string_view>

#include "absl/status/statusor.h"
#include "core/plc/plc.h"

namespace svrc::plc {

enum class InputFormat { kPoly, kSmesh, kNode, kOff, kStl, kObj, kMedit };

// By extension (case-insensitive): .poly .smesh .node .off .stl .obj .mesh
absl::StatusOr<InputFormat> FormatFromPath(std::string_view path);
std::string_view FormatName(InputFormat format);

// Parses `bytes` in `format`; `name` is used in messages and Plc::source_name.
// Sets Plc::input_sha256. Surface formats merge coplanar adjacent triangles
// with equal markers into polygonal facets (ReadOptions).
absl::StatusOr<Plc> ReadPlcBytes(std::string_view bytes, InputFormat format,
                                 std::string_view name);

// Reads the file and dispatches on its extension.
absl::StatusOr<Plc> ReadPlcFile(const std::string& path);

struct ReadOptions {
  // Surface formats: merge exactly coplanar edge-adjacent faces with equal
  // markers into polygonal facets (the default; false keeps one facet per face).
  bool merge_coplanar = true;
  // With merge_coplanar: faces also merge when nearly coplanar, i.e. the other
  // face's vertices are within this fraction of the pair's diameter of one
  // face's plane, provided the whole merged group then passes validation's
  // planarity test within this fraction and every vertex of its faces is on
  // its boundary (else the group merges only its exactly coplanar faces;
  // docs/plc.md "Nearly coplanar merging"). Half the validation's planarity tolerance
  // (ValidationOptions::planarity_tolerance, TetGen's -T 1e-8), so a merged
  // facet is valid. 0: exactly coplanar only. A surface rotated or moved in
  // floating point is coplanar only up to rounding (session 39: hinge.stl
  // turned by a random rotation kept 1,159 facets instead of 562, every
  // split quad's 45-degree corners became crease points, and the run hit the
  // vertex budget).
  double coplanar_tolerance = 5e-9;
};
absl::StatusOr<Plc> ReadPlcBytes(std::string_view bytes, InputFormat format,
                                 std::string_view name, const ReadOptions& options);
absl::StatusOr<Plc> ReadPlcFile(const std::string& path, const ReadOptions& options);

}  // namespace svrc::plc
