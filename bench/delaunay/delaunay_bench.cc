// Side-by-side benchmark of 3D Delaunay tetrahedralization of a point set:
// svrc (Delaunay3 via TetrahedralizePointSet), CGAL Delaunay_triangulation_3
// (range insertion, which spatially sorts) and `tetgen -Q` on a .node file.
// Each peer runs in its own process, so peak RSS is per peer:
//   svrc/CGAL: bytes/tet = (peak RSS − RSS after generating the points) / tets
//   tetgen:    bytes/tet = peak RSS of the tetgen process / tets (it also
//              holds the points it parsed and its output buffers)
//
// Usage: delaunay_bench [--n N] [--seed S] [--input uniform|grid] [--peers svrc,cgal,tetgen]
//        delaunay_bench --child svrc|cgal --n N --seed S --input ...   (internal)
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "core/delaunay/point_set.h"

#ifdef SVRC_BENCH_HAVE_CGAL
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#endif

namespace {

using svrc::geom::Vec3;

std::vector<Vec3> MakePoints(const std::string& input, long n, unsigned seed) {
  std::vector<Vec3> pts;
  if (input == "grid") {
    const long k = std::lround(std::cbrt(static_cast<double>(n)));
    for (long x = 0; x < k; ++x)
      for (long y = 0; y < k; ++y)
        for (long z = 0; z < k; ++z) pts.emplace_back(x, y, z);
    return pts;
  }
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  pts.resize(n);
  for (auto& p : pts) p = Vec3(u(rng), u(rng), u(rng));
  return pts;
}

long MaxRssKiB() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return ru.ru_maxrss;
}

double CpuSeconds() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return ru.ru_utime.tv_sec + ru.ru_utime.tv_usec * 1e-6 + ru.ru_stime.tv_sec + ru.ru_stime.tv_usec * 1e-6;
}

double Now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Child mode: prints "RESULT <tets> <seconds> <rss_before_kib> <peak_kib> <cpu_seconds>".
int RunChild(const std::string& peer, const std::vector<Vec3>& pts) {
  const long rss0 = MaxRssKiB();
  size_t tets = 0;
  double t0 = Now();
  double c0 = CpuSeconds();
  if (peer == "svrc") {
    auto r = svrc::delaunay::TetrahedralizePointSet(pts);
    if (!r.ok()) {
      std::fprintf(stderr, "svrc: %s\n", std::string(r.status().message()).c_str());
      return 1;
    }
    tets = r->tets.size();
    std::fprintf(stderr, "svrc phases (wall): sort+dedup %.3f s, insert %.3f s, canonical output %.3f s, walk steps %llu\n",
                 r->seconds_sort, r->seconds_insert, r->seconds_output,
                 static_cast<unsigned long long>(r->kernel_stats.walk_steps));
  }
#ifdef SVRC_BENCH_HAVE_CGAL
  else if (peer == "cgal") {
    using K = CGAL::Exact_predicates_inexact_constructions_kernel;
    std::vector<K::Point_3> cp;
    cp.reserve(pts.size());
    for (const auto& p : pts) cp.emplace_back(p.x, p.y, p.z);
    t0 = Now();  // conversion not timed
    c0 = CpuSeconds();
    CGAL::Delaunay_triangulation_3<K> dt(cp.begin(), cp.end());
    tets = dt.number_of_finite_cells();
  }
#endif
  else {
    std::fprintf(stderr, "unknown peer %s\n", peer.c_str());
    return 1;
  }
  const double secs = Now() - t0;
  const double cpu = CpuSeconds() - c0;
  std::printf("RESULT %zu %.6f %ld %ld %.6f\n", tets, secs, rss0, MaxRssKiB(), cpu);
  return 0;
}

struct Row {
  std::string name;
  size_t tets = 0;
  double seconds = 0;
  double cpu_seconds = 0;
  double bytes_per_tet = 0;
  bool ok = false;
};

