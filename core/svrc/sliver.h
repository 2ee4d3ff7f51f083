// Sliver removal by topological flips (2-3, and edge removal: 3-2, 4-4, 5-6,
// 6-8, 7-10) on the final tetrahedralization, before labelling: the "sliver
// removal" extension of thesis §6.2.1, phase 1 (no vertex is moved or added).
// Decisions and measurements: docs/svrc-output.md "Sliver removal".
//
// Why: Delaunay refinement with a radius-edge bound leaves slivers — four
// nearly coplanar, nearly cocircular vertices, radius-edge fine, dihedral angles
// near 0° and 180° (thesis §1.3.1 Figure 1.1; Cheng, Dey, Edelsbrunner, Facello,
// Teng, "Sliver exudation", J. ACM 2000). A sliver of a Delaunay mesh is usually
// the tet between two "diagonals" of a flat quadrilateral; a flip that retriangulates
// its neighbourhood often removes it (Joe, "Construction of three-dimensional
// improved-quality triangulations using local transformations", SIAM J. Sci.
// Comput. 1995; Shewchuk, "Two discrete optimization algorithms for the
// topological improvement of tetrahedral meshes", 2002 (edge removal);
// Klingner & Shewchuk, "Aggressive tetrahedral mesh improvement", IMR 2007:
// hill-climbing on the worst quality of the tets an operation replaces).
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

// Default target (docs/svrc-output.md "Sliver removal": flips reach 15° on
// most of the corpus and the generated families at a small cost; where they
// cannot, the worst tet still improves as far as the rules allow).
inline constexpr double kDefaultSliverTargetDeg = 15.0;

struct SliverOptions {
  // A tet is "bad" (queued) when its smallest dihedral angle is below this.
  double target_min_dihedral_deg = kDefaultSliverTargetDeg;
  // No new tet may have a radius-edge ratio above max(max_radius_edge, the
  // largest ratio among the tets the flip replaces): the refiner's guarantee
  // (radius-edge ≤ τ/2) survives the pass. +inf: no bound.
  double max_radius_edge = 2.0;
  // One flag per position (empty: none): crease vertices (thesis Theorem 4
  // bounds radius-edge only for tets not touching a crease). When set, the
  // relaxed bound above applies only to new tets with a crease vertex; a new
  // tet without one must meet max_radius_edge itself (measured: flips next to
  // RipStitchCollar's stars made tets away from the creases of crease_pair 30°
  // reach radius-edge 7.8).
  std::vector<uint8_t> crease_vertex;
  // One flag per input tet (empty: none): 1 = outside the output (the
  // refiner's labelling, PointSetRefinement::tet_outside), never queued. A
  // flip never crosses a constrained face, so the kept tets come out the
  // same; only the time spent on ∂Ω's exterior goes.
  std::vector<uint8_t> skip_tet;
  // No new tet may be larger (volume) than the largest input tet of its
  // component (the tets connected to it across non-constrained faces — the
  // labelling's components, docs/svrc-output.md §2). A flip never crosses a
  // constrained face, so components survive the pass unchanged: every
  // per-region max-volume bound the input meets (size events,
  // MeshParams::max_volume) stays met without the pass knowing the regions.
  // Off by default: it costs quality where no bound asks for it (small
  // components whose largest tet is what a 3-2 flip must exceed).
  bool keep_max_volume = false;
  // Passes over the bad tets; a pass re-queues every bad tet left by the
  // previous one (flips elsewhere may have unblocked it). Stops early when a
  // pass flips nothing.
  uint32_t max_passes = 4;
  // For a bad tet no single flip improves: search sequences of up to
  // lookahead_depth flips — flips of nearby tets that create only tets better
  // than it, then an improving flip of the bad tet — and apply the best one.
  // 1: single flips only. Only for bad tets within max_radius_edge (the
  // others are ∂Ω's exterior, dropped by the labelling).
  uint32_t lookahead_depth = 2;
  // Safety cap on the number of flips (0: 4 × the number of tets + 1000). Every
  // flip strictly raises the worst quality of the tets it replaces, so the
  // pass terminates anyway; the cap bounds the time.
  uint64_t max_flips = 0;
  // An edge removal measures the triangles of its ring on demand: those on
  // one polygon edge first (one of them is in every triangulation), then only
  // where the dynamic program can still use them, and it leaves out those
  // whose first tet's smallest angle is already no better than the flip it
  // would have to beat (the caller's floor, the ring's old worst and the best
  // flip found so far). The chosen flips are the same (tested), with far
  // fewer tets measured. false: every triangle measured (the reference).
  bool prune_edge_removals = true;
  // Also output the final adjacency (SliverResult::neighbors) for the
  // output stage's labelling, which then builds no face table of its own
  // (docs/svrc-design.md §8 item 82).
  bool output_neighbors = false;
};

