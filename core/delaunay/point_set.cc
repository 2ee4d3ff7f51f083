#include "core/delaunay/point_set.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <tuple>

#include "absl/strings/str_cat.h"
#include "core/delaunay/spatial_sort.h"
#include "core/geometry/predicates.h"

namespace svrc::delaunay {
namespace {

double SecondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

bool Collinear(const geom::Vec3& a, const geom::Vec3& b, const geom::Vec3& c) {
  for (int axis = 0; axis < 3; ++axis) {
    if (geom::Orient2dProjected(a, b, c, axis) != 0) return false;
  }
  return true;
}

}  // namespace

std::array<uint32_t, 4> CanonicalRotation(std::array<uint32_t, 4> t) {
  // Even permutations bringing position k first: (k, then a cyclic order of
  // the other three with the right parity).
  static constexpr int kFirst[4][4] = {{0, 1, 2, 3}, {1, 0, 3, 2}, {2, 3, 0, 1}, {3, 2, 1, 0}};
  int k = 0;
  for (int i = 1; i < 4; ++i) {
    if (t[i] < t[k]) k = i;
  }
  std::array<uint32_t, 4> r;
  for (int i = 0; i < 4; ++i) r[i] = t[kFirst[k][i]];
  // Cyclic rotation of r[1..3] (even) to put the smallest second.
  if (r[2] < r[1] && r[2] < r[3]) {
    r = {r[0], r[2], r[3], r[1]};
  } else if (r[3] < r[1] && r[3] < r[2]) {
    r = {r[0], r[3], r[1], r[2]};
  }
  return r;
}

absl::StatusOr<PointSetResult> TetrahedralizePointSet(std::span<const geom::Vec3> points,
                                                      const PointSetOptions& options) {
  const size_t n = points.size();
  if (n >= 0xFFFFFFF0u) return absl::InvalidArgumentError("too many points for 32-bit ids");
  for (size_t i = 0; i < n; ++i) {
    if (!geom::IsFinite(points[i])) {
      return absl::InvalidArgumentError(absl::StrCat("vertex ", i, " has a non-finite coordinate"));
    }
  }
  PointSetResult result;
  auto t0 = std::chrono::steady_clock::now();

  // Hilbert order of all points. Exact duplicates share a Hilbert key, so
  // they are found inside runs of equal keys (short: a run is one cell of a
  // 2^21-per-axis grid), sorted lexicographically there.
  std::vector<uint64_t> keys;
  std::vector<uint32_t> order = HilbertOrder(points, &keys);
  result.representative.resize(n);
  for (size_t i = 0; i < n; ++i) result.representative[i] = static_cast<uint32_t>(i);
  {
    auto lex = [&](uint32_t a, uint32_t b) {
      const auto& p = points[a];
      const auto& q = points[b];
      return std::tie(p.x, p.y, p.z, a) < std::tie(q.x, q.y, q.z, b);
    };
    std::vector<uint32_t> run;
    for (size_t i = 0; i < n;) {
      size_t j = i + 1;
      while (j < n && keys[j] == keys[i]) ++j;
      if (j - i > 1) {
        run.assign(order.begin() + i, order.begin() + j);
        std::sort(run.begin(), run.end(), lex);
        for (size_t k = 1; k < run.size(); ++k) {
          if (points[run[k]] == points[run[k - 1]]) {
            result.representative[run[k]] = result.representative[run[k - 1]];
            ++result.num_duplicates;
          }
        }
      }
      i = j;
    }
  }
  std::vector<uint32_t> unique;
  unique.reserve(n - result.num_duplicates);
  for (uint32_t i : order) {
    if (result.representative[i] == i) unique.push_back(i);
  }
  std::vector<uint32_t> ins = BrioOrder(unique);

  // Four affinely independent points, searched in insertion order, go first.
  const size_t m = ins.size();
  size_t basis[4] = {0, 0, 0, 0};
  size_t found = m > 0 ? 1 : 0;
  for (size_t i = 1; i < m && found < 4; ++i) {
    const auto& p = points[ins[i]];
    if (found == 1) {
      basis[found++] = i;  // distinct from the first: duplicates are merged
    } else if (found == 2) {
      if (!Collinear(points[ins[basis[0]]], points[ins[basis[1]]], p)) basis[found++] = i;
    } else if (geom::Orient3d(points[ins[basis[0]]], points[ins[basis[1]]],
                              points[ins[basis[2]]], p) != 0) {
      basis[found++] = i;
    }
  }
  if (found < 4) {
    const char* what = found <= 1 ? "all points coincide" : found == 2 ? "all points are collinear"
                                                                       : "all points are coplanar";
    return absl::InvalidArgumentError(absl::StrCat(
        "a point set needs at least 4 affinely independent points to be tetrahedralized (",
        n, " points, ", m, " distinct; ", what, ")"));
  }
  // Move the basis to the front, keeping the others in BRIO order.
  {
    std::vector<uint32_t> front;
    for (int k = 0; k < 4; ++k) front.push_back(ins[basis[k]]);
    size_t w = 4;
    std::vector<uint32_t> reordered(m);
    std::copy(front.begin(), front.end(), reordered.begin());
    for (size_t i = 0, k = 0; i < m; ++i) {
      if (k < 4 && i == basis[k]) {
        ++k;
        continue;
      }
      reordered[w++] = ins[i];
    }
    ins.swap(reordered);
  }
  result.seconds_sort = SecondsSince(t0);

  t0 = std::chrono::steady_clock::now();
  Delaunay3 dt;
  dt.Reserve(m);
  dt.set_report_cavity_vertices(false);
  const uint32_t poll = std::max<uint32_t>(options.poll_interval, 1);
  for (size_t i = 0; i < m; ++i) {
    const uint32_t id = ins[i];
    const auto r = dt.Insert(points[id], id);
    if (r.outcome == Delaunay3::InsertOutcome::kDuplicate) {
      return absl::InternalError(absl::StrCat("vertex ", id, " reported as a duplicate of vertex ",
                                              dt.GlobalId(r.vertex), " after merging"));
    }
    if ((i + 1) % poll == 0) {
      if (options.cancel) {
        absl::Status s = options.cancel();
        if (!s.ok()) return s;
      }
      if (options.progress) options.progress(i + 1, m);
    }
  }
  if (options.progress) options.progress(m, m);
  result.kernel_stats = dt.stats();
  result.seconds_insert = SecondsSince(t0);

  t0 = std::chrono::steady_clock::now();
  // Canonical rotation, then an LSD radix sort on the first (smallest) id
  // with 11-bit digits (sequential reads, 2048 write streams per pass), then
  // a small sort of each run of equal first ids (~6.7 tets per vertex).
  std::vector<std::array<uint32_t, 4>> rotated;
  rotated.reserve(dt.NumFiniteTets());
  for (uint32_t t = 0; t < dt.TetCapacity(); ++t) {
    const TetId tid(t);
    if (!dt.IsAlive(tid) || dt.IsGhost(tid)) continue;
    std::array<uint32_t, 4> tv;
    for (int i = 0; i < 4; ++i) tv[i] = dt.GlobalId(dt.TetVertex(tid, i));
    rotated.push_back(CanonicalRotation(tv));
  }
  result.tets.resize(rotated.size());
  constexpr int kDigit = 11;
  constexpr uint32_t kRadix = 1u << kDigit;
  std::vector<uint32_t> count(kRadix);
  for (int shift = 0; shift < 32 && (n - 1) >> shift != 0; shift += kDigit) {
    std::fill(count.begin(), count.end(), 0);
    for (const auto& tv : rotated) ++count[(tv[0] >> shift) & (kRadix - 1)];
    uint32_t acc = 0;
    for (uint32_t& c : count) {
      const uint32_t k = c;
      c = acc;
      acc += k;
    }
    for (const auto& tv : rotated) result.tets[count[(tv[0] >> shift) & (kRadix - 1)]++] = tv;
    rotated.swap(result.tets);
  }
  result.tets.swap(rotated);  // the last pass's output
  rotated = {};
  for (size_t i = 0; i < result.tets.size();) {
    size_t j = i + 1;
    while (j < result.tets.size() && result.tets[j][0] == result.tets[i][0]) ++j;
    if (j - i > 1) std::sort(result.tets.begin() + i, result.tets.begin() + j);
    i = j;
  }
  result.seconds_output = SecondsSince(t0);
  return result;
}

}  // namespace svrc::delaunay
