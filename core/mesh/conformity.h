// The conformity checker every output test trusts (DESIGN.md "What every
// output mesh must satisfy"): validity, coverage and conformity of a TetMesh
// to its input PLC, each violation listed with ids. Tolerances for Steiner
// points on slanted features: docs/conformity.md.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/mesh/tet_mesh.h"
#include "core/plc/plc.h"

namespace svrc::mesh {

enum class ConformityCategory { kValidity, kCoverage, kConformity };

enum class ViolationKind {
  // validity
  kIdOutOfRange,          // ids: tet or triangle index, bad vertex id
  kFlippedTet,            // ids: tet (exact Orient3d < 0)
  kDegenerateTet,         // ids: tet (exact Orient3d == 0)
  kFlatTet,               // ids: tet, vertex (Orient3d > 0, but the vertex is within the
                          // on-plane tolerance of its opposite face's plane)
  kDuplicateTet,          // ids: tet, tet (same four vertices)
  kFaceInMoreThanTwoTets, // ids: the three face vertices, then the tets
  kNeighborsSameSide,     // ids: tet, tet sharing a face on the same side of it
  kTagCountMismatch,      // tet_region / triangle_marker sizes, region ids
  kTriangleNotAFace,      // ids: triangle (not a face of any tet)
  kDuplicateTriangle,     // ids: triangle, triangle
  // coverage
  kOpenFace,              // ids: tet, local face: in one tet, not on a facet/domain boundary
  kVolumeMismatch,        // total tet volume != enclosed volume
  // conformity
  kMissingInputVertex,    // ids: input vertex
  kInputVertexIndex,      // ids: input vertex, mesh vertex (canonical meshes only)
  kBrokenSegment,         // ids: segment (index into ConformitySegments), mesh vertex where the walk stopped
  kFacetNotCovered,       // ids: facet; triangle area on it != facet area (facets
                          // that no tet face lies on are outside the domain: skipped)
  kTriangleOffFacet,      // ids: triangle (lies on no input facet)
  kWrongMarker,           // ids: triangle, facet
  kTetCrossesFacet,       // ids: tet, facet
};
inline constexpr int kNumViolationKinds = static_cast<int>(ViolationKind::kTetCrossesFacet) + 1;

ConformityCategory CategoryOf(ViolationKind kind);
std::string_view KindName(ViolationKind kind);
std::string_view CategoryName(ConformityCategory category);

struct Violation {
  ViolationKind kind;
  std::vector<int64_t> ids;
  std::string message;
};

struct ConformityOptions {
  // The mesh fills its bounding box (MeshParams::keep_bounding_box): faces on
  // the box are boundary faces and the enclosed volume is the box's.
  bool keep_bounding_box = false;
  // Canonical meshes: input vertex i must be mesh vertex i. Otherwise input
  // vertices are looked up by exact coordinates (e.g. TetGen output).
  bool input_vertices_first = true;
  // A point is on a plane / line when the exact predicate says so or its
  // distance is at most tolerance_ulps * 2^-52 * scale, scale = the largest
  // absolute input coordinate (docs/conformity.md).
  double tolerance_ulps = 8;
  double volume_rel_tol = 1e-9;  // |V_mesh - V_enclosed| <= tol * V_enclosed
  double area_rel_tol = 1e-9;    // per facet
  bool check_markers = true;     // triangle marker == marker of a facet it lies on
  size_t max_listed_per_kind = 20;  // counts are always complete
};

struct ConformityReport {
  std::vector<Violation> violations;  // at most max_listed_per_kind per kind
  std::array<size_t, kNumViolationKinds> counts{};
  double mesh_volume = 0;
  double enclosed_volume = 0;
  bool enclosed_volume_known = false;  // see docs/conformity.md for when
  // The cells of the facet arrangement were built (docs/conformity.md): the
  // enclosed volume comes from them and every cell's coverage is checked.
  bool cells_known = false;
  size_t num_cells = 0;               // bounded cells (holes included)
  std::string cells_unknown_reason;   // when !cells_known
  size_t num_segments_checked = 0;
  size_t num_facets_checked = 0;   // valid (planar, non-degenerate) facets
  // Of those, facets outside the domain: the cells on both sides of every
  // piece are unmeshed (cells known), else touched by no tet (docs/conformity.md).
  size_t num_facets_outside = 0;
  // Facets some of whose pieces are outside the domain (cells known only);
  // only the other pieces must be covered.
  size_t num_facets_partly_outside = 0;

  bool ok() const;
  size_t Count(ViolationKind kind) const { return counts[static_cast<int>(kind)]; }
  size_t Count(ConformityCategory category) const;
  // One line per kind with a nonzero count, then the listed violations.
  std::string Summary() const;
};

// tolerance_ulps · 2^-52 · the largest absolute coordinate of `points`: the
// distance within which the checker takes a point as on a plane or a line
// (ConformityOptions::tolerance_ulps). The refiner takes a point of Ω as on a
// facet's plane within the same distance (RefineOptions::stitch_faces_on_plane).
double OnFeatureTolerance(std::span<const geom::Vec3> points,
                          double tolerance_ulps = ConformityOptions{}.tolerance_ulps);

// The segments the checker walks, in the order kBrokenSegment ids refer to:
// the PLC's free segments, then the in-facet 2-vertex polygons and the edges
// of every facet polygon, facet by facet (duplicates removed, first kept).
std::vector<std::array<uint32_t, 2>> ConformitySegments(const plc::Plc& plc);

ConformityReport CheckConformity(const plc::Plc& plc, const TetMesh& mesh,
                                 const ConformityOptions& options = {});

// Only the validity category (no PLC): orientation, ids, duplicates, faces.
ConformityReport CheckValidity(const TetMesh& mesh, const ConformityOptions& options = {});

}  // namespace svrc::mesh
