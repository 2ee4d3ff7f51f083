// PLC meshing side by side (issues #5 and #6): svrc (the `svrc mesh` CLI)
// and Debian's tetgen 1.5 (`tetgen -pq<B>`), each as a subprocess on the same
// input in one run, with a timeout and an address-space limit. Per run: exit
// status, wall and CPU time and peak RSS (wait4 rusage), then the output is
// read back (core/mesh/read_tetgen.h) and measured: tets, worst radius-edge
// (all tets and tets with no crease vertex, thesis §3 / issue #6), min/max
// dihedral (core/mesh/quality.h) and mesh::CheckConformity against the input
// PLC. Inputs: files (corpus paths) and generated families
// (core/plc/families.h). Prints a markdown table with svrc/tetgen ratios.
//
// Usage: svrc_plc_bench [flags] INPUT...   (inputs run in the order given)
//   FILE                  a PLC file (any format ReadPlcFile and tetgen read)
//   family:NAME, --family NAME   one generated family (--list shows the names)
//   families, --families  every generated family (families::StandardInputs)
//   --radius-edge 2,1.414 bounds to run (svrc --radius-edge B, tetgen -pq<B>)
//   --max-volume V        a global max volume (svrc --max-volume V, tetgen -a<V>)
//                         for the FILE inputs after it (0: none again)
//   --min-dihedral D      a smallest dihedral angle to aim at, every run
//                         (svrc --min-dihedral D, tetgen -pq<B>/<D>)
//   --tools svrc,tetgen   which peers run
//   --timeout 120         seconds per run (then SIGKILL: "timeout")
//   --mem-limit-mib 4096  RLIMIT_AS of each child (a run past it fails)
//   --svrc PATH --tetgen PATH --list
//   --workdir DIR         run folders there (kept); default a fresh temp folder,
//                         removed at the end unless --keep
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <condition_variable>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "core/mesh/conformity.h"
#include "core/mesh/quality.h"
#include "core/mesh/read_tetgen.h"
#include "core/plc/families.h"
#include "core/plc/features.h"
#include "core/plc/readers.h"
#include "core/plc/validate.h"

#ifndef SVRC_CLI_PATH
#define SVRC_CLI_PATH "svrc"
#endif
#ifndef SVRC_CORPUS_DIR
#define SVRC_CORPUS_DIR ""
#endif

