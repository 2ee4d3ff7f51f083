// Internal steps of building the feature complex (prepare.cc, creases.cc).
#pragma once

#include "core/plc/features.h"

namespace svrc::plc::internal {

// Marks crease points and segments (thesis Definitions 4-5, guide §5 items
// 5-7) using the facets' frames and triangulations; fills min_angle.
void ComputeCreases(FeatureComplex* fc, double crease_angle_deg);

// Fills diameter, min_feature_distance and spread (docs/plc.md).
void ComputeSpread(FeatureComplex* fc);

}  // namespace svrc::plc::internal
