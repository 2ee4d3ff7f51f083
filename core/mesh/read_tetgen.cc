#include "core/mesh/read_tetgen.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace svrc::mesh {
namespace {

// Lines of a TetGen file with '#' comments and blank lines removed, split
// into whitespace-separated tokens; remembers line numbers for messages.
class TokenLines {
 public:
  static absl::StatusOr<TokenLines> Open(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return absl::NotFoundError(absl::StrCat("cannot open ", path));
    TokenLines t;
    t.path_ = path;
    std::string line;
    int number = 0;
    while (std::getline(in, line)) {
      ++number;
      const size_t hash = line.find('#');
      if (hash != std::string::npos) line.resize(hash);
      std::istringstream ss(line);
      std::vector<std::string> tokens;
      std::string tok;
      while (ss >> tok) tokens.push_back(tok);
      if (!tokens.empty()) t.lines_.push_back({number, std::move(tokens)});
    }
    if (in.bad()) return absl::DataLossError(absl::StrCat("error reading ", path));
    return t;
  }

  bool Done() const { return next_ >= lines_.size(); }
  // The next line, which must have at least `min_tokens` tokens.
  absl::StatusOr<const std::vector<std::string>*> Next(size_t min_tokens, const char* what) {
    if (Done()) return Error(absl::StrCat("unexpected end of file, expected ", what));
    const auto& l = lines_[next_++];
    if (l.second.size() < min_tokens) {
      return Error(absl::StrCat("expected ", min_tokens, " numbers for ", what), l.first);
    }
    current_line_ = l.first;
    return &l.second;
  }
  absl::Status Error(const std::string& msg, int line = 0) const {
    return absl::InvalidArgumentError(
        absl::StrCat(path_, ":", line ? line : current_line_, ": ", msg));
  }
  absl::StatusOr<int64_t> Int(const std::string& s) const {
    int64_t v = 0;
    const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
    if (r.ec != std::errc() || r.ptr != s.data() + s.size()) {
      return Error(absl::StrCat("not an integer: '", s, "'"));
    }
    return v;
  }
  absl::StatusOr<double> Real(const std::string& s) const {
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (end != s.c_str() + s.size() || !std::isfinite(v)) {
      return Error(absl::StrCat("not a finite number: '", s, "'"));
    }
    return v;
  }

 private:
  std::string path_;
  std::vector<std::pair<int, std::vector<std::string>>> lines_;
  size_t next_ = 0;
  int current_line_ = 0;
};

#define SVRC_ASSIGN(lhs, expr)              \
  do {                                      \
    auto _r = (expr);                       \
    if (!_r.ok()) return _r.status();       \
    lhs = *_r;                              \
  } while (0)

}  // namespace

