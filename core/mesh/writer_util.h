// Shared pieces of the mesh writers (write_*.cc): atomic file replacement,
// provenance text, number formatting. Internal to core/mesh.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/status.h"
#include "core/mesh/tet_mesh.h"

namespace svrc::mesh::internal {

// One (path, contents) pair per output file. All contents are written to
// temporary files beside their targets first, then renamed over the targets,
// so a reader never sees a half-written file; on any error the temporaries
// are removed and nothing is renamed. I/O errors name the path and errno text.
absl::Status WriteFilesAtomically(const std::vector<std::pair<std::string, std::string>>& files);

// "svrc <version>", "parameters: ...", "input sha256: ..." (empty fields
// shown as "-"), one line each, without comment markers.
std::vector<std::string> ProvenanceLines(const Provenance& p);

// The shortest decimal that round-trips (std::to_chars): every double exactly.
// FormatDouble writes it at `out`, which must have room for kMaxDoubleChars,
// and returns the end; AppendDouble appends it to a string.
inline constexpr size_t kMaxDoubleChars = 24;
char* FormatDouble(char* out, double v);
void AppendDouble(std::string* out, double v);

}  // namespace svrc::mesh::internal