namespace svrc::bench {
namespace {

namespace fs = std::filesystem;
using plc::families::GeneratedInput;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// ---------------------------------------------------------------- processes

struct ProcessResult {
  bool started = false;
  bool timed_out = false;
  bool exited = false;
  int exit_code = 0;
  int signal = 0;
  double wall_s = 0;
  double cpu_s = 0;      // user + system of the child (wait4)
  long peak_rss_kib = 0;  // ru_maxrss of the child
};

// The running child's process group, for the SIGINT/SIGTERM handler: a
// benchmark that is interrupted must not leave a mesher running.
volatile sig_atomic_t g_child_group = 0;

void KillChildAndExit(int sig) {
  if (g_child_group > 0) kill(-g_child_group, SIGKILL);
  signal(sig, SIG_DFL);
  raise(sig);
}

// fork/exec `argv` in `dir` (stdout, stderr to files there), RLIMIT_AS =
// mem_limit bytes (0: none), its own process group; SIGKILL to the group
// after `timeout_s`. The wait blocks in waitid while a watchdog thread keeps
// the time limit, so the wall time is the child's own to the microsecond
// (session 50: a poll with doubling sleeps, 0.5 → 20 ms, had rounded every
// short run up to the next poll, 7.5 / 15.5 / 31.5 / 51.5 ms, …).
ProcessResult RunProcess(const std::vector<std::string>& argv, const fs::path& dir,
                         const fs::path& out_path, const fs::path& err_path, double timeout_s,
                         uint64_t mem_limit) {
  ProcessResult r;
  std::vector<char*> cargv;
  for (const std::string& a : argv) cargv.push_back(const_cast<char*>(a.c_str()));
  cargv.push_back(nullptr);
  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = fork();
  if (pid < 0) return r;
  if (pid == 0) {
    setpgid(0, 0);
    if (chdir(dir.c_str()) != 0) _exit(126);
    const int out = open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (out < 0 || err < 0) _exit(126);
    dup2(out, 1);
    dup2(err, 2);
    const int in = open("/dev/null", O_RDONLY);
    if (in >= 0) dup2(in, 0);
    if (mem_limit > 0) {
      rlimit lim{mem_limit, mem_limit};
      setrlimit(RLIMIT_AS, &lim);
    }
    execv(cargv[0], cargv.data());
    _exit(127);
  }
  setpgid(pid, pid);
  g_child_group = pid;
  r.started = true;
  std::mutex mu;
  std::condition_variable done_cv;
  bool done = false;
  bool killed = false;  // the watchdog's, read after join
  std::thread watchdog([&] {
    std::unique_lock<std::mutex> lock(mu);
    const auto limit = start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                   std::chrono::duration<double>(timeout_s));
    if (!done_cv.wait_until(lock, limit, [&] { return done; })) {
      killed = true;
      kill(-pid, SIGKILL);
      kill(pid, SIGKILL);
    }
  });
  // Waited for without reaping first: the watchdog may signal the group
  // until `done`, and the pid cannot be reused before the wait4 below.
  siginfo_t info{};
  while (waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOWAIT) < 0 && errno == EINTR) {
  }
  const auto end = std::chrono::steady_clock::now();
  {
    std::lock_guard<std::mutex> lock(mu);
    done = true;
  }
  done_cv.notify_all();
  watchdog.join();
  int status = 0;
  rusage ru{};
  while (wait4(pid, &status, 0, &ru) < 0 && errno == EINTR) {
  }
  r.timed_out = killed;
  g_child_group = 0;
  r.wall_s = std::chrono::duration<double>(end - start).count();
  r.cpu_s = ru.ru_utime.tv_sec + ru.ru_utime.tv_usec * 1e-6 + ru.ru_stime.tv_sec +
            ru.ru_stime.tv_usec * 1e-6;
  r.peak_rss_kib = ru.ru_maxrss;
  if (WIFEXITED(status)) {
    r.exited = true;
    r.exit_code = WEXITSTATUS(status);
  } else if (WIFSIGNALED(status)) {
    r.signal = WTERMSIG(status);
  }
  return r;
}

