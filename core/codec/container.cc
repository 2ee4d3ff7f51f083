// The result container (docs/container.md): a versioned envelope of
// length-prefixed sections around Draco-coded columns (draco_columns.h).
#include "core/codec/container.h"

#include <array>
#include <cmath>
#include <cstring>
#include <limits>

#include "absl/status/status.h"
#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"
#include "core/codec/byte_io.h"
#include "core/codec/draco_columns.h"
#include "core/codec/quantize.h"
#include "core/util/sha256.h"

namespace svrc::codec {
namespace {

constexpr char kMagic[4] = {'S', 'V', 'R', 'C'};
constexpr uint16_t kFormatVersion = 1;
constexpr size_t kHeaderSize = 8;            // magic, version, flags
constexpr size_t kSectionHeaderSize = 12;    // tag, u64 length
constexpr size_t kDigestSize = 32;
constexpr size_t kHashSectionSize = kSectionHeaderSize + kDigestSize;

// Header flags. A decoder rejects bits it does not know.
constexpr uint16_t kFlagQuantized = 1;        // positions in POSQ, not POSL
constexpr uint16_t kFlagTetRegions = 2;       // TETS carries a region column
constexpr uint16_t kFlagTriangleMarkers = 4;  // TRIS carries a marker column
constexpr uint16_t kKnownFlags = kFlagQuantized | kFlagTetRegions | kFlagTriangleMarkers;

using Tag = std::array<char, 4>;
constexpr Tag kProv = {'P', 'R', 'O', 'V'};
constexpr Tag kCounts = {'C', 'N', 'T', 'S'};
constexpr Tag kPosLossless = {'P', 'O', 'S', 'L'};
constexpr Tag kPosQuantized = {'P', 'O', 'S', 'Q'};
constexpr Tag kTets = {'T', 'E', 'T', 'S'};
constexpr Tag kTris = {'T', 'R', 'I', 'S'};
constexpr Tag kHash = {'H', 'A', 'S', 'H'};

absl::Status Invalid(std::string_view what) {
  return absl::InvalidArgumentError(absl::StrCat("container: ", std::string(what)));
}

void WriteSection(ByteWriter* w, const Tag& tag, std::string_view payload) {
  w->Bytes(std::string_view(tag.data(), 4));
  w->U64(payload.size());
  w->Bytes(payload);
}

// A 32-bit column as two 16-bit columns, high half first.
void AppendU32(const std::vector<uint32_t>& values, std::vector<Column>* columns) {
  Column hi(values.size()), lo(values.size());
  for (size_t i = 0; i < values.size(); ++i) {
    hi[i] = static_cast<uint16_t>(values[i] >> 16);
    lo[i] = static_cast<uint16_t>(values[i]);
  }
  columns->push_back(std::move(hi));
  columns->push_back(std::move(lo));
}
uint32_t U32At(const std::vector<Column>& columns, size_t first, size_t i) {
  return (static_cast<uint32_t>(columns[first][i]) << 16) | columns[first + 1][i];
}

// Simplices (tets: k = 4, triangles: k = 3) as delta-friendly 32-bit columns:
// the first id as a difference from the previous simplex's first id, the
// others as differences from the first id, all mod 2^32. Canonical meshes
// (smallest id first, sorted) make all of these small and non-negative;
// any other order still round-trips exactly, it only compresses worse.
template <size_t K>
std::vector<Column> SimplexColumns(const std::vector<std::array<uint32_t, K>>& simplices,
                                   const std::vector<int32_t>& labels) {
  std::vector<Column> columns;
  std::vector<uint32_t> v(simplices.size());
  uint32_t prev = 0;
  for (size_t i = 0; i < simplices.size(); ++i) {
    v[i] = simplices[i][0] - prev;
    prev = simplices[i][0];
  }
  AppendU32(v, &columns);
  for (size_t j = 1; j < K; ++j) {
    for (size_t i = 0; i < simplices.size(); ++i) v[i] = simplices[i][j] - simplices[i][0];
    AppendU32(v, &columns);
  }
  if (!labels.empty()) {
    for (size_t i = 0; i < labels.size(); ++i) v[i] = static_cast<uint32_t>(labels[i]);
    AppendU32(v, &columns);
  }
  return columns;
}

template <size_t K>
absl::Status SimplicesFromColumns(const std::vector<Column>& columns, uint32_t n,
                                  uint32_t num_vertices, bool has_labels,
                                  std::vector<std::array<uint32_t, K>>* simplices,
                                  std::vector<int32_t>* labels) {
  simplices->resize(n);
  uint32_t prev = 0;
  for (uint32_t i = 0; i < n; ++i) {
    auto& s = (*simplices)[i];
    s[0] = prev + U32At(columns, 0, i);
    prev = s[0];
    for (size_t j = 1; j < K; ++j) s[j] = s[0] + U32At(columns, 2 * j, i);
    for (size_t j = 0; j < K; ++j) {
      if (s[j] >= num_vertices) {
        return Invalid(absl::StrCat(K == 4 ? "tet " : "triangle ", i, " has vertex id ", s[j],
                                    " >= ", num_vertices, " vertices"));
      }
    }
  }
  if (has_labels) {
    labels->resize(n);
    for (uint32_t i = 0; i < n; ++i) (*labels)[i] = static_cast<int32_t>(U32At(columns, 2 * K, i));
  }
  return absl::OkStatus();
}

template <size_t K>
absl::Status CheckSimplices(const std::vector<std::array<uint32_t, K>>& simplices,
                            const std::vector<int32_t>& labels, size_t num_vertices,
                            std::string_view what) {
  if (simplices.size() > kMaxElements) {
    return absl::ResourceExhaustedError(absl::StrCat("container: too many ", std::string(what)));
  }
  if (!labels.empty() && labels.size() != simplices.size()) {
    return Invalid(absl::StrCat(std::string(what), ": ", labels.size(), " labels for ", simplices.size()));
  }
  for (size_t i = 0; i < simplices.size(); ++i) {
    for (uint32_t id : simplices[i]) {
      if (id >= num_vertices) {
        return Invalid(absl::StrCat(std::string(what), " ", i, " has vertex id ", id, " >= ", num_vertices));
      }
    }
  }
  return absl::OkStatus();
}

// Lossless positions: each float64's 64 bits as four 16-bit columns, most
// significant first, axes x, y, z (12 columns). Sign/exponent and the top of
// the mantissa vary slowly along a spatially coherent order, so Draco's
// difference prediction takes them down to a few bits; low halves of random
// coordinates stay close to 16 bits.
constexpr size_t kLosslessColumns = 12;

std::vector<Column> LosslessColumns(const std::vector<mesh::Vec3>& positions) {
  std::vector<Column> columns(kLosslessColumns, Column(positions.size()));
  for (size_t i = 0; i < positions.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      uint64_t bits;
      const double x = positions[i][a];
      std::memcpy(&bits, &x, 8);
      for (int c = 0; c < 4; ++c) {
        columns[4 * a + c][i] = static_cast<uint16_t>(bits >> (16 * (3 - c)));
      }
    }
  }
  return columns;
}

std::vector<mesh::Vec3> PositionsFromLossless(const std::vector<Column>& columns, uint32_t n) {
  std::vector<mesh::Vec3> positions(n);
  for (uint32_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) {
      uint64_t bits = 0;
      for (int c = 0; c < 4; ++c) bits = (bits << 16) | columns[4 * a + c][i];
      double x;
      std::memcpy(&x, &bits, 8);
      positions[i][a] = x;
    }
  }
  return positions;
}

