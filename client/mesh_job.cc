#include "client/mesh_job.h"

#include <cmath>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"

namespace svrc::cli {
namespace {

absl::Status CheckRange(const char* name, const std::optional<double>& value, double lo,
                        bool lo_open, double hi, bool hi_open) {
  if (!value) return absl::OkStatus();
  const double v = *value;
  const bool ok = std::isfinite(v) && (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
  if (ok) return absl::OkStatus();
  return absl::InvalidArgumentError(absl::StrCat(name, " must be in ", lo_open ? "(" : "[", lo,
                                                 ", ", hi, hi_open ? ")" : "]", ", got ", v));
}

}  // namespace

absl::Status ValidateOptions(const MeshOptions& o) {
  const double inf = HUGE_VAL;
  for (absl::Status s : {
           CheckRange("radius_edge", o.radius_edge, 0, true, inf, true),
           CheckRange("theta", o.theta, 0, false, 1, false),
           CheckRange("max_rep_angle", o.max_rep_angle, 0, true, 180, true),
           CheckRange("max_volume", o.max_volume, -inf, true, inf, true),
           CheckRange("min_dihedral", o.min_dihedral, -inf, true, core::kMaxMinDihedralDeg, true),
           CheckRange("collar_size_eps", o.collar_size_eps, 0, false, 1, false),
       }) {
    if (!s.ok()) return s;
  }
  if (o.deadline < absl::ZeroDuration()) {
    return absl::InvalidArgumentError("deadline must not be negative");
  }
  if (o.quantization_bits < 0 || o.quantization_bits > 24) {
    return absl::InvalidArgumentError(absl::StrCat(
        "quantization_bits must be 0 (lossless) or 1..24, got ", o.quantization_bits));
  }
  return absl::OkStatus();
}

absl::StatusOr<core::MeshParams> ToMeshParams(const MeshOptions& o) {
  if (absl::Status s = ValidateOptions(o); !s.ok()) return s;
  core::MeshParams p;
  if (o.radius_edge) p.radius_edge = *o.radius_edge;
  if (o.theta) p.theta = *o.theta;
  if (o.max_rep_angle) p.max_rep_angle = *o.max_rep_angle;
  if (o.max_volume) p.max_volume = *o.max_volume;
  if (o.min_dihedral) p.min_dihedral = *o.min_dihedral;
  if (o.keep_bounding_box) p.keep_bounding_box = *o.keep_bounding_box;
  if (o.collar_size_eps) p.collar_size_eps = *o.collar_size_eps;
  if (o.collar_cell_test) p.collar_tet_quality = !*o.collar_cell_test;
  p.max_vertices = o.max_vertices;
  return p;
}

absl::Status CheckImplemented(const MeshOptions& o, const plc::Plc& plc) {
  if (!plc.IsPointSet()) return absl::OkStatus();  // the mesher answers for PLCs
  std::vector<std::string> set;
  if (o.radius_edge) set.push_back("radius_edge");
  if (o.theta) set.push_back("theta");
  if (o.max_rep_angle) set.push_back("max_rep_angle");
  if (o.max_volume && *o.max_volume > 0) set.push_back("max_volume");
  if (o.min_dihedral && *o.min_dihedral > 0) set.push_back("min_dihedral");
  if (o.keep_bounding_box && *o.keep_bounding_box) set.push_back("keep_bounding_box");
  if (o.collar_size_eps && *o.collar_size_eps > 0) set.push_back("collar_size_eps");
  if (o.collar_cell_test && *o.collar_cell_test) set.push_back("collar_cell_test");
  if (set.empty()) return absl::OkStatus();
  return absl::UnimplementedError(absl::StrCat(
      absl::StrJoin(set, ", "),
      ": not implemented for point sets (a point set is tetrahedralized as given, "
      "without refinement)"));
}

absl::StatusOr<mesh::TetMesh> RunMeshing(const plc::Plc& plc, const MeshOptions& options,
                                         const core::ProgressCallback& progress,
                                         const core::CancelToken* cancel) {
  absl::StatusOr<core::MeshParams> params = ToMeshParams(options);
  if (!params.ok()) return params.status();
  if (absl::Status s = CheckImplemented(options, plc); !s.ok()) return s;
  if (options.max_vertices > 0 && plc.vertices.size() > options.max_vertices) {
    return absl::ResourceExhaustedError(absl::StrCat("the input has ", plc.vertices.size(),
                                                     " vertices, more than max_vertices=",
                                                     options.max_vertices));
  }
  if (cancel != nullptr) {
    if (absl::Status s = cancel->Check(); !s.ok()) return s;
  }
  return core::MeshPlc(plc, *params, progress, cancel);
}

}  // namespace svrc::cli
