// Exact, sign-preserving normalisation of the input to a box of extent < 1
// (docs/svrc-design.md §1): x' = (x − t)·2^−e with a per-axis translation t
// that Sterbenz' lemma makes exact, and one power-of-two scale. Every predicate
// sign on normalised points equals the sign on the input points, and input
// points map back bit-exactly.
#pragma once

#include <span>

#include "absl/status/statusor.h"
#include "core/geometry/vec3.h"

namespace svrc::refine {

struct Normalization {
  geom::Vec3 translation;  // t, per axis
  int exponent = 0;        // e: x' = (x − t)·2^−e

  geom::Vec3 Forward(const geom::Vec3& x) const;
  geom::Vec3 Backward(const geom::Vec3& y) const;  // exact for images of input points
  // Length scale: input length = normalised length · 2^e.
  double ToInputLength(double normalised) const;
};

// Chooses the map for `points` (all finite, at least one). INVALID_ARGUMENT on
// non-finite coordinates or extents so small that scaling would leave the
// normal range (< 2^−900).
absl::StatusOr<Normalization> ChooseNormalization(std::span<const geom::Vec3> points);

}  // namespace svrc::refine
