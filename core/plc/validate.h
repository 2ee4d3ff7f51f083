// Validation of a PLC before meshing (DESIGN.md "Core pipeline" 2): non-finite
// coordinates, dangling indices, duplicate vertices, degenerate / zero-area /
// non-planar facets, open or non-manifold boundaries, and features that meet
// other than at shared points and segments (exact predicates, grid index).
// Every rule and tolerance is documented in docs/plc.md.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/plc/features.h"
#include "core/plc/plc.h"

namespace svrc::plc {

enum class ProblemKind {
  kNonFinite,          // vertex ids with NaN/Inf coordinates
  kDanglingIndex,      // facet/polygon or segment referencing a missing vertex
  kDuplicateVertex,    // warning: exact duplicates merged (ids: duplicate, kept, ...)
  kDegeneratePolygon,  // a polygon with < 3 distinct points, collinear, or self-touching
  kZeroAreaFacet,      // all points of a facet collinear
  kNonPlanarFacet,     // a facet point farther than the tolerance from its plane
  kUntriangulable,     // a facet's polygons cross each other (cannot triangulate)
  kOpenBoundary,       // boundary edges where a closed surface is needed
  kNonManifoldEdge,    // warning: a surface edge shared by more than two faces
  kDanglingFacet,      // warning: facets with free edges peeled off the closed part
  kIntersection,       // features meeting other than at shared points/segments
  kSeed,               // warning: region/hole seeds that are non-finite
  kEmpty,              // no vertices
};

struct Problem {
  ProblemKind kind;
  std::string message;        // complete sentence, ids in the file's numbering
  std::vector<uint32_t> ids;  // 0-based ids of the offending items (see kind)
  uint32_t line = 0;          // source line of the first offending item, 0 if unknown
};

struct ValidationOptions {
  // Non-planar facet: max distance of a facet point from the facet plane
  // (Newell normal through the facet's first point) > tol * facet diameter.
  double planarity_tolerance = 1e-8;
  // At most this many ids are listed in a message (then "... and N more").
  size_t max_listed = 10;
  bool check_intersections = true;
};

struct ValidationReport {
  std::vector<Problem> errors;
  std::vector<Problem> warnings;
  bool ok() const { return errors.empty(); }
  // OK, or INVALID_ARGUMENT whose message joins every error (one per line).
  absl::Status ToStatus() const;
  const Problem* Find(ProblemKind kind) const;  // first error of that kind, or null
};

ValidationReport ValidatePlc(const Plc& plc, const ValidationOptions& options = {});

// Validation and the feature complex (features.h) in one pass. On errors
// returns INVALID_ARGUMENT (report->ToStatus()); `report` (optional) receives
// errors and warnings either way.
absl::StatusOr<FeatureComplex> PreparePlc(const Plc& plc, const ValidationOptions& voptions,
                                          const FeatureOptions& foptions,
                                          ValidationReport* report);

}  // namespace svrc::plc
