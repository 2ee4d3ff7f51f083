// Medit .mesh (ASCII, MeshVersionFormatted 2 = double precision; Frey,
// "MEDIT: an interactive mesh visualization software", INRIA RT-0253):
// Vertices (ref 0), Triangles (ref = facet marker), Tetrahedra (ref = region
// id). Provenance in '#' comment lines.
#include <string>

#include "absl/strings/str_cat.h"
#include "core/mesh/writer_util.h"
#include "core/mesh/writers_internal.h"

namespace svrc::mesh::internal {

FileList FormatMedit(const TetMesh& mesh, const std::string& mesh_path) {
  std::string out;
  for (const std::string& l : ProvenanceLines(mesh.provenance)) {
    absl::StrAppend(&out, "# ", SingleLine(l), "\n");
  }
  absl::StrAppend(&out, "MeshVersionFormatted 2\n\nDimension 3\n\nVertices\n",
                  mesh.positions.size(), "\n");
  for (const Vec3& p : mesh.positions) {
    AppendDouble(&out, p.x);
    out += ' ';
    AppendDouble(&out, p.y);
    out += ' ';
    AppendDouble(&out, p.z);
    out += " 0\n";
  }
  absl::StrAppend(&out, "\nTriangles\n", mesh.triangles.size(), "\n");
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    const auto& t = mesh.triangles[i];
    absl::StrAppend(&out, t[0] + 1, " ", t[1] + 1, " ", t[2] + 1, " ", TriangleMarker(mesh, i),
                    "\n");
  }
  absl::StrAppend(&out, "\nTetrahedra\n", mesh.tets.size(), "\n");
  for (size_t i = 0; i < mesh.tets.size(); ++i) {
    const auto& t = mesh.tets[i];
    absl::StrAppend(&out, t[0] + 1, " ", t[1] + 1, " ", t[2] + 1, " ", t[3] + 1, " ",
                    RegionId(mesh, i), "\n");
  }
  absl::StrAppend(&out, "\nEnd\n");
  return {{mesh_path, std::move(out)}};
}

}  // namespace svrc::mesh::internal
