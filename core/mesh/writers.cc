#include "core/mesh/writers.h"

#include <algorithm>
#include <cctype>

#include "absl/strings/str_cat.h"
#include "core/mesh/writer_util.h"
#include "core/mesh/writers_internal.h"

namespace svrc::mesh {

absl::StatusOr<OutputFormat> OutputFormatFromPath(std::string_view path) {
  const size_t dot = path.rfind('.');
  const size_t slash = path.find_last_of("/\\");
  if (dot == std::string_view::npos || (slash != std::string_view::npos && dot < slash)) {
    return absl::InvalidArgumentError(
        absl::StrCat("output path '", std::string(path),
                     "' has no extension (use .node, .vtu, .msh or .mesh)"));
  }
  std::string ext(path.substr(dot + 1));
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == "node") return OutputFormat::kTetgen;
  if (ext == "vtu") return OutputFormat::kVtu;
  if (ext == "msh") return OutputFormat::kMsh;
  if (ext == "mesh") return OutputFormat::kMedit;
  return absl::InvalidArgumentError(absl::StrCat(
      "unknown output extension '.", ext, "' in '", std::string(path),
      "' (use .node, .vtu, .msh or .mesh; .svrc is the result container)"));
}

absl::Status WriteMesh(const TetMesh& mesh, const std::string& path, OutputFormat format) {
  internal::FileList files;
  switch (format) {
    case OutputFormat::kTetgen: files = internal::FormatTetgen(mesh, path); break;
    case OutputFormat::kVtu: files = internal::FormatVtu(mesh, path); break;
    case OutputFormat::kMsh: files = internal::FormatMsh(mesh, path); break;
    case OutputFormat::kMedit: files = internal::FormatMedit(mesh, path); break;
  }
  return internal::WriteFilesAtomically(files);
}

absl::Status WriteMeshFile(const TetMesh& mesh, const std::string& path) {
  auto format = OutputFormatFromPath(path);
  if (!format.ok()) return format.status();
  return WriteMesh(mesh, path, *format);
}

}  // namespace svrc::mesh
