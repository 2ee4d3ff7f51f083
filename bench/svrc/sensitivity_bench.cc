// Output-sensitive cost of SVRC on PLCs (issue #5 "Must show"; thesis ch. 5
// and §1.5.1): series of runs of the PLC pipeline of core::MeshPlc
// (plc::PreparePlc → refine::RefinePlc → refine::BuildOutputMesh) in-process,
// each run in a fresh child process (this binary re-executed with --one) so
// that its peak RSS is its own. Per run: output tets, wall and CPU time per
// output tet, "Voronoi cells plus location-graph links touched per insertion"
// = (RefineStats::destroy_cells_visited + destroy_index_visited (the nodes and
// points of the pending-point index Destroy reads) + links_added + links_removed) /
// insertions, peak RSS bytes per output tet; per series whether each stays
// within 1.5× over the runs with ≥ 10^4 output tets (the criterion).
//
// Series (default: all four, default parameters):
//   cube     families::VolumeConstrainedCube(1, V), V in --cube-volumes
//   skew     families::SkewLines(n) (segments, unit box), n in --skew-n
//   skewvol  the same with a global max volume --skewvol-volume, n in --skewvol-n
//   spread   families::BoxWithCavity(10^-k) (a closed cube of side 10^-k, its
//            own region, centred in the unit box: spread Δ ≈ 10^k), k in --spread-k
//   file:PATH  one corpus file (e.g. e_spread/tiny_cube_in_box.poly)
// Flags: --repeat N (every run N times round robin; the flatness reads, per
// run, the repeat of least CPU time), --radius-edge B (default 2: τ = 2B), --timeout S per run (default
// 600), --mem-limit-mib M (RLIMIT_AS per child, default 8192), --verify (each
// child also runs core::MeshPlc and checks that it gives the same mesh, bit
// for bit: the bench measures what the product does; a post-pass added to
// MeshPlc later, e.g. sliver removal, shows up here as DIFFERENT and is not
// timed by this bench).
// Internal: --one cube V | skew n V | spread k | file PATH  (one run, prints
// one "RESULT key=value ..." line).
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "core/api.h"
#include "core/mesh/quality.h"
#include "core/plc/families.h"
#include "core/plc/readers.h"
#include "core/plc/validate.h"
#include "core/svrc/assemble.h"
#include "core/svrc/refiner.h"

// Heap accounting of this process: the bench links libsvrc_heap_peak.so
// (bench/svrc/heap_peak.c), whose malloc, calloc, realloc, aligned allocators
// and free take the place of glibc's, so every byte the run allocates is
// counted — operator new and aligned new go through them, and so does
// util::PodVector's realloc — as malloc_usable_size, with the high-water mark.
// "peak heap" is that mark during one run minus the bytes live at its start:
// the data structures' own bytes, without the code pages, libraries and
// allocator slack that RSS also holds (a run of 10^4 tets peaks at ~14 MB RSS
// above its start, so a few MB of those shift its ratio). A realloc counts
// its growth only: glibc grows large blocks with mremap, without a second
// copy (sessions before 17 counted operator new alone, and aligned new not at
// all). Preloaded, the same library measures tetgen and the CLI on this scale
// (bench/svrc/flatness_vs_tetgen.sh).
extern "C" {
long long svrc_heap_now(void);
long long svrc_heap_peak(void);
void svrc_heap_reset_peak(void);
}

namespace svrc::bench {
namespace {

// ---------------------------------------------------------------- child

double CpuNow() {
  timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}
double WallNow() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Resident set size now, KiB (/proc/self/status VmRSS).
long RssKib() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::atol(line.c_str() + 6);
  }
  return 0;
}
long PeakRssKib() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return ru.ru_maxrss;
}

bool SameMesh(const mesh::TetMesh& a, const mesh::TetMesh& b) {
  if (a.positions.size() != b.positions.size() || a.tets != b.tets || a.tet_region != b.tet_region) {
    return false;
  }
  for (size_t i = 0; i < a.positions.size(); ++i) {
    if (std::memcmp(&a.positions[i], &b.positions[i], sizeof(geom::Vec3)) != 0) return false;
  }
  return true;
}

