// Result container size and speed (docs/container.md) on two >= 1e6-tet
// meshes, against raw binary and zlib level 6 (what gzip -6 does, minus its
// 18-byte wrapper):
//   grid:     a box of n^3 cubes split into 6 Kuhn tets each, interior
//             vertices jittered by up to 0.2 of the spacing, vertices in
//             Hilbert order (tests/codec/grid_mesh.h), canonicalized;
//   delaunay: the Delaunay tetrahedralization (core/delaunay/point_set.h) of
//             uniform random points in the unit cube, hull faces as
//             triangles, once in the points' input (random) order — the
//             canonical order of a point-set job — and once with the points
//             renumbered along mesh::SpatialOrder first.
// Usage: codec_bench [grid cubes per axis = 56] [random points = 170000; 0: grid only]
#include <algorithm>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <zlib.h>

#include "core/codec/byte_io.h"
#include "core/codec/container.h"
#include "core/delaunay/point_set.h"
#include "core/mesh/canonical.h"
#include "tests/codec/grid_mesh.h"

namespace {

using namespace svrc;

// Process CPU time: the bench is single-threaded and the machine is shared,
// so CPU seconds are what an idle machine's wall clock would show.
double Now() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

// The mesh as plain little-endian arrays: positions (float64), tets (uint32),
// tet regions (int32), triangles (uint32), markers (int32).
std::string RawBytes(const mesh::TetMesh& m) {
  std::string raw;
  auto put = [&](const void* p, size_t n) { raw.append(static_cast<const char*>(p), n); };
  put(m.positions.data(), m.positions.size() * 24);
  put(m.tets.data(), m.tets.size() * 16);
  put(m.tet_region.data(), m.tet_region.size() * 4);
  put(m.triangles.data(), m.triangles.size() * 12);
  put(m.triangle_marker.data(), m.triangle_marker.size() * 4);
  return raw;
}

size_t Zlib6(const std::string& raw, double* seconds) {
  uLongf n = compressBound(raw.size());
  std::vector<Bytef> out(n);
  const double t0 = Now();
  if (compress2(out.data(), &n, reinterpret_cast<const Bytef*>(raw.data()), raw.size(), 6) != Z_OK) {
    std::fprintf(stderr, "zlib failed\n");
    std::exit(1);
  }
  *seconds = Now() - t0;
  return n;
}

std::map<std::string, size_t> SectionSizes(const std::string& bytes) {
  std::map<std::string, size_t> sizes;
  std::vector<codec::Section> sections;
  codec::SplitSections(std::string_view(bytes).substr(8), &sections);
  for (const codec::Section& s : sections) sizes[std::string(s.tag)] = 12 + s.payload.size();
  return sizes;
}

bool Same(const mesh::TetMesh& a, const mesh::TetMesh& b, bool positions) {
  if (positions && std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * 24) != 0) {
    return false;
  }
  return a.positions.size() == b.positions.size() && a.tets == b.tets &&
         a.tet_region == b.tet_region && a.triangles == b.triangles &&
         a.triangle_marker == b.triangle_marker;
}

