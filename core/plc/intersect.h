// Exact intersection tests between closed segments and triangles in 3D (all
// signs through exact.h), used by validation to find features that meet other
// than at shared points and segments.
#pragma once

#include "core/geometry/vec3.h"

namespace svrc::plc {

// Do the closed segment pq and the closed triangle abc (non-degenerate) meet?
bool SegmentMeetsTriangle(const geom::Vec3& p, const geom::Vec3& q, const geom::Vec3& a,
                          const geom::Vec3& b, const geom::Vec3& c);

// Do the closed segments pq and rs meet (any position, including collinear)?
bool SegmentsMeet(const geom::Vec3& p, const geom::Vec3& q, const geom::Vec3& r,
                  const geom::Vec3& s);

// Do the closed segments pq and rs meet in the projection dropping axis
// `drop`? For edges of one facet, whose points are coplanar only up to
// rounding when the facet is slanted (SegmentsMeet needs exact coplanarity).
bool SegmentsMeetProjected(const geom::Vec3& p, const geom::Vec3& q, const geom::Vec3& r,
                           const geom::Vec3& s, int drop);

// A projection axis (to drop) in which the non-degenerate triangle abc keeps
// a non-zero orientation; -1 if abc is degenerate (collinear points).
int FaithfulDrop(const geom::Vec3& a, const geom::Vec3& b, const geom::Vec3& c);

// v is a vertex of triangle (v, b, c); does the segment from v to x contain
// points of the triangle other than v? (x coplanar and pointing into the
// closed corner of the triangle at v.)
bool SegmentFromCornerEntersTriangle(const geom::Vec3& v, const geom::Vec3& x,
                                     const geom::Vec3& b, const geom::Vec3& c);

// Are a, b, c collinear (exactly)?
bool Collinear(const geom::Vec3& a, const geom::Vec3& b, const geom::Vec3& c);

// Is p strictly inside the segment ab (exactly on it, not an endpoint)?
bool StrictlyInsideSegment(const geom::Vec3& p, const geom::Vec3& a, const geom::Vec3& b);

// Is p in the closed triangle abc (exactly, coplanar included)?
bool PointInTriangle(const geom::Vec3& p, const geom::Vec3& a, const geom::Vec3& b,
                     const geom::Vec3& c);

// Euclidean distances (floating point; for the spread).
double PointSegmentDistance(const geom::Vec3& p, const geom::Vec3& a, const geom::Vec3& b);
double PointTriangleDistance(const geom::Vec3& p, const geom::Vec3& a, const geom::Vec3& b,
                             const geom::Vec3& c);
double SegmentSegmentDistance(const geom::Vec3& p, const geom::Vec3& q, const geom::Vec3& r,
                              const geom::Vec3& s);

}  // namespace svrc::plc
