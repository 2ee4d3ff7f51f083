// Growth of per-id arrays (per tet slot, per vertex) to a size the caller
// chose with its own margin: the vector's capacity becomes exactly that size.
// std::vector::resize past the capacity at least doubles it, so an array grown
// in 1.25x or 1.5x steps carried up to twice its size in untouched capacity;
// over a dozen such arrays that was much of a small run's peak heap
// (docs/svrc-design.md §8 item 39).
#pragma once

#include <algorithm>
#include <cstddef>

namespace svrc::util {

template <typename V, typename... Fill>
void GrowExactly(V& v, size_t n, const Fill&... fill) {
  if (v.size() >= n) return;
  if (v.capacity() < n) v.reserve(n);
  v.resize(n, fill...);
}

// Room for `extra` more elements, in steps of a quarter of the size (an
// append-only array otherwise doubles; the same slack as above).
template <typename V>
void ReserveForAppend(V& v, size_t extra = 1) {
  if (v.capacity() - v.size() >= extra) return;
  v.reserve(v.size() + std::max(extra, v.size() / 4 + 16));
}

}  // namespace svrc::util