void Run(const char* name, const mesh::TetMesh& m) {
  const std::string raw = RawBytes(m);
  double zsec = 0;
  const size_t z = Zlib6(raw, &zsec);
  std::printf("\n### %s: %zu vertices, %zu tets, %zu triangles\n\n", name, m.positions.size(),
              m.tets.size(), m.triangles.size());
  std::printf("raw binary (N*24 + M*16 + M*4 regions + T*12 + T*4 markers): %zu bytes; "
              "zlib -6 of raw: %zu bytes (%.1f%% of raw, %.0f CPU ms)\n\n",
              raw.size(), z, 100.0 * z / raw.size(), 1e3 * zsec);
  std::printf("| positions | container bytes | %% of raw | %% of zlib-6 | positions | tets | "
              "triangles | bits/tet (tets part) | encode CPU ms | decode CPU ms | max error (bound) | "
              "collapsed / inverted |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (int bits : {0, 20, 16}) {
    codec::EncodeOptions o;
    o.position_quantization_bits = bits;
    codec::EncodeReport rep;
    std::string bytes;
    double enc = 1e9, dec = 1e9;
    bool ok = true;
    for (int rep_i = 0; rep_i < 2; ++rep_i) {
      const double t0 = Now();
      absl::StatusOr<std::string> b = codec::EncodeTetMesh(m, o, &rep);
      enc = std::min(enc, Now() - t0);
      if (!b.ok()) {
        std::fprintf(stderr, "encode: %s\n", std::string(b.status().message()).c_str());
        std::exit(1);
      }
      bytes = std::move(*b);
      const double t1 = Now();
      absl::StatusOr<mesh::TetMesh> back = codec::DecodeTetMesh(bytes);
      dec = std::min(dec, Now() - t1);
      ok = ok && back.ok() && Same(m, *back, bits == 0);
    }
    if (!ok) {
      std::fprintf(stderr, "round trip mismatch at %d bits\n", bits);
      std::exit(1);
    }
    const auto s = SectionSizes(bytes);
    const size_t pos = bits == 0 ? s.at("POSL") : s.at("POSQ");
    char err[64] = "exact";
    if (bits > 0) std::snprintf(err, sizeof err, "%.2g (%.2g)", rep.max_position_error, rep.position_error_bound);
    std::printf("| %s | %zu | %.1f | %.1f | %zu | %zu | %zu | %.2f | %.0f | %.0f | %s | %llu / %llu |\n",
                bits == 0 ? "lossless f64" : (bits == 20 ? "20-bit" : "16-bit"), bytes.size(),
                100.0 * bytes.size() / raw.size(), 100.0 * bytes.size() / z, pos, s.at("TETS"),
                s.at("TRIS"), 8.0 * s.at("TETS") / m.tets.size(), 1e3 * enc, 1e3 * dec, err,
                static_cast<unsigned long long>(rep.collapsed_tets),
                static_cast<unsigned long long>(rep.inverted_tets));
  }
}

// Faces of exactly one tet, oriented outwards, with marker 1.
void AddHull(mesh::TetMesh* m) {
  std::vector<std::pair<std::array<uint32_t, 3>, std::array<uint32_t, 3>>> faces;  // sorted, oriented
  for (const auto& t : m->tets) {
    const std::array<std::array<uint32_t, 3>, 4> f = {{{t[1], t[2], t[3]}, {t[0], t[3], t[2]},
                                                       {t[0], t[1], t[3]}, {t[0], t[2], t[1]}}};
    for (const auto& o : f) {
      auto s = o;
      std::sort(s.begin(), s.end());
      faces.push_back({s, o});
    }
  }
  std::sort(faces.begin(), faces.end());
  for (size_t i = 0; i < faces.size();) {
    size_t j = i;
    while (j < faces.size() && faces[j].first == faces[i].first) ++j;
    if (j - i == 1) {
      m->triangles.push_back(faces[i].second);
      m->triangle_marker.push_back(1);
    }
    i = j;
  }
}

mesh::TetMesh DelaunayMesh(const std::vector<mesh::Vec3>& pts) {
  absl::StatusOr<delaunay::PointSetResult> r = delaunay::TetrahedralizePointSet(pts);
  if (!r.ok()) {
    std::fprintf(stderr, "delaunay: %s\n", std::string(r.status().message()).c_str());
    std::exit(1);
  }
  mesh::TetMesh m;
  m.positions = pts;
  m.num_input_vertices = static_cast<uint32_t>(pts.size());
  m.tets = std::move(r->tets);
  m.tet_region.assign(m.tets.size(), 0);
  m.regions = {{0, 0}};
  AddHull(&m);
  mesh::Canonicalize(&m);
  m.provenance = {"svrc 0.1.0", "point set", ""};
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::atoi(argv[1]) : 56;
  const int np = argc > 2 ? std::atoi(argv[2]) : 170000;
  codec::testing::GridMeshOptions o;
  o.nx = o.ny = o.nz = n;
  o.spacing = 1.0 / n;
  o.jitter = 0.2;
  o.hilbert_order = true;
  Run("grid (jittered, Hilbert order)", codec::testing::MakeGridMesh(o));

  if (np < 4) return 0;
  std::mt19937_64 rng(7);
  std::vector<mesh::Vec3> pts(np);
  for (auto& p : pts) {
    for (int a = 0; a < 3; ++a) p[a] = static_cast<double>(rng() >> 11) * 0x1p-53;
  }
  Run("delaunay of uniform random points, input (random) order", DelaunayMesh(pts));
  const std::vector<uint32_t> order = mesh::SpatialOrder(pts);
  std::vector<mesh::Vec3> sorted(np);
  for (int i = 0; i < np; ++i) sorted[i] = pts[order[i]];
  Run("delaunay of the same points renumbered along SpatialOrder (Hilbert)", DelaunayMesh(sorted));
  return 0;
}
