// Element quality of a TetMesh: radius-edge ratio (the SVRC bound τ/2 of thesis
// §3, DESIGN.md "Quality"), the six dihedral angles and a normalized aspect
// ratio, summarized as percentiles for tets touching a crease and the rest.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/mesh/tet_mesh.h"

namespace svrc::mesh {

struct TetQuality {
  // Circumradius / shortest edge; √6/4 ≈ 0.612 for the regular tet,
  // +inf for a degenerate (flat) tet.
  double radius_edge = 0;
  // Dihedral angles in degrees at edges (0,1) (0,2) (0,3) (1,2) (1,3) (2,3).
  std::array<double, 6> dihedral_deg{};
  double min_dihedral_deg = 0;
  double max_dihedral_deg = 0;
  // Longest edge / (2√6 · inradius): 1 for the regular tet, +inf when flat.
  double aspect = 0;
  double volume = 0;  // signed, det/6 in floating point (not exact)
};

TetQuality ComputeTetQuality(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

// Order statistics of one metric (nearest-rank percentiles). All zero when
// count == 0.
struct Distribution {
  size_t count = 0;
  double min = 0, p1 = 0, p5 = 0, p50 = 0, p95 = 0, p99 = 0, max = 0;
  // Nearest-rank percentiles of `values` (taken by value and reordered).
  static Distribution Of(std::vector<double> values);
};

struct QualityGroup {
  size_t num_tets = 0;
  Distribution radius_edge;
  Distribution dihedral_deg;  // all six angles of every tet of the group
  Distribution min_dihedral_deg;  // per tet
  Distribution aspect;
  double max_volume = 0;  // the largest TetQuality::volume of the group (signed; 0 if empty)
};

struct QualityReport {
  QualityGroup crease;  // tets with at least one crease vertex
  QualityGroup other;   // the rest (the radius-edge bound applies here)
  QualityGroup all;
};

// `crease_vertex` is empty (no creases) or has one flag per mesh vertex.
QualityReport ComputeQuality(const TetMesh& mesh,
                             const std::vector<uint8_t>& crease_vertex = {});

// The largest dihedral angle (degrees) of the tets with a flagged vertex, each
// less the most that rounding its vertices to doubles can have moved it:
// 8·u/h radians, u = 2^-52 · the tet's largest |coordinate|, h = its smallest
// altitude (a vertex moved by δ turns the normals of its faces by at most
// δ/h). A mesher computes in its own coordinates and rounds Steiner points
// into the input's; far from the origin that moves the angles of small tets
// (random_plcs.py near+rot+far 5: 3.9e-5 degrees over the stitched stars' own
// largest angle). 0 when no tet has a flagged vertex.
double MaxDihedralLessRounding(const TetMesh& mesh, const std::vector<uint8_t>& flagged_vertex);

// The tets without a crease vertex (crease_vertex as for ComputeQuality)
// whose smallest dihedral angle is below min_deg even with the rounding
// allowance of MaxDihedralLessRounding added, and the smallest such angle of
// all those tets (MeshParams::min_dihedral, core/api.cc).
struct MinDihedralShortfall {
  size_t num_below = 0;
  double smallest_deg = 180;  // 180: no tet without a crease vertex
};
MinDihedralShortfall BelowMinDihedral(const TetMesh& mesh, const std::vector<uint8_t>& crease_vertex,
                                      double min_deg);

// Several lines of text for the CLI ("svrc mesh --stats"); ends with '\n'.
std::string FormatQualityReport(const QualityReport& report);

}  // namespace svrc::mesh
