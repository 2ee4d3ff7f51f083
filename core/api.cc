#include "core/api.h"

#include <chrono>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "core/delaunay/point_set.h"
#include "core/geometry/predicates.h"

namespace svrc::core {
namespace {

// A PLC without segments and facets: its Delaunay tetrahedralization (issue
// #2), vertices in input order (exact duplicates merged into their first
// occurrence and left unreferenced), tets canonical, one region 0.
absl::StatusOr<mesh::TetMesh> MeshPointSet(const plc::Plc& plc, const ProgressCallback& progress,
                                           const CancelToken* cancel) {
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  const geom::PredicateStats pred_before = geom::GetPredicateStats();
  delaunay::PointSetOptions options;
  if (progress) {
    options.progress = [&](uint64_t done, uint64_t total) {
      Progress p;
      p.phase = "delaunay";
      p.vertices = done;
      p.queue_size = total - done;
      p.elapsed_seconds = elapsed();
      progress(p);
    };
  }
  if (cancel) options.cancel = [cancel] { return cancel->Check(); };
  auto result = delaunay::TetrahedralizePointSet(plc.vertices, options);
  if (!result.ok()) {
    if (result.status().code() == absl::StatusCode::kInvalidArgument) {
      return absl::InvalidArgumentError(
          absl::StrCat(plc.source_name.empty() ? "<memory>" : plc.source_name, ": ",
                       result.status().message()));
    }
    return result.status();
  }
  const geom::PredicateStats& pred_after = geom::GetPredicateStats();

  mesh::TetMesh out;
  out.positions = plc.vertices;
  out.num_input_vertices = static_cast<uint32_t>(plc.vertices.size());
  out.tets = std::move(result->tets);
  out.tet_region.assign(out.tets.size(), 0);
  out.regions.push_back(mesh::Region{});
  out.provenance.svrc_version = Version();
  out.provenance.parameters = "mode=point_set";
  out.provenance.input_sha256 = plc.input_sha256;
  auto& st = out.stats;
  st.Set("input_vertices", static_cast<double>(plc.vertices.size()));
  st.Set("duplicate_vertices", result->num_duplicates);
  st.Set("output_vertices", static_cast<double>(plc.vertices.size() - result->num_duplicates));
  st.Set("tets", static_cast<double>(out.tets.size()));
  st.Set("delaunay_walk_steps", static_cast<double>(result->kernel_stats.walk_steps));
  st.Set("delaunay_tets_created", static_cast<double>(result->kernel_stats.tets_created));
  st.Set("predicate_calls", static_cast<double>(pred_after.TotalCalls() - pred_before.TotalCalls()));
  st.Set("predicate_exact_fallbacks",
         static_cast<double>(pred_after.TotalExact() - pred_before.TotalExact()));
  st.Set("predicate_sos_decisions", static_cast<double>(pred_after.TotalSos() - pred_before.TotalSos()));
  st.Set("insphere_exact_fallbacks",
         static_cast<double>(pred_after.exact[static_cast<int>(geom::Pred::kInSphere)] -
                             pred_before.exact[static_cast<int>(geom::Pred::kInSphere)]));
  st.Set("orient3d_exact_fallbacks",
         static_cast<double>(pred_after.exact[static_cast<int>(geom::Pred::kOrient3d)] -
                             pred_before.exact[static_cast<int>(geom::Pred::kOrient3d)]));
  st.Set("seconds_sort", result->seconds_sort);
  st.Set("seconds_delaunay", result->seconds_insert);
  st.Set("seconds_output", result->seconds_output);
  st.Set("seconds_total", elapsed());
  if (progress) {
    Progress p;
    p.phase = "done";
    p.vertices = plc.vertices.size() - result->num_duplicates;
    p.elapsed_seconds = elapsed();
    progress(p);
  }
  return out;
}

}  // namespace

absl::Status CancelToken::Check() const {
  if (IsCancelled()) return absl::CancelledError("job cancelled");
  if (DeadlinePassed()) return absl::DeadlineExceededError("job deadline exceeded");
  return absl::OkStatus();
}

std::string Version() { return absl::StrCat("svrc ", SVRC_VERSION); }

absl::StatusOr<mesh::TetMesh> MeshPlc(const plc::Plc& plc, const MeshParams& params,
                                      const ProgressCallback& progress,
                                      const CancelToken* cancel) {
  if (plc.IsPointSet()) return MeshPointSet(plc, progress, cancel);
  return absl::UnimplementedError(
      "PLC meshing (SVRC refinement) is not implemented yet; only point sets are supported");
}

}  // namespace svrc::core
