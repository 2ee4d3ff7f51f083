#include "core/api.h"

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace svrc::core {

absl::Status CancelToken::Check() const {
  if (IsCancelled()) return absl::CancelledError("job cancelled");
  if (DeadlinePassed()) return absl::DeadlineExceededError("job deadline exceeded");
  return absl::OkStatus();
}

std::string Version() { return absl::StrCat("svrc ", SVRC_VERSION); }

absl::StatusOr<mesh::TetMesh> MeshPlc(const plc::Plc& plc, const MeshParams& params,
                                      const ProgressCallback& progress,
                                      const CancelToken* cancel) {
  if (plc.IsPointSet()) {
    return absl::UnimplementedError("point-set tetrahedralization is not implemented yet");
  }
  return absl::UnimplementedError(
      "PLC meshing (SVRC refinement) is not implemented yet; only point sets are supported");
}

}  // namespace svrc::core
