// Which vertices of an output mesh lie on a crease of its PLC (thesis
// Definitions 4-5; docs/plc.md §6): the split ComputeQuality reports
// (radius-edge bounded away from creases, dihedral bounded next to them).
#pragma once

#include <cstdint>
#include <vector>

#include "core/mesh/tet_mesh.h"
#include "core/plc/plc.h"

namespace svrc::mesh {

// One flag per mesh vertex: 1 for a vertex at a crease point of `plc` (exact
// position match) or on a crease segment, found by walking the mesh edges
// from the segment's first end along vertices on the segment (within 1e-12 of
// its length of its line, further along it) to its other end; a conforming
// mesh has every segment as such a chain. All zero if `plc` does not
// validate or has no crease. O(tets + crease-chain vertices × degree).
std::vector<uint8_t> CreaseVertexFlags(const plc::Plc& plc, const TetMesh& mesh);

}  // namespace svrc::mesh