// Quantized positions: per axis the lattice index q as one 16-bit column
// (bits <= 16) or two (high first).
size_t ColumnsPerAxis(int bits) { return bits > 16 ? 2 : 1; }

std::vector<Column> QuantizedColumns(const QuantizedPositions& qp) {
  const size_t per_axis = ColumnsPerAxis(qp.lattice.bits);
  const size_t n = qp.q.size();
  std::vector<Column> columns(3 * per_axis, Column(n));
  for (size_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) {
      const uint32_t q = qp.q[i][a];
      if (per_axis == 2) {
        columns[2 * a][i] = static_cast<uint16_t>(q >> 16);
        columns[2 * a + 1][i] = static_cast<uint16_t>(q);
      } else {
        columns[a][i] = static_cast<uint16_t>(q);
      }
    }
  }
  return columns;
}

struct Counts {
  uint32_t vertices = 0, input_vertices = 0, tets = 0, triangles = 0;
};

uint64_t DefaultMaxMeshBytes(size_t container_bytes) {
  return kDefaultMaxMeshBytesFloor + kDefaultMaxMeshBytesPerByte * static_cast<uint64_t>(container_bytes);
}

}  // namespace

absl::StatusOr<std::string> EncodeTetMesh(const mesh::TetMesh& mesh, const EncodeOptions& options,
                                          EncodeReport* report) {
  const int bits = options.position_quantization_bits;
  if (bits < 0 || bits > kMaxQuantizationBits) {
    return absl::InvalidArgumentError(absl::StrCat(
        "container: position_quantization_bits must be 0 (lossless) or 1..", kMaxQuantizationBits,
        ", got ", bits));
  }
  const size_t nv = mesh.positions.size();
  if (nv > kMaxElements) return absl::ResourceExhaustedError("container: too many vertices");
  if (mesh.num_input_vertices > nv) {
    return Invalid(absl::StrCat("num_input_vertices ", mesh.num_input_vertices, " > ", nv,
                                " vertices"));
  }
  if (absl::Status s = CheckSimplices(mesh.tets, mesh.tet_region, nv, "tet"); !s.ok()) return s;
  if (absl::Status s = CheckSimplices(mesh.triangles, mesh.triangle_marker, nv, "triangle");
      !s.ok()) {
    return s;
  }
  if (mesh.regions.size() > kMaxElements) return absl::ResourceExhaustedError("container: too many regions");
  for (const std::string* s : {&mesh.provenance.svrc_version, &mesh.provenance.parameters,
                               &mesh.provenance.input_sha256}) {
    if (s->size() > std::numeric_limits<uint32_t>::max()) {
      return Invalid("provenance string longer than 4 GiB");
    }
  }

  EncodeReport rep;
  uint16_t flags = 0;
  if (bits > 0) flags |= kFlagQuantized;
  if (!mesh.tet_region.empty()) flags |= kFlagTetRegions;
  if (!mesh.triangle_marker.empty()) flags |= kFlagTriangleMarkers;

  ByteWriter w;
  w.Bytes(std::string_view(kMagic, 4));
  w.U16(kFormatVersion);
  w.U16(flags);

  {
    ByteWriter p;
    p.String(mesh.provenance.svrc_version);
    p.String(mesh.provenance.parameters);
    p.String(mesh.provenance.input_sha256);
    WriteSection(&w, kProv, p.str());
  }
  {
    ByteWriter c;
    c.U32(static_cast<uint32_t>(nv));
    c.U32(mesh.num_input_vertices);
    c.U32(static_cast<uint32_t>(mesh.tets.size()));
    c.U32(static_cast<uint32_t>(mesh.triangles.size()));
    c.U32(static_cast<uint32_t>(mesh.regions.size()));
    for (const mesh::Region& r : mesh.regions) {
      c.F64(r.attribute);
      c.F64(r.max_volume);
    }
    WriteSection(&w, kCounts, c.str());
  }
  if (bits == 0) {
    absl::StatusOr<std::string> blob = EncodeColumns(LosslessColumns(mesh.positions), nv);
    if (!blob.ok()) return blob.status();
    WriteSection(&w, kPosLossless, *blob);
  } else {
    absl::StatusOr<QuantizedPositions> qp = Quantize(mesh.positions, bits);
    if (!qp.ok()) return qp.status();
    const QuantizationReport qr = MeasureQuantization(mesh, *qp);
    rep.max_position_error = qr.max_position_error;
    rep.position_error_bound = qr.position_error_bound;
    rep.collapsed_tets = qr.collapsed_tets;
    rep.inverted_tets = qr.inverted_tets;
    absl::StatusOr<std::string> blob = EncodeColumns(QuantizedColumns(*qp), nv);
    if (!blob.ok()) return blob.status();
    ByteWriter p;
    p.U8(static_cast<uint8_t>(bits));
    p.U32(static_cast<uint32_t>(qp->lattice.exponent));
    for (int a = 0; a < 3; ++a) p.I64(qp->lattice.origin[a]);
    p.Bytes(*blob);
    WriteSection(&w, kPosQuantized, p.str());
  }
  {
    absl::StatusOr<std::string> blob =
        EncodeColumns(SimplexColumns(mesh.tets, mesh.tet_region), mesh.tets.size());
    if (!blob.ok()) return blob.status();
    WriteSection(&w, kTets, *blob);
  }
  {
    absl::StatusOr<std::string> blob = EncodeColumns(
        SimplexColumns(mesh.triangles, mesh.triangle_marker), mesh.triangles.size());
    if (!blob.ok()) return blob.status();
    WriteSection(&w, kTris, *blob);
  }
  const util::Sha256::Digest digest = util::Sha256Digest(w.str());
  WriteSection(&w, kHash, std::string_view(reinterpret_cast<const char*>(digest.data()), digest.size()));

  rep.bytes = w.size();
  if (report != nullptr) *report = rep;
  return std::move(w.str());
}

