// Face adjacency by bucketing: see tet_faces.h.
#include "core/svrc/tet_faces.h"

#include <algorithm>
#include <utility>

namespace svrc::refine {

TetFaces::TetFaces(std::span<const std::array<uint32_t, 4>> tets, size_t num_vertices)
    : bucket_(num_vertices + 1, 0), faces_(4 * tets.size()) {
  // Three faces of a tet contain its smallest vertex; the fourth starts at
  // the second smallest (counted with multiplicity, as the fill below sorts).
  for (const auto& v : tets) {
    int lo = 0;
    for (int i = 1; i < 4; ++i) {
      if (v[i] < v[lo]) lo = i;
    }
    uint32_t second = UINT32_MAX;
    for (int i = 0; i < 4; ++i) {
      if (i != lo) second = std::min(second, v[i]);
    }
    bucket_[v[lo] + 1] += 3;
    ++bucket_[second + 1];
  }
  for (size_t a = 0; a < num_vertices; ++a) bucket_[a + 1] += bucket_[a];
  std::vector<uint32_t> fill(bucket_.begin(), bucket_.end() - 1);
  for (size_t t = 0; t < tets.size(); ++t) {
    // Sorting network on (vertex, position); positions break no ties between
    // distinct vertices. Leaving out s_i gives a sorted face, slot
    // 4t + (position of s_i in the tet).
    std::array<uint64_t, 4> s;
    for (int i = 0; i < 4; ++i) s[i] = (static_cast<uint64_t>(tets[t][i]) << 2) | static_cast<uint64_t>(i);
    auto cswap = [&](int i, int j) {
      if (s[j] < s[i]) std::swap(s[i], s[j]);
    };
    cswap(0, 1);
    cswap(2, 3);
    cswap(0, 2);
    cswap(1, 3);
    cswap(1, 2);
    const uint32_t base = static_cast<uint32_t>(4 * t);
    const uint32_t v0 = static_cast<uint32_t>(s[0] >> 2), v1 = static_cast<uint32_t>(s[1] >> 2),
                   v2 = static_cast<uint32_t>(s[2] >> 2), v3 = static_cast<uint32_t>(s[3] >> 2);
    faces_[fill[v1]++] = TetFace{v2, v3, base + static_cast<uint32_t>(s[0] & 3)};
    faces_[fill[v0]++] = TetFace{v2, v3, base + static_cast<uint32_t>(s[1] & 3)};
    faces_[fill[v0]++] = TetFace{v1, v3, base + static_cast<uint32_t>(s[2] & 3)};
    faces_[fill[v0]++] = TetFace{v1, v2, base + static_cast<uint32_t>(s[3] & 3)};
  }
}

bool TetFaces::Match(absl::FunctionRef<void(uint32_t, uint32_t)> pair, Overused* bad_face) const {
  // A face (a, b, c) finds the earlier ones with the same b through a per-b
  // chain (head stamped with a), then compares c. Each record knows the
  // first record of its face (the smallest slot: the bucket is in tet order).
  constexpr uint32_t kNil = UINT32_MAX;
  const size_t nv = bucket_.size() - 1;
  std::vector<uint32_t> head(nv), head_a(nv, kNil);
  std::vector<uint32_t> chain, first, count;
  for (size_t a = 0; a < nv; ++a) {
    const std::span<const TetFace> r = Bucket(static_cast<uint32_t>(a));
    const uint32_t n = static_cast<uint32_t>(r.size());
    if (n == 0) continue;
    if (chain.size() < n) {
      chain.resize(n);
      first.resize(n);
      count.resize(n);
    }
    uint32_t bad = kNil;  // the record of the smallest (b, c) in > 2 tets
    for (uint32_t k = 0; k < n; ++k) {
      const uint32_t b = r[k].b;
      const uint32_t prev = head_a[b] == a ? head[b] : kNil;
      uint32_t f = kNil;
      for (uint32_t j = prev; j != kNil; j = chain[j]) {
        if (r[j].c == r[k].c) {
          f = first[j];
          break;
        }
      }
      chain[k] = prev;
      head[b] = k;
      head_a[b] = static_cast<uint32_t>(a);
      if (f == kNil) {
        first[k] = k;
        count[k] = 1;
        continue;
      }
      first[k] = f;
      if (++count[f] == 2) {
        pair(r[f].slot, r[k].slot);
      } else if (bad == kNil || r[f].b < r[bad].b || (r[f].b == r[bad].b && r[f].c < r[bad].c)) {
        bad = f;
      }
    }
    if (bad != kNil) {
      bad_face->a = static_cast<uint32_t>(a);
      bad_face->b = r[bad].b;
      bad_face->c = r[bad].c;
      bad_face->count = count[bad];
      uint32_t m = 0;
      for (uint32_t k = bad; k < n && m < 3; ++k) {
        if (r[k].b == r[bad].b && r[k].c == r[bad].c) bad_face->slots[m++] = r[k].slot;
      }
      return false;
    }
  }
  return true;
}

VertexStars StarsOf(std::span<const std::array<uint32_t, 4>> tets, size_t num_vertices,
                    std::span<const uint8_t> flagged, std::span<const uint8_t> alive) {
  VertexStars out;
  std::vector<uint32_t>& start = out.start;
  start.assign(num_vertices + 1, 0);
  for (size_t t = 0; t < tets.size(); ++t) {
    if (!alive.empty() && !alive[t]) continue;
    for (uint32_t v : tets[t]) start[v + 1] += flagged[v];
  }
  for (size_t v = 0; v < num_vertices; ++v) start[v + 1] += start[v];
  out.tet.resize(start.back());
  std::vector<uint32_t> fill(start.begin(), start.end() - 1);
  for (size_t t = 0; t < tets.size(); ++t) {
    if (!alive.empty() && !alive[t]) continue;
    for (uint32_t v : tets[t]) {
      if (flagged[v]) out.tet[fill[v]++] = static_cast<uint32_t>(t);
    }
  }
  return out;
}

void StarBucket(std::span<const std::array<uint32_t, 4>> tets, const VertexStars& stars, uint32_t a,
                std::vector<TetFace>* out) {
  out->clear();
  for (uint32_t k = stars.start[a]; k < stars.start[a + 1]; ++k) {
    const uint32_t t = stars.tet[k];
    const std::array<uint32_t, 4>& v = tets[t];
    for (uint32_t f = 0; f < 4; ++f) {
      if (v[f] == a) continue;  // the face opposite f holds a unless v[f] is a
      std::array<uint32_t, 3> x;
      for (uint32_t g = 0, m = 0; g < 4; ++g) {
        if (g != f) x[m++] = v[g];
      }
      std::sort(x.begin(), x.end());
      if (x[0] == a) out->push_back({x[1], x[2], 4 * t + f});
    }
  }
}

}  // namespace svrc::refine