// One run in this process; prints "RESULT key=value ..." (or "RESULT
// status=... message=..." on failure) to stdout.
int RunOne(const std::vector<std::string>& args, double radius_edge, bool verify) {
  const long base_kib = RssKib();
  const int64_t heap_base = svrc_heap_now();
  svrc_heap_reset_peak();
  plc::Plc plc;
  double max_volume = 0;
  const std::string kind = args.empty() ? "" : args[0];
  auto num = [&](size_t i) { return i < args.size() ? std::atof(args[i].c_str()) : 0.0; };
  if (kind == "cube") {
    plc = plc::families::VolumeConstrainedCube(1, num(1));
  } else if (kind == "skew") {
    plc = plc::families::SkewLines(static_cast<int>(num(1)));
    max_volume = num(2);
  } else if (kind == "spread") {
    plc = plc::families::BoxWithCavity(std::pow(10.0, -num(1)));
  } else if (kind == "file" && args.size() > 1) {
    absl::StatusOr<plc::Plc> p = plc::ReadPlcFile(args[1]);
    if (!p.ok()) {
      std::printf("RESULT status=%s\n", std::string(absl::StatusCodeToString(p.status().code())).c_str());
      return 1;
    }
    plc = *std::move(p);
  } else {
    std::fprintf(stderr, "--one: unknown case\n");
    return 2;
  }

  // The pipeline of core::MeshPlc's PLC branch (core/api.cc), timed per phase.
  const double w0 = WallNow(), c0 = CpuNow();
  plc::ValidationReport vreport;
  absl::StatusOr<plc::FeatureComplex> complex = plc::PreparePlc(plc, {}, {}, &vreport);
  if (!complex.ok()) {
    std::printf("RESULT status=%s\n", std::string(absl::StatusCodeToString(complex.status().code())).c_str());
    std::fprintf(stderr, "%s\n", complex.status().ToString().c_str());
    return 1;
  }
  const double w1 = WallNow(), c1 = CpuNow();
  refine::RefineOptions options;
  options.tau = 2.0 * radius_edge;
  options.max_volume = max_volume;
  const bool keep_box = complex->facets.empty();
  options.keep_bounding_box = keep_box;
  // As core::MeshPlc: M_Ω's adjacency comes out of the refiner; there it goes
  // through the flip pass to the output labelling, here straight to it
  // (docs/svrc-design.md §8 item 82).
  options.output_tet_neighbors = true;
  absl::StatusOr<refine::PointSetRefinement> refined = refine::RefinePlc(*complex, options);
  if (!refined.ok()) {
    std::printf("RESULT status=%s\n", std::string(absl::StatusCodeToString(refined.status().code())).c_str());
    std::fprintf(stderr, "%s\n", refined.status().ToString().c_str());
    return 1;
  }
  const double w2 = WallNow(), c2 = CpuNow();
  const std::vector<refine::ConstrainedFace> faces = refine::ConstrainedFacesOf(*refined, *complex);
  const refine::CoordinateMap map = refine::CoordinateMapOf(*refined);
  absl::StatusOr<refine::OutputStageResult> out =
      refine::BuildOutputMesh(plc, refined->normalised_positions, refined->tets, complex->point_of_vertex,
                              faces, map, keep_box, nullptr, refined->tet_neighbors);
  if (!out.ok()) {
    std::printf("RESULT status=%s\n", std::string(absl::StatusCodeToString(out.status().code())).c_str());
    std::fprintf(stderr, "%s\n", out.status().ToString().c_str());
    return 1;
  }
  const double w3 = WallNow(), c3 = CpuNow();
  const long peak_kib = PeakRssKib();  // before the measurements below allocate
  const int64_t heap_peak = svrc_heap_peak() - heap_base;

  const refine::RefineStats& s = refined->stats;
  const mesh::TetMesh& m = out->mesh;
  const mesh::QualityReport q = mesh::ComputeQuality(m);
  // Vertices of the output's boundary and interface triangles (the surface
  // model of the flatness diagnostics).
  size_t boundary_vertices = 0;
  {
    std::vector<uint8_t> on(m.positions.size(), 0);
    for (const auto& t : m.triangles) {
      for (uint32_t v : t) {
        if (on[v] == 0) {
          on[v] = 1;
          ++boundary_vertices;
        }
      }
    }
  }
  std::string verified = "-";
  if (verify) {
    core::MeshParams params;
    params.radius_edge = radius_edge;
    params.max_volume = max_volume;
    absl::StatusOr<mesh::TetMesh> via_api = core::MeshPlc(plc, params);
    verified = via_api.ok() && SameMesh(*via_api, m) ? "same" : "DIFFERENT";
  }
  // Link changes by the insertion that made them (RefineStats::
  // link_changes_by_kind): lk_KIND and in_KIND.
  std::string kinds;
  for (int k = 0; k < refine::kNumLinkChangeKinds; ++k) {
    absl::StrAppend(&kinds, " lk_", refine::kLinkChangeKindName[k], "=", s.link_changes_by_kind[k], " in_",
                    refine::kLinkChangeKindName[k], "=", s.insertions_by_kind[k], " sec_",
                    refine::kLinkChangeKindName[k], "=", s.seconds_by_kind[k], " ev_", refine::kLinkChangeKindName[k],
                    "=", s.events_by_kind[k]);
  }
  absl::StrAppend(&kinds, " sec_other_events=", s.seconds_other_events, " other_events=", s.other_events);
  std::printf(
      "RESULT status=OK out_vertices=%zu out_tets=%zu boundary_vertices=%zu omega_vertices=%llu omega_tets=%zu "
      "segment_vertices=%llu facet_vertices=%llu insertions=%llu destroy_cells=%llu destroy_index=%llu links_added=%llu "
      "links_removed=%llu warps=%llu yields=%llu max_degree=%u "
      "wall_prepare=%.6f wall_refine=%.6f wall_output=%.6f cpu_prepare=%.6f cpu_refine=%.6f cpu_output=%.6f "
      "base_kib=%ld peak_kib=%ld heap_peak=%lld max_re=%.6g min_dih=%.6g verify=%s%s\n",
      m.positions.size(), m.tets.size(), boundary_vertices, (unsigned long long)s.vertices, refined->tets.size(),
      (unsigned long long)s.segment_vertices, (unsigned long long)s.facet_vertices,
      (unsigned long long)s.insertions, (unsigned long long)s.destroy_cells_visited,
      (unsigned long long)s.destroy_index_visited,
      (unsigned long long)s.links_added, (unsigned long long)s.links_removed, (unsigned long long)s.warps,
      (unsigned long long)s.yields, s.max_degree, w1 - w0, w2 - w1, w3 - w2, c1 - c0, c2 - c1, c3 - c2,
      base_kib, peak_kib, static_cast<long long>(heap_peak), q.all.radius_edge.max, q.all.dihedral_deg.min, verified.c_str(),
      kinds.c_str());
  return 0;
}

