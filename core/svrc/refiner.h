// The SVRC refiner (thesis §3.3): main loop (Figure 3.2), Initialize (3.3),
// Destroy (3.4: warp, else yield, else insert the centre), ForceInsert (3.5),
// UpdateLocation (3.6) and PropagateLocation (3.9), with the corrections of the
// implementer's guide §3. Stages (a) and (b) of the guide's build plan: M_Ω,
// input points (0-balls) and free segments (1D meshes, piece ConfBalls,
// encroachment, partial encroachment, yield); facets and collars come with
// stages (c)–(f). Decisions: docs/svrc-design.md.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/geometry/vec3.h"
#include "core/mesh/tet_mesh.h"
#include "core/plc/features.h"
#include "core/svrc/collar_geometry.h"
#include "core/svrc/assemble.h"
#include "core/svrc/labelling.h"

namespace svrc::refine {

// The stages of RefinePlc as progress reports name them (Progress::phase):
// the first refinement and the size and quality rounds; the COLLAR rounds
// (thesis §3.2.2) with the refinement their points set off; RipStitchCollar
// (Figure 3.12); the points a failed stitch or a stitched mesh crossing a
// facet asks for, and their refinement.
namespace refine_phase {
inline constexpr const char* kRefine = "refine";
inline constexpr const char* kCollar = "collar";
inline constexpr const char* kStitch = "stitch";
inline constexpr const char* kStitchRepair = "stitch-repair";
}  // namespace refine_phase

struct RefineOptions {
  // Voronoi aspect-ratio bound τ (R_v/r_v ≤ τ at the end); the API's
  // radius_edge is τ/2 (docs/svrc-design.md §4).
  double tau = 4.0;
  // ForceInsertOmega proves most cavity cells still good from their last
  // Size() and the new tets (refiner.cc, cell_cert_) instead of walking their
  // stars, and sizes exactly the cells whose farthest corner survived from
  // their memo (OmegaMesh::ShrunkSize). false: Size() for every cavity cell,
  // the reference both must reproduce bit for bit (tests).
  bool certify_cells = true;
  // max_volume: a cavity lying in labelled regions of one size target gives
  // it to its new point and cells, between the size rounds' labellings
  // (refiner.cc, PropagateSizeTargets). false: only the rounds set targets.
  bool propagate_size_targets = true;
  // Once the first size round has labelled M_Ω, the Skinny and size tests
  // read only the corners of the tets the output keeps (CellSize::kept_*):
  // Ω's exterior and holes are no longer graded for quality (the links and
  // Unresolved events still read whole cells). docs/svrc-design.md §8 item
  // 33. Needs propagate_size_targets; never with keep_bounding_box.
  bool size_kept_tets = true;
  // Experimental: M_Ω's Skinny test deferred until the features conform,
  // then M_Ω labelled (as the size rounds do) and every cell tested on its
  // kept tets only.
  bool features_first = false;
  // Once M_Ω is labelled, M_Ω's quality is tested per output tet
  // (radius-edge > τ/2) instead of per Voronoi cell; a bad tet's circumball
  // is the gap ball (docs/svrc-design.md §8 item 34). Implies
  // features_first. PLCs with facets, no collars, no keep_bounding_box only
  // (the others keep the cell test).
  bool tet_quality = true;
  // The per-tet test of tet_quality on the collar path (issue #6: bounds
  // below 2 on creased inputs). M_Ω is not labelled there (its flood leaks
  // through the collars until the stitch), so every finite tet is tested
  // except those with a crease vertex and those whose circumcentre is
  // strictly inside the collars (RipStitchCollar empties them); max_volume
  // stays per cell. docs/svrc-collars.md "Session 30". core::MeshPlc sets it
  // (MeshParams::collar_tet_quality, default on); off: the cell test of
  // Figure 3.5.
  bool collar_tet_quality = false;
  // With tet_quality, max_volume is tested per output tet (circumradius >
  // the regular tet's of its region's bound) when the output's regions have
  // different bounds, per cell (the same verdicts, fewer events) when they
  // share one; true: per tet always.
  bool tet_sizes = false;
  // With tet_quality and a max_volume, each output tet is tested on its
  // volume against its region's bound (the bound the output must meet),
  // instead of its circumradius against the regular tet's of that volume
  // (a cell or tet passing the circumradius test has volume at most the
  // bound, but most tets above it are still far below the bound). Per tet
  // always (tet_sizes implied). docs/svrc-design.md §8 item 35.
  bool tet_volumes = true;
  // With tet_quality, M_Ω's Skinny₃ queue serves each ⌊log₂ r⌋ bucket newest
  // event first (LIFO) instead of oldest first: the newest bad tets lie at the
  // latest insertion, whose tets, cells and links are still in cache. The
  // thesis orders the buckets, not the events inside one (§5.1.2). Measured
  // (docs/svrc-design.md §8 item 52): cube max_volume 1e-5 refinement −16%
  // time on the huge-page heap, −0.9% tets. Stale events wait longer at the
  // bottom of a bucket (the queue peaks twice as high); WorkQueues::
  // ReleaseIfEmpty keeps that out of the labelling's peak. false: oldest
  // first, as the collar path always is.
  bool newest_first_tets = true;
  // With tet_quality, a size round tests only the tets whose label it
  // changed (a tet keeping its label was tested with it when made; docs/
  // svrc-design.md §8 item 53; the same output). false: every tet (tests).
  bool skip_unchanged_tets = true;
  // Destroy in M_Ω gathers every ball of every cell it visits (Figure 3.4
  // line 3) instead of v's balls and the other cells' unresolved 0-balls
  // only (the same choices: docs/svrc-design.md §8 item 36). Tests.
  bool destroy_gather_all = false;
  // Destroy in M_Ω gathers from v and the cells holding unresolved 0-balls,
  // without searching the cells meeting B, when at most this many cells hold
  // them (the same choices either way: a warp target within θr of c lies in a
  // cell meeting B). docs/svrc-design.md §8 item 40; 0 searches whenever any
  // cell holds one (tests).
  uint32_t local_destroy_cells = 256;
  // Destroy in M_Ω takes its warp targets from an index of the unresolved
  // 0-balls' points (PendingPoints: those within θr of c) and its yields from
  // v's links, never reading other cells (the same choices: §8 item 41);
  // false: the cells above (tests).
  bool destroy_index = true;
  // The size rounds label M_Ω with Delaunay3's adjacency instead of building
  // the labelling's face table (§8 item 43; the same labelling); false: the
  // table (tests).
  bool label_with_adjacency = true;
  // Output PointSetRefinement::tet_neighbors (M_Ω's adjacency for the sliver
  // pass, §8 item 80): core::MeshPlc asks for it; it costs RefinePlc 0.6% /
  // 0.9% of its instructions at cube 1e-4 / 1e-5, which a caller without
  // the pass need not pay.
  bool output_tet_neighbors = false;
  // M_Ω's circumcentre cache and Size() memos hold at most 2^omega_cc_log2
  // and 2^omega_memo_log2 records, direct-mapped (OmegaMesh::
  // SetCacheLimits; §8 item 44): memory a run would otherwise spend per tet
  // slot and per vertex. 0: no bound (a half to one record per slot /
  // vertex, §8 item 74). Outputs do not depend on them.
  uint32_t omega_cc_log2 = 20;
  uint32_t omega_memo_log2 = 18;
  // M_Ω's neighbour lists (Delaunay3's cache, read by the cell searches)
  // hold about this many entries at most; past it they are all dropped
  // (§8 item 47). 0: no bound.
  size_t omega_neighbor_entries = size_t{1} << 20;
  // UpdateLocation drops a shrunk cell's link to a lower ball that lies
  // wholly beyond the bisector of the cell's vertex and the new point, and
  // links the new cell's balls in ball-id order (docs/svrc-design.md §8 item
  // 37); false: the B(u, R_u) test alone, in the old cells' link order.
  // Never with collars.
  bool bisector_link_filter = true;
  // With tet_quality, after the refinement (and BreakFlatTets): every kept
  // tet whose smallest dihedral angle is below this many degrees has its
  // circumcentre destroyed, then Run() again; at most sliver_break_rounds
  // rounds. The flip pass (sliver.h) fixes most slivers but leaves a few it
  // cannot flip (docs/svrc-design.md §8 item 38). 0: off.
  // core::MeshPlc raises it to MeshParams::min_dihedral (§8 item 69).
  double sliver_break_deg = 5;
  int sliver_break_rounds = 4;
  // Where BreakSlivers destroys a sliver (thesis §6.2.1 after Chew 1997 and
  // Li–Teng 2001; docs/svrc-design.md §8 item 69). 0: at its circumcentre
  // (item 38). K > 0: the circumcentre, or if the tets its insertion would
  // make (the cavity's boundary faces joined to it, measured before
  // inserting) have a dihedral angle below sliver_break_deg, the best of K
  // more points in the ball of sliver_pick_radius × the circumradius around
  // it: the largest smallest dihedral angle of its new tets, ties to the
  // lower index. A point whose Destroy would split a lower ball (a facet
  // triangle or segment piece: the point strictly inside it) is passed over
  // while another is not; a sliver whose every point is is left to the flip
  // pass, as in item 38, unless sliver_yield.
  int sliver_candidates = 0;
  double sliver_pick_radius = 0.3;
  bool sliver_yield = false;
  // With sliver_candidates: the rounds' target rises from min(15°,
  // sliver_break_deg) in steps of this many degrees (0: straight to it).
  double sliver_ramp_deg = 0;
  // Work of the rounds run whenever the queues run dry, reused while what it
  // read is unchanged: each collar ball's restricted Delaunay of S
  // (CollarRestrictionCache), each facet's settled arc check, each simplex
  // EnqueueMissing found in M_Ω; and in the rounds of BreakSlivers, the tets
  // an earlier round found clear for good. false: everything recomputed every round,
  // the reference the reuse must reproduce bit for bit (tests).
  bool reuse_round_work = true;
  // When the COLLAR rounds run their facet-crossing check (a T′ edge
  // crossing a facet through its ball's centre gets the facet's arc point
  // nearest the crossing). true: in every round from the first one whose
  // restricted triangulation needed no topology or circle repair. false: only
  // in a round with no other repair (sessions 3–18), where each batch of arc
  // points restarts the rounds: crease_pair 5° settled 7 times in 86 rounds;
  // armadillo.off's first 5,845 arc points set off +2.5 M vertices
  // (docs/svrc-collars.md "Session 19").
  bool crossings_once_topology_holds = true;
  // CollarSurfaceOptions::exact_vertex_links (test (c) exact; false: by
  // average degree, (b) covering the rest). Measured in docs/svrc-collars.md
  // "Session 21": more rounds on 5 of 11 crease inputs.
  bool collar_exact_vertex_links = false;
  // CollarSurfaceOptions::exact_sphere_links (tests (d)/(f) exact: each
  // partial sphere's restricted link of a vertex one cycle, as the topology
  // condition asks, not a cycle's average degree). The default since session
  // 25: fandisk.off meshes with it since session 23 (stitch_faces_on_plane),
  // and bunny.off, hinge.stl and the other crease inputs were rerun with it
  // (docs/svrc-collars.md "Session 25": bunny +1.0% tets, +4% CPU; hinge
  // −1.5% tets, −11% CPU). false: the average-degree test of sessions 20–24.
  bool collar_exact_sphere_links = true;
  // The stitched mesh's faces on a facet F also include a face with two
  // points on F and one point of Ω lying on F's plane within the conformity
  // checker's tolerance (8 ulps of the PLC's largest coordinate) whose
  // centroid is in F's region. Such a point is a Voronoi vertex of M_Ω that
  // lies on F exactly: inside a collar, where F's points are suppressed, the
  // Ω ball's yields to F's balls converge on it and it is inserted as a point
  // of Ω (fandisk.off with exact sphere links, session 23). Without the rule
  // its faces are no facet's and the labelling floods through F.
  bool stitch_faces_on_plane = true;
  // Warp radius factor θ (§3.1.1).
  double theta = 0.9;
  // Facet meshes are refined to Voronoi aspect facet_tau_factor·τ. Only M_Ω's
  // τ bounds the output tets; a facet mesh's quality sets how densely the
  // facet is sampled before M_Ω asks for more (its Encroached/Unresolved
  // events still split facet triangles where the tets need it), and any
  // constant keeps the feature mesh well-spaced (bounded ply). 2 measured
  // (docs/svrc-collars.md "Session 6"): crease_pair 30°/10°/5°/1° −25/−26/
  // −22/−10% tets, knife_edge −17%, hinge.stl's facet meshes −43% at a
  // 100,000-vertex budget; volume inputs unchanged (cube 1e-4 −0.7%).
  double facet_tau_factor = 2.0;
  // Vertex budget of M_Ω (corners, inputs and Steiner points) plus the
  // segment and facet meshes' own vertices; 0: derived,
  // max(10^6, 2000·n) (1000·n until session 15). Exceeding it returns
  // RESOURCE_EXHAUSTED.
  uint64_t max_vertices = 0;
  // Polled every `poll_interval` insertions (cancellation/deadline); a non-OK
  // status aborts the run and is returned. May be null.
  std::function<absl::Status()> poll;
  uint32_t poll_interval = 256;
  // RefinePlc: global max tet volume in input units (≤ 0: none); region seeds'
  // max volumes apply too (size events).
  double max_volume = 0;
  // Size events apply to the whole Ω mesh (MeshParams::keep_bounding_box; a
  // PLC without facets has no inside, so its whole Ω mesh is output too).
  bool keep_bounding_box = false;
  // RefinePlc: refine through creases instead of refusing them (no collars:
  // may run to the budget; the caller bounds it). Default: refuse.
  bool attempt_creases = false;
  // RefinePlc: the crease machinery of thesis §3.1.2 (issue #6, stage (d)):
  // a collar ball B(p, g(p)/3) (FastCollarSize, Figure 3.8) when a crease
  // point enters M_Ω, (1,2) points where a vertex collar's sphere meets the
  // segments at that vertex, Unresolved work and warps inside the collars
  // dropped except on crease segments (Figure 3.9), and the end-of-run
  // conformity checks limited to elements outside the collars. Implies
  // attempt_creases.
  bool collars = false;
  // Dead ball records are taken again by new balls (BallStore recycling;
  // not on the collar path, whose structures keep ball ids). Changes ids
  // but not outputs: Destroy's tie-breaks and the newest-first link order
  // read BallStore::Seq, the order balls were made in (§8 items 75, 76).
  bool recycle_balls = true;
  // Stage (e)/(f), experimental (docs/svrc-collars.md "Wiring status"):
  // after the queues run dry, rounds of COLLAR events (CollarRepairs in M_Ω,
  // ArcRepairs in the facet meshes), then RipStitchCollar on M_Ω; the output
  // tets are the stitched ones. Off: the run ends after stage (d), and the
  // mesh inside the collars is M_Ω's (not conforming there).
  bool collar_surface = false;
  // Facet arcs checked for consistency and σ only (ArcOptions require_on_arc
  // = false, eps = 0): the rounds converge, but arc chords are not
  // guaranteed, so facets inside collars may not be sealed (measured).
  bool loose_arcs = false;
  // Lemma 17 enforced: a crease point (with its own collar ball) between
  // consecutive collar balls of a crease segment that meet below π/2
  // (measured: the flat tetrahedron meshes only with it; docs/svrc-collars.md
  // "Wiring status (session 5)").
  bool split_necks = true;
  // Crease input vertices enter M_Ω before the queues run, each getting its
  // collar at once (CreateCollar; g(v) is a property of the PLC, so the ball
  // is the one a later warp would give). The thesis needs crease points
  // "inserted in time" (§3.1.2, Lemma 23; Figure 3.9 triggers CreateCollar
  // for isolated θ₀-medial crease points): with Figure 3.11's order M_Ω is
  // refined last, so without this the facet meshes refine around sharp facet
  // corners before any collar exists. Off by default: measured (docs/
  // svrc-collars.md "Session 6"), it cuts hinge.stl's in-collar feature-mesh
  // points 6.5× but not its size, and knife_edge grows 5,268 → 7,304 tets.
  bool early_crease_vertices = false;
  // A size labelling frees M_Ω's circumcentre cache and size memos before it
  // builds its arrays, and its arrays before the tests that refill them: the
  // two no longer add up at the run's heap peak (session 28; the same
  // refinement: the caches do not change answers).
  // Without collars, the cells a ball meets (a new ball's links, Destroy's
  // cells, the invariant check) are tested against every Delaunay
  // neighbour's bisector, not only the nearest vertex's (session 28; a
  // conservative superset either way; docs/svrc-design.md §8 item 57).
  bool tight_ball_cells = true;
  // Without collars, an Unresolved event in a cell next to the output's
  // boundary (star tets outside it and kept) whose gap ball ⟨farthest corner,
  // R_v⟩ holds no warp target, with R_v more than 16 times the kept R_v,
  // destroys the cell's largest kept gap ball ⟨kept corner, kept R_v⟩
  // instead when that one holds one (within θ·its radius of its centre):
  // the pending point is warped to at once instead of after insertions at
  // the cell's exterior corners, whose cavities reach across M_Ω's coarse
  // exterior (cube --max-volume 1e-5: 139 events of radius above 0.06, up
  // to ~1,300 tets destroyed each, 12% of the refinement's time;
  // docs/svrc-design.md §8 item 71). false: always the farthest corner.
  bool unresolved_kept_warp = true;
  bool release_label_caches = true;
  // A tet's queued Skinny event is removed when the tet is destroyed, not
  // left in the queue until popped stale (session 29; the same refinement:
  // the order of the live events is unchanged).
  bool drop_dead_tet_events = true;
  // ... only the tables of at least this many bytes (OmegaMesh::
  // ReleaseCaches: glibc's mmap threshold; 0 releases every table). 0 since
  // session 44 (was 32 MiB: the small runs' tables stayed in their heap
  // peak; §8 item 74).
  size_t release_cache_min_bytes = 0;
  // Snap band of facet arcs, relative to the circle radius (thesis δ, §3.1.2).
  double arc_snap = 0.02;
  // σ: the largest representation angle of the collar surface (radians;
  // MeshParams::max_rep_angle).
  double max_rep_angle = 0.5235987755982988;
  // > 0: the COLLAR rounds test RepBall radius > collar_size_eps · css(x)
  // (Ch. 6) instead of the angle (MeshParams::collar_size_eps).
  double collar_size_eps = 0;
  // Snap band of the partial spheres and circles, relative to their radius
  // (thesis §3.1.2 δ): a vertex that near S counts as on S for the angle
  // test only. The stitched tets use the true positions, so with δ > 0 they
  // exceed σ where the sample of S is about as fine as δ·ρ (measured:
  // knife_edge.poly's stars reach 84.8° at σ = 60° with δ = 0.02). The
  // rounds start with collar_snap (0: the true angles, what the stars and
  // books see); when a repair would need a point below the RepBall floor
  // (vertices close to S chased down: wedge-1.smesh), the band becomes
  // collar_snap_fallback for the rest of the run (RefineStats::collar_snap).
  // docs/svrc-collars.md "Session 11".
  double collar_snap = 0;
  double collar_snap_fallback = 0.02;
  // Called at every poll: the stage of RefinePlc (RefinePhase), vertices in
  // all meshes, pending events, radius of the event about to be destroyed
  // (the largest work radius); and once as each stage begins. May be null.
  std::function<void(const char* phase, uint64_t vertices, uint64_t queue, double radius)> progress;
  // > 0: check the stage-(a) invariants (guide §6 (a)) every that many
  // insertions, and always at the end. For tests; costs O(n·m) per check.
  uint32_t validate_every = 0;
};

// The insertions RefineStats::link_changes_by_kind tells apart: into M_Ω by
// the point's containment dimension (an M_Ω point split by whether it
// changed any link), into a facet mesh, into a segment mesh.
enum LinkChangeKind : int {
  kOmegaCd0 = 0,
  kOmegaCd1 = 1,
  kOmegaCd2 = 2,
  kOmegaCd3Linked = 3,
  kOmegaCd3Unlinked = 4,
  kFacetMesh = 5,
  kSegmentMesh = 6,
};
inline constexpr int kNumLinkChangeKinds = 7;
inline constexpr const char* kLinkChangeKindName[kNumLinkChangeKinds] = {"omega_cd0", "omega_cd1", "omega_cd2", "omega_cd3_linked",
                                                        "omega_cd3_unlinked", "facet", "segment"};

// Run statistics (thesis ch. 5 quantities; guide §7 "measure per run").
struct RefineStats {
  uint64_t vertices = 0;           // in M_Ω at the end (corners included)
  uint64_t input_vertices = 0;     // (dimension 0)
  uint64_t steiner_vertices = 0;   // created in M_Ω (dimension 3), corners excluded
  uint64_t segment_vertices = 0;   // created in segment meshes (dimension 1)
  uint64_t facet_vertices = 0;     // created in facet meshes (dimension 2), in F or not
  // Where the feature-mesh work went (collars only): created segment and
  // facet points strictly inside a collar ball at the end of the run.
  uint64_t segment_vertices_in_collars = 0;
  uint64_t facet_vertices_in_collars = 0;
  uint64_t facet_vertices_in_omega = 0;  // of those, in M_Ω at the end (inside their facet)
  uint64_t insertions = 0;
  uint64_t warps = 0;              // Destroy line 6
  uint64_t yields = 0;             // Destroy line 13
  uint64_t max_yield_chain = 0;    // the most yields in one Destroy
  uint64_t duplicates = 0;         // warp targets equal to an existing vertex
  uint64_t phantom_corners = 0;    // clipped cell corners equal to an existing vertex (skipped)
  uint64_t tied_balls = 0;         // pieces/triangles missing at the end (ties), re-enqueued
  // Ball records at the end, and how many are alive: ball ids are never
  // reused, so the dead ones (and their per-id side arrays) stay allocated.
  uint64_t ball_records = 0;
  uint64_t balls_alive = 0;
  uint64_t balls_recycled = 0;  // dead ball records taken again (recycle_balls)
  uint64_t straddle_yields = 0;    // facet triangles crossing a piece: the piece split first
  uint64_t size_rounds = 0;        // max_volume: label + size-event rounds run
  uint64_t labels_unchanged = 0;   // tets a size round relabelled as they were: not retested
  uint64_t labels_changed = 0;     // tets whose propagated label a size round corrected (retested)
  uint64_t queue_releases = 0;     // times the empty work queues gave back their event slots
  uint64_t collars = 0;            // collar balls created (stage (d))
  uint64_t vertex_collars = 0;     // of those, centred on an input vertex
  uint64_t collars_skipped_inside = 0;  // crease points strictly inside a collar: no ball
  uint64_t collar_radii_stepped = 0;    // balls made smaller than g/3 to keep vertices off their sphere
  uint64_t collar_cells_explored = 0;  // FastCollarSize cells popped, summed (Lemma 35)
  uint64_t max_collar_cells = 0;
  uint64_t suppressed_points = 0;  // unresolved points dropped inside collars (Figure 3.9)
  uint64_t points_12 = 0;          // (1,2) points: vertex-collar spheres ∩ segments
  uint64_t points_12_skipped = 0;  // (1,2) points not inserted: a segment point already at t
  uint64_t points_12_without_ball = 0;  // (1,2) points that got no ball (inside another, or no size)
  uint64_t stitch_hidden_balls = 0;     // balls inside their chain neighbours' union, left out of the stitch
  uint64_t stitch_flat_tets = 0;        // stars / books refused as flat, over every stitch attempt
  uint64_t stitch_size_repairs = 0;     // points of S queued for stars / books above max_volume (all size passes)
  uint64_t clipped_size_points = 0;     // points of Ω for kept Delaunay tets above max_volume the cell test missed
  uint64_t neck_splits = 0;        // crease points between balls meeting below π/2 (Lemma 17)
  uint64_t collar_rounds = 0;      // rounds of COLLAR events (3D + facet arcs)
  uint64_t collar_balls_computed = 0;  // Del(M)|_S of one partial sphere computed in a COLLAR round
  uint64_t collar_balls_reused = 0;    // ... taken from the last round (no cell it read changed)
  // In the computed balls: candidates whose restricted triangles were
  // computed, and those taken from the ball's last computation (star and
  // neighbours' candidacy unchanged).
  uint64_t collar_owners_computed = 0;
  uint64_t collar_owners_reused = 0;
  uint64_t collar_circle_owners_computed = 0;  // the same for the circles' restricted edges
  uint64_t collar_circle_owners_reused = 0;
  uint64_t arc_facets_computed = 0;    // ArcRepairs of one facet in a COLLAR round
  uint64_t arc_facets_settled = 0;     // ... skipped: nothing to repair last round, no insertion since
  uint64_t collar_pairs = 0;       // collar balls whose spheres intersect (pairs)
  uint64_t collar_pairs_not_smooth = 0;  // of those, meeting below π/2 (Lemma 14)
  double collar_worst_smoothness = 0;    // largest |c₁c₂|² / (r₁² + r₂²) of those
  // The final RipStitchCollar's stars and books and their measured shape
  // (StitchResult; docs/svrc-collars.md §1).
  uint64_t stitch_stars = 0, stitch_books = 0;
  StitchShape stitch;
  double collar_snap = 0;          // the snap band δ in force at the end of the COLLAR rounds
  uint64_t collar_repairs = 0;     // points inserted on S in M_Ω
  // Of the COLLAR rounds' points, by reason: topology, angle, circle, size
  // (CollarRepair::Reason; the stitch-failure repairs are not in it).
  std::array<uint64_t, 4> collar_repairs_by_reason{};
  uint64_t arc_repairs = 0;        // points inserted on facet arcs
  uint64_t stitched_arc_crossings = 0;  // arc points for stitched tets crossing a facet inside a collar
  uint64_t stitch_faces_on_plane = 0;   // facet faces with a point of Ω on the plane (stitch_faces_on_plane)
  uint64_t stitched_crossings = 0;      // all points for stitched tets crossing a facet (arc points included)
  uint64_t flat_tets_broken = 0;   // near-flat tets of M_Ω broken by an insertion at the end
  uint64_t slivers_broken = 0;     // kept slivers broken by an insertion at the end (per-tet mode)
  uint64_t sliver_rounds = 0;      // BreakSlivers rounds that broke at least one
  uint64_t sliver_picks_off_centre = 0;  // ... at a point other than the circumcentre (sliver_candidates)
  uint64_t sliver_yields_skipped = 0;    // slivers left to the flip pass: every point would split a lower ball
  uint64_t sliver_scan_reused = 0; // tets a later BreakSlivers round skipped: an earlier one found them clear
  std::array<uint64_t, 4> events_pushed{};   // by EventType
  std::array<uint64_t, 4> events_popped{};
  std::array<uint64_t, 4> events_stale{};
  std::array<uint64_t, 4> events_removed_dead{};  // removed when their tet died (RemoveObjectEvent), never popped
  uint64_t destroy_cells_visited = 0;  // |𝒱| summed over Destroy calls
  uint64_t destroy_index_visited = 0;  // PendingPoints nodes and points read by Destroy (destroy_index)
  uint64_t destroy_balls_read = 0;     // balls Destroy in M_Ω tested for a warp or a yield
  uint64_t destroys_local = 0;     // Destroy in M_Ω without the search of cells meeting B (local_destroy_cells)
  uint64_t max_destroy_cells = 0;
  uint64_t buckets_walked = 0;
  uint64_t max_bucket_walk = 0;
  uint64_t links_added = 0;        // LW-events (Lemma 36)
  uint64_t links_removed = 0;
  // The same link changes (added + removed) split by the insertion that made
  // them, with the number of such insertions (LinkChangeKind): why the
  // location graph's work per insertion falls as a mesh grows (each kind's
  // cost stays flat; the share of insertions next to a feature falls:
  // bench/RESULTS.md "Session 28").
  std::array<uint64_t, kNumLinkChangeKinds> link_changes_by_kind{};
  std::array<uint64_t, kNumLinkChangeKinds> insertions_by_kind{};
  // The refinement loop's wall time by the same kinds, per event: each
  // event's time (finding it live in the queue, its Destroy, its insertions
  // and every update that follows) goes to the lowest-dimensional mesh it
  // inserted into (kSegmentMesh, else kFacetMesh: a feature point's event
  // usually inserts it into its feature's mesh and then into M_Ω), else to
  // its one M_Ω insertion's kind; events with none or several M_Ω
  // insertions only are counted apart. Why the time per output tet falls as
  // a mesh grows while each kind's time per event stays flat (session 42).
  std::array<double, kNumLinkChangeKinds> seconds_by_kind{};
  std::array<uint64_t, kNumLinkChangeKinds> events_by_kind{};
  double seconds_other_events = 0;
  uint64_t other_events = 0;
  uint64_t clipped_cells = 0;      // cell-size queries that clipped to Ω
  uint64_t sizes_certified = 0;    // cavity cells kept good without a star walk
  uint64_t sizes_certified_partial = 0;  // ... of them next to the output's boundary (session 41)
  uint64_t sizes_certified_clipped = 0;  // ... of those clipped to Ω (session 43)
  uint64_t unresolved_kept_warps = 0;    // Unresolved events destroyed at the kept corner (session 42)
  uint64_t sizes_uncertified = 0;  // ... of which a link needed the exact R_v after all
  uint64_t sizes_shrunk = 0;       // cavity cells sized from their memo (OmegaMesh::ShrunkSize)
  uint64_t size_queries = 0;       // M_Ω Size() calls (and ShrunkSize answers)
  uint64_t sizes_computed = 0;     // ... that walked the star (no memo)
  uint64_t circumcentres = 0;      // M_Ω circumcentres computed (cache misses)
  uint64_t neighbor_cache_flushes = 0;  // M_Ω's neighbour lists dropped at their bound
  uint64_t size_targets_propagated = 0;  // max_volume targets given between size rounds
  uint64_t sizes_outside = 0;            // cavity cells outside the output, not sized (size_kept_tets)
  uint32_t max_degree = 0;         // Delaunay degree in M_Ω at the end (Thm 2)
  uint64_t predicate_calls = 0;
  uint64_t predicate_exact = 0;    // filter failures → exact arithmetic
  uint64_t predicate_sos = 0;      // exact zero → symbolic perturbation
  double max_aspect = 0;           // max R_v/r_v over cells at the end (0 under tet_quality)
  double seconds = 0;              // in Run(): the queues' work
  double seconds_labelling = 0;    // labelling M_Ω for size targets (SetSizeTargets)
  double seconds_breaks = 0;       // the scans of BreakFlatTets and BreakSlivers (their insertions: Run())

