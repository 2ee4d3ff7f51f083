// Collar-surface sampling check and COLLAR events (thesis §3.1.2, §3.2.2
// Definitions 37–38; §2.4 Definitions 28–34, Lemmas 15–16; guide "Restricted
// Delaunay of S, topology and angle", stage (e), §4 σ, δ, ε_s).
//
// Decides whether the vertices of a Delaunay3 mesh are a collar-consistent
// sample of the collar surface S with representation angles ≤ σ, and if not,
// lists the points of S to insert: the centres of the RepBalls to destroy
// (COLLAR events). Each check that fails names the place of the failure:
//   (a) a Voronoi edge meeting S ≠ 1 times          → one of its roots;
//   (b) a Delaunay edge in ∉ {0, 2} restricted triangles of S
//       (its Voronoi facet meets S in ≠ 1 arc)        → the largest RepBall
//       centre on that facet's boundary;
//   (c) a vertex whose restricted link is not one cycle → the point of S in
//       its Voronoi cell farthest from it (among the cell's rep points, the
//       circle crossings and the sphere point opposite the vertex);
//       The same within each partial sphere (a path at a circle), since
//       Lemma 15 makes each partial sphere's triangulation homeomorphic to it;
//   (d) a partial sphere with no restricted triangle  → the point of the
//       partial sphere farthest from its nearest vertex (26 directions);
//   (e) a circle whose restricted edges are not one cycle of ≥ 3 vertices
//       → the midpoint of the biggest gap between its rep points;
//   (f) partial sphere i's restricted triangles have a boundary edge that is
//       not a restricted edge of one of its circles, or vice versa (Lemma 15:
//       the circles' cycles partition Del(M)|_S) → that triangle's rep point or
//       that edge's circle point;
//   angle > σ (Definition 34; Snap of §3.1.2 for the angle only) → rep point.
// The simple criterion of Ch. 6 (option size_criterion) replaces the angle
// test by RepBall radius > ε_s·css(x). It does not replace (a)–(f): Lemma 16
// (ε-sample ⇒ consistent) assumes every vertex is on S, and M_Ω's vertices
// off S broke the topology at every ε_s tried (0.3 … 0.07), so (a)–(f) stay
// on as the safety net and the report counts how often they fire.
#pragma once

#include <cstdint>
#include <functional>
#include <numbers>
#include <utility>
#include <vector>

#include "core/delaunay/delaunay3.h"
#include "core/svrc/collar_geometry.h"
#include "core/svrc/restricted_delaunay.h"