// The quality the pass ranks tets by: the smallest and largest dihedral
// angle (degrees), the radius-edge ratio and |volume| of tet abcd, equal bit
// for bit to those fields of mesh::ComputeTetQuality(a, b, c, d) (volume: its
// absolute value) — the same expressions, without the aspect ratio, and with
// std::atan2 evaluated only for the edges whose angle can be the smallest or
// the largest: a monotone pseudo-angle of each edge's (sin, cos) pair rules
// out the others with a margin far above the rounding of either function
// (sliver.cc). Exposed for the equality test.
struct SliverTetQuality {
  double min_dihedral_deg = 0;
  double max_dihedral_deg = 0;
  double radius_edge = 0;
  double volume = 0;
};
SliverTetQuality MeasureSliverTet(const geom::Vec3& a, const geom::Vec3& b, const geom::Vec3& c,
                                  const geom::Vec3& d);

// Statistics of one run (exported as "sliver.*" counters).
struct SliverStats {
  uint64_t tets_before = 0, tets_after = 0;  // all tets, SliverOptions::skip_tet's included
  // Over the tets the pass works on (not skip_tet's, which are neither
  // measured nor flipped): those whose smallest dihedral angle is below the
  // target, and the extremes. With the exterior's (before session 49) cube
  // --max-volume 1e-3 reported 0.62° and radius-edge 48.8 for an output of
  // 15.05° and 1.29.
  uint64_t bad_before = 0, bad_after = 0;
  double min_dihedral_before = 0, min_dihedral_after = 0;  // degrees, worst tet
  double max_dihedral_before = 0, max_dihedral_after = 0;  // degrees, worst tet
  double max_radius_edge_before = 0, max_radius_edge_after = 0;
  uint64_t flips_23 = 0, flips_32 = 0, flips_44 = 0;
  uint64_t flips_edge_removal = 0;  // removals of an edge with 5..7 tets around it
  uint64_t lookahead_sequences = 0; // flip sequences found by the lookahead (flips counted above)
  uint64_t passes = 0;
  uint64_t candidates = 0;            // 2-3 flips and edge removals evaluated (legal or not)
  // No candidate tet strictly positive (exact Orient3d) — for an edge removal:
  // no triangulation of the ring made only of positive tets within the bounds.
  uint64_t rejected_orientation = 0;
  uint64_t rejected_constraint = 0;   // would remove a constrained face or edge
  uint64_t rejected_radius_edge = 0;  // a new tet over the radius-edge bound
  uint64_t rejected_volume = 0;       // a new tet larger than its component's largest
  uint64_t rejected_no_gain = 0;      // legal, but no better than the tets it replaces
  uint64_t pruned_triangles = 0;      // ring triangles left out (prune_edge_removals)
  uint64_t rejected_crease_angle = 0; // would give a tet touching a crease a larger dihedral than it replaces
  uint64_t stuck = 0;                 // bad tets no flip improved (summed over passes)
  bool hit_flip_cap = false;
  double seconds = 0;

  uint64_t flips() const { return flips_23 + flips_32 + flips_44 + flips_edge_removal; }
  void ExportTo(mesh::MeshStats* out) const;
};