std::string ReadText(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The last line of `text` containing `needle` (or the last non-empty line
// when needle is empty), trimmed.
std::string LastLine(const std::string& text, const std::string& needle = "") {
  std::string best;
  for (absl::string_view line : absl::StrSplit(text, '\n')) {
    line = absl::StripAsciiWhitespace(line);
    if (line.empty()) continue;
    if (needle.empty() || line.find(needle) != absl::string_view::npos) best = std::string(line);
  }
  return best;
}

// ---------------------------------------------------------------- inputs

struct Input {
  std::string name;       // table label
  fs::path source;        // a file to copy, or empty for a generated PLC
  plc::Plc plc;           // what the checker compares against
  double max_volume = 0;  // global bound (svrc --max-volume, tetgen a<V>)
};

struct Options {
  std::vector<double> bounds = {2.0, 1.414};
  bool run_svrc = true, run_tetgen = true;
  double timeout_s = 120;
  uint64_t mem_limit_mib = 4096;
  std::string svrc = SVRC_CLI_PATH;
  std::string tetgen = "/usr/bin/tetgen";
  std::string workdir;
  bool keep = false;
  double min_dihedral = 0;  // > 0: svrc --min-dihedral, tetgen -q<B>/<D>
};

// TetGen takes the volume as digits (no exponent): fixed notation, trimmed.
std::string FixedNumber(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.12f", v);
  std::string s = buf;
  while (!s.empty() && s.back() == '0') s.pop_back();
  if (!s.empty() && s.back() == '.') s.pop_back();
  return s;
}

std::string Label(const fs::path& p) {
  const std::string corpus = SVRC_CORPUS_DIR;
  std::error_code ec;
  if (!corpus.empty()) {
    const fs::path rel = fs::relative(fs::weakly_canonical(p, ec), fs::weakly_canonical(corpus, ec), ec);
    if (!ec && !rel.empty() && rel.native().rfind("..", 0) != 0) return rel.string();
  }
  return p.filename().string();
}

// ---------------------------------------------------------------- one run

struct Measured {
  std::string tool;     // "svrc" / "tetgen"
  std::string command;  // switches, for the table
  std::string result;   // "ok", "timeout", "UNIMPLEMENTED (exit 5)", "SIGABRT", ...
  std::string detail;   // error text for the notes
  ProcessResult proc;
  bool meshed = false;
  size_t vertices = 0, tets = 0;
  double worst_re = kNaN, worst_re_off_crease = kNaN, min_dih = kNaN, max_dih = kNaN;
  std::string conforms = "-";
};

std::string SignalName(int sig) {
  switch (sig) {
    case SIGABRT: return "SIGABRT";
    case SIGSEGV: return "SIGSEGV";
    case SIGKILL: return "SIGKILL";
    case SIGBUS: return "SIGBUS";
    case SIGFPE: return "SIGFPE";
    default: return absl::StrCat("signal ", sig);
  }
}

// The creases of the input complex (docs/plc.md §6): crease points and
// crease segments. A mesh vertex "touches a crease" when it is within `tol`
// of one (issue #6: the radius-edge bound holds for tets not touching a crease).
struct Creases {
  std::vector<geom::Vec3> points;
  std::vector<std::pair<geom::Vec3, geom::Vec3>> segments;
  double tol = 0;
  bool empty() const { return points.empty() && segments.empty(); }
};

// One flag per mesh vertex: on a crease point or crease segment. A uniform
// grid over the vertices keeps this near-linear.
std::vector<uint8_t> CreaseVertices(const std::vector<geom::Vec3>& pos, const Creases& cr) {
  std::vector<uint8_t> flag(pos.size(), 0);
  if (cr.empty() || pos.empty()) return flag;
  geom::Vec3 lo = pos[0], hi = pos[0];
  for (const auto& p : pos) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], p[a]);
      hi[a] = std::max(hi[a], p[a]);
    }
  }
  const int g = std::clamp(static_cast<int>(std::cbrt(pos.size() / 2.0)), 1, 128);
  double cell[3];
  for (int a = 0; a < 3; ++a) cell[a] = std::max((hi[a] - lo[a]) / g, 1e-300);
  auto index = [&](double v, int a) {
    return std::clamp(static_cast<int>((v - lo[a]) / cell[a]), 0, g - 1);
  };
  std::vector<std::vector<uint32_t>> bucket(size_t(g) * g * g);
  for (uint32_t v = 0; v < pos.size(); ++v) {
    bucket[(size_t(index(pos[v].z, 2)) * g + index(pos[v].y, 1)) * g + index(pos[v].x, 0)]
        .push_back(v);
  }
  auto visit = [&](geom::Vec3 a, geom::Vec3 b, auto&& near) {
    int c0[3], c1[3];
    for (int k = 0; k < 3; ++k) {
      c0[k] = index(std::min(a[k], b[k]) - cr.tol, k);
      c1[k] = index(std::max(a[k], b[k]) + cr.tol, k);
    }
    for (int z = c0[2]; z <= c1[2]; ++z) {
      for (int y = c0[1]; y <= c1[1]; ++y) {
        for (int x = c0[0]; x <= c1[0]; ++x) {
          for (uint32_t v : bucket[(size_t(z) * g + y) * g + x]) {
            if (!flag[v] && near(pos[v])) flag[v] = 1;
          }
        }
      }
    }
  };
  for (const auto& p : cr.points) {
    visit(p, p, [&](const geom::Vec3& q) { return geom::Dist(p, q) <= cr.tol; });
  }
  for (const auto& [a, b] : cr.segments) {
    const geom::Vec3 d = b - a;
    const double l2 = geom::Norm2(d);
    visit(a, b, [&](const geom::Vec3& q) {
      const double t = l2 > 0 ? std::clamp(geom::Dot(q - a, d) / l2, 0.0, 1.0) : 0.0;
      return geom::Dist(q, a + t * d) <= cr.tol;
    });
  }
  return flag;
}