namespace svrc::refine {

struct CollarSurfaceOptions {
  // Largest representation angle (thesis §3.1.2 σ), radians.
  double sigma = std::numbers::pi / 6;
  // Snap band relative to the ball radius (§3.1.2 δ): for the angle only, a
  // vertex within δρ of a sphere is moved onto it (SnapToSphere).
  double delta = 0.02;
  // Ch. 6 simple criterion instead of the angle test (topology tests stay).
  bool size_criterion = false;
  double eps_s = 0.3;
  // Search only vertices whose Voronoi cell may meet a ball (|vc| − R_v ≤ ρ,
  // found by a walk from the centre's nearest vertex). false = every vertex
  // (the reference the local search is measured against).
  bool local_search = true;
  // Fill the report's topology summary (χ per partial sphere and per
  // component, components of the triangulation). Diagnostics only: the
  // repairs do not read them; the refiner turns it off (their sorts were ~3%
  // of wedge-1.smesh's COLLAR rounds).
  bool topology_summary = true;
  // Test (c), each vertex's link one cycle: exact (every link vertex of
  // degree 2) or, false, by average degree, the degree part left to (b),
  // which reports an edge in 1 or 3 restricted triangles. The exact test
  // repairs the same defect twice (docs/svrc-collars.md "Session 21").
  bool exact_vertex_links = false;
  // Tests (d)/(f), the link of a vertex not on a circle within one partial
  // sphere one cycle: exact or, false, by average degree. (b) counts an
  // edge's triangles over all of S, so a tail here (an edge with one triangle
  // on this sphere and one on another) passes it, and so does a lollipop
  // with the average degree of a cycle. Exact since session 25 (off in
  // sessions 21–24: with it fandisk.off's stitched mesh leaked until session
  // 23's stitch_faces_on_plane; measured: docs/svrc-collars.md "Session 25").
  bool exact_sphere_links = true;
};

// One COLLAR event (Definition 38's RepBall B(x, radius) to destroy): insert x.
struct CollarRepair {
  enum Reason : uint8_t { kTopology = 0, kAngle = 1, kCircle = 2, kSize = 3 };
  static constexpr uint32_t kNoCircle = 0xFFFFFFFFu;
  Vec3 x;                       // on S: on sphere `ball`, not strictly inside another ball
  uint32_t ball = 0;            // the partial sphere (for circles: circle.a)
  uint32_t circle = kNoCircle;  // index into CollarDescription::circles when collar_dim == 1
  int collar_dim = 2;           // Definition 37's d(x): 1 on a circle, 2 on a partial sphere
  double radius = 0;            // RepBall radius (distance to the nearest vertex); priority
  Reason reason = kTopology;
  // The vertex nearest to x when the repair was computed: a walk hint for
  // the caller's own nearest-vertex query (M_Ω only grows in a round).
  delaunay::VertexId near;
};

// Del(M)|_S of the whole collar description (Definition 28).
struct CollarRestriction {
  // Restricted triangles of every partial sphere (RestrictedTriangle::ball),
  // ball by ball, each ball's in candidate-vertex order. x is the root with
  // the worst angle; angle uses snapped vertices (Snap).
  std::vector<RestrictedTriangle> triangles;
  // Per circle of the description: its restricted edges (sorted by vertex
  // ids), the angle of each rep point in the CircleFrame, and whether the
  // circle is on S: 0 covered by a third ball, 1 whole, 2 partly covered.
  std::vector<std::vector<RestrictedEdge>> circle_edges;
  std::vector<std::vector<double>> circle_params;  // parallel to circle_edges
  std::vector<uint8_t> circle_state;
  std::vector<std::vector<Arc>> circle_arcs;  // ClipCircleByBalls
  // Vertices examined per ball (the local search's cost).
  std::vector<uint32_t> candidates_per_ball;
  // Per ball: the vertex nearest to its centre (invalid without local
  // search), whose tet starts the walks of queries on that ball's sphere.
  std::vector<delaunay::VertexId> center_vertex;
};

// ComputeCollarRestriction's per-ball and per-circle results kept between
// calls on one Delaunay3 that only grows (vertices are inserted, never
// removed), as the refiner's COLLAR rounds call it. A ball's results are a
// function of the vertices its computation read (its candidates and their
// Delaunay neighbours: their positions, stars and Voronoi cells) and of the
// balls; an insertion changes the star of exactly the vertices of the tets it
// destroys (Delaunay3::InsertResult::cavity_vertices) and whose Voronoi
// cell meets a ball must carve it from a cell already meeting it. So a ball
// none of whose read vertices changed since its last computation, in an
// unchanged description, has the same candidates, triangles and roots (the
// same tets, so the same rounding), and a circle both of whose balls are
// unchanged the same edges. With a cache the result is identical to a call
// without one (tests/svrc/collar_surface_test.cc checks this round by round).
struct CollarRestrictionCache {
  // generation(v) must move on whenever v's star changes (the refiner's
  // OmegaMesh::CellGeneration, bumped for every cavity vertex).
  std::function<uint32_t(uint32_t)> generation;
  // Work done by the calls so far.
  uint64_t balls_computed = 0, balls_reused = 0;
  uint64_t owners_computed = 0, owners_reused = 0;  // candidates of computed balls
  uint64_t circles_computed = 0, circles_reused = 0;

