// svrc mesh IN -o OUT [mesh flags]: meshes locally, no server. The same
// pipeline as the server's workers (client/mesh_job.h), so a remote job's
// output is byte-identical to this command's for the same input and flags.
#include <chrono>
#include <filesystem>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "core/mesh/quality.h"
#include "core/mesh/stats_payload.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "client/cli_util.h"
#include "client/command.h"
#include "core/codec/container.h"
#include "core/plc/readers.h"
#include "core/util/huge_pages.h"

namespace svrc::cli {
namespace {

int RunMesh(const std::vector<std::string>& argv);

const Command kMesh{
    "mesh",
    "mesh IN -o OUT [--radius-edge X] [--max-volume V] [--theta T] [--max-rep-angle A] [--collar-size-eps E] "
    "[--collar-cell-test] [--min-dihedral D] [--keep-bounding-box] [--max-vertices N] [--deadline 30s] "
    "[--quantization-bits B] [--quiet] [--stats]   (OUT: .node .vtu .msh .mesh .svrc; --stats: "
    "the run's counters and the mesh quality)",
    &RunMesh};
const RegisterCommand kRegister{kMesh};

// --stats: one "  name value" line per counter, in the mesher's order.
void PrintCounters(const mesh::MeshStats& stats) {
  for (const auto& [name, value] : stats.counters) std::printf("  %-34s %.10g\n", name.c_str(), value);
}

int RunMesh(const std::vector<std::string>& argv) {
  std::vector<std::string> values = MeshValueFlags();
  values.push_back("-o");
  std::vector<std::string> switches = MeshSwitches();
  switches.push_back("--quiet");
  switches.push_back("--stats");
  absl::StatusOr<Args> args = ParseArgs(argv, values, switches);
  if (!args.ok()) return UsageError(kMesh, std::string(args.status().message()));
  if (args->positional.size() != 1) return UsageError(kMesh, "expected one input file");
  const std::string out = args->Get("-o");
  if (out.empty()) return UsageError(kMesh, "missing -o OUT");
  absl::StatusOr<MeshOptions> options = MeshOptionsFromArgs(*args);
  if (!options.ok()) return UsageError(kMesh, std::string(options.status().message()));

  const std::string& in = args->positional[0];
  absl::StatusOr<plc::Plc> plc = plc::ReadPlcFile(in);
  if (!plc.ok()) {
    return Fail(plc.status().code() == absl::StatusCode::kInvalidArgument ||
                        plc.status().code() == absl::StatusCode::kNotFound
                    ? kExitInvalidInput
                    : ExitCodeFor(plc.status(), true),
                std::string(plc.status().message()));
  }
  // A long job off the collar path re-executes this command once with its heap
  // on transparent huge pages (core::HugePageHeapPays, core/util/huge_pages.h;
  // docs/svrc-design.md §8 item 49: a tenth of the page faults, 10–15% less
  // wall time). Small ones do not: the second start-up would double their
  // time; nor collar jobs, which ran 1.3–1.8x slower on it. Nor does an input
  // that is not a regular file (a pipe, /dev/stdin): the new process could not
  // read it again. Returns only if it did not re-execute.
  std::error_code regular_error;
  if (absl::StatusOr<core::MeshParams> params = ToMeshParams(*options);
      params.ok() && std::filesystem::is_regular_file(in, regular_error) && core::HugePageHeapPays(*plc, *params)) {
    std::vector<std::string> words{"svrc", "mesh"};
    words.insert(words.end(), argv.begin(), argv.end());
    std::vector<char*> exec_argv;
    for (std::string& w : words) exec_argv.push_back(w.data());
    exec_argv.push_back(nullptr);
    util::ReexecWithHugePageHeap(exec_argv.data());
  }
  core::CancelToken cancel;
  if (options->deadline > absl::ZeroDuration()) {
    cancel.SetDeadline(std::chrono::steady_clock::now() +
                       absl::ToChronoNanoseconds(options->deadline));
  }
  ProgressPrinter printer(!args->switches.count("--quiet"));
  const auto start = std::chrono::steady_clock::now();
  absl::StatusOr<mesh::TetMesh> mesh = RunMeshing(
      *plc, *options,
      [&](const core::Progress& p) {
        const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        printer.Update("local", p.phase, p.vertices, p.queue_size, p.largest_work_radius,
                       p.target_radius, t);
      },
      &cancel);
  printer.Done();
  if (!mesh.ok()) {
    // A failed run's counters come with its status (core/mesh/stats_payload.h).
    if (args->switches.count("--stats")) {
      if (std::optional<mesh::MeshStats> partial = mesh::StatsOf(mesh.status()); partial.has_value()) {
        std::printf("counters of the failed run:\n");
        PrintCounters(*partial);
      }
    }
    return Fail(ExitCodeFor(mesh.status(), true),
                absl::StrCat(in, ": ", absl::StatusCodeToString(mesh.status().code()), ": ",
                             mesh.status().message()));
  }
  // A quantized container is lossy: write what a remote client would decode
  // from it, so that local and remote outputs stay byte-identical.
  if (options->quantization_bits > 0 && !absl::EndsWithIgnoreCase(out, ".svrc")) {
    codec::EncodeOptions encode;
    encode.position_quantization_bits = options->quantization_bits;
    absl::StatusOr<std::string> bytes = codec::EncodeTetMesh(*mesh, encode);
    if (!bytes.ok()) return Fail(kExitJobFailed, std::string(bytes.status().message()));
    mesh = codec::DecodeTetMesh(*bytes);
    if (!mesh.ok()) return Fail(kExitJobFailed, std::string(mesh.status().message()));
  }
  if (absl::Status s = WriteMeshOutput(*mesh, out, options->quantization_bits); !s.ok()) {
    return Fail(kExitJobFailed, absl::StrCat("cannot write ", out, ": ", s.message()));
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("wrote %s: %zu vertices, %zu tets, %zu boundary triangles in %.3f s\n", out.c_str(),
              mesh->num_vertices(), mesh->num_tets(), mesh->triangles.size(), seconds);
  WarnMinDihedral(mesh->stats);
  if (args->switches.count("--stats")) {
    PrintCounters(mesh->stats);
    std::printf("  %-34s %d\n", "cli.huge_page_heap", util::HugePageHeapRequested() ? 1 : 0);
    std::fputs(mesh::FormatQualityReport(mesh::ComputeQuality(*mesh)).c_str(), stdout);
  }
  return kExitOk;
}

}  // namespace
}  // namespace svrc::cli
