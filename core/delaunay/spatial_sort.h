// Spatial orders for incremental insertion: Hilbert keys and a biased
// randomized insertion order (BRIO, Amenta–Choi–Rote 2003) whose rounds are
// each sorted along a Hilbert curve. Deterministic: no seeds from the clock.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/geometry/vec3.h"

namespace svrc::delaunay {

// Hilbert index (63 bits) of integer coordinates in [0, 2^21), after
// Skilling, "Programming the Hilbert curve" (AIP Conf. Proc. 707, 2004).
uint64_t HilbertIndex21(uint32_t x, uint32_t y, uint32_t z);

// Indices [0, pts.size()) sorted by the Hilbert index of each point quantized
// on the points' bounding cube (ties by index). Points must be finite. If
// `sorted_keys` is set it receives the Hilbert index of each entry of the
// result (equal points have equal keys).
std::vector<uint32_t> HilbertOrder(std::span<const geom::Vec3> pts,
                                   std::vector<uint64_t>* sorted_keys = nullptr);

// BRIO: a point goes to round k >= 0 with probability 2^-(k+1) (the last
// round holds about half of the points), decided by a hash of its index; the
// rounds are inserted smallest first and each keeps the order of `order`
// (a Hilbert order). The first round is made to hold at least ~64 points.
std::vector<uint32_t> BrioOrder(std::span<const uint32_t> order);

}  // namespace svrc::delaunay