// Reads <node> back and fills the mesh columns.
void MeasureMesh(const Input& in, const fs::path& node, bool canonical, const Creases& creases,
                 Measured* m) {
  absl::StatusOr<mesh::TetMesh> mesh = mesh::ReadTetgenMesh(node.string());
  if (!mesh.ok()) {
    m->result = "unreadable output";
    m->detail = std::string(mesh.status().message());
    return;
  }
  m->vertices = mesh->positions.size();
  m->tets = mesh->tets.size();
  if (m->tets == 0) {
    m->result = "empty mesh";
    return;
  }
  m->meshed = true;
  const std::vector<uint8_t> crease = CreaseVertices(mesh->positions, creases);
  const mesh::QualityReport q = mesh::ComputeQuality(*mesh, crease);
  m->worst_re = q.all.radius_edge.max;
  m->worst_re_off_crease = q.other.num_tets > 0 ? q.other.radius_edge.max : kNaN;
  m->min_dih = q.all.dihedral_deg.min;
  m->max_dih = q.all.dihedral_deg.max;

  mesh::ConformityOptions opt;
  opt.input_vertices_first = canonical;
  // tetgen writes marker 1 on the boundary of unmarked surface inputs.
  opt.check_markers = canonical || !in.plc.is_surface;
  if (in.plc.IsPointSet()) {
    // A point set's Delaunay tetrahedralization: validity, and every input
    // vertex present (the PLC checker needs facets for coverage).
    const mesh::ConformityReport r = mesh::CheckValidity(*mesh, opt);
    std::map<std::tuple<double, double, double>, int> have;
    for (const auto& p : mesh->positions) have[std::make_tuple(p.x, p.y, p.z)] = 1;
    size_t missing = 0;
    for (const auto& p : in.plc.vertices) missing += !have.count(std::make_tuple(p.x, p.y, p.z));
    if (r.ok() && missing == 0) {
      m->conforms = "valid (points)";
    } else {
      m->conforms = absl::StrCat("NO: ", r.ok() ? "" : LastLine(r.Summary(), "/"),
                                 missing ? absl::StrCat(" missing vertices ", missing) : "");
    }
    return;
  }
  const mesh::ConformityReport r = mesh::CheckConformity(in.plc, *mesh, opt);
  if (r.ok()) {
    m->conforms = "yes";
  } else {
    // The first "category/kind: count" line of the summary.
    std::string first;
    for (absl::string_view line : absl::StrSplit(r.Summary(), '\n')) {
      if (line.find('/') != absl::string_view::npos && line.find(": ") != absl::string_view::npos &&
          line.rfind("  ", 0) != 0) {
        first = std::string(line);
        break;
      }
    }
    size_t total = 0;
    for (size_t c : r.counts) total += c;
    m->conforms = absl::StrCat("NO (", total, "): ", first);
    m->detail = r.Summary();
  }
}

