// Sliver removal by topological flips (2-3, 3-2, 4-4) on the final
// tetrahedralization, before labelling: the "sliver removal" extension of thesis
// §6.2.1, phase 1 (no vertex is moved or added). Decisions: docs/svrc-output.md
// "Sliver removal".
//
// Why: Delaunay refinement with a radius-edge bound leaves slivers — four
// nearly coplanar, nearly cocircular vertices, radius-edge fine, dihedral angles
// near 0° and 180° (thesis §1.3.1 Figure 1.1; Cheng, Dey, Edelsbrunner, Facello,
// Teng, "Sliver exudation", J. ACM 2000). A sliver of a Delaunay mesh is usually
// the tet between two "diagonals" of a flat quadrilateral; a flip that retriangulates
// its neighbourhood often removes it (Joe, "Construction of three-dimensional
// improved-quality triangulations using local transformations", SIAM J. Sci.
// Comput. 1995; Klingner & Shewchuk, "Aggressive tetrahedral mesh improvement",
// IMR 2007: hill-climbing on the worst quality of the tets a flip replaces).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "absl/status/statusor.h"
#include "core/geometry/vec3.h"
#include "core/mesh/tet_mesh.h"
#include "core/svrc/labelling.h"

namespace svrc::refine {

// Default target when MeshParams::min_dihedral is not set (docs/svrc-output.md
// "Sliver removal": what flips reach on the corpus and the generated families).
inline constexpr double kDefaultSliverTargetDeg = 5.0;

struct SliverOptions {
  // A tet is "bad" (queued) when its smallest dihedral angle is below this.
  double target_min_dihedral_deg = kDefaultSliverTargetDeg;
  // No new tet may have a radius-edge ratio above max(max_radius_edge, the
  // largest ratio among the tets the flip replaces): the refiner's guarantee
  // (radius-edge ≤ τ/2) survives the pass. +inf: no bound.
  double max_radius_edge = 2.0;
  // Passes over the bad tets; a pass re-queues every bad tet left by the
  // previous one (flips elsewhere may have unblocked it). Stops early when a
  // pass flips nothing.
  uint32_t max_passes = 4;
  // Safety cap on the number of flips (0: 4 × the number of tets + 1000). Every
  // flip strictly raises the worst quality of the tets it replaces, so the
  // pass terminates anyway; the cap bounds the time.
  uint64_t max_flips = 0;
};

// Statistics of one run (exported as "sliver.*" counters).
struct SliverStats {
  uint64_t tets_before = 0, tets_after = 0;
  // Tets whose smallest dihedral angle is below the target (all tets of the
  // input, exterior included: the pass runs before labelling).
  uint64_t bad_before = 0, bad_after = 0;
  double min_dihedral_before = 0, min_dihedral_after = 0;  // degrees, worst tet
  double max_dihedral_before = 0, max_dihedral_after = 0;  // degrees, worst tet
  double max_radius_edge_before = 0, max_radius_edge_after = 0;
  uint64_t flips_23 = 0, flips_32 = 0, flips_44 = 0;
  uint64_t passes = 0;
  uint64_t candidates = 0;            // flips evaluated (legal or not)
  uint64_t rejected_orientation = 0;  // a new tet not strictly positive (exact Orient3d)
  uint64_t rejected_constraint = 0;   // would remove a constrained face or edge
  uint64_t rejected_radius_edge = 0;  // a new tet over the radius-edge bound
  uint64_t rejected_no_gain = 0;      // legal, but no better than the tets it replaces
  uint64_t stuck = 0;                 // bad tets no flip improved (summed over passes)
  bool hit_flip_cap = false;
  double seconds = 0;

  uint64_t flips() const { return flips_23 + flips_32 + flips_44; }
  void ExportTo(mesh::MeshStats* out) const;
};

struct SliverInput {
  // Vertex positions in the coordinates the tets are positively oriented in
  // (the mesher's normalised ones), the tets (Orient3d(p0,p1,p2,p3) > 0, each
  // face in at most two tets).
  std::span<const geom::Vec3> positions;
  std::span<const std::array<uint32_t, 4>> tets;
  // Triangles that must stay faces (in-facet triangles; any vertex order) and
  // edges that must stay edges (segment pieces). Each must be a face / edge of
  // `tets`.
  std::span<const std::array<uint32_t, 3>> constrained_faces;
  std::span<const std::array<uint32_t, 2>> constrained_edges;
};

struct SliverResult {
  // Positively oriented, the same union and the same boundary faces as the
  // input (flips happen only inside closed neighbourhoods: no hull face or
  // hull edge is ever removed), every constrained face a face and every
  // constrained edge an edge. Surviving input tets keep their vertex order;
  // the order of the list is deterministic (slot order of the flip structure).
  std::vector<std::array<uint32_t, 4>> tets;
  SliverStats stats;
};

// Improves the worst tets by flips: a priority queue of bad tets, worst first
// (ties by slot index); for the popped tet every 2-3 flip across one of its
// faces and every 3-2 / 4-4 flip removing one of its edges (edge of degree 3 /
// 4 with a closed ring) is evaluated; the legal one with the best new worst
// quality is applied if that is strictly better than the worst tet it replaces
// and no new tet exceeds the radius-edge bound. Legality is exact: every new
// tet strictly positive by geom::Orient3d, no constrained face or edge removed.
// Quality (smallest dihedral angle, radius-edge ratio) is floating point,
// computed from the vertices in sorted-id order so that a tet's value does not
// depend on how it was written. Deterministic.
// INVALID_ARGUMENT: an id out of range, a repeated vertex, a tet not strictly
// positive, a face in three tets, a constrained face or edge that is not in the
// mesh. INTERNAL: a constraint lost at the end (a bug).
absl::StatusOr<SliverResult> RemoveSlivers(const SliverInput& input, const SliverOptions& options);

// The pipeline's form (core/api.cc): constrained faces as the output stage's
// ConstrainedFace list, constrained edges as consecutive vertices of segment
// chains (PointSetRefinement::segment_chains).
absl::StatusOr<SliverResult> RemoveSlivers(std::span<const geom::Vec3> positions,
                                           std::span<const std::array<uint32_t, 4>> tets,
                                           std::span<const ConstrainedFace> faces,
                                           std::span<const std::vector<uint32_t>> segment_chains,
                                           const SliverOptions& options);

}  // namespace svrc::refine
