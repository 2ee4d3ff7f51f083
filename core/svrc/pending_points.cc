#include "core/svrc/pending_points.h"

#include <algorithm>
#include <cmath>

namespace svrc::refine {

using geom::Vec3;

PendingPoints::PendingPoints(const Vec3& center, double half) {
  Node root;
  root.center = center;
  root.half = half;
  nodes_.push_back(std::move(root));
}

bool PendingPoints::InRoot(const Vec3& p) const {
  const Node& r = nodes_[0];
  return std::abs(p.x - r.center.x) <= r.half && std::abs(p.y - r.center.y) <= r.half &&
         std::abs(p.z - r.center.z) <= r.half;
}

uint32_t PendingPoints::Leaf(const Vec3& p) const {
  uint32_t n = 0;
  while (nodes_[n].child >= 0) n = static_cast<uint32_t>(nodes_[n].child + Octant(nodes_[n], p));
  return n;
}

void PendingPoints::Split(uint32_t n) {
  const int32_t first = static_cast<int32_t>(nodes_.size());
  const double h = 0.5 * nodes_[n].half;
  for (int k = 0; k < 8; ++k) {
    Node c;
    const Vec3& o = nodes_[n].center;
    c.center = Vec3{o.x + ((k & 1) ? h : -h), o.y + ((k & 2) ? h : -h), o.z + ((k & 4) ? h : -h)};
    c.half = h;
    c.depth = nodes_[n].depth + 1;
    nodes_.push_back(std::move(c));  // may move nodes_: index, do not hold references
  }
  std::vector<Entry> entries = std::move(nodes_[n].entries);
  nodes_[n].entries = {};
  nodes_[n].child = first;
  for (const Entry& e : entries) nodes_[static_cast<uint32_t>(first + Octant(nodes_[n], e.p))].entries.push_back(e);
}

void PendingPoints::Insert(uint32_t id, const Vec3& p) {
  ++size_;
  if (!InRoot(p)) {
    outside_.push_back({p, id});
    return;
  }
  const uint32_t n = Leaf(p);
  nodes_[n].entries.push_back({p, id});
  if (nodes_[n].entries.size() > kLeafSize && nodes_[n].depth < kMaxDepth) Split(n);
}

bool PendingPoints::Erase(uint32_t id, const Vec3& p) {
  std::vector<Entry>& list = InRoot(p) ? nodes_[Leaf(p)].entries : outside_;
  for (size_t i = 0; i < list.size(); ++i) {
    if (list[i].id != id) continue;
    list[i] = list.back();
    list.pop_back();
    --size_;
    return true;
  }
  return false;
}

uint64_t PendingPoints::Near(const Vec3& c, double r, std::vector<uint32_t>* out) const {
  uint64_t work = 0;
  // Conservative in rounding: a child's box (centre ± half, one rounding per
  // coordinate) may miss a point of its octant by an ulp of the centre, and
  // r² by a few ulps; both slacks are far above those errors.
  const double r2 = r * r * (1 + 1e-9);
  auto dist2_to_box = [&](const Node& n) {
    double d2 = 0;
    for (int i = 0; i < 3; ++i) {
      const double g = std::abs(c[i] - n.center[i]) - n.half * (1 + 1e-9) -
                       1e-15 * (std::abs(n.center[i]) + std::abs(c[i]));
      if (g > 0) d2 += g * g;
    }
    return d2;
  };
  for (const Entry& e : outside_) {
    ++work;
    if (geom::Dist2(e.p, c) <= r2) out->push_back(e.id);
  }
  if (size_ == outside_.size()) return work;
  stack_.assign(1, 0);
  while (!stack_.empty()) {
    const Node& n = nodes_[stack_.back()];
    stack_.pop_back();
    ++work;
    if (dist2_to_box(n) > r2) continue;
    if (n.child < 0) {
      for (const Entry& e : n.entries) {
        ++work;
        if (geom::Dist2(e.p, c) <= r2) out->push_back(e.id);
      }
      continue;
    }
    for (int k = 0; k < 8; ++k) stack_.push_back(static_cast<uint32_t>(n.child + k));
  }
  return work;
}

}  // namespace svrc::refine
