// Surface readers: OFF, STL (ASCII and binary), Wavefront OBJ, Medit .mesh.
// They fill a SurfaceSoup; BuildSurfacePlc (merge_facets.cc) makes the PLC.
#include <cmath>
#include <cstring>
#include <map>
#include <string>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "core/plc/read_internal.h"
#include "core/plc/read_util.h"

namespace svrc::plc::internal {
namespace {

constexpr int64_t kMaxCount = int64_t{1} << 31;

absl::Status ReadXyz(LineReader& r, Vec3* p, std::string_view what) {
  absl::Status err;
  for (int k = 0; k < 3; ++k) {
    if (!r.LineDouble(&(*p)[k], &err)) {
      return err.ok() ? r.Error(Cat(what, " has no ", "xyz"[k], " coordinate")) : err;
    }
  }
  return absl::OkStatus();
}

}  // namespace

// OFF: "OFF" (optionally with prefixes C/N/ST/4 and the counts on the same
// line), "nv nf ne", nv vertex lines, nf face lines "k i1..ik [color]".
// '#' comments are accepted (TetGen's reader rejects them).
absl::Status ReadOff(std::string_view bytes, const std::string& name, SurfaceSoup* soup) {
  LineReader r(bytes, name);
  if (!r.NextLine()) return r.Error("empty file: expected 'OFF'");
  std::string_view head = r.Take();
  if (!head.ends_with("OFF") || head.size() > 8) {
    return r.Error(Cat("expected 'OFF', got '", head.substr(0, 40), "'"));
  }
  if (head.starts_with("4") || head.find('n') != std::string_view::npos) {
    return r.Error(Cat("OFF variant '", head, "' is not supported"));
  }
  if (r.Remaining() == 0 && !r.NextLine()) return r.Error("unexpected end of file: expected the counts");
  int64_t nv = 0, nf = 0, ne = 0;
  absl::Status err;
  if (!r.LineInt(&nv, &err)) return err.ok() ? r.Error("expected the number of vertices") : err;
  if (!r.LineInt(&nf, &err)) return err.ok() ? r.Error("expected the number of faces") : err;
  if (r.Remaining() > 0 && !r.LineInt(&ne, &err)) return err;
  if (nv < 0 || nv >= kMaxCount) return r.Error(Cat("invalid number of vertices ", nv));
  if (nf < 0 || nf >= kMaxCount) return r.Error(Cat("invalid number of faces ", nf));
  soup->vertices.reserve(CappedReserve(nv, r.bytes_left(), 6));
  for (int64_t i = 0; i < nv; ++i) {
    if (!r.NextLine()) return r.Error(Cat("unexpected end of file: expected ", nv, " vertices, found ", i));
    Vec3 p;
    if (absl::Status s = ReadXyz(r, &p, Cat("vertex ", i)); !s.ok()) return s;
    soup->vertices.push_back(p);
    soup->vertex_lines.push_back(static_cast<uint32_t>(r.line()));
  }
  soup->faces.reserve(CappedReserve(nf, r.bytes_left(), 8));
  for (int64_t f = 0; f < nf; ++f) {
    if (!r.NextLine()) return r.Error(Cat("unexpected end of file: expected ", nf, " faces, found ", f));
    int64_t k = 0;
    if (!r.LineInt(&k, &err)) return err;
    if (k < 3 || static_cast<size_t>(k) > r.Remaining()) {
      return r.Error(Cat("face ", f, ": invalid number of corners ", k));
    }
    std::vector<uint32_t> face;
    face.reserve(static_cast<size_t>(k));
    for (int64_t i = 0; i < k; ++i) {
      int64_t v = 0;
      if (!r.LineInt(&v, &err)) return err;
      if (v < 0 || v >= nv) {
        return r.Error(Cat("face ", f, ": vertex index ", v, " out of range (vertices are numbered 0..", nv - 1, ")"));
      }
      face.push_back(static_cast<uint32_t>(v));
    }
    soup->faces.push_back(std::move(face));
    soup->face_markers.push_back(0);  // trailing colour values are ignored
    soup->face_lines.push_back(static_cast<uint32_t>(r.line()));
  }
  // Edge lines (ne) are not used by OFF readers in practice; ignore the rest.
  return absl::OkStatus();
}

namespace {

absl::Status ReadBinaryStl(std::string_view bytes, const std::string& name, SurfaceSoup* soup) {
  uint32_t n = 0;
  std::memcpy(&n, bytes.data() + 80, 4);  // little-endian on every platform we build for
  soup->vertices.reserve(size_t{n} * 3);
  for (uint32_t t = 0; t < n; ++t) {
    const char* rec = bytes.data() + 84 + size_t{t} * 50;
    std::vector<uint32_t> face;
    for (int k = 0; k < 3; ++k) {
      float xyz[3];
      std::memcpy(xyz, rec + 12 + 12 * k, 12);
      soup->vertices.emplace_back(xyz[0], xyz[1], xyz[2]);
      soup->vertex_lines.push_back(0);
      face.push_back(static_cast<uint32_t>(soup->vertices.size() - 1));
    }
    soup->faces.push_back(std::move(face));
    soup->face_markers.push_back(0);
    soup->face_lines.push_back(0);
  }
  (void)name;
  return absl::OkStatus();
}

absl::Status ReadAsciiStl(std::string_view bytes, const std::string& name, SurfaceSoup* soup) {
  LineReader r(bytes, name, 0);
  std::map<std::string, int32_t, std::less<>> solid_marker;
  int32_t marker = 0;
  bool in_solid = false, in_facet = false, in_loop = false;
  std::vector<uint32_t> face;
  uint32_t face_line = 0;
  while (r.NextLine()) {
    std::string_view kw = r.Take();
    const std::string lower = Lower(kw);
    if (lower == "solid") {
      if (in_solid) return r.Error("'solid' inside a solid");
      in_solid = true;
      std::string solid_name;
      if (r.Remaining() > 0) {
        // The name is the rest of the line.
        const std::string_view raw = r.raw_line();
        const size_t pos = r.Peek().data() - raw.data();
        solid_name = std::string(Strip(raw.substr(pos)));
      }
      auto it = solid_marker.find(solid_name);
      if (it == solid_marker.end()) {
        marker = static_cast<int32_t>(solid_marker.size()) + 1;
        solid_marker.emplace(solid_name, marker);
        if (soup->marker_names.size() <= static_cast<size_t>(marker)) soup->marker_names.resize(marker + 1);
        soup->marker_names[marker] = solid_name;
      } else {
        marker = it->second;
      }
      r.SkipRestOfLine();
    } else if (lower == "endsolid") {
      if (!in_solid || in_facet) return r.Error("unexpected 'endsolid'");
      in_solid = false;
      r.SkipRestOfLine();
    } else if (lower == "facet") {
      if (!in_solid || in_facet) return r.Error("unexpected 'facet'");
      in_facet = true;
      face.clear();
      face_line = static_cast<uint32_t>(r.line());
      r.SkipRestOfLine();  // the normal is recomputed, never trusted
    } else if (lower == "outer") {
      if (!in_facet || in_loop) return r.Error("unexpected 'outer loop'");
      if (r.Remaining() == 0 || Lower(r.Take()) != "loop") return r.Error("expected 'outer loop'");
      in_loop = true;
    } else if (lower == "vertex") {
      if (!in_loop) return r.Error("'vertex' outside a loop");
      Vec3 p;
      if (absl::Status s = ReadXyz(r, &p, "vertex"); !s.ok()) return s;
      if (r.Remaining() > 0) return r.Error("extra data after a vertex");
      soup->vertices.push_back(p);
      soup->vertex_lines.push_back(static_cast<uint32_t>(r.line()));
      face.push_back(static_cast<uint32_t>(soup->vertices.size() - 1));
    } else if (lower == "endloop") {
      if (!in_loop) return r.Error("unexpected 'endloop'");
      in_loop = false;
    } else if (lower == "endfacet") {
      if (!in_facet || in_loop) return r.Error("unexpected 'endfacet'");
      in_facet = false;
      if (face.size() < 3) return r.Error(Cat("facet with ", face.size(), " vertices"));
      soup->faces.push_back(face);
      soup->face_markers.push_back(marker);
      soup->face_lines.push_back(face_line);
    } else {
      return r.Error(Cat("unexpected '", kw.substr(0, 40), "' in ASCII STL"));
    }
    if (r.Remaining() > 0 && lower != "solid") {
      return r.Error(Cat("unexpected '", r.Peek().substr(0, 40), "'"));
    }
  }
  if (in_solid || in_facet) return r.Error("unexpected end of file inside a solid");
  if (soup->faces.empty()) return r.Error("no facets");
  return absl::OkStatus();
}

}  // namespace

// Binary when the size is exactly 84 + 50 n for the count n at offset 80
// (ASCII files may start with "solid" in binary headers too); else ASCII.
absl::Status ReadStl(std::string_view bytes, const std::string& name, SurfaceSoup* soup) {
  soup->index_base = 1;  // facets and vertices numbered from 1 in messages, as TetGen does
  if (bytes.size() >= 84) {
    uint32_t n = 0;
    std::memcpy(&n, bytes.data() + 80, 4);
    if (bytes.size() == 84 + uint64_t{n} * 50) {
      if (n == 0) return absl::InvalidArgumentError(Cat(name, ":0: binary STL with no triangles"));
      return ReadBinaryStl(bytes, name, soup);
    }
  }
  size_t i = 0;
  while (i < bytes.size() && IsSpace(bytes[i])) ++i;
  if (Lower(bytes.substr(i, 5)) != "solid") {
    return absl::InvalidArgumentError(Cat(
        name, ":1: neither ASCII STL ('solid') nor binary STL (size ", bytes.size(),
        " is not 84 + 50 x the triangle count)"));
  }
  for (char c : bytes) {
    if (c == 0) return absl::InvalidArgumentError(Cat(name, ":1: NUL byte in ASCII STL"));
  }
  return ReadAsciiStl(bytes, name, soup);
}

// OBJ: v, f (a, a/b, a/b/c, a//c; negative = relative), l (polylines become
// free segments), g/o (group name -> facet marker, 1, 2, ... by first use;
// faces before any group get 0). Other statements are ignored.
absl::Status ReadObj(std::string_view bytes, const std::string& name, SurfaceSoup* soup) {
  LineReader r(bytes, name);
  std::map<std::string, int32_t, std::less<>> group_marker;
  int32_t marker = 0;
  soup->index_base = 1;
  soup->marker_names.assign(1, "");
  auto vertex_ref = [&](std::string_view tok, uint32_t* out) -> absl::Status {
    const size_t slash = tok.find('/');
    const std::string_view head = tok.substr(0, slash);
    int64_t v = 0;
    if (!ParseInt(head, &v)) return r.Error(Cat("bad vertex reference '", tok.substr(0, 40), "'"));
    const int64_t n = static_cast<int64_t>(soup->vertices.size());
    const int64_t idx = v < 0 ? n + v : v - 1;
    if (v == 0 || idx < 0 || idx >= n) {
      return r.Error(Cat("vertex reference ", v, " out of range (", n, " vertices so far)"));
    }
    *out = static_cast<uint32_t>(idx);
    return absl::OkStatus();
  };
  uint32_t face_count = 0;
  while (r.NextLine()) {
    const std::string_view kw = r.Take();
    if (kw == "v") {
      Vec3 p;
      if (absl::Status s = ReadXyz(r, &p, "vertex"); !s.ok()) return s;
      soup->vertices.push_back(p);
      soup->vertex_lines.push_back(static_cast<uint32_t>(r.line()));
    } else if (kw == "f" || kw == "fo") {
      if (r.Remaining() < 3) return r.Error(Cat("face with ", r.Remaining(), " vertices"));
      std::vector<uint32_t> face;
      while (r.Remaining() > 0) {
        uint32_t idx = 0;
        if (absl::Status s = vertex_ref(r.Take(), &idx); !s.ok()) return s;
        face.push_back(idx);
      }
      soup->faces.push_back(std::move(face));
      soup->face_markers.push_back(marker);
      soup->face_lines.push_back(static_cast<uint32_t>(r.line()));
      ++face_count;
    } else if (kw == "l") {
      if (r.Remaining() < 2) return r.Error("line element with fewer than 2 vertices");
      uint32_t prev = 0;
      if (absl::Status s = vertex_ref(r.Take(), &prev); !s.ok()) return s;
      while (r.Remaining() > 0) {
        uint32_t idx = 0;
        if (absl::Status s = vertex_ref(r.Take(), &idx); !s.ok()) return s;
        soup->segments.push_back({prev, idx, marker});
        prev = idx;
      }
    } else if (kw == "g" || kw == "o") {
      std::string group;
      if (r.Remaining() > 0) {
        const std::string_view raw = r.raw_line();
        group = std::string(Strip(raw.substr(r.Peek().data() - raw.data())));
      }
      if (group.empty() || group == "default") {
        marker = 0;
      } else {
        auto it = group_marker.find(group);
        if (it == group_marker.end()) {
          marker = static_cast<int32_t>(group_marker.size()) + 1;
          group_marker.emplace(group, marker);
          soup->marker_names.push_back(group);
        } else {
          marker = it->second;
        }
      }
      r.SkipRestOfLine();
    } else if (kw == "vn" || kw == "vt" || kw == "vp" || kw == "s" || kw == "usemtl" ||
               kw == "mtllib" || kw == "p" || kw == "cstype" || kw == "deg" ||
               kw == "curv" || kw == "surf" || kw == "parm" || kw == "end") {
      r.SkipRestOfLine();
    } else {
      return r.Error(Cat("unknown OBJ statement '", kw.substr(0, 40), "'"));
    }
  }
  if (soup->vertices.empty()) return r.Error("no vertices");
  if (soup->marker_names.size() == 1) soup->marker_names.clear();
  return absl::OkStatus();
}

// Medit .mesh (ASCII): MeshVersionFormatted, Dimension 3, Vertices
// (x y z ref), Triangles / Quadrilaterals (1-based ids + ref = facet marker),
// Edges (free segments), End. Volume elements and other known blocks are skipped.
absl::Status ReadMedit(std::string_view bytes, const std::string& name, SurfaceSoup* soup) {
  LineReader r(bytes, name);
  soup->index_base = 1;
  // Entries per item of the blocks we skip.
  static const std::map<std::string, int, std::less<>> kSkip = {
      {"Corners", 1}, {"Ridges", 1}, {"RequiredVertices", 1}, {"RequiredEdges", 1},
      {"RequiredTriangles", 1}, {"RequiredQuadrilaterals", 1}, {"Normals", 3},
      {"NormalAtVertices", 2}, {"Tangents", 3}, {"TangentAtVertices", 2},
      {"TangentAtEdges", 3}, {"Tetrahedra", 5}, {"Hexahedra", 9}, {"Prisms", 7},
      {"Pyramids", 6}, {"Identifier", 0}, {"Geometry", 0}};
  bool have_dim = false;
  std::string_view tok;
  while (true) {
    if (r.Remaining() == 0 && !r.NextLine()) break;
    const std::string_view kw = r.Take();
    if (kw == "End") {
      r.SkipRestOfLine();
      if (r.NextLine()) return r.Error("data after 'End'");
      break;
    }
    int64_t v = 0;
    if (kw == "MeshVersionFormatted") {
      if (absl::Status s = r.NextInt("the mesh version", &v); !s.ok()) return s;
      if (v < 1 || v > 4) return r.Error(Cat("unsupported MeshVersionFormatted ", v));
      continue;
    }
    if (kw == "Dimension") {
      if (absl::Status s = r.NextInt("the dimension", &v); !s.ok()) return s;
      if (v != 3) return r.Error(Cat("dimension ", v, " is not supported (only 3)"));
      have_dim = true;
      continue;
    }
    int64_t n = 0;
    const size_t block_line = r.line();
    auto count = [&]() -> absl::Status {
      if (absl::Status s = r.NextInt(Cat("the number of ", kw), &n); !s.ok()) return s;
      if (n < 0 || n >= kMaxCount) return r.Error(Cat("invalid number of ", kw, " ", n));
      return absl::OkStatus();
    };
    if (kw == "Vertices") {
      if (!have_dim) return r.Error("'Vertices' before 'Dimension 3'");
      if (absl::Status s = count(); !s.ok()) return s;
      soup->vertices.reserve(soup->vertices.size() + CappedReserve(n, r.bytes_left(), 8));
      for (int64_t i = 0; i < n; ++i) {
        Vec3 p;
        for (int k = 0; k < 3; ++k) {
          if (absl::Status s = r.NextDouble("a vertex coordinate", &p[k]); !s.ok()) return s;
        }
        int64_t ref = 0;
        if (absl::Status s = r.NextInt("a vertex reference", &ref); !s.ok()) return s;
        soup->vertices.push_back(p);
        soup->vertex_lines.push_back(static_cast<uint32_t>(r.line()));
        soup->vertex_markers.push_back(static_cast<int32_t>(ref));
      }
    } else if (kw == "Triangles" || kw == "Quadrilaterals" || kw == "Edges") {
      const int k = kw == "Triangles" ? 3 : (kw == "Edges" ? 2 : 4);
      if (absl::Status s = count(); !s.ok()) return s;
      for (int64_t i = 0; i < n; ++i) {
        std::vector<uint32_t> face;
        for (int c = 0; c < k; ++c) {
          if (absl::Status s = r.NextInt("a vertex id", &v); !s.ok()) return s;
          if (v < 1 || v > static_cast<int64_t>(soup->vertices.size())) {
            return r.Error(Cat(kw, " ", i + 1, ": vertex id ", v, " out of range (1..",
                                        soup->vertices.size(), ")"));
          }
          face.push_back(static_cast<uint32_t>(v - 1));
        }
        int64_t ref = 0;
        if (absl::Status s = r.NextInt("an element reference", &ref); !s.ok()) return s;
        if (ref < INT32_MIN || ref > INT32_MAX) return r.Error(Cat("reference ", ref, " out of range"));
        if (k == 2) {
          soup->segments.push_back({face[0], face[1], static_cast<int32_t>(ref)});
        } else {
          soup->faces.push_back(std::move(face));
          soup->face_markers.push_back(static_cast<int32_t>(ref));
          soup->face_lines.push_back(static_cast<uint32_t>(r.line()));
        }
      }
    } else if (auto it = kSkip.find(kw); it != kSkip.end()) {
      if (it->second == 0) {  // a keyword followed by one value
        if (absl::Status s = r.NextToken(kw, &tok); !s.ok()) return s;
        continue;
      }
      if (absl::Status s = count(); !s.ok()) return s;
      for (int64_t i = 0; i < n * it->second; ++i) {
        if (absl::Status s = r.NextToken(kw, &tok); !s.ok()) return s;
      }
    } else {
      return r.Error(Cat("unknown Medit keyword '", kw.substr(0, 40), "'"));
    }
    (void)block_line;
  }
  if (soup->vertices.empty()) return r.Error("no Vertices block");
  return absl::OkStatus();
}

}  // namespace svrc::plc::internal
