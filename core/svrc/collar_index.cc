#include "core/svrc/collar_index.h"

#include <algorithm>
#include <cmath>

#include "core/geometry/predicates.h"

namespace svrc::refine {

// Level k holds balls with 2^(k-1) < 2r ≤ 2^k: a grid of cell size 2^k, so a
// ball's box [c − r, c + r] spans at most two cells per axis.
int32_t CollarIndex::LevelOf(double radius) {
  int e = 0;
  std::frexp(2 * radius, &e);  // 2r = m·2^e, m ∈ [0.5, 1)
  return e;
}

CollarIndex::Key CollarIndex::KeyOf(int32_t level, const geom::Vec3& x) {
  const double inv = std::ldexp(1.0, -level);
  return {level, static_cast<int64_t>(std::floor(x.x * inv)), static_cast<int64_t>(std::floor(x.y * inv)),
          static_cast<int64_t>(std::floor(x.z * inv))};
}

uint32_t CollarIndex::Add(const CollarBall& ball) {
  const uint32_t id = size();
  balls_.push_back(ball);
  const int32_t level = LevelOf(ball.radius);
  auto it = std::lower_bound(levels_.begin(), levels_.end(), level);
  if (it == levels_.end() || *it != level) levels_.insert(it, level);
  const Vec3 r{ball.radius, ball.radius, ball.radius};
  const Key lo = KeyOf(level, ball.center - r), hi = KeyOf(level, ball.center + r);
  for (int64_t x = lo.x; x <= hi.x; ++x) {
    for (int64_t y = lo.y; y <= hi.y; ++y) {
      for (int64_t z = lo.z; z <= hi.z; ++z) grid_[Key{level, x, y, z}].push_back(id);
    }
  }
  return id;
}

void CollarIndex::ForEachIntersectingPair(const std::function<void(uint32_t, uint32_t, double)>& fn) const {
  // Sweep in x: ball j can meet ball i only if their x-extents overlap.
  std::vector<uint32_t> order(balls_.size());
  for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    const double la = balls_[a].center.x - balls_[a].radius, lb = balls_[b].center.x - balls_[b].radius;
    return la < lb || (la == lb && a < b);
  });
  for (size_t k = 0; k < order.size(); ++k) {
    const CollarBall& a = balls_[order[k]];
    for (size_t l = k + 1; l < order.size(); ++l) {
      const CollarBall& b = balls_[order[l]];
      if (b.center.x - b.radius > a.center.x + a.radius) break;
      const double d = geom::Dist(a.center, b.center);
      if (d >= a.radius + b.radius || d <= std::fabs(a.radius - b.radius)) continue;  // spheres apart or nested
      fn(order[k], order[l], d * d / (a.radius * a.radius + b.radius * b.radius));
    }
  }
}

CollarIndex::Smoothness CollarIndex::MeasureSmoothness() const {
  Smoothness s;
  ForEachIntersectingPair([&](uint32_t, uint32_t, double ratio) {
    ++s.intersecting;
    if (ratio > 1) {
      ++s.not_smooth;
      s.worst = std::max(s.worst, ratio);
    }
  });
  return s;
}

uint32_t CollarIndex::FindContaining(const geom::Vec3& x) const {
  uint32_t best = kNone;
  for (int32_t level : levels_) {
    auto it = grid_.find(KeyOf(level, x));
    if (it == grid_.end()) continue;
    for (uint32_t id : it->second) {
      if (id >= best) continue;
      if (geom::InBall(x, balls_[id].center, balls_[id].radius) > 0) best = id;
    }
  }
  return best;
}

}  // namespace svrc::refine
