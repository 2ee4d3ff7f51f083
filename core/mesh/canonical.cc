#include "core/mesh/canonical.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>

namespace svrc::mesh {
namespace {

constexpr int kHilbertBits = 21;

// Sorts `items` (arrays of N vertex ids) by (item, tag, original position),
// tags may be empty, and applies the order to both. The records are sorted
// themselves, their ids packed two to a 64-bit word, rather than an index
// permutation through a comparator that reads the arrays (two cache misses
// per comparison: 2.8% of cube --max-volume 1e-5's instructions).
template <size_t N>
void SortCarrying(std::vector<std::array<uint32_t, N>>* items, std::vector<int32_t>* tags) {
  static_assert(N == 3 || N == 4);
  const size_t n = items->size();
  const bool has_tags = tags->size() == n;
  struct Record {
    uint64_t hi, lo;  // ids 0,1 and 2,3 (0 for a triangle), unsigned order
    int32_t tag;
    uint32_t pos;
  };
  const auto less = [](const Record& a, const Record& b) {
    if (a.hi != b.hi) return a.hi < b.hi;
    if (a.lo != b.lo) return a.lo < b.lo;
    if (a.tag != b.tag) return a.tag < b.tag;
    return a.pos < b.pos;
  };
  auto record = [&](size_t i) {
    const std::array<uint32_t, N>& t = (*items)[i];
    const uint64_t hi = (uint64_t{t[0]} << 32) | t[1];
    const uint64_t lo = (uint64_t{t[2]} << 32) | (N == 4 ? t[N - 1] : 0u);
    return Record{hi, lo, has_tags ? (*tags)[i] : 0, static_cast<uint32_t>(i)};
  };
  uint32_t max_first = 0;
  for (const auto& t : *items) max_first = std::max(max_first, t[0]);
  std::vector<Record> rec(n);
  if (max_first <= 4 * n + 1024) {
    // Bucketed by the first id (a counting sort), each bucket then sorted:
    // the order is the comparator's total order (the position breaks every
    // tie), as one std::sort of all records gave, which was 44% of the
    // output stage's instructions at cube --max-volume 1e-5 (n log n).
    std::vector<uint32_t> start(size_t{max_first} + 2, 0);
    for (const auto& t : *items) ++start[size_t{t[0]} + 1];
    for (size_t a = 0; a <= max_first; ++a) start[a + 1] += start[a];
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (size_t i = 0; i < n; ++i) rec[fill[(*items)[i][0]]++] = record(i);
    for (size_t a = 0; a <= max_first; ++a) {
      if (start[a + 1] - start[a] > 1) std::sort(rec.begin() + start[a], rec.begin() + start[a + 1], less);
    }
  } else {
    for (size_t i = 0; i < n; ++i) rec[i] = record(i);
    std::sort(rec.begin(), rec.end(), less);
  }
  std::vector<std::array<uint32_t, N>> sorted(n);
  for (size_t k = 0; k < n; ++k) sorted[k] = (*items)[rec[k].pos];
  *items = std::move(sorted);
  if (has_tags) {
    for (size_t k = 0; k < n; ++k) (*tags)[k] = rec[k].tag;
  }
}

}  // namespace

uint64_t HilbertKey21(uint32_t x, uint32_t y, uint32_t z) {
  // J. Skilling, "Programming the Hilbert curve", AIP Conf. Proc. 707 (2004):
  // axes -> transposed Hilbert index, then interleave the bits.
  uint32_t X[3] = {x, y, z};
  const uint32_t m = 1u << (kHilbertBits - 1);
  for (uint32_t q = m; q > 1; q >>= 1) {
    const uint32_t p = q - 1;
    for (int i = 0; i < 3; ++i) {
      if (X[i] & q) {
        X[0] ^= p;  // invert
      } else {      // exchange
        const uint32_t t = (X[0] ^ X[i]) & p;
        X[0] ^= t;
        X[i] ^= t;
      }
    }
  }
  for (int i = 1; i < 3; ++i) X[i] ^= X[i - 1];  // Gray encode
  uint32_t t = 0;
  for (uint32_t q = m; q > 1; q >>= 1) {
    if (X[2] & q) t ^= q - 1;
  }
  for (int i = 0; i < 3; ++i) X[i] ^= t;
  uint64_t key = 0;
  for (int b = kHilbertBits - 1; b >= 0; --b) {
    for (int i = 0; i < 3; ++i) key = (key << 1) | ((X[i] >> b) & 1u);
  }
  return key;
}

std::vector<uint32_t> SpatialOrder(const std::vector<Vec3>& pts) {
  const size_t n = pts.size();
  geom::Box3 box;
  for (const Vec3& p : pts) {
    if (geom::IsFinite(p)) box.Add(p);
  }
  double extent = 0;
  if (!box.Empty()) {
    extent = std::max({box.hi.x - box.lo.x, box.hi.y - box.lo.y, box.hi.z - box.lo.z});
  }
  const double cells = static_cast<double>(1u << kHilbertBits);
  const double scale = (extent > 0 && std::isfinite(extent)) ? cells / extent : 0.0;
  auto quantize = [&](double v, double lo) -> uint32_t {
    const double q = std::floor((v - lo) * scale);
    if (!(q > 0)) return 0;  // also NaN
    if (q >= cells - 1) return (1u << kHilbertBits) - 1;
    return static_cast<uint32_t>(q);
  };
  std::vector<std::pair<uint64_t, uint32_t>> keyed(n);
  for (size_t i = 0; i < n; ++i) {
    const Vec3& p = pts[i];
    uint64_t key = 0;
    if (geom::IsFinite(p)) {
      key = HilbertKey21(quantize(p.x, box.lo.x), quantize(p.y, box.lo.y),
                         quantize(p.z, box.lo.z));
    }
    keyed[i] = {key, static_cast<uint32_t>(i)};
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<uint32_t> order(n);
  for (size_t i = 0; i < n; ++i) order[i] = keyed[i].second;
  return order;
}

std::array<uint32_t, 4> CanonicalTet(std::array<uint32_t, 4> t) {
  // Each of these moves the entry at position k to the front by two swaps
  // (an even permutation).
  const int k = static_cast<int>(std::min_element(t.begin(), t.end()) - t.begin());
  switch (k) {
    case 1: t = {t[1], t[0], t[3], t[2]}; break;
    case 2: t = {t[2], t[3], t[0], t[1]}; break;
    case 3: t = {t[3], t[2], t[1], t[0]}; break;
    default: break;
  }
  // A cyclic rotation of the last three is even too.
  if (t[2] < t[1] && t[2] < t[3]) {
    t = {t[0], t[2], t[3], t[1]};
  } else if (t[3] < t[1] && t[3] < t[2]) {
    t = {t[0], t[3], t[1], t[2]};
  }
  return t;
}

std::array<uint32_t, 3> CanonicalTriangle(std::array<uint32_t, 3> t) {
  if (t[1] < t[0] && t[1] < t[2]) return {t[1], t[2], t[0]};
  if (t[2] < t[0] && t[2] < t[1]) return {t[2], t[0], t[1]};
  return t;
}

void Canonicalize(TetMesh* mesh) {
  for (auto& t : mesh->tets) t = CanonicalTet(t);
  for (auto& t : mesh->triangles) t = CanonicalTriangle(t);
  SortCarrying(&mesh->tets, &mesh->tet_region);
  SortCarrying(&mesh->triangles, &mesh->triangle_marker);
}

bool IsCanonical(const TetMesh& mesh) {
  auto sorted = [](const auto& items, const std::vector<int32_t>& tags) {
    const bool has_tags = tags.size() == items.size();
    for (size_t i = 1; i < items.size(); ++i) {
      if (items[i] < items[i - 1]) return false;
      if (has_tags && items[i] == items[i - 1] && tags[i] < tags[i - 1]) return false;
    }
    return true;
  };
  for (const auto& t : mesh.tets) {
    if (CanonicalTet(t) != t) return false;
  }
  for (const auto& t : mesh.triangles) {
    if (CanonicalTriangle(t) != t) return false;
  }
  return sorted(mesh.tets, mesh.tet_region) && sorted(mesh.triangles, mesh.triangle_marker);
}

void PermuteVertices(TetMesh* mesh, std::span<const uint32_t> new_to_old) {
  const size_t n = mesh->positions.size();
  assert(new_to_old.size() == n);
  std::vector<uint32_t> old_to_new(n);
  std::vector<Vec3> positions(n);
  for (size_t i = 0; i < n; ++i) {
    old_to_new[new_to_old[i]] = static_cast<uint32_t>(i);
    positions[i] = mesh->positions[new_to_old[i]];
  }
  mesh->positions = std::move(positions);
  for (auto& t : mesh->tets) {
    for (auto& v : t) v = old_to_new[v];
  }
  for (auto& t : mesh->triangles) {
    for (auto& v : t) v = old_to_new[v];
  }
}

}  // namespace svrc::mesh