// ---------------------------------------------------------------- parent

volatile sig_atomic_t g_child = 0;

void KillChildAndExit(int sig) {
  if (g_child > 0) kill(g_child, SIGKILL);
  signal(sig, SIG_DFL);
  raise(sig);
}

struct RunResult {
  std::string status;  // "OK", a status code name, "timeout", "signal N", "exit N"
  std::map<std::string, std::string> kv;
  double D(const std::string& k) const {
    auto it = kv.find(k);
    return it == kv.end() ? std::nan("") : std::atof(it->second.c_str());
  }
};

// Re-executes this binary with `--one args...`, stdout through a pipe, a
// timeout (SIGKILL) and RLIMIT_AS.
RunResult Spawn(const std::vector<std::string>& one_args, double radius_edge, bool verify, double timeout_s,
                uint64_t mem_limit_mib) {
  RunResult r;
  std::vector<std::string> argv = {"/proc/self/exe", "--radius-edge", absl::StrCat(radius_edge)};
  if (verify) argv.push_back("--verify");
  argv.push_back("--one");
  for (const auto& a : one_args) argv.push_back(a);
  std::vector<char*> cargv;
  for (auto& a : argv) cargv.push_back(a.data());
  cargv.push_back(nullptr);
  int fd[2];
  if (pipe(fd) != 0) {
    r.status = "pipe failed";
    return r;
  }
  std::fflush(stdout);
  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = fork();
  if (pid < 0) {
    r.status = "fork failed";
    return r;
  }
  if (pid == 0) {
    close(fd[0]);
    dup2(fd[1], 1);
    close(fd[1]);
    if (mem_limit_mib > 0) {
      rlimit lim{mem_limit_mib << 20, mem_limit_mib << 20};
      setrlimit(RLIMIT_AS, &lim);
    }
    execv(cargv[0], cargv.data());
    _exit(127);
  }
  g_child = pid;
  close(fd[1]);
  fcntl(fd[0], F_SETFL, O_NONBLOCK);
  std::string text;
  char buf[4096];
  int status = 0;
  bool timed_out = false;
  for (;;) {
    for (;;) {
      const ssize_t n = read(fd[0], buf, sizeof buf);
      if (n <= 0) break;
      text.append(buf, static_cast<size_t>(n));
    }
    const pid_t w = waitpid(pid, &status, WNOHANG);
    if (w == pid) break;
    if (w < 0 && errno != EINTR) break;
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > timeout_s) {
      timed_out = true;
      kill(pid, SIGKILL);
      while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
      }
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  for (;;) {
    const ssize_t n = read(fd[0], buf, sizeof buf);
    if (n <= 0) break;
    text.append(buf, static_cast<size_t>(n));
  }
  close(fd[0]);
  g_child = 0;
  for (absl::string_view line : absl::StrSplit(text, '\n')) {
    if (line.rfind("RESULT ", 0) != 0) continue;
    for (absl::string_view kv : absl::StrSplit(line.substr(7), ' ', absl::SkipEmpty())) {
      const size_t eq = kv.find('=');
      if (eq != absl::string_view::npos) r.kv[std::string(kv.substr(0, eq))] = std::string(kv.substr(eq + 1));
    }
  }
  if (timed_out) {
    r.status = absl::StrCat("timeout (", timeout_s, " s)");
  } else if (WIFSIGNALED(status)) {
    r.status = absl::StrCat("signal ", WTERMSIG(status));
  } else if (r.kv.count("status")) {
    r.status = r.kv["status"];
  } else {
    r.status = absl::StrCat("exit ", WEXITSTATUS(status));
  }
  return r;
}

