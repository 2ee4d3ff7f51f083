// Delaunay tetrahedralization of a point set (what `tetgen` does without -p):
// BRIO + Hilbert insertion into Delaunay3, output in canonical order. The
// result is the Delaunay tetrahedralization of the points under symbolic
// perturbation by input index, so it does not depend on the insertion order.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "absl/status/statusor.h"
#include "core/delaunay/delaunay3.h"
#include "core/geometry/vec3.h"

namespace svrc::delaunay {

struct PointSetOptions {
  // Called with (points inserted, points to insert) every `poll_interval`
  // insertions and at the end. May be null.
  std::function<void(uint64_t, uint64_t)> progress;
  // Polled every `poll_interval` insertions; a non-OK status aborts the run
  // and is returned. May be null.
  std::function<absl::Status()> cancel;
  uint32_t poll_interval = 4096;
};

struct PointSetResult {
  // Positively oriented tets over input vertex ids, each rotated by an even
  // permutation so that its smallest id comes first and the smallest of the
  // other three second, sorted lexicographically.
  std::vector<std::array<uint32_t, 4>> tets;
  // Per input vertex: itself, or the first (lowest-index) input vertex with
  // exactly the same coordinates. Merged vertices appear in no tet.
  std::vector<uint32_t> representative;
  uint32_t num_duplicates = 0;
  Delaunay3::Stats kernel_stats;
  double seconds_sort = 0;
  double seconds_insert = 0;
  double seconds_output = 0;
};

// INVALID_ARGUMENT if a coordinate is not finite or if the points do not
// contain four affinely independent ones (no tetrahedron exists); the
// status of options.cancel if that aborts the run.
absl::StatusOr<PointSetResult> TetrahedralizePointSet(std::span<const geom::Vec3> points,
                                                      const PointSetOptions& options = {});

// The canonical rotation used above (same as mesh::CanonicalTet).
std::array<uint32_t, 4> CanonicalRotation(std::array<uint32_t, 4> t);

}  // namespace svrc::delaunay
