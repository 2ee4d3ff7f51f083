// Reader for TetGen's mesh output (.node/.ele/.face), for comparing with
// tetgen runs and reading back our own TetGen writer. Not a PLC reader (those
// are core/plc/readers.h).
#pragma once

#include <string>

#include "absl/status/statusor.h"
#include "core/mesh/tet_mesh.h"

namespace svrc::mesh {

// Reads `<base>.node`, `<base>.ele` and, when present, `<base>.face`
// (`node_path` is the .node file; `<base>` is it without the extension). The
// first index in the .node file decides the base (0 or 1), as in TetGen.
// Tet region attributes (first .ele attribute) become TetMesh::regions, one
// per distinct value in increasing order; tet_region indexes them. Face
// boundary markers become triangle_marker (0 when the file has none).
// num_input_vertices is set to the number of .node points. Tets are kept as
// written (no reorientation). INVALID_ARGUMENT with file and line on bad input.
absl::StatusOr<TetMesh> ReadTetgenMesh(const std::string& node_path);

}  // namespace svrc::mesh
