// Output assembly (DESIGN.md pipeline step 7, "Result encoding"): the kept tets
// of a labelled tetrahedralization become a canonical mesh::TetMesh — input
// vertices bit-exact at their PLC ids, Steiner points in SpatialOrder, regions,
// boundary/interface triangles with facet markers. Decisions: docs/svrc-output.md.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "absl/status/statusor.h"
#include "core/geometry/vec3.h"
#include "core/mesh/tet_mesh.h"
#include "core/plc/plc.h"
#include "core/svrc/labelling.h"

namespace svrc::refine {

// The mesher's coordinate map, x_mesher = (x_input − translation)·2^−exponent
// (docs/svrc-design.md §1; the same fields and formulas as
// refine::Normalization, repeated here so this module depends on no refiner
// code). The default is the identity.
struct CoordinateMap {
  geom::Vec3 translation{0, 0, 0};
  int exponent = 0;

  geom::Vec3 ToMesher(const geom::Vec3& x) const;  // Normalization::Forward
  geom::Vec3 ToInput(const geom::Vec3& y) const;   // Normalization::Backward
};

struct AssembleInput {
  const plc::Plc* plc = nullptr;  // the input (vertices, seeds); required
  // The tetrahedralization, in the mesher's coordinates (see LabelInput).
  std::span<const geom::Vec3> positions;
  std::span<const std::array<uint32_t, 4>> tets;
  // Per PLC vertex: the vertex of `positions` it became (exact duplicates: the
  // same vertex as their first occurrence). Size plc->vertices.size().
  std::span<const uint32_t> input_vertex;
  CoordinateMap map;
  const Labelling* labelling = nullptr;  // LabelRegions over the same tets; required
  const mesh::MeshStats* stats = nullptr;  // copied into the mesh first (may be null)
};

// Facts about the assembly the caller may want to log or test.
struct AssembleReport {
  uint32_t num_input_vertices = 0;    // = plc->vertices.size()
  uint32_t num_unused_input_vertices = 0;  // in no kept tet (duplicates, dropped parts)
  uint32_t num_steiner_vertices = 0;  // used by kept tets, not input vertices
  uint32_t num_dropped_vertices = 0;  // mesher vertices in no kept tet (∂Ω corners, ...)
  uint32_t num_dropped_tets = 0;
  uint32_t num_regions = 0;
  // Tets whose exact orientation on the *output* coordinates is not positive
  // (the back map rounds Steiner points once; a near-flat tet can flip). 0 is
  // required for a valid mesh; the mesh is returned anyway so the caller can
  // report it.
  uint32_t num_nonpositive_tets = 0;
};

struct AssembledMesh {
  mesh::TetMesh mesh;
  AssembleReport report;
};

// Builds the output mesh (docs/svrc-output.md "Assembly"):
//  - positions[i] = plc->vertices[i] for every PLC vertex i (bit-exact, even
//    if unused), then the Steiner points used by kept tets, mapped back with
//    `map.ToInput`, in mesh::SpatialOrder of their output coordinates;
//  - kept tets (duplicate PLC vertices replaced by their first occurrence);
//  - regions: components with a seed in PLC seed order, then unseeded kept
//    components (attribute 0) by their smallest canonical tet;
//  - one triangle per Labelling face, normal ((b−a)×(c−a)) pointing into the
//    kept tet of the lower region id (boundary: into the kept tet; same region
//    on both sides: towards the apex with the smaller output vertex id);
//  - mesh::Canonicalize; stats copied and "output.*" counters appended.
// INVALID_ARGUMENT for inconsistent inputs (sizes, ids); INTERNAL when an input
// vertex's mesher position does not map back to the PLC's coordinates exactly
// (input_vertex or map is wrong).
absl::StatusOr<AssembledMesh> AssembleMesh(const AssembleInput& input);

// The whole output stage in one call: maps the PLC's seeds with `map`, labels
// (LabelRegions), assembles (AssembleMesh). Label issues are returned too.
// `neighbor_tets` (optional, LabelInput::neighbor_tets): the tets'
// adjacency, e.g. the sliver pass's; the labelling then builds no face table.
struct OutputStageResult {
  mesh::TetMesh mesh;
  AssembleReport report;
  std::vector<LabelIssue> issues;
};
absl::StatusOr<OutputStageResult> BuildOutputMesh(const plc::Plc& plc,
                                                  std::span<const geom::Vec3> positions,
                                                  std::span<const std::array<uint32_t, 4>> tets,
                                                  std::span<const uint32_t> input_vertex,
                                                  std::span<const ConstrainedFace> constrained_faces,
                                                  const CoordinateMap& map, bool keep_bounding_box,
                                                  const mesh::MeshStats* stats = nullptr,
                                                  std::span<const std::array<uint32_t, 4>> neighbor_tets = {});

}  // namespace svrc::refine
