// A uniform grid over axis-aligned boxes: the spatial index that keeps the
// intersection and distance checks of validation near-linear instead of
// quadratic (DESIGN.md "Validate and prepare").
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/geometry/vec3.h"

namespace svrc::plc {

class BoxGrid {
 public:
  // About `n_items` cells over `bounds` (cubic cells, at most ~2M).
  BoxGrid(const geom::Box3& bounds, size_t n_items) : bounds_(bounds) {
    const geom::Vec3 ext = bounds.Empty() ? geom::Vec3() : bounds.hi - bounds.lo;
    const double m = std::max({ext.x, ext.y, ext.z});
    const double cells = std::clamp<double>(static_cast<double>(n_items), 1.0, 2.0e6);
    h_ = m > 0 ? m / std::cbrt(cells) : 1.0;
    if (!(h_ > 0) || !std::isfinite(h_)) h_ = 1.0;
    for (int k = 0; k < 3; ++k) {
      n_[k] = static_cast<int64_t>(std::clamp(std::floor(ext[k] / h_) + 1, 1.0, 2048.0));
    }
    cells_.resize(static_cast<size_t>(n_[0] * n_[1] * n_[2]));
  }

  uint32_t Insert(const geom::Box3& box) {
    const uint32_t id = static_cast<uint32_t>(boxes_.size());
    boxes_.push_back(box);
    int64_t lo[3], hi[3];
    Range(box, lo, hi);
    for (int64_t z = lo[2]; z <= hi[2]; ++z)
      for (int64_t y = lo[1]; y <= hi[1]; ++y)
        for (int64_t x = lo[0]; x <= hi[0]; ++x) cells_[Index(x, y, z)].push_back(id);
    return id;
  }

  const geom::Box3& box(uint32_t id) const { return boxes_[id]; }

  // Ids of the boxes overlapping `q`, sorted, without duplicates.
  void Query(const geom::Box3& q, std::vector<uint32_t>* out) const {
    out->clear();
    int64_t lo[3], hi[3];
    Range(q, lo, hi);
    for (int64_t z = lo[2]; z <= hi[2]; ++z)
      for (int64_t y = lo[1]; y <= hi[1]; ++y)
        for (int64_t x = lo[0]; x <= hi[0]; ++x)
          for (uint32_t id : cells_[Index(x, y, z)])
            if (Overlap(boxes_[id], q)) out->push_back(id);
    std::sort(out->begin(), out->end());
    out->erase(std::unique(out->begin(), out->end()), out->end());
  }

  static bool Overlap(const geom::Box3& a, const geom::Box3& b) {
    return a.lo.x <= b.hi.x && b.lo.x <= a.hi.x && a.lo.y <= b.hi.y && b.lo.y <= a.hi.y &&
           a.lo.z <= b.hi.z && b.lo.z <= a.hi.z;
  }

  // f(i, j), i < j, once per pair of overlapping boxes (in a deterministic order).
  template <class F>
  void ForEachOverlappingPair(F&& f) const {
    for (size_t c = 0; c < cells_.size(); ++c) {
      const auto& ids = cells_[c];
      for (size_t s = 0; s < ids.size(); ++s) {
        for (size_t t = s + 1; t < ids.size(); ++t) {
          const geom::Box3& a = boxes_[ids[s]];
          const geom::Box3& b = boxes_[ids[t]];
          if (!Overlap(a, b)) continue;
          // Report in the cell holding the low corner of the overlap only.
          const geom::Vec3 corner{std::max(a.lo.x, b.lo.x), std::max(a.lo.y, b.lo.y),
                                  std::max(a.lo.z, b.lo.z)};
          if (CellOf(corner) != c) continue;
          f(std::min(ids[s], ids[t]), std::max(ids[s], ids[t]));
        }
      }
    }
  }

 private:
  int64_t Coord(double v, int k) const {
    const double t = std::floor((v - bounds_.lo[k]) / h_);
    if (!(t >= 0)) return 0;
    return std::min<int64_t>(static_cast<int64_t>(std::min(t, 4.0e9)), n_[k] - 1);
  }
  void Range(const geom::Box3& b, int64_t lo[3], int64_t hi[3]) const {
    for (int k = 0; k < 3; ++k) {
      lo[k] = Coord(b.lo[k], k);
      hi[k] = Coord(b.hi[k], k);
    }
  }
  size_t Index(int64_t x, int64_t y, int64_t z) const {
    return static_cast<size_t>((z * n_[1] + y) * n_[0] + x);
  }
  size_t CellOf(const geom::Vec3& p) const { return Index(Coord(p.x, 0), Coord(p.y, 1), Coord(p.z, 2)); }

  geom::Box3 bounds_;
  double h_ = 1;
  int64_t n_[3] = {1, 1, 1};
  std::vector<std::vector<uint32_t>> cells_;
  std::vector<geom::Box3> boxes_;
};

}  // namespace svrc::plc