Measured RunTetgen(const Input& in, const fs::path& input_file, double bound,
                   const Creases& crease_points, const Options& o,
                   const fs::path& dir) {
  Measured m;
  m.tool = "tetgen";
  fs::create_directories(dir);
  const fs::path copy = dir / input_file.filename();
  fs::copy_file(input_file, copy, fs::copy_options::overwrite_existing);
  std::string sw;
  if (in.plc.IsPointSet()) {
    sw = "-Q";  // Delaunay of the points, as svrc does for a point set
  } else {
    sw = absl::StrCat("-pq", absl::StrCat(bound), o.min_dihedral > 0 ? absl::StrCat("/", o.min_dihedral) : "", "A");
    bool region_volumes = false;
    for (const auto& r : in.plc.regions) region_volumes |= r.max_volume > 0;
    if (region_volumes) sw += "a";
    if (in.max_volume > 0) sw += absl::StrCat("a", FixedNumber(in.max_volume));
    sw += "Q";
  }
  m.command = absl::StrCat("tetgen ", sw);
  std::vector<std::string> argv;
  // Unbuffered stdout: tetgen's errors end in abort(), which loses buffered output.
  if (fs::exists("/usr/bin/stdbuf")) argv = {"/usr/bin/stdbuf", "-o0"};
  argv.push_back(o.tetgen);
  argv.push_back(sw);
  argv.push_back(copy.filename().string());
  m.proc = RunProcess(argv, dir, dir / "tetgen.out", dir / "tetgen.err", o.timeout_s,
                      o.mem_limit_mib << 20);
  const std::string out = ReadText(dir / "tetgen.out") + ReadText(dir / "tetgen.err");
  if (!m.proc.started) {
    m.result = "fork failed";
  } else if (m.proc.timed_out) {
    m.result = "timeout";
  } else if (!m.proc.exited) {
    m.result = SignalName(m.proc.signal);
    m.detail = LastLine(out);
  } else if (m.proc.exit_code != 0) {
    m.result = absl::StrCat("exit ", m.proc.exit_code);
    m.detail = LastLine(out);
  } else {
    fs::path node = copy;
    node.replace_extension(".1.node");
    m.result = "ok";
    MeasureMesh(in, node, /*canonical=*/false, crease_points, &m);
  }
  if (m.detail.empty() && m.result != "ok") m.detail = LastLine(out, "rror");
  return m;
}

Measured RunSvrc(const Input& in, const fs::path& input_file, double bound,
                 const Creases& crease_points, const Options& o,
                 const fs::path& dir) {
  Measured m;
  m.tool = "svrc";
  fs::create_directories(dir);
  const fs::path out = dir / "out.node";
  std::vector<std::string> argv = {o.svrc, "mesh", input_file.string(), "-o", out.string(),
                                   "--quiet"};
  std::string flags;
  if (!in.plc.IsPointSet()) {
    argv.push_back("--radius-edge");
    argv.push_back(absl::StrCat(bound));
    flags = absl::StrCat("--radius-edge ", bound);
  }
  if (in.max_volume > 0) {
    argv.push_back("--max-volume");
    argv.push_back(absl::StrCat(in.max_volume));
    absl::StrAppend(&flags, " --max-volume ", in.max_volume);
  }
  if (o.min_dihedral > 0 && !in.plc.IsPointSet()) {
    argv.push_back("--min-dihedral");
    argv.push_back(absl::StrCat(o.min_dihedral));
    absl::StrAppend(&flags, " --min-dihedral ", o.min_dihedral);
  }
  m.command = absl::StrCat("svrc mesh", flags.empty() ? "" : " ", flags);
  m.proc = RunProcess(argv, dir, dir / "svrc.out", dir / "svrc.err", o.timeout_s,
                      o.mem_limit_mib << 20);
  const std::string err = ReadText(dir / "svrc.err");
  if (!m.proc.started) {
    m.result = "fork failed";
  } else if (m.proc.timed_out) {
    m.result = "timeout";
  } else if (!m.proc.exited) {
    m.result = SignalName(m.proc.signal);
    m.detail = LastLine(err);
  } else if (m.proc.exit_code != 0) {
    // "svrc: IN: CODE: message" -> CODE.
    const std::string line = LastLine(err);
    m.detail = line;
    std::string code;
    for (absl::string_view part : absl::StrSplit(line, ": ")) {
      if (!part.empty() && std::all_of(part.begin(), part.end(),
                                       [](char c) { return (c >= 'A' && c <= 'Z') || c == '_'; })) {
        code = std::string(part);
        break;
      }
    }
    m.result = code.empty() ? absl::StrCat("exit ", m.proc.exit_code)
                            : absl::StrCat(code, " (exit ", m.proc.exit_code, ")");
  } else {
    m.result = "ok";
    MeasureMesh(in, out, /*canonical=*/true, crease_points, &m);
  }
  return m;
}

