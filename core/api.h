// The core's public entry point: mesh a PLC with SVRC (thesis ch. 3).
// No gRPC, no protobuf: the service and the CLI both call MeshPlc.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <string>

#include "absl/status/statusor.h"
#include "core/mesh/tet_mesh.h"
#include "core/plc/plc.h"

namespace svrc::core {

// MeshParams::min_dihedral must be below this: a tet's smallest dihedral
// angle is at most arccos(1/3) ≈ 70.53°, the regular tetrahedron's.
inline constexpr double kMaxMinDihedralDeg = 70.5;

// Mesh parameters. Names match the API (proto) and the CLI flags (`-` for `_`).
struct MeshParams {
  // Radius-edge bound for tets not touching a crease [tau/2]. TetGen -q2.
  double radius_edge = 2.0;
  // Warp radius factor [theta] (thesis §3.1.1).
  double theta = 0.9;
  // Largest representation angle on the collar surface, degrees [sigma]
  // (thesis §3.1.2; the dihedral bound next to creases, docs/svrc-collars.md
  // §1). 60, not the guide's 30: at 30 the COLLAR rounds do not settle yet
  // (measured on two facets at 30°, docs/svrc-collars.md "Wiring status").
  double max_rep_angle = 60.0;
  // The simple criterion of thesis Ch. 6 for the COLLAR rounds: > 0 repairs a
  // representation ball of radius > collar_size_eps · css(x) (the collar
  // surface size) instead of an angle > max_rep_angle; the topology tests
  // stay. It bounds no representation angle, hence no dihedral angle next to
  // the creases (docs/svrc-collars.md "Session 16" measures both). 0: the
  // angle test (default). At most 1.
  double collar_size_eps = 0.0;
  // With collars, M_Ω's quality is tested per tet (radius-edge above
  // radius_edge) instead of per Voronoi cell (Figure 3.5), skipping the tets
  // with a crease vertex and those whose circumcentre is strictly inside the
  // collars (RipStitchCollar replaces them); the size test stays per cell.
  // The no-collar path has tested per tet since session 13. Since session 30
  // (docs/svrc-collars.md "Session 30"): the crease inputs mesh at
  // radius_edge 1.5 and 1.414, where the cell test does not settle; fewer
  // tets at 2. false: the cell test (CLI --collar-cell-test, job field
  // collar_cell_test).
  bool collar_tet_quality = true;
  // Global max tet volume in input units³; <= 0: none.
  double max_volume = 0.0;
  // Sliver removal target in degrees (thesis §6.2.1; docs/svrc-design.md §8
  // item 69), best effort: the sliver rounds and flips aim at it; the tets
  // away from creases left below it are counted in the stats
  // (min_dihedral.below, .smallest). <= 0: off; below kMaxMinDihedralDeg.
  double min_dihedral = 0.0;
  // Return the whole bounding-domain mesh instead of the PLC's regions.
  bool keep_bounding_box = false;
  // Hard cap on the refiner's vertices (M_Ω and feature meshes); 0: derived
  // from the input, max(10^6, 2000 × input points) (the no-progress guard).
  uint64_t max_vertices = 0;
};

// A snapshot of progress, reported from the meshing thread.
struct Progress {
  // "validate", "refine", with creases "collar", "stitch", "stitch-repair"
  // (refine::refine_phase), then "assemble", "check", "done". Mild creases
  // (45°–90°) whose refinement without collars overruns its budget, ends with
  // an error or leaves a tet away from the creases above the bound start
  // again with collars:
  // "refine-collars", then "collar" and on.
  std::string phase;
  uint64_t vertices = 0;             // vertices in the output mesh so far
  uint64_t queue_size = 0;           // pending work events
  double largest_work_radius = 0;    // radius of the largest pending gap ball
  double target_radius = 0;          // radius the refinement is heading for (0: n/a)
  double elapsed_seconds = 0;
};
using ProgressCallback = std::function<void(const Progress&)>;

// Cooperative cancellation: the mesher polls IsCancelled() every few hundred
// insertions and then returns CANCELLED (or DEADLINE_EXCEEDED past the deadline).
class CancelToken {
 public:
  CancelToken() = default;
  explicit CancelToken(std::chrono::steady_clock::time_point deadline)
      : deadline_ns_(deadline.time_since_epoch().count()) {}

  void Cancel() { cancelled_.store(true, std::memory_order_relaxed); }
  bool IsCancelled() const { return cancelled_.load(std::memory_order_relaxed); }
  bool DeadlinePassed() const {
    const int64_t d = deadline_ns_.load(std::memory_order_relaxed);
    return d != 0 && std::chrono::steady_clock::now().time_since_epoch().count() >= d;
  }
  void SetDeadline(std::chrono::steady_clock::time_point deadline) {
    deadline_ns_.store(deadline.time_since_epoch().count(), std::memory_order_relaxed);
  }
  // OK, CANCELLED or DEADLINE_EXCEEDED.
  absl::Status Check() const;

 private:
  std::atomic<bool> cancelled_{false};
  std::atomic<int64_t> deadline_ns_{0};
};

// Meshes `plc`. A PLC without segments and facets is a point set: the result
// is its Delaunay tetrahedralization (what `tetgen` does without -p). `progress`
// and `cancel` may be null. Errors: INVALID_ARGUMENT (broken input, with the
// offending ids), UNIMPLEMENTED (a feature the core does not do yet — never a
// wrong mesh), RESOURCE_EXHAUSTED (vertex budget, or an allocation that
// failed: caught, never a crash), CANCELLED, DEADLINE_EXCEEDED.
absl::StatusOr<mesh::TetMesh> MeshPlc(const plc::Plc& plc, const MeshParams& params,
                                      const ProgressCallback& progress = nullptr,
                                      const CancelToken* cancel = nullptr);

// Whether meshing `plc` with `params` gains from a heap on transparent huge
// pages (core/util/huge_pages.h; docs/svrc-design.md §8 item 49): a job likely
// to take more than a second and hundreds of MB (a max_volume, global or per
// region, or 1,000 or more input vertices) that does not take the collar path
// (no crease below 45 degrees). The CLI re-executes itself for such jobs only:
// for a small job the second start-up costs about as much as the job, and
// collar jobs ran 1.3-1.8x slower on the huge-page heap (session 24: bunny.off,
// two facets at 0.1 degrees), where cube.poly --max-volume 1e-6 ran 10-15%
// faster. A guess, not a bound; false for an input PreparePlc refuses.
bool HugePageHeapPays(const plc::Plc& plc, const MeshParams& params);

// "svrc <major>.<minor>.<patch>", for provenance in every result.
std::string Version();

}  // namespace svrc::core
