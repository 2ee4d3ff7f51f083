// Stage-(a) SVRC benchmark (guide §7): point-set refinement on
//   skew  n : two skew lines of n points each (x=0,z=0 and y=0,z=1) — the raw
//             Delaunay has Θ(n²) tets, SVR's output must stay O(n);
//   pair  k : a unit box's corners plus two points 10^-k apart (spread 10^k) —
//             output must grow like log Δ;
//   random n: n uniform points in the unit cube.
// Prints vertices, tets, time, and the per-run counters of RefineStats.
//   comb  n : n parallel unit segments 10^-3 apart (stage (b));
//   nearseg k: a unit segment and a point 10^-k from its midpoint.
// Usage: svrc_refine_bench [--hash] skew 1000 | pair 12 | random 10000 | comb 4 | nearseg 6 [tau]
//   --hash: also print an FNV-1a 64 hash of the output (position bits, tets in
//           output order, segment chains) to check that a change of the
//           implementation left the output byte-identical.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <random>
#include <string>
#include <vector>

#include "core/svrc/refiner.h"

namespace {

// FNV-1a, 64 bit, over raw bytes (doubles by their bit patterns).
struct Fnv64 {
  uint64_t h = 0xcbf29ce484222325ull;
  void Bytes(const void* p, size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (size_t i = 0; i < n; ++i) {
      h ^= b[i];
      h *= 0x100000001b3ull;
    }
  }
  template <typename T>
  void Value(const T& v) {
    Bytes(&v, sizeof v);
  }
};

uint64_t HashOutput(const svrc::refine::PointSetRefinement& r) {
  Fnv64 f;
  f.Value(uint64_t{r.positions.size()});
  for (const auto& p : r.positions) {
    f.Value(p.x);
    f.Value(p.y);
    f.Value(p.z);
  }
  f.Value(uint64_t{r.tets.size()});
  for (const auto& t : r.tets) f.Bytes(t.data(), sizeof(uint32_t) * 4);
  f.Value(uint64_t{r.segment_chains.size()});
  for (const auto& c : r.segment_chains) {
    f.Value(uint64_t{c.size()});
    f.Bytes(c.data(), sizeof(uint32_t) * c.size());
  }
  return f.h;
}

}  // namespace

int main(int argc, char** argv) {
  bool hash = false;
  if (argc > 1 && (std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0)) {
    std::printf("usage: %s [--hash] skew|pair|random|comb|nearseg N [tau]\n", argv[0]);
    return 0;
  }
  if (argc > 1 && std::strcmp(argv[1], "--hash") == 0) {
    hash = true;
    --argc;
    ++argv;
  }
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s [--hash] skew|pair|random|comb|nearseg N [tau]\n", argv[0]);
    return 2;
  }
  const std::string kind = argv[1];
  const int n = std::atoi(argv[2]);
  svrc::refine::RefineOptions options;
  if (argc > 3) options.tau = std::atof(argv[3]);
  std::vector<svrc::geom::Vec3> pts;
  std::vector<svrc::refine::SegmentInput> segs;
  if (kind == "skew") {
    for (int i = 0; i < n; ++i) pts.push_back({0, double(i) / n, 0});
    for (int i = 0; i < n; ++i) pts.push_back({double(i) / n, 0, 1});
  } else if (kind == "pair") {
    for (int i = 0; i < 8; ++i) pts.push_back({double(i & 1), double((i >> 1) & 1), double(i >> 2)});
    pts.push_back({0.5, 0.5, 0.5});
    pts.push_back({0.5, 0.5, 0.5 + std::pow(10.0, -n)});
  } else if (kind == "comb") {
    // n parallel unit segments 10^-3 apart (free segments, stage (b)).
    for (int i = 0; i < n; ++i) {
      pts.push_back({0, 0, 1e-3 * i});
      pts.push_back({1, 0, 1e-3 * i});
      segs.push_back({uint32_t(2 * i), uint32_t(2 * i + 1)});
    }
  } else if (kind == "nearseg") {
    // A unit segment and a point 10^-n from its midpoint.
    pts = {{0, 0, 0}, {1, 0, 0}, {0.5, std::pow(10.0, -n), 0}};
    segs.push_back({0, 1});
  } else {
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> u(0, 1);
    for (int i = 0; i < n; ++i) pts.push_back({u(rng), u(rng), u(rng)});
  }
  // Process CPU time of the whole call (Initialize + Run + Output): on the
  // shared machine wall time (RefineStats::seconds) is inflated by the load.
  timespec cpu0, cpu1;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &cpu0);
  auto r = svrc::refine::RefinePointsAndSegments(pts, segs, options);
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &cpu1);
  const double cpu = double(cpu1.tv_sec - cpu0.tv_sec) + 1e-9 * double(cpu1.tv_nsec - cpu0.tv_nsec);
  if (!r.ok()) {
    std::fprintf(stderr, "%s\n", r.status().ToString().c_str());
    return 1;
  }
  const auto& s = r->stats;
  std::printf(
      "%s %d tau=%.2f: inputs=%zu vertices=%llu (segment %llu, yields %llu, encroached %llu) tets=%zu seconds=%.3f us/vertex=%.2f warps=%llu "
      "max_degree=%u max_aspect=%.3f buckets_walked=%llu max_walk=%llu links=%llu/%llu "
      "destroy_cells_avg=%.1f max=%llu clipped=%llu skinny=%llu/%llu stale unresolved=%llu/%llu stale "
      "pred_exact=%llu/%llu sos=%llu\n",
      kind.c_str(), n, options.tau, pts.size(), (unsigned long long)s.vertices,
      (unsigned long long)s.segment_vertices, (unsigned long long)s.yields,
      (unsigned long long)s.events_popped[1], r->tets.size(),
      s.seconds, 1e6 * s.seconds / double(s.vertices), (unsigned long long)s.warps, s.max_degree,
      s.max_aspect, (unsigned long long)s.buckets_walked, (unsigned long long)s.max_bucket_walk,
      (unsigned long long)s.links_added, (unsigned long long)s.links_removed,
      double(s.destroy_cells_visited) / double(s.insertions), (unsigned long long)s.max_destroy_cells,
      (unsigned long long)s.clipped_cells, (unsigned long long)s.events_popped[0],
      (unsigned long long)s.events_stale[0], (unsigned long long)s.events_popped[2],
      (unsigned long long)s.events_stale[2], (unsigned long long)s.predicate_exact,
      (unsigned long long)s.predicate_calls, (unsigned long long)s.predicate_sos);
  std::printf("cpu_seconds=%.3f cpu_us/vertex=%.2f\n", cpu, 1e6 * cpu / double(s.vertices));
  if (hash) {
    std::printf("hash=%016llx positions=%zu tets=%zu\n", (unsigned long long)HashOutput(*r),
                r->positions.size(), r->tets.size());
  }
  return 0;
}
