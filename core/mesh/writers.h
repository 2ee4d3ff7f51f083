// Writers for the formats simulation codes read: TetGen .node/.ele/.face
// (shortest round-trip decimals), VTK .vtu, Gmsh .msh 4.1, Medit .mesh. Each records the mesh's
// provenance (svrc version, parameters, input sha256) in the format's comment
// or metadata slot.
#pragma once

#include <string>
#include <string_view>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/mesh/tet_mesh.h"

namespace svrc::mesh {

enum class OutputFormat { kTetgen, kVtu, kMsh, kMedit };

// By extension (case-insensitive): .node (writes .node/.ele/.face beside it),
// .vtu (writes <stem>.vtu with the tets and <stem>.boundary.vtu with the
// boundary/interface triangles), .msh, .mesh.
// (.svrc, the raw result container, is core/codec's.)
absl::StatusOr<OutputFormat> OutputFormatFromPath(std::string_view path);

absl::Status WriteMesh(const TetMesh& mesh, const std::string& path, OutputFormat format);
// Dispatches on the extension of `path`.
absl::Status WriteMeshFile(const TetMesh& mesh, const std::string& path);

}  // namespace svrc::mesh
