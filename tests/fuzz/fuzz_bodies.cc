#include "tests/fuzz/fuzz_bodies.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <optional>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "core/codec/container.h"
#include "core/plc/readers.h"
#include "core/plc/validate.h"
#include "core/util/sha256.h"

namespace svrc::fuzz {
namespace {

constexpr plc::InputFormat kFormats[] = {
    plc::InputFormat::kPoly, plc::InputFormat::kSmesh, plc::InputFormat::kNode,
    plc::InputFormat::kOff,  plc::InputFormat::kStl,   plc::InputFormat::kObj,
    plc::InputFormat::kMedit};

std::optional<plc::InputFormat> ReaderFormat(Target target) {
  const int i = static_cast<int>(target);
  if (i < 7) return kFormats[i];
  return std::nullopt;
}

std::string BadCode(std::string_view what, const absl::Status& s) {
  return absl::StrCat(std::string(what), " returned ", s.ToString(), " (only OK or INVALID_ARGUMENT allowed)");
}

// Reader contract (readers.h): OK or INVALID_ARGUMENT, and an OK PLC carries
// the sha256 of exactly the bytes read.
std::string RunReader(plc::InputFormat format, std::string_view bytes,
                      absl::StatusOr<plc::Plc>* out) {
  *out = plc::ReadPlcBytes(bytes, format, "fuzz");
  if (!out->ok()) {
    if (!absl::IsInvalidArgument(out->status())) return BadCode("ReadPlcBytes", out->status());
    return "";
  }
  if ((*out)->input_sha256 != util::Sha256Hex(bytes)) {
    return absl::StrCat("ReadPlcBytes: input_sha256 ", (*out)->input_sha256,
                        " is not the sha256 of the input");
  }
  return "";
}

// Validation contract (validate.h): PreparePlc is OK exactly when the report
// has no errors, fails with INVALID_ARGUMENT otherwise, and agrees with
// ValidatePlc on whether the PLC is valid.
std::string RunValidate(std::string_view bytes) {
  if (bytes.empty()) return "";
  const plc::InputFormat format = kFormats[static_cast<uint8_t>(bytes[0]) % 7];
  absl::StatusOr<plc::Plc> p;
  if (std::string err = RunReader(format, bytes.substr(1), &p); !err.empty()) return err;
  if (!p.ok()) return "";
  size_t polygon_vertices = 0;
  for (const plc::Facet& f : p->facets) {
    for (const plc::Polygon& poly : f.polygons) polygon_vertices += poly.vertices.size();
  }
  if (p->vertices.size() > kMaxValidateVertices || p->facets.size() > kMaxValidateFacets ||
      polygon_vertices > kMaxValidatePolygonVertices) {
    return "";
  }
  const plc::ValidationReport alone = plc::ValidatePlc(*p);
  plc::ValidationReport report;
  const absl::StatusOr<plc::FeatureComplex> fc =
      plc::PreparePlc(*p, plc::ValidationOptions{}, plc::FeatureOptions{}, &report);
  if (fc.ok() != report.ok()) {
    return absl::StrCat("PreparePlc: status ", fc.status().ToString(), " but the report has ",
                        report.errors.size(), " errors");
  }
  if (!fc.ok() && !absl::IsInvalidArgument(fc.status())) return BadCode("PreparePlc", fc.status());
  if (alone.ok() != report.ok()) {
    return absl::StrCat("ValidatePlc says ", alone.ok() ? "valid" : "invalid",
                        " but PreparePlc says ", report.ok() ? "valid" : "invalid", ": ",
                        alone.ok() ? report.ToStatus().ToString() : alone.ToStatus().ToString());
  }
  if (fc.ok()) {
    // Every id the complex hands out must index its own arrays.
    for (const plc::FeatureSegment& s : fc->segments) {
      if (s.a >= fc->points.size() || s.b >= fc->points.size()) {
        return "PreparePlc: a segment references a missing point";
      }
    }
  }
  return "";
}

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

// Everything the container carries (docs/container.md "What is lossless").
std::string CompareMeshes(const mesh::TetMesh& a, const mesh::TetMesh& b) {
  if (a.positions.size() != b.positions.size()) return "vertex count differs";
  for (size_t i = 0; i < a.positions.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      if (!SameBits(a.positions[i][k], b.positions[i][k])) {
        return absl::StrCat("position ", i, " axis ", k, " differs");
      }
    }
  }
  if (a.num_input_vertices != b.num_input_vertices) return "num_input_vertices differs";
  if (a.tets != b.tets) return "tets differ";
  if (a.tet_region != b.tet_region) return "tet_region differs";
  if (a.triangles != b.triangles) return "triangles differ";
  if (a.triangle_marker != b.triangle_marker) return "triangle_marker differs";
  if (a.regions.size() != b.regions.size()) return "region count differs";
  for (size_t i = 0; i < a.regions.size(); ++i) {
    if (!SameBits(a.regions[i].attribute, b.regions[i].attribute) ||
        !SameBits(a.regions[i].max_volume, b.regions[i].max_volume)) {
      return absl::StrCat("region ", i, " differs");
    }
  }
  if (a.provenance.svrc_version != b.provenance.svrc_version ||
      a.provenance.parameters != b.provenance.parameters ||
      a.provenance.input_sha256 != b.provenance.input_sha256) {
    return "provenance differs";
  }
  return "";
}

// Decoder contract (container.h): OK, INVALID_ARGUMENT, or RESOURCE_EXHAUSTED
// (the size limit); what decodes is a mesh the encoder accepts, and encoding
// it losslessly then decoding gives the same mesh bit for bit.
std::string RunDecode(std::string_view bytes) {
  const absl::StatusOr<mesh::TetMesh> m = codec::DecodeTetMesh(bytes);
  if (!m.ok()) {
    if (absl::IsInvalidArgument(m.status()) || absl::IsResourceExhausted(m.status())) return "";
    return absl::StrCat("DecodeTetMesh returned ", m.status().ToString());
  }
  const absl::StatusOr<std::string> again = codec::EncodeTetMesh(*m, codec::EncodeOptions{});
  if (!again.ok()) {
    return absl::StrCat("a decoded mesh does not re-encode: ", again.status().ToString());
  }
  const absl::StatusOr<mesh::TetMesh> back = codec::DecodeTetMesh(*again);
  if (!back.ok()) {
    return absl::StrCat("a re-encoded mesh does not decode: ", back.status().ToString());
  }
  if (std::string diff = CompareMeshes(*m, *back); !diff.empty()) {
    return absl::StrCat("re-encoding is not lossless: ", diff);
  }
  return "";
}

// Replaces (or appends) the trailing HASH section with the right digest so
// that mutated containers reach the section parser (docs/container.md).
std::string Rehash(std::string_view bytes) {
  constexpr size_t kHashSection = 4 + 8 + 32;
  std::string body(bytes);
  if (body.size() >= kHashSection && body.compare(body.size() - kHashSection, 4, "HASH") == 0) {
    body.resize(body.size() - kHashSection);
  }
  const util::Sha256::Digest d = util::Sha256Digest(body);
  body.append("HASH");
  const uint64_t len = d.size();
  for (int i = 0; i < 8; ++i) body.push_back(static_cast<char>((len >> (8 * i)) & 0xff));
  body.append(reinterpret_cast<const char*>(d.data()), d.size());
  return body;
}

}  // namespace

