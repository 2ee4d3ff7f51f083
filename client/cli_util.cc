#include "client/cli_util.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/time/time.h"
#include "core/codec/container.h"
#include "core/mesh/writers.h"

namespace svrc::cli {
namespace {

absl::Status ParseDouble(const Args& args, const std::string& flag, std::optional<double>* out) {
  if (!args.values.count(flag)) return absl::OkStatus();
  double v;
  if (!absl::SimpleAtod(args.Get(flag), &v)) {
    return absl::InvalidArgumentError(absl::StrCat(flag, ": not a number: '", args.Get(flag), "'"));
  }
  *out = v;
  return absl::OkStatus();
}

}  // namespace

const std::vector<std::string>& MeshValueFlags() {
  static const std::vector<std::string> flags = {
      "--radius-edge", "--max-volume",   "--theta",    "--max-rep-angle",     "--min-dihedral",
      "--max-vertices", "--deadline",    "--quantization-bits", "--collar-size-eps"};
  return flags;
}

const std::vector<std::string>& MeshSwitches() {
  static const std::vector<std::string> flags = {"--keep-bounding-box", "--collar-cell-test"};
  return flags;
}

absl::StatusOr<Args> ParseArgs(const std::vector<std::string>& argv,
                               const std::vector<std::string>& value_flags,
                               const std::vector<std::string>& switches) {
  auto is_value = [&](const std::string& n) {
    return std::find(value_flags.begin(), value_flags.end(), n) != value_flags.end();
  };
  auto is_switch = [&](const std::string& n) {
    return std::find(switches.begin(), switches.end(), n) != switches.end();
  };
  Args args;
  for (size_t i = 0; i < argv.size(); ++i) {
    const std::string& a = argv[i];
    if (a.size() < 2 || a[0] != '-' || a == "--") {
      if (a != "--") args.positional.push_back(a);
      continue;
    }
    std::string name = a, value;
    bool has_value = false;
    if (const size_t eq = a.find('='); eq != std::string::npos) {
      name = a.substr(0, eq);
      value = a.substr(eq + 1);
      has_value = true;
    }
    if (is_switch(name)) {
      if (has_value && value != "true" && value != "false") {
        return absl::InvalidArgumentError(absl::StrCat(name, " takes true or false"));
      }
      if (!has_value || value == "true") args.switches.insert(name);
      else args.switches.erase(name);
      continue;
    }
    if (!is_value(name)) return absl::InvalidArgumentError(absl::StrCat("unknown option ", name));
    if (!has_value) {
      if (i + 1 >= argv.size()) return absl::InvalidArgumentError(absl::StrCat(name, " needs a value"));
      value = argv[++i];
    }
    args.values[name] = value;
  }
  return args;
}

absl::StatusOr<MeshOptions> MeshOptionsFromArgs(const Args& args) {
  MeshOptions o;
  for (auto [flag, field] : std::initializer_list<std::pair<const char*, std::optional<double>*>>{
           {"--radius-edge", &o.radius_edge},
           {"--theta", &o.theta},
           {"--max-rep-angle", &o.max_rep_angle},
           {"--max-volume", &o.max_volume},
           {"--min-dihedral", &o.min_dihedral},
           {"--collar-size-eps", &o.collar_size_eps}}) {
    if (absl::Status s = ParseDouble(args, flag, field); !s.ok()) return s;
  }
  if (args.switches.count("--keep-bounding-box")) o.keep_bounding_box = true;
  if (args.switches.count("--collar-cell-test")) o.collar_cell_test = true;
  if (args.values.count("--max-vertices") &&
      !absl::SimpleAtoi(args.Get("--max-vertices"), &o.max_vertices)) {
    return absl::InvalidArgumentError(
        absl::StrCat("--max-vertices: not a count: '", args.Get("--max-vertices"), "'"));
  }
  if (args.values.count("--deadline")) {
    const std::string v = args.Get("--deadline");
    double seconds;
    if (absl::SimpleAtod(v, &seconds)) {
      o.deadline = absl::Seconds(seconds);
    } else if (!absl::ParseDuration(v, &o.deadline)) {
      return absl::InvalidArgumentError(
          absl::StrCat("--deadline: not a duration (e.g. 30s, 5m, 1.5): '", v, "'"));
    }
    if (o.deadline <= absl::ZeroDuration()) {
      return absl::InvalidArgumentError("--deadline must be positive");
    }
  }
  if (args.values.count("--quantization-bits") &&
      !absl::SimpleAtoi(args.Get("--quantization-bits"), &o.quantization_bits)) {
    return absl::InvalidArgumentError(absl::StrCat("--quantization-bits: not an integer: '",
                                                   args.Get("--quantization-bits"), "'"));
  }
  if (absl::Status s = ValidateOptions(o); !s.ok()) return s;
  return o;
}

int ExitCodeFor(const absl::Status& status, bool job_outcome) {
  if (status.ok()) return kExitOk;
  switch (status.code()) {
    case absl::StatusCode::kInvalidArgument:
      return kExitInvalidInput;
    case absl::StatusCode::kCancelled:
    case absl::StatusCode::kDeadlineExceeded:
      return job_outcome ? kExitCancelled : kExitServer;
    default:
      return job_outcome ? kExitJobFailed : kExitServer;
  }
}

int Fail(int code, const std::string& message) {
  std::string line = message;
  std::replace(line.begin(), line.end(), '\n', ' ');
  std::fprintf(stderr, "svrc: %s\n", line.c_str());
  return code;
}

int UsageError(const Command& command, const std::string& message) {
  std::fprintf(stderr, "svrc %s: %s\nusage: svrc %s\n", command.name, message.c_str(),
               command.usage);
  return kExitUsage;
}

absl::Status WriteFileBytes(const std::string& path, const std::string& bytes) {
  const std::filesystem::path p(path);
  if (p.has_parent_path()) {
    std::error_code ec;
    std::filesystem::create_directories(p.parent_path(), ec);
  }
  const std::string tmp = path + ".part";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!out) return absl::PermissionDeniedError(absl::StrCat("cannot write ", tmp));
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) return absl::PermissionDeniedError(absl::StrCat("cannot rename to ", path, ": ", ec.message()));
  return absl::OkStatus();
}

