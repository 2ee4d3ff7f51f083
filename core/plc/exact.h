// Exact orientation signs used by the PLC readers and validation (coplanar
// merging, intersection tests, point-on-segment): thin wrappers over
// core/geometry/predicates.h; every sign decision of core/plc goes through here.
#pragma once

#include "core/geometry/vec3.h"

namespace svrc::plc {

// Sign of det[b-a, c-a, d-a] (+1, 0, -1), exact. Antisymmetric in its arguments.
int Orient3dSign(const geom::Vec3& a, const geom::Vec3& b, const geom::Vec3& c,
                 const geom::Vec3& d);

// Exact sign of the 2D orientation of the projections of a, b, c onto the
// coordinate plane that drops axis `drop` (0, 1 or 2): (i, j) = the other two
// axes in cyclic order, so drop=2 is the xy plane.
int Orient2dSign(const geom::Vec3& a, const geom::Vec3& b, const geom::Vec3& c, int drop);

}  // namespace svrc::plc
