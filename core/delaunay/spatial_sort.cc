#include "core/delaunay/spatial_sort.h"

#include <algorithm>
#include <bit>
#include <cmath>

namespace svrc::delaunay {

uint64_t HilbertIndex21(uint32_t x, uint32_t y, uint32_t z) {
  // Skilling's AxesToTranspose: undo excess work level by level, then Gray
  // encode; the index is the transposed bits interleaved, high bits first.
  constexpr int kBits = 21;
  uint32_t X[3] = {x, y, z};
  const uint32_t m = 1u << (kBits - 1);
  for (uint32_t q = m; q > 1; q >>= 1) {
    const uint32_t p = q - 1;
    for (int i = 0; i < 3; ++i) {
      if (X[i] & q) {
        X[0] ^= p;  // invert
      } else {
        const uint32_t t = (X[0] ^ X[i]) & p;  // exchange
        X[0] ^= t;
        X[i] ^= t;
      }
    }
  }
  for (int i = 1; i < 3; ++i) X[i] ^= X[i - 1];
  uint32_t t = 0;
  for (uint32_t q = m; q > 1; q >>= 1) {
    if (X[2] & q) t ^= q - 1;
  }
  for (int i = 0; i < 3; ++i) X[i] ^= t;
  uint64_t key = 0;
  for (int b = kBits - 1; b >= 0; --b) {
    for (int i = 0; i < 3; ++i) key = (key << 1) | ((X[i] >> b) & 1u);
  }
  return key;
}

std::vector<uint32_t> HilbertOrder(std::span<const geom::Vec3> pts,
                                   std::vector<uint64_t>* sorted_keys) {
  const size_t n = pts.size();
  std::vector<uint32_t> order(n);
  if (sorted_keys) sorted_keys->clear();
  if (n == 0) return order;
  geom::Box3 box;
  for (const auto& p : pts) box.Add(p);
  const double ext = std::max({box.hi.x - box.lo.x, box.hi.y - box.lo.y, box.hi.z - box.lo.z});
  const double scale = ext > 0 ? static_cast<double>((1u << 21) - 1) / ext : 0.0;
  std::vector<std::pair<uint64_t, uint32_t>> keyed(n);
  auto q = [&](double v, double lo) {
    double s = (v - lo) * scale;
    if (!(s >= 0)) s = 0;
    if (s > (1u << 21) - 1) s = (1u << 21) - 1;
    return static_cast<uint32_t>(s);
  };
  for (size_t i = 0; i < n; ++i) {
    const auto& p = pts[i];
    keyed[i] = {HilbertIndex21(q(p.x, box.lo.x), q(p.y, box.lo.y), q(p.z, box.lo.z)),
                static_cast<uint32_t>(i)};
  }
  std::sort(keyed.begin(), keyed.end());
  for (size_t i = 0; i < n; ++i) order[i] = keyed[i].second;
  if (sorted_keys) {
    sorted_keys->resize(n);
    for (size_t i = 0; i < n; ++i) (*sorted_keys)[i] = keyed[i].first;
  }
  return order;
}

namespace {
uint64_t SplitMix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}
}  // namespace

std::vector<uint32_t> BrioOrder(std::span<const uint32_t> order) {
  const size_t n = order.size();
  // Rounds 0..max_round, round k has ~n/2^(k+1) points; the smallest (the
  // highest k) is first. Cap so that the first round holds >= ~64 points.
  int max_round = 0;
  while ((n >> (max_round + 2)) >= 64) ++max_round;
  std::vector<uint8_t> round(n);
  std::vector<uint32_t> count(max_round + 1, 0);
  for (size_t i = 0; i < n; ++i) {
    const uint64_t h = SplitMix64(order[i]);
    const int k = std::min(std::countr_one(h), max_round);  // P(k) = 2^-(k+1)
    round[i] = static_cast<uint8_t>(k);
    ++count[k];
  }
  // Start offsets: round max_round first.
  std::vector<uint32_t> start(max_round + 1, 0);
  uint32_t acc = 0;
  for (int k = max_round; k >= 0; --k) {
    start[k] = acc;
    acc += count[k];
  }
  std::vector<uint32_t> out(n);
  for (size_t i = 0; i < n; ++i) out[start[round[i]]++] = order[i];
  return out;
}

}  // namespace svrc::delaunay
