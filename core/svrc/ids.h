// Typed 32-bit ids for the SVRC refinement (thesis §3.2.1): global points,
// protective balls, feature meshes, BLG links, queued events. Flat arrays and
// ids, never pointers into containers (STYLE.md); kNone sentinels.
#pragma once

#include <cstdint>

#include "core/delaunay/delaunay3.h"

namespace svrc::refine {

template <typename Tag>
using Id = delaunay::TypedId<Tag>;

using PointId = Id<struct PointIdTag>;      // a point of the PLC or a Steiner point, global
using BallId = Id<struct BallIdTag>;        // a protective ball (ConfBall / RepBall)
using MeshId = Id<struct MeshIdTag>;        // a feature mesh M_F (M_Ω is mesh 0)
using FeatureId = Id<struct FeatureIdTag>;  // a feature of the PLC (vertex, segment, facet) or Ω
using EventId = Id<struct EventIdTag>;      // one queued work event

inline constexpr PointId kNonePoint{};
inline constexpr BallId kNoneBall{};
inline constexpr MeshId kNoneMesh{};
inline constexpr FeatureId kNoneFeature{};
inline constexpr EventId kNoneEvent{};

// M_Ω is always mesh 0; its feature is Ω itself.
inline constexpr MeshId kOmegaMesh{0};

}  // namespace svrc::refine
