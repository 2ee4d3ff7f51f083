// Synthetic tetrahedral meshes for the codec tests and bench/codec: a box of
// nx*ny*nz cubes, each split into the 6 Kuhn tetrahedra (all sharing the
// cube's main diagonal, so neighbouring cubes match), optionally with jittered
// interior vertices and a Hilbert vertex order, then canonicalized.
#pragma once

#include <cstdint>

#include "core/mesh/tet_mesh.h"

namespace svrc::codec::testing {

struct GridMeshOptions {
  int nx = 2, ny = 2, nz = 2;
  mesh::Vec3 origin = {0, 0, 0};
  double spacing = 1.0;
  // Interior vertices move by up to jitter * spacing per axis (deterministic
  // generator, platform independent).
  double jitter = 0.0;
  uint64_t seed = 1;
  // Renumber vertices along mesh::SpatialOrder (what a mesher's canonical
  // order looks like); otherwise grid order, x fastest.
  bool hilbert_order = false;
};

// Tets are positively oriented (det[b-a, c-a, d-a] > 0 before jitter), two
// regions (cubes with x index < nx/2 are region 0), boundary triangles carry
// markers 1..6 (faces x-, x+, y-, y+, z-, z+). num_input_vertices is 8.
// Provenance is filled with fixed strings.
mesh::TetMesh MakeGridMesh(const GridMeshOptions& options);

}  // namespace svrc::codec::testing
