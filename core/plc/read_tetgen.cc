// TetGen .node / .poly / .smesh readers (TetGen 1.5 manual, "File formats").
// Index base: the number of the first node decides (0 or 1), as in TetGen.
#include <cmath>
#include <string>

#include "absl/strings/str_cat.h"
#include "core/plc/read_internal.h"
#include "core/plc/read_util.h"

namespace svrc::plc::internal {
namespace {

constexpr int64_t kMaxCount = int64_t{1} << 31;

// Part 1: `<#points> <dim> <#attributes> <#boundary markers>` then the points.
// Returns the number of points read (0 is allowed only when `allow_empty`:
// then the points are in a separate .node file).
absl::Status ReadNodeSection(LineReader& r, Plc* plc, bool allow_empty) {
  if (!r.NextLine()) return r.Error("empty file: expected the node list header");
  const size_t header_line = r.line();
  int64_t n = 0, dim = 3, nattr = 0, nbm = 0;
  absl::Status err;
  if (!r.LineInt(&n, &err)) return err.ok() ? r.Error("expected the number of points") : err;
  if (r.Remaining() > 0 && !r.LineInt(&dim, &err)) return err;
  if (r.Remaining() > 0 && !r.LineInt(&nattr, &err)) return err;
  if (r.Remaining() > 0 && !r.LineInt(&nbm, &err)) return err;
  if (n < 0 || n >= kMaxCount) return r.Error(Cat("invalid number of points ", n));
  if (n == 0 && !allow_empty) return r.Error("no points");
  if (dim != 3) return r.Error(Cat("dimension ", dim, " is not supported (only 3)"));
  if (nattr < 0 || nattr > 1000) return r.Error(Cat("invalid number of attributes ", nattr));
  if (nbm != 0 && nbm != 1) return r.Error(Cat("invalid number of boundary markers ", nbm, " (0 or 1)"));
  (void)header_line;
  const size_t reserve = CappedReserve(n, r.bytes_left(), 8);
  plc->vertices.reserve(reserve);
  plc->vertex_lines.reserve(reserve);
  if (nbm) plc->vertex_markers.reserve(reserve);
  for (int64_t i = 0; i < n; ++i) {
    if (!r.NextLine()) {
      return r.Error(Cat("unexpected end of file: expected ", n, " points, found ", i));
    }
    int64_t id = 0;
    if (!r.LineInt(&id, &err)) return err;
    if (i == 0) {
      if (id != 0 && id != 1) return r.Error(Cat("first point number must be 0 or 1, got ", id));
      plc->index_base = static_cast<uint32_t>(id);
    } else if (id != static_cast<int64_t>(plc->index_base) + i) {
      return r.Error(Cat("point number ", id, " out of sequence (expected ",
                                  static_cast<int64_t>(plc->index_base) + i, ")"));
    }
    Vec3 p;
    for (int k = 0; k < 3; ++k) {
      if (!r.LineDouble(&p[k], &err)) {
        return err.ok() ? r.Error(Cat("point ", id, " has no ", "xyz"[k], " coordinate")) : err;
      }
    }
    for (int64_t a = 0; a < nattr; ++a) {
      double attr;
      if (!r.LineDouble(&attr, &err)) {
        if (!err.ok()) return err;
        break;  // missing attributes default to 0, as in TetGen
      }
    }
    if (nbm) {
      int64_t m = 0;
      if (!r.LineInt(&m, &err) && !err.ok()) return err;
      if (m < INT32_MIN || m > INT32_MAX) return r.Error(Cat("marker ", m, " out of range"));
      plc->vertex_markers.push_back(static_cast<int32_t>(m));
    }
    plc->vertices.push_back(p);
    plc->vertex_lines.push_back(static_cast<uint32_t>(r.line()));
  }
  return absl::OkStatus();
}

// A vertex number of the file -> 0-based index, with range check.
absl::Status VertexIndex(LineReader& r, const Plc& plc, int64_t v, size_t facet, size_t polygon,
                         uint32_t* out) {
  const int64_t base = plc.index_base;
  const int64_t n = static_cast<int64_t>(plc.vertices.size());
  if (v < base || v >= base + n) {
    return r.Error(Cat("facet ", facet + base, " polygon ", polygon + base,
                                ": vertex index ", v, " out of range (points are numbered ",
                                base, "..", base + n - 1, ")"));
  }
  *out = static_cast<uint32_t>(v - base);
  return absl::OkStatus();
}

absl::Status ReadPolygon(LineReader& r, Plc* plc, size_t facet, size_t polygon, int64_t k,
                         Polygon* poly) {
  if (k < 1 || k >= kMaxCount) {
    return r.Error(Cat("facet ", facet + plc->index_base, " polygon ",
                                polygon + plc->index_base, ": invalid number of corners ", k));
  }
  poly->vertices.reserve(CappedReserve(k, r.bytes_left() + r.raw_line().size(), 2));
  for (int64_t i = 0; i < k; ++i) {
    int64_t v = 0;
    if (absl::Status s = r.NextInt("a polygon corner", &v); !s.ok()) return s;
    uint32_t idx = 0;
    if (absl::Status s = VertexIndex(r, *plc, v, facet, polygon, &idx); !s.ok()) return s;
    poly->vertices.push_back(idx);
  }
  if (k == 1) {
    return r.Error(Cat("facet ", facet + plc->index_base, " polygon ",
                                polygon + plc->index_base, " has a single corner"));
  }
  return absl::OkStatus();
}

// Adds a facet; a facet made only of 2-vertex polygons becomes free segments.
void AddFacet(Plc* plc, Facet f, uint32_t line) {
  bool has_loop = false;
  for (const Polygon& p : f.polygons) has_loop |= p.vertices.size() >= 3;
  if (!has_loop) {
    for (const Polygon& p : f.polygons) {
      plc->segments.push_back({p.vertices[0], p.vertices[1], f.marker});
    }
    return;
  }
  plc->facets.push_back(std::move(f));
  plc->facet_lines.push_back(line);
}

absl::Status ReadSeedPoint(LineReader& r, Vec3* p, std::string_view what) {
  for (int k = 0; k < 3; ++k) {
    if (absl::Status s = r.NextDouble(what, &(*p)[k]); !s.ok()) return s;
  }
  return absl::OkStatus();
}

absl::Status ReadHolesAndRegions(LineReader& r, Plc* plc) {
  // Parts 3 and 4 may be missing at the end of the file (TetGen reads 0).
  if (!r.NextLine()) return absl::OkStatus();
  int64_t nh = 0;
  absl::Status err;
  if (!r.LineInt(&nh, &err)) return err;
  if (nh < 0 || nh >= kMaxCount) return r.Error(Cat("invalid number of holes ", nh));
  for (int64_t i = 0; i < nh; ++i) {
    if (!r.NextLine()) return r.Error(Cat("unexpected end of file: expected ", nh, " holes, found ", i));
    int64_t id;
    if (!r.LineInt(&id, &err)) return err;
    Vec3 p;
    for (int k = 0; k < 3; ++k) {
      if (!r.LineDouble(&p[k], &err)) return err.ok() ? r.Error(Cat("hole ", id, " has no ", "xyz"[k], " coordinate")) : err;
    }
    plc->holes.push_back(p);
  }
  if (!r.NextLine()) return absl::OkStatus();
  int64_t nr = 0;
  if (!r.LineInt(&nr, &err)) return err;
  if (nr < 0 || nr >= kMaxCount) return r.Error(Cat("invalid number of regions ", nr));
  for (int64_t i = 0; i < nr; ++i) {
    if (!r.NextLine()) return r.Error(Cat("unexpected end of file: expected ", nr, " regions, found ", i));
    int64_t id;
    if (!r.LineInt(&id, &err)) return err;
    RegionSeed seed;
    for (int k = 0; k < 3; ++k) {
      if (!r.LineDouble(&seed.point[k], &err)) return err.ok() ? r.Error(Cat("region ", id, " has no ", "xyz"[k], " coordinate")) : err;
    }
    if (!r.LineDouble(&seed.attribute, &err) && !err.ok()) return err;
    seed.max_volume = -1;
    if (!r.LineDouble(&seed.max_volume, &err) && !err.ok()) return err;
    plc->regions.push_back(seed);
  }
  if (r.NextLine()) return r.Error("unexpected data after the region list");
  return absl::OkStatus();
}

}  // namespace

absl::Status ReadTetgen(std::string_view bytes, InputFormat format, Plc* plc,
                        const NodeLoader& load_nodes) {
  LineReader r(bytes, plc->source_name);
  if (absl::Status s = ReadNodeSection(r, plc, format != InputFormat::kNode); !s.ok()) return s;
  if (format == InputFormat::kNode) {
    if (r.NextLine()) return r.Error("unexpected data after the point list");
    return absl::OkStatus();
  }
  if (plc->vertices.empty()) {
    // Points in a separate .node file (TetGen: "0" in the .poly node header).
    if (!load_nodes) return r.Error("the point list is empty and no .node file is available");
    absl::StatusOr<std::string> node_bytes = load_nodes();
    if (!node_bytes.ok()) return node_bytes.status();
    Plc nodes;
    nodes.source_name = plc->source_name.substr(0, plc->source_name.rfind('.')) + ".node";
    LineReader nr(*node_bytes, nodes.source_name);
    if (absl::Status s = ReadNodeSection(nr, &nodes, false); !s.ok()) return s;
    plc->vertices = std::move(nodes.vertices);
    plc->vertex_markers = std::move(nodes.vertex_markers);
    plc->index_base = nodes.index_base;
    plc->vertex_lines.assign(plc->vertices.size(), 0);
  }
  if (!r.NextLine()) return r.Error("unexpected end of file: expected the facet list header");
  int64_t nf = 0, fbm = 0;
  absl::Status err;
  if (!r.LineInt(&nf, &err)) return err;
  if (r.Remaining() > 0 && !r.LineInt(&fbm, &err)) return err;
  if (nf < 0 || nf >= kMaxCount) return r.Error(Cat("invalid number of facets ", nf));
  if (fbm != 0 && fbm != 1) return r.Error(Cat("invalid boundary marker flag ", fbm));
  const uint32_t base = plc->index_base;
  for (int64_t f = 0; f < nf; ++f) {
    if (!r.NextLine()) {
      return r.Error(Cat("unexpected end of file: expected ", nf, " facets, found ", f));
    }
    const uint32_t line = static_cast<uint32_t>(r.line());
    Facet facet;
    if (format == InputFormat::kSmesh) {
      int64_t k = 0;
      if (!r.LineInt(&k, &err)) return err;
      Polygon poly;
      if (absl::Status s = ReadPolygon(r, plc, f, 0, k, &poly); !s.ok()) return s;
      facet.polygons.push_back(std::move(poly));
      if (fbm) {
        int64_t m = 0;
        if (!r.LineInt(&m, &err) && !err.ok()) return err;
        if (m < INT32_MIN || m > INT32_MAX) return r.Error(Cat("marker ", m, " out of range"));
        facet.marker = static_cast<int32_t>(m);
      }
      if (r.Remaining() > 0) return r.Error(Cat("facet ", f + base, ": unexpected '", r.Peek().substr(0, 40), "'"));
    } else {
      int64_t np = 0, nh = 0, m = 0;
      if (!r.LineInt(&np, &err)) return err;
      if (r.Remaining() > 0 && !r.LineInt(&nh, &err)) return err;
      if (fbm && r.Remaining() > 0 && !r.LineInt(&m, &err)) return err;
      if (np < 1 || np >= kMaxCount) return r.Error(Cat("facet ", f + base, ": invalid number of polygons ", np));
      if (nh < 0 || nh >= kMaxCount) return r.Error(Cat("facet ", f + base, ": invalid number of holes ", nh));
      if (m < INT32_MIN || m > INT32_MAX) return r.Error(Cat("marker ", m, " out of range"));
      facet.marker = static_cast<int32_t>(m);
      for (int64_t p = 0; p < np; ++p) {
        // As in TetGen, each polygon starts on a new line (its corners may
        // continue on the following ones); the rest of a line is ignored.
        r.SkipRestOfLine();
        int64_t k = 0;
        if (absl::Status s = r.NextInt("the number of polygon corners", &k); !s.ok()) return s;
        Polygon poly;
        if (absl::Status s = ReadPolygon(r, plc, f, p, k, &poly); !s.ok()) return s;
        facet.polygons.push_back(std::move(poly));
      }
      for (int64_t h = 0; h < nh; ++h) {
        r.SkipRestOfLine();
        int64_t id = 0;
        if (absl::Status s = r.NextInt("a facet hole number", &id); !s.ok()) return s;
        Vec3 p;
        if (absl::Status s = ReadSeedPoint(r, &p, "a facet hole coordinate"); !s.ok()) return s;
        facet.holes.push_back(p);
      }
    }
    AddFacet(plc, std::move(facet), line);
  }
  return ReadHolesAndRegions(r, plc);
}

}  // namespace svrc::plc::internal
