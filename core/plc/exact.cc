// Forwards to core/geometry/predicates.h, the only place where a sign of a
// floating-point expression is decided. Non-finite inputs (which validation
// rejects later) give 0 instead of reaching the exact arithmetic.
#include "core/plc/exact.h"

#include "core/geometry/predicates.h"

namespace svrc::plc {

int Orient3dSign(const geom::Vec3& a, const geom::Vec3& b, const geom::Vec3& c,
                 const geom::Vec3& d) {
  if (!geom::IsFinite(a) || !geom::IsFinite(b) || !geom::IsFinite(c) || !geom::IsFinite(d)) return 0;
  return geom::Orient3d(a, b, c, d);
}

int Orient2dSign(const geom::Vec3& a, const geom::Vec3& b, const geom::Vec3& c, int drop) {
  if (!geom::IsFinite(a) || !geom::IsFinite(b) || !geom::IsFinite(c)) return 0;
  return geom::Orient2dProjected(a, b, c, drop);
}

}  // namespace svrc::plc
