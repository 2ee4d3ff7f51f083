// Lossy positions for the result container (docs/container.md): every
// coordinate snapped to a lattice of spacing 2^exponent, so decoded positions
// are exact doubles (origin + q) * 2^exponent and the damage — max error,
// tets collapsed or inverted by rounding — is measured exactly at encode time.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/mesh/tet_mesh.h"

namespace svrc::codec {

inline constexpr int kMaxQuantizationBits = 24;

// Coordinate a of a vertex with lattice index q (0 <= q < 2^bits) decodes to
// (origin[a] + q) * 2^exponent, computed exactly.
struct Lattice {
  int bits = 0;
  int32_t exponent = 0;
  std::array<int64_t, 3> origin = {0, 0, 0};

  // bits in 1..kMaxQuantizationBits, exponent in [-1074, 1023], every
  // lattice point exactly representable (finite is checked per vertex: near
  // the float64 limit the unused end of the lattice may overflow).
  absl::Status Validate() const;
  double Dequantize(int axis, uint32_t q) const;
};

struct QuantizedPositions {
  Lattice lattice;
  std::vector<std::array<uint32_t, 3>> q;
};

// Snaps `positions` to the finest power-of-two lattice with at most 2^bits
// points per axis that spans their bounding box (one spacing for all axes, a
// separate origin per axis), rounding to nearest. The spacing is at most
// twice bbox_extent / (2^bits - 1), and never finer than the float64 spacing
// of the coordinates. INVALID_ARGUMENT on NaN/Inf or a box too large to
// quantize. Deterministic.
absl::StatusOr<QuantizedPositions> Quantize(const std::vector<mesh::Vec3>& positions, int bits);

struct QuantizationReport {
  double max_position_error = 0;    // max over vertices and axes of |decoded - input|
  double position_error_bound = 0;  // half the lattice spacing: the per-axis bound
  uint64_t collapsed_tets = 0;      // nonzero orientation before, zero after
  uint64_t inverted_tets = 0;       // orientation sign flipped
};

// Compares `mesh` with its quantized positions `qp`; orientations before and
// after rounding are exact (geom::Orient3d). Tets already flat are not counted.
QuantizationReport MeasureQuantization(const mesh::TetMesh& mesh, const QuantizedPositions& qp);

}  // namespace svrc::codec
