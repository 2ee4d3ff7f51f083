// Synthetic PLCs and meshes for the mesh tests: a box PLC (optionally split by
// an internal facet) and its Kuhn (Freudenthal) grid tetrahedralization, which
// conforms to it exactly.
#pragma once

#include <string>

#include "core/mesh/tet_mesh.h"
#include "core/plc/plc.h"

namespace svrc::mesh::testing {

// Box [lo, hi]: vertices 0..7 are the corners, corner (i,j,k) in {0,1}^3 is
// vertex i + 2j + 4k; facets x=lo, x=hi, y=lo, y=hi, z=lo, z=hi with markers
// 1..6. With `split`, vertices 8..11 are the corners of the plane
// x = (lo.x+hi.x)/2 and facet 6 (marker 7) is that internal facet.
plc::Plc BoxPlc(Vec3 lo, Vec3 hi, bool split = false);

// Kuhn subdivision of the box into n^3 cells of 6 tets each (n even when the
// PLC is split). Vertices: the PLC's vertices first, in PLC order, then the
// other grid points in grid order. Triangles: the faces on the box boundary
// and on the internal facet, with the facet markers. Region 0 everywhere.
TetMesh KuhnBoxMesh(const plc::Plc& box_plc, int n);

// Replaces mesh->triangles by the tet faces on the box boundary (markers 1..6
// as in BoxPlc) and, when the PLC is split, on the internal facet (marker 7).
void AssignBoxTriangles(const plc::Plc& box_plc, TetMesh* mesh);

// Replaces mesh->triangles by the tet faces lying on an axis-aligned
// rectangular facet of `plc` (the facet's bounding box is flat along one axis),
// each with that facet's marker (first facet wins).
void AssignAxisAlignedTriangles(const plc::Plc& plc, TetMesh* mesh);

// True when `tool` is on PATH.
bool HaveTool(const std::string& tool);

// Runs `cmd` with sh in `dir`, stdout and stderr to `dir/log`; returns the
// exit status (128 + signal when killed).
int RunIn(const std::string& dir, const std::string& cmd, const std::string& log);

// Sum of the floating-point tet volumes.
double TotalVolume(const TetMesh& mesh);

}  // namespace svrc::mesh::testing