Row RunPeerProcess(const char* self, const std::string& peer, long n, unsigned seed, const std::string& input) {
  Row row;
  row.name = peer;
  const std::string cmd = std::string(self) + " --child " + peer + " --n " + std::to_string(n) + " --seed " +
                          std::to_string(seed) + " --input " + input;
  FILE* f = popen(cmd.c_str(), "r");
  if (!f) return row;
  char line[512];
  while (std::fgets(line, sizeof line, f)) {
    unsigned long long tets;
    double secs;
    long rss0, peak;
    double cpu;
    if (std::sscanf(line, "RESULT %llu %lf %ld %ld %lf", &tets, &secs, &rss0, &peak, &cpu) == 5) {
      row.tets = tets;
      row.seconds = secs;
      row.cpu_seconds = cpu;
      row.bytes_per_tet = tets ? (peak - rss0) * 1024.0 / tets : 0;
      row.ok = true;
    }
  }
  pclose(f);
  return row;
}

Row RunTetgen(const std::vector<Vec3>& pts) {
  Row row;
  row.name = "tetgen -Q";
  char dir[] = "/tmp/svrc_bench_XXXXXX";
  if (!mkdtemp(dir)) return row;
  const std::string node = std::string(dir) + "/pts.node";
  FILE* f = std::fopen(node.c_str(), "w");
  std::fprintf(f, "%zu 3 0 0\n", pts.size());
  for (size_t i = 0; i < pts.size(); ++i) std::fprintf(f, "%zu %.17g %.17g %.17g\n", i, pts[i].x, pts[i].y, pts[i].z);
  std::fclose(f);
  const double t0 = Now();
  const pid_t pid = fork();
  if (pid == 0) {
    if (!std::freopen("/dev/null", "w", stdout)) _exit(126);
    execlp("tetgen", "tetgen", "-Q", node.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  int status = 0;
  rusage ru{};
  wait4(pid, &status, 0, &ru);
  row.seconds = Now() - t0;
  row.cpu_seconds = ru.ru_utime.tv_sec + ru.ru_utime.tv_usec * 1e-6 + ru.ru_stime.tv_sec + ru.ru_stime.tv_usec * 1e-6;
  // Count tets from the .ele header.
  const std::string ele = std::string(dir) + "/pts.1.ele";
  FILE* e = std::fopen(ele.c_str(), "r");
  unsigned long long tets = 0;
  if (e && std::fscanf(e, "%llu", &tets) == 1) row.ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
  if (e) std::fclose(e);
  row.tets = tets;
  row.bytes_per_tet = tets ? ru.ru_maxrss * 1024.0 / tets : 0;
  std::system((std::string("rm -rf ") + dir).c_str());
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  long n = 1000000;
  unsigned seed = 1;
  std::string child, input = "uniform", peers = "svrc,cgal,tetgen";
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string k = argv[i], v = argv[i + 1];
    if (k == "--n") n = std::atol(v.c_str());
    else if (k == "--seed") seed = static_cast<unsigned>(std::atol(v.c_str()));
    else if (k == "--child") child = v;
    else if (k == "--input") input = v;
    else if (k == "--peers") peers = v;
  }
  if (!child.empty()) return RunChild(child, MakePoints(input, n, seed));

  std::vector<Row> rows;
  auto has = [&](const char* p) { return peers.find(p) != std::string::npos; };
  if (has("svrc")) rows.push_back(RunPeerProcess(argv[0], "svrc", n, seed, input));
#ifdef SVRC_BENCH_HAVE_CGAL
  if (has("cgal")) rows.push_back(RunPeerProcess(argv[0], "cgal", n, seed, input));
#endif
  if (has("tetgen")) rows.push_back(RunTetgen(MakePoints(input, n, seed)));
  const bool have_svrc = !rows.empty() && rows[0].name == "svrc" && rows[0].ok;
  std::printf("%s points: n=%ld seed=%u\n", input.c_str(), n, seed);
  std::printf("%-10s %10s %9s %9s %13s %11s %10s %10s\n", "peer", "tets", "wall s", "cpu s",
              "Mtets/cpu-s", "bytes/tet", "wall/svrc", "cpu/svrc");
  for (const Row& r : rows) {
    if (!r.ok) {
      std::printf("%-10s failed\n", r.name.c_str());
      continue;
    }
    std::printf("%-10s %10zu %9.3f %9.3f %13.3f %11.1f %10.2f %10.2f\n", r.name.c_str(), r.tets, r.seconds,
                r.cpu_seconds, r.tets / r.cpu_seconds / 1e6, r.bytes_per_tet,
                have_svrc ? r.seconds / rows[0].seconds : 0.0, have_svrc ? r.cpu_seconds / rows[0].cpu_seconds : 0.0);
  }
  return 0;
}
