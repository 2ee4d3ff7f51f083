// The points of M_Ω's unresolved 0-balls by position, for Destroy's warp
// targets (Figure 3.4 line 4: 0-balls not yet in M_Ω within θr of the gap
// ball's centre). docs/svrc-design.md §8 item 41.
//
// Before this index, Destroy found those targets either by reading every
// cell of M_Ω that held an unresolved 0-ball (up to 256 of them, wherever
// they were) or by searching the cells meeting the gap ball. Both made the
// work per insertion grow with the mesh (cube --max-volume 1e-6: 140 cells
// read per insertion against 48 at 1e-5). A query here reads the octree
// nodes meeting the ball and the few points in them.
//
// An octree over Ω's cube: a leaf splits into eight when it holds more than
// kLeafSize points (down to a depth cap, where leaves just grow). Points are
// erased by the position they were inserted with; nodes are never merged.
// Queries are conservative: every point within r of c is reported, and
// perhaps some just beyond (the caller tests the exact distance).
#pragma once

#include <cstdint>
#include <vector>

#include "core/geometry/vec3.h"

namespace svrc::refine {

class PendingPoints {
 public:
  // The root cube: centre and half side. Points outside it are kept in a
  // list every query reads (none are expected: every point lies in Ω).
  PendingPoints(const geom::Vec3& center, double half);

  void Insert(uint32_t id, const geom::Vec3& p);
  // Erases the entry `id` inserted at p; false when there is none.
  bool Erase(uint32_t id, const geom::Vec3& p);
  size_t size() const { return size_; }

  // Appends to *out the ids of the points within distance r of c (and
  // possibly some slightly farther), in no particular order. Returns the
  // nodes and points read (the work of the query).
  uint64_t Near(const geom::Vec3& c, double r, std::vector<uint32_t>* out) const;

 private:
  static constexpr uint32_t kLeafSize = 32;
  static constexpr int kMaxDepth = 40;
  struct Entry {
    geom::Vec3 p;
    uint32_t id;
  };
  struct Node {
    geom::Vec3 center;
    double half = 0;
    int32_t child = -1;  // first of 8 consecutive children; -1: a leaf
    int32_t depth = 0;
    std::vector<Entry> entries;  // a leaf's points
  };
  static int Octant(const Node& n, const geom::Vec3& p) {
    return (p.x >= n.center.x ? 1 : 0) | (p.y >= n.center.y ? 2 : 0) | (p.z >= n.center.z ? 4 : 0);
  }
  bool InRoot(const geom::Vec3& p) const;
  uint32_t Leaf(const geom::Vec3& p) const;
  void Split(uint32_t n);

  std::vector<Node> nodes_;
  std::vector<Entry> outside_;
  size_t size_ = 0;
  mutable std::vector<uint32_t> stack_;
};

}  // namespace svrc::refine
