// RipStitchCollar (thesis Figure 3.12, §3.1.2, proof of Theorem 4; guide
// "RipStitchCollar (3.12)" and stage (f)): empty the Delaunay tets inside the
// collar system and fill the hole with stars (crease vertex + restricted
// triangle of its partial sphere) and books (crease edge + restricted edge of
// the circle of its two balls), verified exactly before it is returned.
#pragma once

#include <array>
#include <cstdint>
#include <numbers>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "core/delaunay/delaunay3.h"
#include "core/svrc/collar_geometry.h"

namespace svrc::refine {

// A collar ball with the Delaunay vertex at its centre (a crease point).
struct StitchBall {
  CollarBall ball;
  delaunay::VertexId centre;
};

// The default of StitchOptions::min_flatness (see StitchedTetFlatness).
inline constexpr double kFlatStitchedTet = 1e-9;

// Quality preconditions: a hole-boundary face whose representation angle or
// RepBall is too large is reported as a failure at its representation point
// (a COLLAR event for the refiner, thesis §3.1.2) instead of being stitched.
// Defaults are the guide's σ = 30° and ε_s = 0.3 (§4): the RepBall radius is
// compared with ε_s·css(x), css(x) = min_j max(ρ_j, |x c_j|) (the guide's
// 1-Lipschitz minorant of Definition 32's rad). For a book the "RepBall" is
// max(|xa|, |xb|) at the circle point x and the angle is the circle's
// (Definition 34). Pass π/2 and +∞ to switch both checks off.
struct StitchOptions {
  double max_rep_angle = std::numbers::pi / 6;
  double max_rep_ratio = 0.3;
  // A positively oriented star or book whose StitchedTetFlatness is below
  // this is refused as star_flat / book_flat. Tests raise it to make the
  // refusal fire in scenes too small to hold a flat star.
  double min_flatness = kFlatStitchedTet;
};

struct StitchInput {
  const delaunay::Delaunay3* dt = nullptr;
  std::span<const StitchBall> balls;
  // Pairs of balls (indices into `balls`) whose centres are consecutive
  // vertices of one crease segment. Each pair whose spheres cross
  // (SphereSphereCircle) gets a book over their circle; every pair of balls
  // whose spheres cross must be listed (Lemma 13: only balls on one segment
  // meet), otherwise the stitch fails with kUnlistedCircle.
  std::span<const std::pair<uint32_t, uint32_t>> crease_edges;
  StitchOptions options;
};

// Why the stitch was refused, where, and next to which ball. `where` is a
// point of the collar surface S whenever one is known (a representation point
// or a circle point), so the refiner can queue a COLLAR event there;
// otherwise a face centroid, edge midpoint or vertex.
struct StitchFailure {
  enum class Kind : uint8_t {
    kUnlistedCircle,         // two balls' spheres cross but are not a crease edge
    kCreaseVertexOnSurface,  // a crease vertex's Voronoi cell leaves the collars
    kNoCrossing,             // a hole-boundary Voronoi edge meets S 0 times (rounding)
    kMultipleCrossings,      // ... meets S more than once (Definition 30 violated)
    kLargeAngle,             // representation angle > options.max_rep_angle
    kCoarseSample,           // RepBall > options.max_rep_ratio · css(x)
    kStarInverted,           // Orient3d(star) ≤ 0
    kStarFlat,               // Orient3d(star) > 0 but StitchedTetFlatness < options.min_flatness
    kNonManifoldEdge,        // an edge of T′ in ≠ 2 faces of T′
    kCircleCrossing,         // T′ edge vs circle disagreement (0/2 crossings, wrong pair)
    kBookDegenerate,         // Orient3d(book) = 0
    kBookFlat,               // Orient3d(book) ≠ 0 but StitchedTetFlatness < options.min_flatness
    kFaceMismatch,           // exact face matching failed (a face not shared properly)
    kVertexOutsideCollars,   // a vertex only on inside tets is not strictly inside a ball
    kCreaseVertexUnused,     // a crease vertex in no stitched tet
    kCreaseEdgeMissing,      // crossing crease edge vw got no book
    kBookFold,               // two books of one crease edge on the same side of their shared face
  };
  Kind kind;
  Vec3 where;
  uint32_t ball = kNoBall;  // nearest ball (by |x − c| − ρ) when none is implied
  std::string detail;
  static constexpr uint32_t kNoBall = 0xFFFFFFFFu;
};
const char* StitchFailureKindName(StitchFailure::Kind kind);

struct StitchResult {
  // All finite tets of the final mesh as dt vertex ids, each positively
  // oriented (exact Orient3d > 0): the Delaunay tets outside the collars (slot
  // order), then the stars (T′ order), then the books (edge order).
  std::vector<std::array<uint32_t, 4>> tets;
  // dt vertices all of whose tets were inside (Figure 3.12's 𝓘, cells inside
  // the collar region), excluding crease vertices; ascending. Used by no tet.
  std::vector<uint32_t> removed_vertices;