  // Appends the counters to a MeshStats (names "svrc.*").
  void ExportTo(mesh::MeshStats* out) const;
};

struct PointSetRefinement {
  // Input points first, bit-exact and in input order, then the 8 corners of Ω,
  // then Steiner points in creation order (input coordinates).
  std::vector<geom::Vec3> positions;
  uint32_t num_input = 0;
  // Tets of M_Ω over `positions`, positively oriented in normalised
  // coordinates (Delaunay3's invariant), in Delaunay3 slot order.
  std::vector<std::array<uint32_t, 4>> tets;
  // Per tet of `tets` (empty unless M_Ω was labelled during the refinement
  // and not stitched): 1 = known to lie outside the output (exterior or
  // hole). SliverOptions::skip_tet.
  std::vector<uint8_t> tet_outside;
  // Per tet of `tets` (empty unless RefineOptions::output_tet_neighbors, and
  // after the collar stitch): the index in `tets` of
  // the tet across face f (the face opposite vertex f), 0xFFFFFFFF on M_Ω's
  // hull — Delaunay3's adjacency, which the sliver pass takes instead of
  // building a face table (SliverInput::neighbors; docs/svrc-design.md §8
  // item 80).
  std::vector<std::array<uint32_t, 4>> tet_neighbors;
  // Per input point: the position index of the mesh vertex it became (itself,
  // or an earlier point with identical coordinates).
  std::vector<uint32_t> input_vertex;
  // Ω in input coordinates.
  geom::Box3 omega;
  // Per input segment: its vertices from a to b as position indices (a chain
  // of edges of the tets; stage (b)).
  std::vector<std::vector<uint32_t>> segment_chains;
  // Stage (c), RefinePlc only: `positions` in the mesher's (normalised)
  // coordinates, the tets are positively oriented in them.
  std::vector<geom::Vec3> normalised_positions;
  // The exact map x' = (x − t)·2^−e from input to normalised coordinates.
  geom::Vec3 normalisation_translation{0, 0, 0};
  int normalisation_exponent = 0;
  // Per facet of the complex: its in-facet triangles (position indices), each
  // a face of `tets` (checked before returning).
  std::vector<std::vector<std::array<uint32_t, 3>>> facet_triangles;
  // options.collars: the collar balls (normalised coordinates), in creation
  // order, each centred on a crease point (a position index).
  struct Collar {
    uint32_t centre = 0;
    int feature_dim = 0;      // the centre's feature: 0 an input point, 1 a crease segment
    uint32_t feature = 0;     // its index in the complex's points or segments
    geom::Vec3 center;
    double radius = 0;
  };
  std::vector<Collar> collars;
  // options.collars: per position, its containment dimension pair
  // (Definition 37) as 10·CD + collar dimension, e.g. 22 for a point on a
  // facet arc; and per position the Ω vertex it is (or none).
  std::vector<uint8_t> point_cd;
  RefineStats stats;
};

// Point-set SVR inside SVRC's machinery (guide §6 stage (a)): refines M_Ω until
// every input point is a vertex and every cell has R_v/r_v ≤ τ. Errors:
// INVALID_ARGUMENT (no points, non-finite), RESOURCE_EXHAUSTED (budget),
// the poll status (CANCELLED, DEADLINE_EXCEEDED), INTERNAL (an invariant
// check failed with validate_every > 0; message names it).
absl::StatusOr<PointSetRefinement> RefinePointSet(std::span<const geom::Vec3> points,
                                                  const RefineOptions& options);

// A free segment between two input points (indices into `points`).
struct SegmentInput {
  uint32_t a = 0, b = 0;
};

// Stage (b): points and free segments. The segments must be a valid complex
// with the points ("plc" validates PLCs): distinct endpoints, no point of the
// input strictly inside a segment, segments meeting only at endpoints.
// INVALID_ARGUMENT for endpoint ids out of range or equal; UNIMPLEMENTED when
// two segments meet at an acute angle (a crease: needs collars, stage (d)). At the end every
// segment is a chain of M_Ω edges (`segment_chains`) and every cell of M_Ω and
// of each segment mesh has R_v/r_v ≤ τ.
absl::StatusOr<PointSetRefinement> RefinePointsAndSegments(std::span<const geom::Vec3> points,
                                                           std::span<const SegmentInput> segments,
                                                           const RefineOptions& options);

// Stage (c): a validated PLC's feature complex (plc::PreparePlc) — points,
// segments, facets (with holes, in-facet segments and points). Refuses
// creases (two features meeting below 90°, complex crease flags) with
// FAILED_PRECONDITION naming the first one: they need collars (issue #6).
// Otherwise as RefinePointsAndSegments, plus: every in-facet triangle of
// every facet mesh is a face of the output tets (`facet_triangles`), every
// segment-mesh cell is τ-well-spaced and every facet-mesh cell
// (facet_tau_factor·τ)-well-spaced. Position i < number of
// complex points is complex point i (input coordinates, bit-exact).
absl::StatusOr<PointSetRefinement> RefinePlc(const plc::FeatureComplex& complex,
                                             const RefineOptions& options);

// The output stage's inputs from a RefinePlc result: its in-facet triangles as
// constrained faces carrying their facet's marker and input index, and its
// exact normalisation as the assembly's coordinate map.
std::vector<ConstrainedFace> ConstrainedFacesOf(const PointSetRefinement& refined,
                                                const plc::FeatureComplex& complex);
CoordinateMap CoordinateMapOf(const PointSetRefinement& refined);

}  // namespace svrc::refine