std::string_view TargetName(Target target) {
  switch (target) {
    case Target::kPoly: return "plc_poly";
    case Target::kSmesh: return "plc_smesh";
    case Target::kNode: return "plc_node";
    case Target::kOff: return "plc_off";
    case Target::kStl: return "plc_stl";
    case Target::kObj: return "plc_obj";
    case Target::kMedit: return "plc_medit";
    case Target::kValidate: return "plc_validate";
    case Target::kDecode: return "codec_decode";
    case Target::kDecodeRehash: return "codec_decode_rehash";
  }
  return "unknown";
}

std::string RunOne(Target target, std::string_view bytes) {
  if (std::optional<plc::InputFormat> f = ReaderFormat(target)) {
    absl::StatusOr<plc::Plc> p;
    return RunReader(*f, bytes, &p);
  }
  switch (target) {
    case Target::kValidate: return RunValidate(bytes);
    case Target::kDecode: return RunDecode(bytes);
    case Target::kDecodeRehash: return RunDecode(Rehash(bytes));
    default: return "unknown target";
  }
}

std::vector<std::string> SeedFiles(Target target, const std::string& corpus_dir) {
  std::vector<std::string> files;
  if (target == Target::kDecode || target == Target::kDecodeRehash) return files;
  const std::optional<plc::InputFormat> want = ReaderFormat(target);
  for (const auto& e : std::filesystem::recursive_directory_iterator(corpus_dir)) {
    if (!e.is_regular_file()) continue;
    const absl::StatusOr<plc::InputFormat> f = plc::FormatFromPath(e.path().string());
    if (f.ok() && (!want || *f == *want)) files.push_back(e.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::string SeedBytes(Target target, const std::string& path, const std::string& file_bytes) {
  if (target != Target::kValidate) return file_bytes;
  const absl::StatusOr<plc::InputFormat> f = plc::FormatFromPath(path);
  const int index = f.ok() ? static_cast<int>(*f) : 0;
  return std::string(1, static_cast<char>(index)) + file_bytes;
}

}  // namespace svrc::fuzz
