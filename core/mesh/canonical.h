// Canonical order of a TetMesh (DESIGN.md "Result encoding"): the byte-identical
// output of a local and a remote run depends on it. Vertices are ordered by the
// producer (input vertices first in input order, Steiner points along
// SpatialOrder); Canonicalize fixes the order of tets and triangles.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/mesh/tet_mesh.h"

namespace svrc::mesh {

// A permutation of [0, pts.size()) listing the points along a 3D Hilbert curve
// over the points' bounding cube, quantized to 2^21 cells per axis; points in
// the same cell keep their index order. Non-finite coordinates quantize to the
// low corner. Deterministic: depends on the coordinates and their order only.
std::vector<uint32_t> SpatialOrder(const std::vector<Vec3>& pts);

// The Hilbert key SpatialOrder sorts by (63 bits), of a point quantized to
// integer coordinates in [0, 2^21).
uint64_t HilbertKey21(uint32_t x, uint32_t y, uint32_t z);

// Rotates `t` by an even permutation (orientation is kept) so that its
// smallest id comes first and, of the remaining three (cyclically rotated),
// the smallest comes second. Two orderings of the same oriented tet give the
// same result.
std::array<uint32_t, 4> CanonicalTet(std::array<uint32_t, 4> t);
// Cyclic rotation of a triangle so that its smallest id comes first.
std::array<uint32_t, 3> CanonicalTriangle(std::array<uint32_t, 3> t);

// Rotates every tet and triangle to canonical form and sorts tets
// (lexicographically, carrying tet_region; ties by region) and triangles
// (carrying triangle_marker; ties by marker). Vertices are not touched.
// tet_region / triangle_marker may be empty; otherwise they must have one
// entry per tet / triangle.
void Canonicalize(TetMesh* mesh);

// True when Canonicalize would not change the mesh.
bool IsCanonical(const TetMesh& mesh);

// Renumbers vertices: new vertex i is old vertex new_to_old[i] (a permutation
// of [0, num_vertices)). Positions, tets and triangles are rewritten;
// num_input_vertices is kept, so a producer must keep input vertices at
// [0, num_input_vertices). Call Canonicalize afterwards.
void PermuteVertices(TetMesh* mesh, std::span<const uint32_t> new_to_old);

}  // namespace svrc::mesh