absl::StatusOr<mesh::TetMesh> DecodeTetMesh(std::string_view bytes) {
  return DecodeTetMesh(bytes, DecodeOptions());
}

absl::StatusOr<mesh::TetMesh> DecodeTetMesh(std::string_view bytes, const DecodeOptions& options) {
  if (bytes.size() < kHeaderSize + kHashSectionSize) return Invalid("truncated (too short)");
  if (std::memcmp(bytes.data(), kMagic, 4) != 0) return Invalid("not an SVRC container (magic)");
  ByteReader header(bytes.substr(4, 4));
  uint16_t version = 0, flags = 0;
  header.U16(&version);
  header.U16(&flags);
  if (version != kFormatVersion) {
    return Invalid(absl::StrCat("format version ", version, " (this decoder reads ", kFormatVersion, ")"));
  }
  if ((flags & ~kKnownFlags) != 0) return Invalid(absl::StrCat("unknown flags ", flags));

  // Integrity first: accidental damage never reaches the parsers below.
  const std::string_view body = bytes.substr(0, bytes.size() - kHashSectionSize);
  {
    ByteReader h(bytes.substr(body.size()));
    std::string_view tag, digest;
    uint64_t length = 0;
    h.Bytes(4, &tag);
    h.U64(&length);
    h.Bytes(kDigestSize, &digest);
    if (tag != std::string_view(kHash.data(), 4) || length != kDigestSize) {
      return Invalid("truncated (no HASH section at the end)");
    }
    const util::Sha256::Digest actual = util::Sha256Digest(body);
    if (std::memcmp(actual.data(), digest.data(), kDigestSize) != 0) {
      return Invalid("sha256 mismatch: the container is damaged or truncated");
    }
  }

  // Sections, in any order, each at most once; unknown ancillary sections
  // (tag starting with a lowercase letter) are skipped.
  std::string_view prov, counts, posl, posq, tets, tris;
  bool seen_prov = false, seen_counts = false, seen_posl = false, seen_posq = false,
       seen_tets = false, seen_tris = false;
  std::vector<Section> sections;
  if (!SplitSections(body.substr(kHeaderSize), &sections)) {
    return Invalid("a section's length runs past the end");
  }
  for (const Section& section : sections) {
    const std::string_view tag_bytes = section.tag;
    const Tag tag = {tag_bytes[0], tag_bytes[1], tag_bytes[2], tag_bytes[3]};
    auto take = [&](bool* seen, std::string_view* slot) -> absl::Status {
      if (*seen) return Invalid(absl::StrCat("duplicate section '", std::string(tag_bytes), "'"));
      *seen = true;
      *slot = section.payload;
      return absl::OkStatus();
    };
    absl::Status s;
    if (tag == kProv) s = take(&seen_prov, &prov);
    else if (tag == kCounts) s = take(&seen_counts, &counts);
    else if (tag == kPosLossless) s = take(&seen_posl, &posl);
    else if (tag == kPosQuantized) s = take(&seen_posq, &posq);
    else if (tag == kTets) s = take(&seen_tets, &tets);
    else if (tag == kTris) s = take(&seen_tris, &tris);
    else if (tag[0] >= 'a' && tag[0] <= 'z') continue;
    else return Invalid(absl::StrCat("unknown required section '", absl::CEscape(std::string(tag_bytes)), "'"));
    if (!s.ok()) return s;
  }
  const bool quantized = (flags & kFlagQuantized) != 0;
  if (!seen_prov || !seen_counts || !seen_tets || !seen_tris) return Invalid("missing section");
  if (quantized ? (!seen_posq || seen_posl) : (!seen_posl || seen_posq)) {
    return Invalid("positions section does not match the flags");
  }

  mesh::TetMesh mesh;
  {
    ByteReader p(prov);
    if (!p.String(&mesh.provenance.svrc_version) || !p.String(&mesh.provenance.parameters) ||
        !p.String(&mesh.provenance.input_sha256) || !p.AtEnd()) {
      return Invalid("malformed PROV section");
    }
  }
  Counts n;
  {
    ByteReader c(counts);
    uint32_t num_regions = 0;
    if (!c.U32(&n.vertices) || !c.U32(&n.input_vertices) || !c.U32(&n.tets) ||
        !c.U32(&n.triangles) || !c.U32(&num_regions)) {
      return Invalid("malformed CNTS section");
    }
    if (n.vertices > kMaxElements || n.tets > kMaxElements || n.triangles > kMaxElements) {
      return Invalid("counts exceed the format's limit");
    }
    if (n.input_vertices > n.vertices) return Invalid("more input vertices than vertices");
    if (num_regions > c.remaining() / 16 || c.remaining() != 16 * uint64_t{num_regions}) {
      return Invalid("CNTS region table does not match its length");
    }
    // What the decoded mesh will take, checked before anything is allocated:
    // Draco can code a constant column in almost no bytes, so counts alone
    // could otherwise ask for gigabytes.
    const uint64_t mesh_bytes = uint64_t{n.vertices} * sizeof(mesh::Vec3) +
                                uint64_t{n.tets} * (4 * 4 + 4) + uint64_t{n.triangles} * (3 * 4 + 4);
    const uint64_t limit =
        options.max_mesh_bytes != 0 ? options.max_mesh_bytes : DefaultMaxMeshBytes(bytes.size());
    if (mesh_bytes > limit) {
      return Invalid(absl::StrCat("counts (", n.vertices, " vertices, ", n.tets, " tets, ",
                                  n.triangles, " triangles) need ", mesh_bytes,
                                  " bytes, over the decoder's limit of ", limit));
    }
    mesh.num_input_vertices = n.input_vertices;
    mesh.regions.resize(num_regions);
    for (mesh::Region& reg : mesh.regions) {
      c.F64(&reg.attribute);
      c.F64(&reg.max_volume);
    }
  }
  if (!quantized) {
    absl::StatusOr<std::vector<Column>> cols = DecodeColumns(posl, n.vertices, kLosslessColumns);
    if (!cols.ok()) return cols.status();
    mesh.positions = PositionsFromLossless(*cols, n.vertices);
  } else {
    ByteReader p(posq);
    uint8_t bits = 0;
    uint32_t exponent = 0;
    Lattice lattice;
    if (!p.U8(&bits) || !p.U32(&exponent) || !p.I64(&lattice.origin[0]) ||
        !p.I64(&lattice.origin[1]) || !p.I64(&lattice.origin[2])) {
      return Invalid("malformed POSQ section");
    }
    lattice.bits = bits;
    lattice.exponent = static_cast<int32_t>(exponent);
    if (absl::Status s = lattice.Validate(); !s.ok()) return s;
    std::string_view blob;
    p.Bytes(p.remaining(), &blob);
    const size_t per_axis = ColumnsPerAxis(bits);
    absl::StatusOr<std::vector<Column>> cols = DecodeColumns(blob, n.vertices, 3 * per_axis);
    if (!cols.ok()) return cols.status();
    mesh.positions.resize(n.vertices);
    for (uint32_t i = 0; i < n.vertices; ++i) {
      for (int a = 0; a < 3; ++a) {
        const uint32_t q = per_axis == 2
                               ? (uint32_t{(*cols)[2 * a][i]} << 16) | (*cols)[2 * a + 1][i]
                               : (*cols)[a][i];
        if (q >> bits != 0) return Invalid(absl::StrCat("vertex ", i, " outside the lattice"));
        mesh.positions[i][a] = lattice.Dequantize(a, q);
        if (!std::isfinite(mesh.positions[i][a])) {
          return Invalid(absl::StrCat("vertex ", i, " decodes to a non-finite coordinate"));
        }
      }
    }
  }
  {
    const bool has = (flags & kFlagTetRegions) != 0;
    absl::StatusOr<std::vector<Column>> cols = DecodeColumns(tets, n.tets, 2 * (4 + (has ? 1 : 0)));
    if (!cols.ok()) return cols.status();
    if (absl::Status s = SimplicesFromColumns<4>(*cols, n.tets, n.vertices, has, &mesh.tets,
                                                 &mesh.tet_region);
        !s.ok()) {
      return s;
    }
  }
  {
    const bool has = (flags & kFlagTriangleMarkers) != 0;
    absl::StatusOr<std::vector<Column>> cols =
        DecodeColumns(tris, n.triangles, 2 * (3 + (has ? 1 : 0)));
    if (!cols.ok()) return cols.status();
    if (absl::Status s = SimplicesFromColumns<3>(*cols, n.triangles, n.vertices, has,
                                                 &mesh.triangles, &mesh.triangle_marker);
        !s.ok()) {
      return s;
    }
  }
  return mesh;
}

}  // namespace svrc::codec
