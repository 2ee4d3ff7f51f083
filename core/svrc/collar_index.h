// The collar system of a running refinement (thesis §3.1.2, Figure 3.7's
// "augment the collar system"): the collar balls B(c, g(c)/3) created so far,
// with a hierarchical grid answering "is x strictly inside some collar ball"
// (the suppression test of Figure 3.9) in O(levels) hash lookups.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "absl/container/flat_hash_map.h"
#include "core/geometry/vec3.h"
#include "core/svrc/collar_geometry.h"

namespace svrc::refine {

class CollarIndex {
 public:
  static constexpr uint32_t kNone = 0xFFFFFFFFu;

  // Adds a ball (radius > 0); returns its id (0, 1, ... in insertion order).
  uint32_t Add(const CollarBall& ball);
  uint32_t size() const { return static_cast<uint32_t>(balls_.size()); }
  const CollarBall& ball(uint32_t i) const { return balls_[i]; }
  const std::vector<CollarBall>& balls() const { return balls_; }

  // The lowest id of a ball with x strictly inside (exact: geom::InBall > 0),
  // or kNone.
  uint32_t FindContaining(const geom::Vec3& x) const;
  bool StrictlyInside(const geom::Vec3& x) const { return FindContaining(x) != kNone; }

  // Lemma 14: two balls whose spheres intersect meet at a tangent angle
  // ≥ π/2 iff |c₁c₂|² ≤ r₁² + r₂² (a smooth collar system, Definition 27;
  // Lemma 17 says SVRC produces one). Counts over all pairs whose spheres
  // intersect; `worst` = the largest |c₁c₂|² / (r₁² + r₂²) among them.
  struct Smoothness {
    uint64_t intersecting = 0, not_smooth = 0;
    double worst = 0;
  };
  Smoothness MeasureSmoothness() const;
  // fn(i, j, |c_i c_j|² / (r_i² + r_j²)) for every pair of balls whose
  // spheres intersect (neither apart nor nested), found by a sweep in x.
  void ForEachIntersectingPair(const std::function<void(uint32_t, uint32_t, double)>& fn) const;

 private:
  struct Key {
    int32_t level;
    int64_t x, y, z;
    friend bool operator==(const Key&, const Key&) = default;
    template <typename H>
    friend H AbslHashValue(H h, const Key& k) {
      return H::combine(std::move(h), k.level, k.x, k.y, k.z);
    }
  };
  static int32_t LevelOf(double radius);
  static Key KeyOf(int32_t level, const geom::Vec3& x);

  std::vector<CollarBall> balls_;
  absl::flat_hash_map<Key, std::vector<uint32_t>> grid_;
  std::vector<int32_t> levels_;  // occupied levels, ascending
};

}  // namespace svrc::refine
