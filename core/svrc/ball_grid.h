// A uniform grid of collar balls: "which balls can contain p / meet this
// box" without scanning them all (RipStitchCollar's hole boundary, the COLLAR
// rounds' "on S" tests: a scan of every ball per root and repair was 22% of
// a fandisk.off run's samples, 5,651 balls). Exact: StrictlyInside gives the
// answer of InsideAnyBall / !OnCollarSurface over the same list. A double x
// strictly inside a ball has c − r < x < c + r, and every step from a
// coordinate to its cell (subtraction, division, floor, clamp) is monotone,
// so the ball is filed in the cell holding x.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "core/geometry/predicates.h"
#include "core/svrc/collar_geometry.h"

namespace svrc::refine {

// Uniform grid over the balls' bounding boxes, so that "which balls can
// contain p / meet this segment" is local (the refiner has thousands of balls
// and the hole boundary tens of thousands of faces). Sorted (cell, ball)
// pairs: lookups only, no iteration order leaks into the output.
class BallGrid {
 public:
  static constexpr uint32_t kNone = 0xFFFFFFFFu;
  explicit BallGrid(std::span<const CollarBall> balls) : balls_(balls) {
    if (balls.empty()) return;
    double sum_r = 0, max_r = 0;
    Vec3 lo = balls[0].center, hi = balls[0].center;
    for (const CollarBall& b : balls) {
      sum_r += b.radius;
      max_r = std::max(max_r, b.radius);
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], b.center[k] - b.radius);
        hi[k] = std::max(hi[k], b.center[k] + b.radius);
      }
    }
    origin_ = lo;
    bbox_hi_ = hi;
    // A large ball covers at most ~17³ cells; small balls share cells.
    h_ = std::max(2 * sum_r / static_cast<double>(balls.size()), max_r / 8);
    for (uint32_t i = 0; i < balls.size(); ++i) {
      const CollarBall& b = balls[i];
      int64_t c0[3], c1[3];
      CellRange(b.center - Vec3(b.radius, b.radius, b.radius),
                b.center + Vec3(b.radius, b.radius, b.radius), c0, c1);
      for (int64_t x = c0[0]; x <= c1[0]; ++x) {
        for (int64_t y = c0[1]; y <= c1[1]; ++y) {
          for (int64_t z = c0[2]; z <= c1[2]; ++z) cells_.push_back({Key(x, y, z), i});
        }
      }
    }
    std::sort(cells_.begin(), cells_.end());
  }

  const Vec3& lo() const { return origin_; }
  const Vec3& hi() const { return bbox_hi_; }

  // Balls whose bounding box may meet the box [lo, hi]; ascending, unique.
  // All balls when the box spans more cells than there are balls.
  void Query(const Vec3& lo, const Vec3& hi, std::vector<uint32_t>* out) const {
    out->clear();
    if (balls_.empty()) return;
    int64_t c0[3], c1[3];
    CellRange(lo, hi, c0, c1);
    const double ncells = static_cast<double>(c1[0] - c0[0] + 1) *
                          static_cast<double>(c1[1] - c0[1] + 1) *
                          static_cast<double>(c1[2] - c0[2] + 1);
    if (ncells > 4.0 * static_cast<double>(balls_.size()) + 64) {
      for (uint32_t i = 0; i < balls_.size(); ++i) out->push_back(i);
      return;
    }
    for (int64_t x = c0[0]; x <= c1[0]; ++x) {
      for (int64_t y = c0[1]; y <= c1[1]; ++y) {
        for (int64_t z = c0[2]; z <= c1[2]; ++z) {
          const uint64_t key = Key(x, y, z);
          auto it = std::lower_bound(cells_.begin(), cells_.end(), std::pair<uint64_t, uint32_t>{key, 0});
          for (; it != cells_.end() && it->first == key; ++it) out->push_back(it->second);
        }
      }
    }
    std::sort(out->begin(), out->end());
    out->erase(std::unique(out->begin(), out->end()), out->end());
  }

  // Exact: p strictly inside some ball other than skip1, skip2 (geom::InBall).
  bool StrictlyInside(const Vec3& p, uint32_t skip1 = kNone, uint32_t skip2 = kNone) const {
    if (balls_.empty()) return false;
    int64_t c[3];
    for (int k = 0; k < 3; ++k) c[k] = Coord(p[k], k);
    const uint64_t key = Key(c[0], c[1], c[2]);
    auto it = std::lower_bound(cells_.begin(), cells_.end(), std::pair<uint64_t, uint32_t>{key, 0});
    for (; it != cells_.end() && it->first == key; ++it) {
      const uint32_t j = it->second;
      if (j == skip1 || j == skip2) continue;
      if (geom::InBall(p, balls_[j].center, balls_[j].radius) > 0) return true;
    }
    return false;
  }

 private:
  static constexpr int64_t kMaxCell = (int64_t{1} << 21) - 1;
  int64_t Coord(double v, int axis) const {
    const double c = std::floor((v - origin_[axis]) / h_);
    if (!(c > 0)) return 0;  // also NaN
    if (c >= static_cast<double>(kMaxCell)) return kMaxCell;
    return static_cast<int64_t>(c);
  }
  void CellRange(const Vec3& lo, const Vec3& hi, int64_t c0[3], int64_t c1[3]) const {
    for (int k = 0; k < 3; ++k) {
      c0[k] = Coord(lo[k], k);
      c1[k] = Coord(hi[k], k);
    }
  }
  static uint64_t Key(int64_t x, int64_t y, int64_t z) {
    return (static_cast<uint64_t>(x) << 42) | (static_cast<uint64_t>(y) << 21) |
           static_cast<uint64_t>(z);
  }

  std::span<const CollarBall> balls_;
  Vec3 origin_, bbox_hi_;
  double h_ = 1;
  std::vector<std::pair<uint64_t, uint32_t>> cells_;
};

}  // namespace svrc::refine
