// TetGen .node/.ele/.face (TetGen manual §5.2): 1-based like tetgen's own
// output, coordinates with %.17g, the region attribute per tet, the facet
// marker per boundary/interface triangle, provenance in '#' comments.
#include <string>

#include "absl/strings/str_cat.h"
#include "core/mesh/writer_util.h"
#include "core/mesh/writers_internal.h"

namespace svrc::mesh::internal {

std::vector<std::pair<std::string, std::string>> FormatTetgen(const TetMesh& mesh,
                                                              const std::string& node_path) {
  std::string base = node_path;
  if (base.size() > 5 && base.substr(base.size() - 5) == ".node") base.resize(base.size() - 5);
  std::string header;
  for (const std::string& l : ProvenanceLines(mesh.provenance)) {
    absl::StrAppend(&header, "# ", SingleLine(l), "\n");
  }
  std::string node = header;
  absl::StrAppend(&node, mesh.positions.size(), " 3 0 0\n");
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    absl::StrAppend(&node, i + 1);
    for (int a = 0; a < 3; ++a) {
      node += ' ';
      AppendDouble(&node, mesh.positions[i][a]);
    }
    node += '\n';
  }
  std::string ele = header;
  absl::StrAppend(&ele, mesh.tets.size(), " 4 1\n");
  for (size_t i = 0; i < mesh.tets.size(); ++i) {
    const auto& t = mesh.tets[i];
    absl::StrAppend(&ele, i + 1, " ", t[0] + 1, " ", t[1] + 1, " ", t[2] + 1, " ", t[3] + 1, " ");
    AppendDouble(&ele, RegionAttribute(mesh, i));
    ele += '\n';
  }
  std::string face = header;
  absl::StrAppend(&face, mesh.triangles.size(), " 1\n");
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    const auto& t = mesh.triangles[i];
    absl::StrAppend(&face, i + 1, " ", t[0] + 1, " ", t[1] + 1, " ", t[2] + 1, " ",
                    TriangleMarker(mesh, i), "\n");
  }
  return {{base + ".node", std::move(node)},
          {base + ".ele", std::move(ele)},
          {base + ".face", std::move(face)}};
}

}  // namespace svrc::mesh::internal
