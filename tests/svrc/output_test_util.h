// Inputs for the output-stage tests (labelling_test.cc, assemble_test.cc):
// Kuhn grid tetrahedralizations, box PLCs, and the constrained faces of a
// tetrahedralization on convex facets (exact coplanarity and containment).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "core/geometry/vec3.h"
#include "core/mesh/tet_mesh.h"
#include "core/plc/plc.h"
#include "core/svrc/assemble.h"
#include "core/svrc/labelling.h"

namespace svrc::refine::testing {

using geom::Vec3;

// The Kuhn (Freudenthal) subdivision of [0,n]^3 into n^3 unit cubes of 6
// positively oriented tets each; vertex (i,j,k) has id i + (n+1)(j + (n+1)k)
// and integer coordinates. Conforms to every grid plane.
struct Grid {
  int n = 0;
  std::vector<Vec3> positions;
  std::vector<std::array<uint32_t, 4>> tets;
  uint32_t Id(int i, int j, int k) const {
    return static_cast<uint32_t>(i + (n + 1) * (j + (n + 1) * k));
  }
};
Grid KuhnGrid(int n);

// n tets with the apex (0, 0, 1) = vertex 0 in common and nothing else but
// the edges to their neighbours: tet i = (0, r_i, r_{i+1}, m_i), positively
// oriented, over ring points r_i = 1 .. n on the unit circle and m_i = n+1 ..
// 2n, 0.9 × the midpoint of r_i r_{i+1}. Vertex 0 (the lowest id) has degree
// n, every edge at most 2, and vertex 0 is in every cone face (0, r_i,
// r_{i+1}), as an input vertex at a crease is in a fine mesh's facet
// triangles (crease_pair_0.1deg, session 40). `cone_faces` gets the n faces.
Grid ApexFan(int n, std::vector<std::array<uint32_t, 3>>* cone_faces);

// A convex planar polygon (in the mesher's coordinates) with its marker.
struct ConvexFacet {
  std::vector<Vec3> pts;
  int32_t marker = 0;
  uint32_t facet = kNoFacet;
};

// The faces of `tets` lying on a facet: three vertices exactly coplanar with
// it and inside or on its (convex) polygon. First facet wins.
std::vector<ConstrainedFace> FacesOnConvexFacets(std::span<const Vec3> pos,
                                                 std::span<const std::array<uint32_t, 4>> tets,
                                                 const std::vector<ConvexFacet>& facets);

// The facets of `plc` (first polygon of each, assumed convex), mapped to the
// mesher's coordinates.
std::vector<ConvexFacet> ConvexFacetsOf(const plc::Plc& plc, const CoordinateMap& map);

// Adds the 8 corners of the box [lo, hi] (corner (a,b,c) in {0,1}^3 is the
// a + 2b + 4c-th added vertex) and its 6 quad facets, all with `marker`.
void AddBox(plc::Plc* plc, Vec3 lo, Vec3 hi, int32_t marker);

// Per PLC vertex: the grid vertex with the same coordinates under `map`
// (ToMesher); fails the test if there is none.
std::vector<uint32_t> GridVertexOf(const plc::Plc& plc, const Grid& grid, const CoordinateMap& map);

double TetVolume(const mesh::TetMesh& m, size_t t);
Vec3 TetCentroid(const mesh::TetMesh& m, size_t t);

// Byte-exact equality of everything the codec writes (positions by bits).
bool SameMesh(const mesh::TetMesh& a, const mesh::TetMesh& b);

}  // namespace svrc::refine::testing