  // Filled by ComputeCollarRestriction.
  struct PerBall {
    std::vector<uint32_t> cand;                       // ascending
    std::vector<std::pair<uint32_t, uint32_t>> read;  // (vertex, generation) read
    std::vector<RestrictedTriangle> triangles;
    // Per candidate (parallel to cand): its generation when its triangles
    // were computed, and where they start in `triangles` (one more entry:
    // the end). A recomputed ball copies the triangles of a candidate whose
    // star did not change and none of whose Delaunay neighbours entered or
    // left the candidates (those are all the triangles read).
    std::vector<uint32_t> cand_gen;
    std::vector<uint32_t> tri_begin;
    delaunay::VertexId center_vertex;
  };
  bool valid = false;
  double delta = 0;
  std::vector<CollarBall> balls;
  std::vector<std::pair<uint32_t, uint32_t>> circle_balls;
  std::vector<PerBall> per_ball;
  CollarRestriction last;  // its circle members are reused
  // Per circle: the candidates of both its balls at its last computation
  // and their generations then (an edge's owner with the same generation,
  // none of whose neighbours entered or left the list, keeps its edges).
  std::vector<std::vector<uint32_t>> circle_both, circle_both_gen;
  uint64_t circle_owners_computed = 0, circle_owners_reused = 0;
  size_t last_triangles = 0;  // last.triangles' count (that member is not kept)
  // Per vertex: R_v (Delaunay3::OutRadius) at the generation it was computed
  // at; the candidate search of a recomputed ball reads it for cells whose
  // stars did not change since (wedge-1.smesh: the star walks and
  // circumcentres of OutRadius were ~16% of the run).
  struct OutRadiusMemo {
    uint32_t generation = 0;
    bool valid = false;
    double radius = 0;
  };
  std::vector<OutRadiusMemo> out_radius;
};

// `cache` may be null (every ball computed); with a cache the result is the
// same and only balls whose read vertices changed are computed again.
CollarRestriction ComputeCollarRestriction(const delaunay::Delaunay3& dt,
                                           const CollarDescription& collars,
                                           const CollarSurfaceOptions& opt,
                                           CollarRestrictionCache* cache = nullptr);

struct CollarSurfaceReport {
  int repairs[4] = {0, 0, 0, 0};  // by CollarRepair::Reason
  int duplicates = 0;             // repair points proposed twice (merged)
  int restricted_triangles = 0;   // distinct Delaunay triangles in Del(M)|_S
  int restricted_circle_edges = 0;
  // Violations found (whether or not they produce repairs in size mode).
  int bad_roots = 0;       // (a)
  int bad_facets = 0;      // (b)
  int bad_links = 0;       // (c) in S
  int bad_sphere_links = 0;  // (c) within one partial sphere (cycle, or path at a circle)
  int empty_spheres = 0;   // (d)
  int bad_circles = 0;     // (e)
  int bad_boundaries = 0;  // (f)
  int bad_angles = 0;      // triangles and circle edges with angle > σ
  int too_big = 0;         // RepBalls with radius > ε_s·css(x)
  std::vector<int> euler_per_ball;       // χ of each partial sphere's triangles
  std::vector<int> circles_on_surface_per_ball;  // whole circles bounding it
  int num_components = 0;                // connected components of S (ball graph)
  std::vector<int> euler_per_component;  // χ of the restricted triangles of each
  int triangulation_components = 0;      // components of Del(M)|_S (shared vertices)
  double worst_angle = 0;         // triangles (snapped), radians
  double worst_circle_angle = 0;  // circle edges, radians
  double max_rep_ratio = 0;       // max RepBall radius / css(x)
  uint64_t candidates = 0;        // Σ candidate vertices over balls
  bool consistent = false;        // no topology violation: (a)–(f) all pass
};

// css(x) ≈ min_j(ρ_j + max(0, |x c_j| − ρ_j)): a 1-Lipschitz minorant of
// Definition 32's rad(s).
double CollarSurfaceSize(const Vec3& x, const CollarDescription& collars);

// The COLLAR events of `dt` against `collars`, largest radius first (ties:
// reason, ball, x), each point once. Empty iff the vertices pass (a)–(f)
// (a collar-consistent sample, as far as these tests see) and every
// representation angle is ≤ σ (with size_criterion: every RepBall radius is
// ≤ ε_s·css(x) instead of the angle bound). `report` may be null.
// `triangles`, when not null, receives the restricted triangles the tests
// read (CollarRestriction::triangles), so a caller need not compute them
// again.
std::vector<CollarRepair> CollarRepairs(const delaunay::Delaunay3& dt,
                                        const CollarDescription& collars,
                                        const CollarSurfaceOptions& opt,
                                        CollarSurfaceReport* report,
                                        CollarRestrictionCache* cache = nullptr,
                                        std::vector<RestrictedTriangle>* triangles = nullptr);

namespace detail {
// The link and circle test of CollarRepairs (exposed for its unit test): one
// cycle through every vertex: no repeated edge, every vertex of degree 2, at
// least `min_vertices` vertices, connected. With exact_degrees false the
// degree test is an average (E = V: connected with one cycle, so a lollipop
// with degrees 1, 3, 2, 2 passes), which the vertex links use since test (b)
// covers the rest (docs/svrc-collars.md "Session 21").
// IsOneCycle works on stack arrays up to 48 edges; IsOneCycleGeneral is the
// allocating version (the reference).
bool IsOneCycle(const std::vector<std::pair<uint32_t, uint32_t>>& edges, size_t min_vertices, bool exact_degrees);
bool IsOneCycleGeneral(std::vector<std::pair<uint32_t, uint32_t>> edges, size_t min_vertices, bool exact_degrees);
}  // namespace detail

}  // namespace svrc::refine