std::string F(double v, int prec) {
  if (std::isnan(v)) return "-";
  char b[64];
  std::snprintf(b, sizeof b, "%.*f", prec, v);
  return b;
}
std::string G(double v) {
  if (std::isnan(v)) return "-";
  char b[64];
  std::snprintf(b, sizeof b, "%.4g", v);
  return b;
}

struct Row {
  std::string series, param;
  RunResult r;
  double tets = 0, cpu = 0, wall = 0, touched = 0, peak_b = 0, alloc_b = 0, heap_b = 0;
  double k = 0;  // spread: log10 of 1/side
};

void PrintHeader() {
  std::printf(
      "| series | parameter | result | output vertices | output tets | M_Ω vertices | M_Ω tets | insertions | wall s | "
      "cpu s (prepare/refine/output) | cpu µs/tet | wall µs/tet | cells+links per insertion (cells, links) | "
      "peak RSS MiB | peak B/tet | (peak − start) B/tet | peak heap B/tet | max r/e | min dih | MeshPlc same |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
}

Row Measure(const std::string& series, const std::string& param, const std::vector<std::string>& one_args,
            double radius_edge, bool verify, double timeout_s, uint64_t mem_mib) {
  Row row;
  row.series = series;
  row.param = param;
  std::fprintf(stderr, "[sensitivity] %s %s ...\n", series.c_str(), param.c_str());
  row.r = Spawn(one_args, radius_edge, verify, timeout_s, mem_mib);
  const RunResult& r = row.r;
  if (r.status != "OK") {
    std::printf("| %s | %s | %s | - | - | - | - | - | - | - | - | - | - | - | - | - | - | - | - | - |\n", series.c_str(),
                param.c_str(), r.status.c_str());
    std::fflush(stdout);
    return row;
  }
  row.tets = r.D("out_tets");
  row.cpu = r.D("cpu_prepare") + r.D("cpu_refine") + r.D("cpu_output");
  row.wall = r.D("wall_prepare") + r.D("wall_refine") + r.D("wall_output");
  const double ins = r.D("insertions");
  const double cells = r.D("destroy_cells") + r.D("destroy_index"), links = r.D("links_added") + r.D("links_removed");
  row.touched = (cells + links) / ins;
  row.peak_b = r.D("peak_kib") * 1024.0 / row.tets;
  row.alloc_b = (r.D("peak_kib") - r.D("base_kib")) * 1024.0 / row.tets;
  row.heap_b = r.D("heap_peak") / row.tets;
  std::printf(
      "| %s | %s | ok | %.0f | %.0f | %.0f | %.0f | %.0f | %s | %s (%s/%s/%s) | %s | %s | %s (%s, %s) | %s | %s | %s | %s "
      "| %s | %s | %s |\n",
      series.c_str(), param.c_str(), r.D("out_vertices"), row.tets, r.D("omega_vertices"), r.D("omega_tets"), ins,
      F(row.wall, 2).c_str(), F(row.cpu, 2).c_str(), F(r.D("cpu_prepare"), 2).c_str(),
      F(r.D("cpu_refine"), 2).c_str(), F(r.D("cpu_output"), 2).c_str(), F(1e6 * row.cpu / row.tets, 2).c_str(),
      F(1e6 * row.wall / row.tets, 2).c_str(), F(row.touched, 1).c_str(), F(cells / ins, 1).c_str(),
      F(links / ins, 1).c_str(), F(r.D("peak_kib") / 1024.0, 1).c_str(), F(row.peak_b, 0).c_str(),
      F(row.alloc_b, 0).c_str(), F(row.heap_b, 0).c_str(), G(r.D("max_re")).c_str(), G(r.D("min_dih")).c_str(),
      r.kv.count("verify") ? r.kv.at("verify").c_str() : "-");
  std::fflush(stdout);
  return row;
}

// max/min of `get` over the ok rows with ≥ 10^4 output tets.
struct Spread {
  double lo = 0, hi = 0;
  int n = 0;
};
template <typename Get>
Spread RangeOf(const std::vector<Row>& rows, Get get) {
  Spread s;
  for (const Row& r : rows) {
    if (r.r.status != "OK" || r.tets < 1e4) continue;
    const double v = get(r);
    if (s.n == 0) s.lo = s.hi = v;
    s.lo = std::min(s.lo, v);
    s.hi = std::max(s.hi, v);
    ++s.n;
  }
  return s;
}

void PrintFlatness(const std::string& series, const std::vector<Row>& rows) {
  double tlo = 0, thi = 0;
  int n = 0;
  for (const Row& r : rows) {
    if (r.r.status != "OK" || r.tets < 1e4) continue;
    tlo = n == 0 ? r.tets : std::min(tlo, r.tets);
    thi = n == 0 ? r.tets : std::max(thi, r.tets);
    ++n;
  }
  if (n < 2) {
    std::printf("- %s: fewer than 2 runs with >= 10^4 output tets, no verdict\n", series.c_str());
    return;
  }
  std::printf("- %s: %d runs, %.3g .. %.3g output tets (×%.1f):", series.c_str(), n, tlo, thi, thi / tlo);
  struct Measure {
    const char* name;
    double (*get)(const Row&);
  };
  const Measure measures[] = {
      {"cpu µs/tet", [](const Row& r) { return 1e6 * r.cpu / r.tets; }},
      {"wall µs/tet", [](const Row& r) { return 1e6 * r.wall / r.tets; }},
      {"cells+links/insertion", [](const Row& r) { return r.touched; }},
      {"peak B/tet", [](const Row& r) { return r.peak_b; }},
      {"(peak − start) B/tet", [](const Row& r) { return r.alloc_b; }},
      {"peak heap B/tet", [](const Row& r) { return r.heap_b; }},
  };
  bool first = true;
  for (const Measure& m : measures) {
    const Spread s = RangeOf(rows, m.get);
    std::printf("%s %s %.4g..%.4g = ×%.2f %s", first ? "" : ";", m.name, s.lo, s.hi, s.hi / s.lo,
                s.hi / s.lo <= 1.5 ? "(flat within 1.5×: yes)" : "(flat within 1.5×: NO)");
    first = false;
  }
  std::printf("\n");
  // Diagnostics, not the criterion: per output vertex (a boundary
  // vertex has fewer tets than an interior one, so the small runs have fewer
  // tets per vertex: cube 1e-4 5.1, 1e-6 6.0; bench/RESULTS.md "Session 51"),
  // per tet of the whole M_Ω (the bounding-domain mesh the refiner builds,
  // output or not), and the marginal cost between consecutive runs (a fixed
  // per-run cost cancels out).
  const Measure omega[] = {
      {"cpu µs per output vertex", [](const Row& r) { return 1e6 * r.cpu / r.r.D("out_vertices"); }},
      {"peak heap B per output vertex", [](const Row& r) { return r.r.D("heap_peak") / r.r.D("out_vertices"); }},
      {"cpu µs per M_Ω tet", [](const Row& r) { return 1e6 * r.cpu / r.r.D("omega_tets"); }},
      {"(peak − start) B per M_Ω tet",
       [](const Row& r) { return (r.r.D("peak_kib") - r.r.D("base_kib")) * 1024.0 / r.r.D("omega_tets"); }},
  };
  std::printf("  - diagnostics:");
  first = true;
  for (const Measure& m : omega) {
    const Spread s = RangeOf(rows, m.get);
    std::printf("%s %s %.4g..%.4g = ×%.2f", first ? "" : ";", m.name, s.lo, s.hi, s.hi / s.lo);
    first = false;
  }
  std::printf("; marginal cost between consecutive runs (Δcpu/Δtets µs, Δ(peak − start)/Δtets B):");
  const Row* prev = nullptr;
  for (const Row& r : rows) {
    if (r.r.status != "OK") continue;
    if (prev != nullptr && r.tets > prev->tets) {
      const double dt = r.tets - prev->tets;
      const double dmem = (r.r.D("peak_kib") - r.r.D("base_kib") - prev->r.D("peak_kib") + prev->r.D("base_kib")) *
                          1024.0;
      std::printf(" %.3g→%.3g: %.1f µs, %.0f B;", prev->tets, r.tets, 1e6 * (r.cpu - prev->cpu) / dt, dmem / dt);
    }
    prev = &r;
  }
  std::printf("\n");
  // The surface model: with T output tets and S boundary vertices, a cost
  // y ≈ a·T + b·S, fitted exactly on the smallest and the largest run. The
  // per-tet ratio of the two runs is (a + b·s₁)/(a + b·s₂) with s = S/T, so
  // it is ≤ 1.5 exactly when b ≤ 0.5·a/(s₁ − 1.5·s₂): what a boundary vertex
  // may cost for the cube's series to be flat (issue #5; bench/RESULTS.md
  // "Session 45").
  {
    const Row *small = nullptr, *large = nullptr;
    for (const Row& r : rows) {
      if (r.r.status != "OK" || r.tets < 1e4 || !(r.r.D("boundary_vertices") > 0)) continue;
      if (small == nullptr || r.tets < small->tets) small = &r;
      if (large == nullptr || r.tets > large->tets) large = &r;
    }
    const double s1 = small == nullptr ? 0 : small->r.D("boundary_vertices") / small->tets;
    const double s2 = large == nullptr ? 0 : large->r.D("boundary_vertices") / large->tets;
    if (small != nullptr && large != small && s1 > 1.5 * s2) {  // else the surface cannot unflatten it
      std::printf("  - surface model y ≈ a·T + b·S (T output tets, S boundary vertices %.0f .. %.0f; fit on %.3g and "
                  "%.3g tets):",
                  small->r.D("boundary_vertices"), large->r.D("boundary_vertices"), small->tets, large->tets);
      struct Cost {
        const char* name;
        const char* unit;
        double scale;
        double (*total)(const Row&);
      };
      const Cost costs[] = {{"peak heap", "B", 1, [](const Row& r) { return r.heap_b * r.tets; }},
                            {"cpu", "µs", 1e6, [](const Row& r) { return r.cpu; }}};
      bool first_cost = true;
      for (const Cost& c : costs) {
        // y1 = a·T1 + b·S1, y2 = a·T2 + b·S2, per tet: y/T = a + b·s.
        const double p1 = c.scale * c.total(*small) / small->tets, p2 = c.scale * c.total(*large) / large->tets;
        const double b = (p1 - p2) / (s1 - s2), a = p2 - b * s2;
        const double need = 0.5 * a / (s1 - 1.5 * s2);
        std::printf("%s %s a = %.3g %s per tet, b = %.4g %s per boundary vertex (flat within 1.5× needs b ≤ %.4g)",
                    first_cost ? "" : ";", c.name, a, c.unit, b, c.unit, need);
        first_cost = false;
      }
      std::printf("\n");
    }
  }
  // The location graph's link changes per insertion, by the insertion that
  // made them (RefineStats::link_changes_by_kind), and each kind's share of
  // the insertions: a kind whose cost stays flat but whose share moves
  // moves the cells+links column.
  std::printf("  - link changes per insertion by kind (share of the insertions into all meshes):");
  for (int k = 0; k < refine::kNumLinkChangeKinds; ++k) {
    const std::string name = refine::kLinkChangeKindName[k];
    std::printf("%s %s", k == 0 ? "" : ";", name.c_str());
    for (const Row& r : rows) {
      if (r.r.status != "OK") continue;
      double ins = 0;  // insertions into every mesh
      for (const char* kn : refine::kLinkChangeKindName) ins += r.r.D(std::string("in_") + kn);
      const double n = r.r.D("in_" + name);
      std::printf(" %s (%s%%)", n > 0 ? F(r.r.D("lk_" + name) / n, 1).c_str() : "-", F(100 * n / ins, 1).c_str());
    }
  }
  std::printf("\n");
  // The refinement loop's time per event by the same kinds
  // (RefineStats::seconds_by_kind: an event's wall time goes to the
  // lowest-dimensional mesh it inserted into, else its M_Ω insertion's
  // kind), each kind's share of the loop's time, and the spread of each
  // kind's µs per event over the runs: flat per kind while the mix moves is
  // the thesis' output-sensitive cost.
  auto loop_seconds = [](const Row& r) {
    double loop = r.r.D("sec_other_events");
    for (const char* kn : refine::kLinkChangeKindName) loop += r.r.D(std::string("sec_") + kn);
    return loop;
  };
  std::printf("  - refinement loop µs per event by kind (share of the loop's time; events of no kind: share); spread over the runs:");
  for (int k = 0; k < refine::kNumLinkChangeKinds; ++k) {
    const std::string name = refine::kLinkChangeKindName[k];
    std::printf("%s %s", k == 0 ? "" : ";", name.c_str());
    double lo = HUGE_VAL, hi = 0;
    for (const Row& r : rows) {
      if (r.r.status != "OK") continue;
      const double loop = loop_seconds(r);
      const double n = r.r.D("ev_" + name);
      const double us = n > 0 ? 1e6 * r.r.D("sec_" + name) / n : 0;
      if (n >= 100) {  // a kind with a handful of events says nothing about its cost
        lo = std::min(lo, us);
        hi = std::max(hi, us);
      }
      std::printf(" %s (%s%%)", n > 0 ? F(us, 1).c_str() : "-", F(loop > 0 ? 100 * r.r.D("sec_" + name) / loop : 0, 1).c_str());
    }
    if (hi > 0) std::printf(" ×%s", F(hi / lo, 2).c_str());
  }
  std::printf("; no kind");
  for (const Row& r : rows) {
    if (r.r.status != "OK") continue;
    const double loop = loop_seconds(r);
    std::printf(" %s%%", F(loop > 0 ? 100 * r.r.D("sec_other_events") / loop : 0, 1).c_str());
  }
  std::printf("\n");
}

std::vector<std::string> List(const std::string& s) {
  std::vector<std::string> out;
  for (absl::string_view p : absl::StrSplit(s, ',', absl::SkipEmpty())) out.emplace_back(p);
  return out;
}

int Main(int argc, char** argv) {
  double radius_edge = 2.0, timeout_s = 600;
  uint64_t mem_mib = 8192;
  bool verify = false;
  std::string cube_volumes = "1e-4,3e-5,1e-5,3e-6,1e-6";
  std::string skew_n = "100,300,1000,3000";
  std::string skewvol_n = "100,300,1000,3000";
  std::string skewvol_volume = "1e-4";
  std::string spread_k = "1,2,3,4,5,6";
  int repeat = 1;  // --repeat N: each run N times round robin, the least CPU time kept
  std::vector<std::string> series;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--one") {
      std::vector<std::string> rest(argv + i + 1, argv + argc);
      return RunOne(rest, radius_edge, verify);
    } else if (a == "--radius-edge") {
      radius_edge = std::atof(value().c_str());
    } else if (a == "--timeout") {
      timeout_s = std::atof(value().c_str());
    } else if (a == "--mem-limit-mib") {
      mem_mib = std::strtoull(value().c_str(), nullptr, 10);
    } else if (a == "--verify") {
      verify = true;
    } else if (a == "--cube-volumes") {
      cube_volumes = value();
    } else if (a == "--skew-n") {
      skew_n = value();
    } else if (a == "--skewvol-n") {
      skewvol_n = value();
    } else if (a == "--skewvol-volume") {
      skewvol_volume = value();
    } else if (a == "--spread-k") {
      spread_k = value();
    } else if (a == "--repeat") {
      repeat = std::max(1, std::atoi(value().c_str()));
    } else if (a == "-h" || a == "--help") {
      std::printf(
          "usage: %s [--radius-edge 2] [--timeout 600] [--mem-limit-mib 8192] [--verify]\n"
          "  [--cube-volumes 1e-4,...] [--skew-n 100,...] [--skewvol-n 100,...] [--skewvol-volume 1e-4]\n"
          "  [--spread-k 1,...,6] [--repeat N] [cube] [skew] [skewvol] [spread] [file:PATH]...\n",
          argv[0]);
      return 0;
    } else if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr, "unknown flag %s\n", a.c_str());
      return 2;
    } else {
      series.push_back(a);
    }
  }
  if (series.empty()) series = {"cube", "skew", "skewvol", "spread"};
  signal(SIGINT, KillChildAndExit);
  signal(SIGTERM, KillChildAndExit);
  signal(SIGHUP, KillChildAndExit);

  std::printf("svrc_sensitivity_bench: radius-edge %g (tau %g), timeout %.0f s, RLIMIT_AS %llu MiB, %u hardware "
              "threads\n\n",
              radius_edge, 2 * radius_edge, timeout_s, (unsigned long long)mem_mib,
              std::thread::hardware_concurrency());
  PrintHeader();
  // The runs of each series, then measured `repeat` times round robin (every
  // run once, then again: the box's speed drifts over minutes, and a run's
  // repeats should see the same minutes as the others'); per run the repeat
  // with the least CPU time is kept for the flatness (this box's timings of
  // one binary spread ±15% between minutes on the 0.1 s runs, session 42).
  struct Spec {
    std::string param;
    std::vector<std::string> args;
    double k = 0;
  };
  std::vector<std::pair<std::string, std::vector<Spec>>> specs;
  for (const std::string& s : series) {
    std::vector<Spec> list;
    if (s == "cube") {
      for (const std::string& v : List(cube_volumes)) list.push_back({"max vol " + v, {"cube", v}});
    } else if (s == "skew") {
      for (const std::string& n : List(skew_n)) list.push_back({"n " + n, {"skew", n, "0"}});
    } else if (s == "skewvol") {
      for (const std::string& n : List(skewvol_n)) {
        list.push_back({absl::StrCat("n ", n, ", max vol ", skewvol_volume), {"skew", n, skewvol_volume}});
      }
    } else if (s == "spread") {
      for (const std::string& k : List(spread_k)) list.push_back({"side 1e-" + k, {"spread", k}, std::atof(k.c_str())});
    } else if (s.rfind("file:", 0) == 0) {
      list.push_back({s.substr(5), {"file", s.substr(5)}});
    } else {
      std::fprintf(stderr, "unknown series %s\n", s.c_str());
      return 2;
    }
    specs.emplace_back(s, std::move(list));
  }
  std::vector<std::pair<std::string, std::vector<Row>>> all;
  for (const auto& [s, list] : specs) all.emplace_back(s, std::vector<Row>(list.size()));
  for (int rep = 0; rep < repeat; ++rep) {
    for (size_t i = 0; i < specs.size(); ++i) {
      const std::string& s = specs[i].first;
      const std::string name = s.rfind("file:", 0) == 0 ? "file" : s;
      for (size_t j = 0; j < specs[i].second.size(); ++j) {
        const Spec& sp = specs[i].second[j];
        Row row = Measure(name, sp.param, sp.args, radius_edge, verify, timeout_s, mem_mib);
        row.k = sp.k;
        Row& kept = all[i].second[j];
        const bool ok = row.r.status == "OK";
        if (rep == 0 || (ok && (kept.r.status != "OK" || row.cpu < kept.cpu))) kept = std::move(row);
      }
    }
  }
  if (repeat > 1) std::printf("\n(Below: per run the repeat of least CPU time, of %d.)\n", repeat);

  std::printf("\nFlatness over the runs with >= 10^4 output tets (max/min; the issue asks <= 1.5):\n\n");
  for (const auto& [name, rows] : all) {
    if (name == "spread" || name.rfind("file:", 0) == 0) continue;
    PrintFlatness(name, rows);
  }
  for (const auto& [name, rows] : all) {
    if (name != "spread") continue;
    std::printf("\nSpread (log Δ = k): per decade of Δ, the growth of output vertices and CPU time:\n\n");
    std::printf("| k (side 10^-k) | output vertices | vertices per decade since previous row | cpu s | cpu s per "
                "decade since previous row |\n|---|---|---|---|---|\n");
    const Row* prev = nullptr;
    for (const Row& r : rows) {
      if (r.r.status != "OK") continue;
      const double v = r.r.D("out_vertices");
      const double decades = prev ? r.k - prev->k : 0;
      std::printf("| %g | %.0f | %s | %s | %s |\n", r.k, v,
                  prev ? F((v - prev->r.D("out_vertices")) / decades, 0).c_str() : "-", F(r.cpu, 3).c_str(),
                  prev ? F((r.cpu - prev->cpu) / decades, 3).c_str() : "-");
      prev = &r;
    }
  }
  return 0;
}

}  // namespace
}  // namespace svrc::bench

int main(int argc, char** argv) { return svrc::bench::Main(argc, argv); }