// ---------------------------------------------------------------- table

std::string Fmt(double v, int prec = 3) {
  if (std::isnan(v)) return "-";
  if (std::isinf(v)) return "inf";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", prec, v);
  return buf;
}
std::string Sig(double v) {
  if (std::isnan(v)) return "-";
  if (std::isinf(v)) return "inf";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

void PrintRow(const std::string& input, const std::string& bound, const Measured& m,
              const Measured* peer) {
  const bool ran = m.proc.started;
  std::string time_ratio = "", tet_ratio = "";
  if (peer && m.meshed && peer->meshed && peer->proc.wall_s > 0) {
    time_ratio = Fmt(m.proc.wall_s / peer->proc.wall_s, 2);
    if (peer->proc.cpu_s > 0) time_ratio += " (cpu " + Fmt(m.proc.cpu_s / peer->proc.cpu_s, 2) + ")";
    tet_ratio = Fmt(double(m.tets) / double(peer->tets), 2);
  }
  std::printf("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |\n",
              input.c_str(), bound.c_str(), m.command.c_str(), m.result.c_str(),
              ran ? Fmt(m.proc.wall_s).c_str() : "-", ran ? Fmt(m.proc.cpu_s).c_str() : "-",
              ran ? Fmt(m.proc.peak_rss_kib / 1024.0, 1).c_str() : "-",
              m.meshed ? std::to_string(m.vertices).c_str() : "-",
              m.meshed ? std::to_string(m.tets).c_str() : "-", Sig(m.worst_re).c_str(),
              Sig(m.worst_re_off_crease).c_str(), Sig(m.min_dih).c_str(), Sig(m.max_dih).c_str(),
              m.conforms.c_str(), time_ratio.c_str(), tet_ratio.c_str());
  std::fflush(stdout);
}

std::vector<double> ParseList(const std::string& s) {
  std::vector<double> out;
  for (absl::string_view part : absl::StrSplit(s, ',', absl::SkipEmpty())) {
    double v = 0;
    if (absl::SimpleAtod(part, &v)) out.push_back(v);
  }
  return out;
}

int Usage(const char* argv0) {
  std::fprintf(stderr,
               "usage: %s [--radius-edge 2,1.414] [--tools svrc,tetgen] [--timeout 120] "
               "[--mem-limit-mib 4096] [--min-dihedral D] [--svrc PATH] [--tetgen PATH] [--workdir DIR] [--keep] "
               "[--list] INPUT...\n  INPUT: a PLC file, family:NAME (--family NAME), "
               "families (--families); --max-volume V applies to the files after it\n",
               argv0);
  return 2;
}

int Main(int argc, char** argv) {
  Options o;
  // Inputs in command-line order: a file path, "family:NAME" or "families"
  // (every generated family).
  std::vector<std::string> specs;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--families") {
      specs.push_back("families");
    } else if (a == "--family") {
      specs.push_back("family:" + value());
    } else if (a == "--radius-edge") {
      o.bounds = ParseList(value());
    } else if (a == "--max-volume") {
      specs.push_back("maxvol:" + value());
    } else if (a == "--min-dihedral") {
      o.min_dihedral = std::atof(value().c_str());
    } else if (a == "--tools") {
      const std::string t = value();
      o.run_svrc = t.find("svrc") != std::string::npos;
      o.run_tetgen = t.find("tetgen") != std::string::npos;
    } else if (a == "--timeout") {
      o.timeout_s = std::atof(value().c_str());
    } else if (a == "--mem-limit-mib") {
      o.mem_limit_mib = std::strtoull(value().c_str(), nullptr, 10);
    } else if (a == "--svrc") {
      o.svrc = value();
    } else if (a == "--tetgen") {
      o.tetgen = value();
    } else if (a == "--workdir") {
      o.workdir = value();
    } else if (a == "--keep") {
      o.keep = true;
    } else if (a == "--list") {
      for (const GeneratedInput& g : plc::families::StandardInputs()) {
        std::printf("%-26s %s%s\n", g.name.c_str(), g.description.c_str(),
                    g.max_volume > 0 ? absl::StrCat(" [max volume ", g.max_volume, "]").c_str() : "");
      }
      return 0;
    } else if (a == "-h" || a == "--help") {
      return Usage(argv[0]);
    } else if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr, "unknown flag %s\n", a.c_str());
      return Usage(argv[0]);
    } else {
      specs.push_back(a);
    }
  }
  if (o.bounds.empty()) return Usage(argv[0]);
  signal(SIGINT, KillChildAndExit);
  signal(SIGTERM, KillChildAndExit);
  signal(SIGHUP, KillChildAndExit);

  std::vector<Input> inputs;
  std::vector<GeneratedInput> generated = plc::families::StandardInputs();
  double file_max_volume = 0;  // --max-volume: for the file inputs after it
  for (const std::string& spec : specs) {
    if (spec.rfind("maxvol:", 0) == 0) {
      file_max_volume = std::atof(spec.c_str() + 7);
      if (!(file_max_volume >= 0)) {
        std::fprintf(stderr, "bad --max-volume %s\n", spec.c_str() + 7);
        return 2;
      }
    } else if (spec == "families") {
      for (const GeneratedInput& g : generated) {
        inputs.push_back(Input{g.name, {}, g.plc, g.max_volume});
      }
    } else if (spec.rfind("family:", 0) == 0) {
      const std::string name = spec.substr(7);
      auto it = std::find_if(generated.begin(), generated.end(),
                             [&](const GeneratedInput& g) { return g.name == name; });
      if (it == generated.end()) {
        std::fprintf(stderr, "unknown family %s (see --list)\n", name.c_str());
        return 2;
      }
      inputs.push_back(Input{it->name, {}, it->plc, it->max_volume});
    } else {
      absl::StatusOr<plc::Plc> plc = plc::ReadPlcFile(spec);
      if (!plc.ok()) {
        std::fprintf(stderr, "cannot read %s: %s\n", spec.c_str(), plc.status().ToString().c_str());
        return 1;
      }
      const std::string label =
          file_max_volume > 0 ? absl::StrCat(Label(spec), " (max volume ", file_max_volume, ")") : Label(spec);
      inputs.push_back(Input{label, fs::absolute(spec), *std::move(plc), file_max_volume});
    }
  }
  if (inputs.empty()) return Usage(argv[0]);

  fs::path work;
  bool created_work = false;  // only a folder we made is removed at the end
  if (o.workdir.empty()) {
    std::string tmpl = (fs::temp_directory_path() / "svrc_plc_bench.XXXXXX").string();
    if (!mkdtemp(tmpl.data())) {
      std::perror("mkdtemp");
      return 1;
    }
    work = tmpl;
    created_work = true;
  } else {
    work = fs::absolute(o.workdir);
    fs::create_directories(work);
  }
  o.svrc = fs::absolute(o.svrc).string();

  std::printf("svrc_plc_bench: svrc = %s, tetgen = %s, timeout %.0f s, RLIMIT_AS %llu MiB, "
              "%u hardware threads\n\n",
              o.svrc.c_str(), o.tetgen.c_str(), o.timeout_s,
              static_cast<unsigned long long>(o.mem_limit_mib), std::thread::hardware_concurrency());
  std::printf("| input | bound | command | result | wall s | cpu s | peak MiB | vertices | tets | "
              "max r/e | max r/e off crease | min dih | max dih | conforms | svrc/tetgen time | "
              "svrc/tetgen tets |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  std::fflush(stdout);

  std::vector<std::string> notes;
  for (size_t k = 0; k < inputs.size(); ++k) {
    const Input& in = inputs[k];
    std::string dirname = in.name;
    for (char& c : dirname) {
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '-') c = '_';
    }
    const fs::path idir = work / absl::StrCat(k, "_", dirname);
    fs::create_directories(idir);
    fs::path input_file;
    if (in.source.empty()) {
      input_file = idir / (in.name + (in.plc.IsPointSet() ? ".node" : ".poly"));
      if (absl::Status s = plc::families::WritePoly(in.plc, input_file.string()); !s.ok()) {
        std::fprintf(stderr, "%s\n", s.ToString().c_str());
        return 1;
      }
    } else {
      input_file = idir / in.source.filename();
      fs::copy_file(in.source, input_file, fs::copy_options::overwrite_existing);
    }
    // Crease points of the input (docs/plc.md §6) for the off-crease quality.
    Creases crease_points;
    plc::ValidationReport vreport;
    absl::StatusOr<plc::FeatureComplex> fc =
        plc::PreparePlc(in.plc, plc::ValidationOptions{}, plc::FeatureOptions{}, &vreport);
    if (fc.ok()) {
      for (const auto& p : fc->points) {
        if (p.crease) crease_points.points.push_back(p.p);
      }
      for (const auto& sg : fc->segments) {
        if (sg.crease) crease_points.segments.push_back({fc->points[sg.a].p, fc->points[sg.b].p});
      }
      crease_points.tol = 1e-9 * fc->diameter;
    } else {
      notes.push_back(absl::StrCat(in.name, ": input does not validate: ", fc.status().message()));
    }
    const std::vector<double> bounds =
        in.plc.IsPointSet() ? std::vector<double>{o.bounds.front()} : o.bounds;
    for (double b : bounds) {
      const std::string bound = in.plc.IsPointSet() ? "Delaunay" : absl::StrCat(b);
      const fs::path rdir = idir / absl::StrCat("q", b);
      std::optional<Measured> tet, sv;
      std::fprintf(stderr, "[%zu/%zu] %s %s ...\n", k + 1, inputs.size(), in.name.c_str(),
                   bound.c_str());
      if (o.run_tetgen) {
        tet = RunTetgen(in, input_file, b, crease_points, o, rdir / "tetgen");
        PrintRow(in.name, bound, *tet, nullptr);
      }
      if (o.run_svrc) {
        sv = RunSvrc(in, input_file, b, crease_points, o, rdir / "svrc");
        PrintRow(in.name, bound, *sv, tet ? &*tet : nullptr);
      }
      for (const std::optional<Measured>* m : {&tet, &sv}) {
        if (!m->has_value() || (*m)->detail.empty()) continue;
        std::string d = (*m)->detail;
        std::replace(d.begin(), d.end(), '\n', ' ');
        if (d.size() > 400) d = d.substr(0, 400) + " ...";
        notes.push_back(absl::StrCat(in.name, " ", bound, " ", (*m)->command, ": ", (*m)->result,
                                     ": ", d));
      }
    }
  }
  if (!notes.empty()) {
    std::printf("\nNotes:\n");
    for (const std::string& n : notes) std::printf("- %s\n", n.c_str());
  }
  if (created_work && !o.keep) {
    std::error_code ec;
    fs::remove_all(work, ec);
  } else {
    std::printf("\nrun folders kept in %s\n", work.c_str());
  }
  return 0;
}

}  // namespace
}  // namespace svrc::bench

int main(int argc, char** argv) { return svrc::bench::Main(argc, argv); }