absl::Status WriteMeshOutput(const mesh::TetMesh& mesh, const std::string& path,
                             int quantization_bits) {
  if (absl::EndsWithIgnoreCase(path, ".svrc")) {
    codec::EncodeOptions options;
    options.position_quantization_bits = quantization_bits;
    absl::StatusOr<std::string> bytes = codec::EncodeTetMesh(mesh, options);
    if (!bytes.ok()) return bytes.status();
    return WriteFileBytes(path, *bytes);
  }
  const std::filesystem::path p(path);
  if (p.has_parent_path()) {
    std::error_code ec;
    std::filesystem::create_directories(p.parent_path(), ec);
  }
  return mesh::WriteMeshFile(mesh, path);
}

bool WarnMinDihedral(const mesh::MeshStats& stats) {
  const double below = stats.Get("min_dihedral.below");
  if (!(below > 0)) return false;
  std::fprintf(stderr,
               "svrc: warning: %.0f tets away from the creases are below min_dihedral %g degrees "
               "(smallest %.4g); the sliver removal is best effort (docs/svrc-design.md section 8 item 69)\n",
               below, stats.Get("min_dihedral.target"), stats.Get("min_dihedral.smallest"));
  return true;
}

ProgressPrinter::ProgressPrinter(bool enabled) : enabled_(enabled), tty_(isatty(2) != 0) {}

ProgressPrinter::~ProgressPrinter() { Done(); }

void ProgressPrinter::Update(const std::string& state, const std::string& phase,
                             uint64_t vertices, uint64_t queue_size, double largest_radius,
                             double target_radius, double elapsed_seconds) {
  if (!enabled_) return;
  std::string text = absl::StrFormat("%-9s %-9s %10d vertices  queue %-8d", state, phase,
                                     vertices, queue_size);
  if (largest_radius > 0) {
    absl::StrAppend(&text, absl::StrFormat("  r %.3g", largest_radius));
    if (target_radius > 0) absl::StrAppend(&text, absl::StrFormat(" -> %.3g", target_radius));
  }
  absl::StrAppend(&text, absl::StrFormat("  %7.1f s", elapsed_seconds));
  if (!tty_) {
    std::fprintf(stderr, "%s\n", text.c_str());
    return;
  }
  // The bar follows the largest pending radius down to the target on a log
  // scale (the refinement's own measure of progress); without a target it
  // only shows that something moves.
  constexpr int kWidth = 24;
  std::string bar(kWidth, ' ');
  if (largest_radius > 0 && first_radius_ <= 0) first_radius_ = largest_radius;
  if (target_radius > 0 && first_radius_ > target_radius && largest_radius > 0) {
    double f = std::log(first_radius_ / largest_radius) / std::log(first_radius_ / target_radius);
    f = std::clamp(f, 0.0, 1.0);
    std::fill(bar.begin(), bar.begin() + static_cast<int>(f * kWidth), '#');
  } else {
    bar[static_cast<int>(elapsed_seconds * 4) % kWidth] = '#';
  }
  std::fprintf(stderr, "\r[%s] %s\x1b[K", bar.c_str(), text.c_str());
  std::fflush(stderr);
  open_line_ = true;
}

void ProgressPrinter::Done() {
  if (open_line_) std::fprintf(stderr, "\n");
  open_line_ = false;
}

}  // namespace svrc::cli