struct SliverInput {
  // Vertex positions in the coordinates the tets are positively oriented in
  // (the mesher's normalised ones), the tets (Orient3d(p0,p1,p2,p3) > 0, or
  // = 0 for a flat tet a symbolically perturbed Delaunay kernel may leave on
  // exactly coplanar points; each face in at most two tets).
  std::span<const geom::Vec3> positions;
  std::span<const std::array<uint32_t, 4>> tets;
  // Triangles that must stay faces (in-facet triangles; any vertex order) and
  // edges that must stay edges (segment pieces). Each must be a face / edge of
  // `tets`.
  std::span<const std::array<uint32_t, 3>> constrained_faces;
  std::span<const std::array<uint32_t, 2>> constrained_edges;
  // Optional (null: built from the tets): per tet, the tet across face f
  // (the face opposite vertex f), 0xFFFFFFFF where none — a mesher's own
  // adjacency (PointSetRefinement::tet_neighbors). Moved from; trusted (only
  // the ids' range is checked). The face table it
  // replaces was 12% of the pass's instructions and 48 bytes per tet of fresh
  // memory (docs/svrc-design.md §8 item 80).
  std::vector<std::array<uint32_t, 4>>* neighbors = nullptr;
};

struct SliverResult {
  // Positively oriented (flat input tets that no flip replaced stay as they
  // were), the same union and the same boundary faces as the
  // input (flips happen only inside closed neighbourhoods: no hull face or
  // hull edge is ever removed), every constrained face a face and every
  // constrained edge an edge. Surviving input tets keep their vertex order;
  // the order of the list is deterministic (slot order of the flip structure).
  std::vector<std::array<uint32_t, 4>> tets;
  // With SliverOptions::output_neighbors: per tet of `tets`, the index in
  // `tets` of the tet across face f (the face opposite local vertex f),
  // 0xFFFFFFFF on the hull — the adjacency the flips kept up, in the form of
  // SliverInput::neighbors and LabelInput::neighbor_tets.
  std::vector<std::array<uint32_t, 4>> neighbors;
  SliverStats stats;
};

// Improves the worst tets by flips: a priority queue of bad tets, worst first
// (ties by slot index); for the popped tet every 2-3 flip across one of its
// faces and the removal of each of its edges whose ring is closed with 3..7
// tets (the best triangulation of the ring polygon, by dynamic programming:
// 3-2, 4-4, 5-6, 6-8, 7-10) is evaluated; the legal one with the best new
// worst quality is applied if that is strictly better than the worst tet it
// replaces and no new tet exceeds the radius-edge (and volume) bound. If none
// is, a depth-limited search (lookahead_depth) looks for flips of nearby tets
// that create only tets better than the bad one and after which it has an
// improving flip. Legality is exact: every new tet strictly positive by
// geom::Orient3d, no constrained face or edge removed. Quality (smallest
// dihedral angle, radius-edge ratio, volume) is floating point, computed from
// the vertices in sorted-id order so that a tet's value does not depend on how
// it was written; every applied operation strictly raises the worst quality of
// the tets it touches, so the pass cannot cycle. Deterministic.
// INVALID_ARGUMENT: an id out of range, a repeated vertex, a negatively
// oriented tet, a face in three tets, a constrained face or edge that is not in the
// mesh. INTERNAL: a constraint lost at the end (a bug).
absl::StatusOr<SliverResult> RemoveSlivers(const SliverInput& input, const SliverOptions& options);

// The pipeline's form (core/api.cc): constrained faces as the output stage's
// ConstrainedFace list, constrained edges as consecutive vertices of segment
// chains (PointSetRefinement::segment_chains).
absl::StatusOr<SliverResult> RemoveSlivers(std::span<const geom::Vec3> positions,
                                           std::span<const std::array<uint32_t, 4>> tets,
                                           std::span<const ConstrainedFace> faces,
                                           std::span<const std::vector<uint32_t>> segment_chains,
                                           const SliverOptions& options,
                                           std::vector<std::array<uint32_t, 4>>* neighbors = nullptr);

}  // namespace svrc::refine
