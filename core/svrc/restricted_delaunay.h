// Restricted Delaunay of the collar surface S (thesis §2.4.2, Definitions 28–31,
// 34, 38; guide "Restricted Delaunay of S"): restricted triangles of one partial
// sphere with representation points, RepBall radii and representation angles;
// restricted edges of a collar circle; the topological-ball validator (a)–(e).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "core/delaunay/delaunay3.h"
#include "core/svrc/collar_geometry.h"

namespace svrc::refine {

// A triangle of Del(M)|_S for partial sphere `ball` (Definition 29: its dual
// Voronoi edge pierces S at x). Vertex ids ascending.
struct RestrictedTriangle {
  delaunay::VertexId v[3];
  uint32_t ball = 0;        // the partial sphere (index into the balls span)
  Vec3 x;                   // representation point (worst angle if several)
  double rep_radius = 0;    // RepBall B(x, |x − v0|) (Definition 38)
  double angle = 0;         // representation angle σ(T) (Definition 34), radians
  int num_roots = 0;        // Voronoi-edge ∩ S count; ≠ 1 violates (a)
};

// A restricted edge of a collar circle: its Voronoi facet meets the circle at x.
struct RestrictedEdge {
  delaunay::VertexId v[2];  // ascending
  Vec3 x;
  double angle = 0;         // CircleRepresentationAngle
};

// Options for the Voronoi skeleton: hull faces have a Voronoi ray, cut at
// `ray_length` (default: long enough to cross every ball given).
struct RestrictedOptions {
  double ray_length = 0;  // 0 = automatic
};

// Restricted triangles of partial sphere `ball` of `balls` in `dt` (finite
// triangles in tet-slot order, each once; deterministic). For every Voronoi
// edge (segment between the circumcentres of the two tets sharing the
// triangle, or the ray of a hull triangle) the roots on sphere `ball` that are
// on S (not strictly inside another ball) are kept. The angle uses `snapped`
// coordinates when given (Snap, thesis §3.1.2): the normal of the triangle of
// snapped vertices; `snapped` is indexed by VertexId value.
std::vector<RestrictedTriangle> RestrictedSphereTriangles(const delaunay::Delaunay3& dt,
                                                          std::span<const CollarBall> balls,
                                                          uint32_t ball,
                                                          std::span<const Vec3> snapped = {},
                                                          RestrictedOptions opt = {});

// Restricted edges of `circle`: Delaunay edges ab whose Voronoi facet (part of
// the bisector plane of ab closer to a, b than to any vertex) meets the circle,
// skipping points strictly inside `others`. Each of the ≤ 2 bisector ∩ circle
// points is kept iff a (or b) is a nearest vertex of it (NearestVertex walk;
// a construction-level test on a constructed point). Sorted by vertex ids.
std::vector<RestrictedEdge> RestrictedCircleEdges(const delaunay::Delaunay3& dt,
                                                  const Circle3& circle,
                                                  std::span<const CollarBall> others);

// Snap (thesis §3.1.2): p moved radially onto the sphere of `ball` when
// ||p − c| − ρ| ≤ delta·ρ; otherwise p unchanged.
Vec3 SnapToSphere(const Vec3& p, const CollarBall& ball, double delta);

// The practical topological-ball test (guide (a)–(e)) for partial sphere `ball`
// given its restricted triangles, and optionally the restricted edges of the
// circles on its boundary. Checks: (a) every triangle has one root; (b) every
// Delaunay edge has 0 or 2 restricted triangles around it (its Voronoi facet
// meets S in at most one arc); (c) each vertex's restricted link is one cycle;
// (d) a non-empty partial sphere has at least one restricted triangle;
// (e) each circle's restricted edges form one cycle of ≥ 3 vertices.
// For a whole sphere (no circles) (a)–(d) make the restricted triangulation a
// closed 2-manifold. OK or FAILED_PRECONDITION naming the first violation.
struct TopologyReport {
  int bad_roots = 0;          // (a)
  int bad_facets = 0;         // (b)
  int bad_links = 0;          // (c)
  bool empty_sphere = false;  // (d)
  int bad_circles = 0;        // (e)
  int euler = 0;              // V − E + F of the restricted triangles
};
absl::Status ValidateRestrictedTopology(std::span<const RestrictedTriangle> tris,
                                        std::span<const std::vector<RestrictedEdge>> circle_edges,
                                        TopologyReport* report);

}  // namespace svrc::refine
