// The result container: a small versioned envelope holding Draco-encoded parts
// (positions, tets with region ids, boundary triangles with facet markers)
// plus provenance. DESIGN.md "Result encoding"; format in docs/container.md.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "absl/status/statusor.h"
#include "core/mesh/tet_mesh.h"

namespace svrc::codec {

struct EncodeOptions {
  // 0 = lossless float64 positions (bit-exact round trip). 1..24 = quantize
  // positions to this many bits per axis over the bounding box (lossy; the
  // error bound and any collapsed/inverted tets are reported).
  int position_quantization_bits = 0;
};

struct EncodeReport {
  uint64_t bytes = 0;
  double max_position_error = 0;   // 0 when lossless
  uint64_t collapsed_tets = 0;     // quantized only: tets with zero volume after rounding
  uint64_t inverted_tets = 0;      // quantized only: tets whose orientation flipped
  // Quantized only: the a-priori per-axis bound, half the lattice spacing
  // (spacing <= 2 * largest bbox extent / (2^bits - 1)). max_position_error
  // above is the measured per-axis maximum |decoded - input|, <= this bound.
  double position_error_bound = 0;
};

// Decoder limits. The decoded mesh's size (24 bytes per vertex, 20 per tet,
// 16 per triangle) is checked against the counts before anything is
// allocated, because Draco can code a constant column in almost no bytes.
inline constexpr uint64_t kDefaultMaxMeshBytesFloor = uint64_t{256} << 20;
inline constexpr uint64_t kDefaultMaxMeshBytesPerByte = 64;
struct DecodeOptions {
  // 0 = default: kDefaultMaxMeshBytesFloor + kDefaultMaxMeshBytesPerByte x
  // the container's size (real containers decode to < 10x their size).
  uint64_t max_mesh_bytes = 0;
};

// Encodes `mesh` (already in canonical order; the encoder never reorders
// vertices). Deterministic: same mesh and options, same bytes.
absl::StatusOr<std::string> EncodeTetMesh(const mesh::TetMesh& mesh, const EncodeOptions& options,
                                          EncodeReport* report = nullptr);

// Decodes a container. Never crashes on malformed bytes: INVALID_ARGUMENT.
absl::StatusOr<mesh::TetMesh> DecodeTetMesh(std::string_view bytes);
absl::StatusOr<mesh::TetMesh> DecodeTetMesh(std::string_view bytes, const DecodeOptions& options);

}  // namespace svrc::codec
