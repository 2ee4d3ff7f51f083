// Planar polygon helpers for facets given in 3D: projection by dropping the
// dominant normal axis (exact: coordinates are copied, not rotated), loop
// orientation and ear-clipping triangulation with hole bridges, all signs by
// exact predicates (exact.h). Used by coplanar merging and validation.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/geometry/vec3.h"

namespace svrc::plc {

// Newell's normal of a closed loop (robust for non-convex polygons; its length
// is twice the polygon's area).
geom::Vec3 NewellNormal(const std::vector<geom::Vec3>& pts, const std::vector<uint32_t>& loop);

// The axis to drop so that the projection keeps the largest area (the
// dominant component of `normal`), ties broken towards z.
int DropAxis(const geom::Vec3& normal);

// +1 counter-clockwise, -1 clockwise in the projection dropping `drop`;
// 0 if degenerate (all collinear). Exact.
int LoopOrientation(const std::vector<geom::Vec3>& pts, const std::vector<uint32_t>& loop, int drop);

// Point-in-loop test in the projection (crossing number, floating point; for
// seed points, which are never meant to be on the boundary).
bool PointInLoop(const std::vector<geom::Vec3>& pts, const std::vector<uint32_t>& loop,
                 const geom::Vec3& q, int drop);

// Triangulates the region bounded by `outer` minus the `holes` (each a simple
// loop strictly inside outer, pairwise disjoint), projected by dropping `drop`.
// Loops may have collinear vertices; orientation does not matter. Appends
// triangles of point indices (counter-clockwise in the projection when
// outer is) and returns true, or returns false (nothing appended) if the input
// is not a simple polygon with holes.
bool TriangulatePolygon(const std::vector<geom::Vec3>& pts, const std::vector<uint32_t>& outer,
                        const std::vector<std::vector<uint32_t>>& holes, int drop,
                        std::vector<std::array<uint32_t, 3>>* triangles);

// Makes a triangulation from TriangulatePolygon (counter-clockwise in the
// projection) contain the given points as vertices (split triangles) and the
// given segments as edges (cavity retriangulation). Points must lie in the
// triangulated region; no point may lie strictly inside a segment. Returns
// false (triangles possibly partly updated) if a constraint cannot be inserted.
bool InsertConstraints(const std::vector<geom::Vec3>& pts, int drop,
                       const std::vector<uint32_t>& points,
                       const std::vector<std::array<uint32_t, 2>>& segments,
                       std::vector<std::array<uint32_t, 3>>* triangles);

// One point strictly inside a simple loop (centroid of an ear); false if none.
bool PointInsideLoop(const std::vector<geom::Vec3>& pts, const std::vector<uint32_t>& loop,
                     int drop, geom::Vec3* out);

}  // namespace svrc::plc
