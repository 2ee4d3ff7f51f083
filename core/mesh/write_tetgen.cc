// TetGen .node/.ele/.face (TetGen manual §5.2): 1-based like tetgen's own
// output, coordinates as the shortest decimals that read back to the same
// doubles (AppendDouble), the region attribute per tet, the facet
// marker per boundary/interface triangle, provenance in '#' comments.
#include <bit>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

#include "absl/strings/str_cat.h"
#include "core/mesh/writer_util.h"
#include "core/mesh/writers_internal.h"

namespace svrc::mesh::internal {

namespace {

// One line at a time in a stack buffer, appended to the file's text with
// one call: absl::StrAppend of ten pieces per tet was 1.4% of the CLI's
// instructions on cube --max-volume 1e-5 (session 25). The same bytes.
class LineBuffer {
 public:
  template <typename Int>
  LineBuffer& Integer(Int v) {
    end_ = std::to_chars(end_, buf_ + sizeof(buf_), v).ptr;
    return *this;
  }
  LineBuffer& Double(double v) {
    end_ = FormatDouble(end_, v);
    return *this;
  }
  LineBuffer& Text(std::string_view s) {
    std::memcpy(end_, s.data(), s.size());
    end_ += s.size();
    return *this;
  }
  LineBuffer& Char(char c) {
    *end_++ = c;
    return *this;
  }
  void AppendTo(std::string* out) {
    out->append(buf_, end_);
    end_ = buf_;
  }

 private:
  // Longest line: a .node line, an index (≤ 20 digits) and three shortest
  // round-trip doubles (≤ kMaxDoubleChars each), separators and '\n'.
  char buf_[160];
  char* end_ = buf_;
};

}  // namespace

std::vector<std::pair<std::string, std::string>> FormatTetgen(const TetMesh& mesh,
                                                              const std::string& node_path) {
  std::string base = node_path;
  if (base.size() > 5 && base.substr(base.size() - 5) == ".node") base.resize(base.size() - 5);
  std::string header;
  for (const std::string& l : ProvenanceLines(mesh.provenance)) {
    absl::StrAppend(&header, "# ", SingleLine(l), "\n");
  }
  LineBuffer line;
  std::string node = header;
  node.reserve(header.size() + 64 * mesh.positions.size() + 32);
  absl::StrAppend(&node, mesh.positions.size(), " 3 0 0\n");
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    line.Integer(i + 1);
    for (int a = 0; a < 3; ++a) line.Char(' ').Double(mesh.positions[i][a]);
    line.Char('\n').AppendTo(&node);
  }
  std::string ele = header;
  ele.reserve(header.size() + 40 * mesh.tets.size() + 32);
  absl::StrAppend(&ele, mesh.tets.size(), " 4 1\n");
  // The region attribute's text, formatted once per value (by its bits:
  // -0 and 0 print differently).
  uint64_t attribute_bits = 0;
  std::string attribute_text;
  bool have_attribute = false;
  for (size_t i = 0; i < mesh.tets.size(); ++i) {
    const auto& t = mesh.tets[i];
    const double attribute = RegionAttribute(mesh, i);
    const uint64_t bits = std::bit_cast<uint64_t>(attribute);
    if (!have_attribute || bits != attribute_bits) {
      attribute_text.clear();
      AppendDouble(&attribute_text, attribute);
      attribute_bits = bits;
      have_attribute = true;
    }
    line.Integer(i + 1);
    for (int k = 0; k < 4; ++k) line.Char(' ').Integer(uint64_t{t[k]} + 1);
    line.Char(' ').Text(attribute_text).Char('\n').AppendTo(&ele);
  }
  std::string face = header;
  face.reserve(header.size() + 40 * mesh.triangles.size() + 32);
  absl::StrAppend(&face, mesh.triangles.size(), " 1\n");
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    const auto& t = mesh.triangles[i];
    line.Integer(i + 1);
    for (int k = 0; k < 3; ++k) line.Char(' ').Integer(uint64_t{t[k]} + 1);
    line.Char(' ').Integer(TriangleMarker(mesh, i)).Char('\n').AppendTo(&face);
  }
  return {{base + ".node", std::move(node)},
          {base + ".ele", std::move(ele)},
          {base + ".face", std::move(face)}};
}

}  // namespace svrc::mesh::internal