absl::StatusOr<TetMesh> ReadTetgenMesh(const std::string& node_path) {
  std::string base = node_path;
  if (base.size() > 5 && base.substr(base.size() - 5) == ".node") base.resize(base.size() - 5);
  TetMesh mesh;
  int64_t index_base = 0;
  {
    auto file_or = TokenLines::Open(base + ".node");
    if (!file_or.ok()) return file_or.status();
    TokenLines& f = *file_or;
    const std::vector<std::string>* h;
    SVRC_ASSIGN(h, f.Next(1, "the .node header"));
    int64_t n = 0, dim = 3, nattr = 0, nmark = 0;
    SVRC_ASSIGN(n, f.Int((*h)[0]));
    if (h->size() > 1) SVRC_ASSIGN(dim, f.Int((*h)[1]));
    if (h->size() > 2) SVRC_ASSIGN(nattr, f.Int((*h)[2]));
    if (h->size() > 3) SVRC_ASSIGN(nmark, f.Int((*h)[3]));
    if (n < 0 || n > (int64_t{1} << 31) || dim != 3 || nattr < 0 || nmark < 0) {
      return f.Error("bad .node header");
    }
    mesh.positions.reserve(n);
    for (int64_t i = 0; i < n; ++i) {
      const std::vector<std::string>* l;
      SVRC_ASSIGN(l, f.Next(4, "a point"));
      int64_t idx;
      SVRC_ASSIGN(idx, f.Int((*l)[0]));
      if (i == 0) {
        if (idx != 0 && idx != 1) return f.Error("first point index must be 0 or 1");
        index_base = idx;
      }
      if (idx != i + index_base) return f.Error("points must be numbered consecutively");
      Vec3 p;
      for (int a = 0; a < 3; ++a) SVRC_ASSIGN(p[a], f.Real((*l)[1 + a]));
      mesh.positions.push_back(p);
    }
    mesh.num_input_vertices = static_cast<uint32_t>(n);
  }
  const int64_t nv = static_cast<int64_t>(mesh.positions.size());
  auto vertex = [&](TokenLines& f, const std::string& s) -> absl::StatusOr<uint32_t> {
    auto v = f.Int(s);
    if (!v.ok()) return v.status();
    const int64_t id = *v - index_base;
    if (id < 0 || id >= nv) return f.Error(absl::StrCat("vertex index ", *v, " out of range"));
    return static_cast<uint32_t>(id);
  };
  {
    auto file_or = TokenLines::Open(base + ".ele");
    if (!file_or.ok()) return file_or.status();
    TokenLines& f = *file_or;
    const std::vector<std::string>* h;
    SVRC_ASSIGN(h, f.Next(1, "the .ele header"));
    int64_t n = 0, per = 4, nattr = 0;
    SVRC_ASSIGN(n, f.Int((*h)[0]));
    if (h->size() > 1) SVRC_ASSIGN(per, f.Int((*h)[1]));
    if (h->size() > 2) SVRC_ASSIGN(nattr, f.Int((*h)[2]));
    if (n < 0 || n > (int64_t{1} << 31) || per != 4 || nattr < 0) {
      return f.Error("bad .ele header (only 4-node tets are supported)");
    }
    std::vector<double> attr;
    for (int64_t i = 0; i < n; ++i) {
      const std::vector<std::string>* l;
      SVRC_ASSIGN(l, f.Next(5 + (nattr > 0 ? 1 : 0), "a tetrahedron"));
      std::array<uint32_t, 4> t;
      for (int k = 0; k < 4; ++k) SVRC_ASSIGN(t[k], vertex(f, (*l)[1 + k]));
      mesh.tets.push_back(t);
      if (nattr > 0) {
        double a;
        SVRC_ASSIGN(a, f.Real((*l)[5]));
        attr.push_back(a);
      }
    }
    std::vector<double> values = attr;
    std::sort(values.begin(), values.end());
    values.erase(std::unique(values.begin(), values.end()), values.end());
    if (values.empty()) values.push_back(0);
    for (double v : values) mesh.regions.push_back(Region{v, 0});
    mesh.tet_region.assign(mesh.tets.size(), 0);
    for (size_t i = 0; i < attr.size(); ++i) {
      mesh.tet_region[i] = static_cast<int32_t>(
          std::lower_bound(values.begin(), values.end(), attr[i]) - values.begin());
    }
  }
  {
    auto file_or = TokenLines::Open(base + ".face");
    if (file_or.ok()) {
      TokenLines& f = *file_or;
      const std::vector<std::string>* h;
      SVRC_ASSIGN(h, f.Next(1, "the .face header"));
      int64_t n = 0, nmark = 0;
      SVRC_ASSIGN(n, f.Int((*h)[0]));
      if (h->size() > 1) SVRC_ASSIGN(nmark, f.Int((*h)[1]));
      if (n < 0 || n > (int64_t{1} << 31) || nmark < 0) return f.Error("bad .face header");
      for (int64_t i = 0; i < n; ++i) {
        const std::vector<std::string>* l;
        SVRC_ASSIGN(l, f.Next(4 + (nmark > 0 ? 1 : 0), "a face"));
        std::array<uint32_t, 3> t;
        for (int k = 0; k < 3; ++k) SVRC_ASSIGN(t[k], vertex(f, (*l)[1 + k]));
        int64_t marker = 0;
        if (nmark > 0) SVRC_ASSIGN(marker, f.Int((*l)[4]));
        mesh.triangles.push_back(t);
        mesh.triangle_marker.push_back(static_cast<int32_t>(marker));
      }
    } else if (!absl::IsNotFound(file_or.status())) {
      return file_or.status();
    }
  }
  return mesh;
}

}  // namespace svrc::mesh
