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

void CollarIndex::Candidates(const geom::Vec3& c, double r, std::vector<uint32_t>* out) const {
  out->clear();
  const Vec3 rv{r, r, r};
  for (int32_t level : levels_) {
    const Key lo = KeyOf(level, c - rv), hi = KeyOf(level, c + rv);
    // A query much larger than the level's cells: scan its balls instead.
    if ((hi.x - lo.x + 1) * (hi.y - lo.y + 1) * (hi.z - lo.z + 1) > 512) {
      for (uint32_t id = 0; id < size(); ++id) {
        if (LevelOf(balls_[id].radius) != level) continue;
        out->push_back(id);
      }
      continue;
    }
    for (int64_t x = lo.x; x <= hi.x; ++x) {
      for (int64_t y = lo.y; y <= hi.y; ++y) {
        for (int64_t z = lo.z; z <= hi.z; ++z) {
          auto it = grid_.find(Key{level, x, y, z});
          if (it != grid_.end()) out->insert(out->end(), it->second.begin(), it->second.end());
        }
      }
    }
  }
  std::sort(out->begin(), out->end());
  out->erase(std::unique(out->begin(), out->end()), out->end());
  // Exact box overlap filter.
  std::erase_if(*out, [&](uint32_t id) {
    const CollarBall& b = balls_[id];
    return std::abs(b.center.x - c.x) > b.radius + r || std::abs(b.center.y - c.y) > b.radius + r ||
           std::abs(b.center.z - c.z) > b.radius + r;
  });
}

}  // namespace svrc::refine