  // Counters.
  uint32_t outside_tets = 0;    // Delaunay tets kept
  uint32_t inside_tets = 0;     // Delaunay tets removed
  uint32_t boundary_faces = 0;  // |T′| (hull faces of inside tets included)
  uint32_t stars = 0;
  uint32_t books = 0;
  uint32_t crease_edges_without_circle = 0;  // listed pairs whose spheres do not cross

  // The stars' and books' measured shape and the doc's bounds (§1).
  StitchShape shape;
};

// Balls of one crease chain whose spheres are not on S. `chain` lists balls
// (indices into `balls`) whose centres are consecutive along one crease
// segment, its ends possibly vertex balls. An interior ball i whose two
// neighbours in the chain cross in a circle that is nowhere strictly inside
// ball i lies inside the union of the two (centres on one line; docs/
// svrc-collars.md "Session 33"): its sphere is no part of S, the
// neighbours' circle is, and their pair is the crease edge. Removes every
// such ball from *chain (again after each removal: the new neighbours may
// hide the next) and returns the removed ones in the order removed. The end
// balls stay.
std::vector<uint32_t> PruneHiddenChainBalls(std::span<const CollarBall> balls, std::vector<uint32_t>* chain);

// A stitched tet's smallest altitude over its longest edge (0 for a flat
// tet, √(2/3) for a regular one). A star or book whose four vertices lie on
// one plane up to rounding can still have Orient3d > 0; the stitch refuses
// it below StitchOptions::min_flatness (star_flat / book_flat, repaired as an inverted
// star / a degenerate book). Such a star lay on a facet through its ball's centre on
// armadillo.off (session 34): its four faces were all on the facet within the
// checker's tolerance, so the facet was counted twice over the tet's area
// ("facet_not_covered ... cover area 1.2132, facet area 1.0988").
double StitchedTetFlatness(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

// Rip and stitch (see docs/svrc-collars.md "RipStitchCollar (stage f)"):
//  1. A finite tet of dt is inside iff its circumcentre is strictly inside the
//     union of the balls (geom::InBall on the constructed circumcentre: a
//     construction-level decision, the guide's criterion). Ghost tets are
//     outside.
//  2. T′ = faces between an inside and an outside tet (Theorem 4's proof: with
//     a collar-consistent sample this is Del(M)|_S).
//  3. Each T′ face's Voronoi edge (inside circumcentre → outside circumcentre,
//     or a hull ray) must cross S exactly once, at x on the partial sphere of
//     ball i: star (centre_i, face).
//  4. Each T′ edge whose two T′ faces chose balls i ≠ j must have (i, j) a
//     crease edge, and the circle of i, j must cross its Voronoi facet exactly
//     once (edges whose faces chose the same ball: no circle of that ball
//     crosses it): book (centre_i, centre_j, a, b).
//  5. Exact verification: every stitched tet Orient3d > 0; every face of a
//     stitched tet is shared by exactly two stitched tets on opposite sides or
//     is a T′ face with the stitched tet on the inside tet's side; every T′
//     face is matched exactly once. With all tets positive, the stitched tets'
//     boundary chain then equals ∂(hole), so they tile the hole exactly (the
//     covering number of a point is the winding number of the boundary).
//     Removed vertices are strictly inside some ball and in no tet; crease
//     vertices are in some tet and in no outside tet; every crossing crease
//     edge is an edge of a book.
// On any failure: FAILED_PRECONDITION naming the first failure and their
// count; all failures are appended to `failures` (if given). No mesh is
// returned unless it passed verification. INVALID_ARGUMENT for malformed
// input (null dt, bad ids, not 3D).
absl::StatusOr<StitchResult> RipStitchCollar(const StitchInput& in,
                                             std::vector<StitchFailure>* failures = nullptr);

}  // namespace svrc::refine
