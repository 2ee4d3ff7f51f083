// VTK XML UnstructuredGrid (.vtu, VTK file format spec "XML File Formats"),
// data inline as base64 ("binary" format, UInt64 size headers), little
// endian. Two files: <stem>.vtu holds the tets (cell data "region" and
// "region_attribute"); <stem>.boundary.vtu holds the boundary/interface
// triangles (cell data "facet_marker") over the same point list, so point ids
// agree (docs/conformity.md, "Output formats"). Provenance: an XML comment.
#include <bit>
#include <cstring>
#include <string>

#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "core/mesh/writer_util.h"
#include "core/mesh/writers_internal.h"

namespace svrc::mesh::internal {
namespace {

static_assert(std::endian::native == std::endian::little, "the .vtu writer assumes little endian");

template <typename T>
void AppendDataArray(std::string* out, const char* type, const char* name, int components,
                     const std::vector<T>& values) {
  absl::StrAppend(out, "        <DataArray type=\"", type, "\" Name=\"", name, "\"");
  if (components > 1) absl::StrAppend(out, " NumberOfComponents=\"", components, "\"");
  absl::StrAppend(out, " format=\"binary\">\n          ");
  // VTK reads the size header and the data as two base64 blocks.
  const uint64_t bytes = values.size() * sizeof(T);
  std::string header(sizeof(bytes), '\0');
  std::memcpy(header.data(), &bytes, sizeof(bytes));
  std::string data(bytes, '\0');
  if (bytes > 0) std::memcpy(data.data(), values.data(), bytes);
  absl::StrAppend(out, absl::Base64Escape(header), absl::Base64Escape(data), "\n");
  absl::StrAppend(out, "        </DataArray>\n");
}

std::string Document(const TetMesh& mesh, const std::vector<double>& points, size_t num_cells,
                     int nodes_per_cell, uint8_t vtk_type,
                     const std::vector<int64_t>& connectivity, const std::string& cell_data) {
  std::string out = "<?xml version=\"1.0\"?>\n<!--\n";
  for (const std::string& l : ProvenanceLines(mesh.provenance)) {
    // "--" may not appear inside an XML comment.
    absl::StrAppend(&out, "  ", absl::StrReplaceAll(SingleLine(l), {{"--", "- -"}}), "\n");
  }
  absl::StrAppend(&out, "-->\n");
  absl::StrAppend(&out,
                  "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
                  "header_type=\"UInt64\">\n  <UnstructuredGrid>\n");
  absl::StrAppend(&out, "    <Piece NumberOfPoints=\"", mesh.positions.size(),
                  "\" NumberOfCells=\"", num_cells, "\">\n");
  absl::StrAppend(&out, "      <Points>\n");
  AppendDataArray(&out, "Float64", "Points", 3, points);
  absl::StrAppend(&out, "      </Points>\n      <Cells>\n");
  AppendDataArray(&out, "Int64", "connectivity", 1, connectivity);
  std::vector<int64_t> offsets(num_cells);
  for (size_t i = 0; i < num_cells; ++i) offsets[i] = static_cast<int64_t>(i + 1) * nodes_per_cell;
  AppendDataArray(&out, "Int64", "offsets", 1, offsets);
  AppendDataArray(&out, "UInt8", "types", 1, std::vector<uint8_t>(num_cells, vtk_type));
  absl::StrAppend(&out, "      </Cells>\n      <CellData>\n", cell_data, "      </CellData>\n");
  absl::StrAppend(&out, "    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n");
  return out;
}

}  // namespace

FileList FormatVtu(const TetMesh& mesh, const std::string& vtu_path) {
  std::string stem = vtu_path;
  if (stem.size() > 4 && stem.substr(stem.size() - 4) == ".vtu") stem.resize(stem.size() - 4);
  std::vector<double> points;
  points.reserve(3 * mesh.positions.size());
  for (const Vec3& p : mesh.positions) points.insert(points.end(), {p.x, p.y, p.z});

  std::vector<int64_t> tets;
  tets.reserve(4 * mesh.tets.size());
  std::vector<int32_t> region(mesh.tets.size());
  std::vector<double> attribute(mesh.tets.size());
  for (size_t i = 0; i < mesh.tets.size(); ++i) {
    for (uint32_t v : mesh.tets[i]) tets.push_back(v);
    region[i] = RegionId(mesh, i);
    attribute[i] = RegionAttribute(mesh, i);
  }
  std::string tet_data;
  AppendDataArray(&tet_data, "Int32", "region", 1, region);
  AppendDataArray(&tet_data, "Float64", "region_attribute", 1, attribute);
  std::string volume = Document(mesh, points, mesh.tets.size(), 4, /*VTK_TETRA=*/10, tets, tet_data);

  std::vector<int64_t> tris;
  tris.reserve(3 * mesh.triangles.size());
  std::vector<int32_t> marker(mesh.triangles.size());
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    for (uint32_t v : mesh.triangles[i]) tris.push_back(v);
    marker[i] = TriangleMarker(mesh, i);
  }
  std::string tri_data;
  AppendDataArray(&tri_data, "Int32", "facet_marker", 1, marker);
  std::string boundary =
      Document(mesh, points, mesh.triangles.size(), 3, /*VTK_TRIANGLE=*/5, tris, tri_data);
  return {{stem + ".vtu", std::move(volume)}, {stem + ".boundary.vtu", std::move(boundary)}};
}

}  // namespace svrc::mesh::internal
