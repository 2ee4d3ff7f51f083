// What one meshing job asks for — mesh parameters, limits, encoding — and the
// one pipeline that runs it, shared by `svrc mesh` (local) and the server's
// workers, so that the same request gives the same mesh and the same errors
// in both places. No gRPC, no protobuf (builds with SVRC_BUILD_SERVICE=OFF).
#pragma once

#include <cstdint>
#include <optional>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "core/api.h"
#include "core/mesh/tet_mesh.h"
#include "core/plc/plc.h"

namespace svrc::cli {

// Names follow core::MeshParams, the API (MeshParameters, JobLimits,
// EncodingOptions) and the CLI flags (`-` for `_`). Unset: the core default.
struct MeshOptions {
  std::optional<double> radius_edge;
  std::optional<double> theta;
  std::optional<double> max_rep_angle;
  std::optional<double> max_volume;
  std::optional<double> min_dihedral;
  std::optional<bool> keep_bounding_box;
  std::optional<double> collar_size_eps;
  std::optional<bool> collar_cell_test;  // --collar-cell-test: MeshParams::collar_tet_quality = false
  uint64_t max_vertices = 0;                     // 0: the core's guard
  absl::Duration deadline = absl::ZeroDuration();  // 0: none
  int quantization_bits = 0;                     // 0: lossless
};

// INVALID_ARGUMENT naming the field for non-finite or out-of-domain values.
absl::Status ValidateOptions(const MeshOptions& options);
// ValidateOptions, then the core's parameters (defaults for unset fields).
absl::StatusOr<core::MeshParams> ToMeshParams(const MeshOptions& options);

// UNIMPLEMENTED for parameters the mesher would otherwise ignore for this
// input: a point set is tetrahedralized as given (no refinement), so any
// refinement parameter set explicitly is rejected, never ignored.
absl::Status CheckImplemented(const MeshOptions& options, const plc::Plc& plc);

// The pipeline: ToMeshParams, CheckImplemented, the max_vertices limit
// against the input (every input vertex is an output vertex), the cancel
// token, then core::MeshPlc.
absl::StatusOr<mesh::TetMesh> RunMeshing(const plc::Plc& plc, const MeshOptions& options,
                                         const core::ProgressCallback& progress,
                                         const core::CancelToken* cancel);

}  // namespace svrc::cli
