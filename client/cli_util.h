// Shared pieces of the `svrc` subcommands: argument parsing, the mesh
// parameter flags, exit codes from a status, writing a mesh by extension, and
// the progress display (a bar on a terminal, plain lines otherwise).
#pragma once

#include <cstdio>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "client/command.h"
#include "client/mesh_job.h"
#include "core/mesh/tet_mesh.h"

namespace svrc::cli {

struct Args {
  std::vector<std::string> positional;
  std::map<std::string, std::string> values;  // "--name" or "-o" -> value
  std::set<std::string> switches;             // boolean flags present

  bool Has(const std::string& name) const { return values.count(name) || switches.count(name); }
  std::string Get(const std::string& name, const std::string& fallback = "") const {
    auto it = values.find(name);
    return it == values.end() ? fallback : it->second;
  }
};

// The value flags every mesh-producing command takes (--radius-edge, ...).
const std::vector<std::string>& MeshValueFlags();
// Boolean mesh flags (--keep-bounding-box).
const std::vector<std::string>& MeshSwitches();

// Parses `--name=value`, `--name value`, `-o value` and boolean switches;
// INVALID_ARGUMENT (a usage error) for anything not declared.
absl::StatusOr<Args> ParseArgs(const std::vector<std::string>& argv,
                               const std::vector<std::string>& value_flags,
                               const std::vector<std::string>& switches);

// Mesh parameter flags → MeshOptions (validated).
absl::StatusOr<MeshOptions> MeshOptionsFromArgs(const Args& args);

// Exit status for an error (kExitOk for OK). `job_outcome`: the status ended a
// job (local or remote) rather than an RPC: INVALID_ARGUMENT → 3, CANCELLED /
// DEADLINE_EXCEEDED → 6, anything else → 5. For an RPC: INVALID_ARGUMENT → 3,
// anything else → 4 (server or connection).
int ExitCodeFor(const absl::Status& status, bool job_outcome);

// Prints "svrc: <message>" (one line) to stderr and returns `code`.
int Fail(int code, const std::string& message);
int UsageError(const Command& command, const std::string& message);

// Writes `mesh` to `path`: `.svrc` → the encoded container (with
// `quantization_bits`); .node/.vtu/.msh/.mesh → core/mesh/writers.h.
absl::Status WriteMeshOutput(const mesh::TetMesh& mesh, const std::string& path,
                             int quantization_bits);
// A run with min_dihedral that left tets (away from creases) below it says
// so on stderr: "svrc: warning: ..." from the counters min_dihedral.* of
// core::MeshPlc. Returns whether it printed.
bool WarnMinDihedral(const mesh::MeshStats& stats);
// Writes raw bytes (atomically: temp file + rename).
absl::Status WriteFileBytes(const std::string& path, const std::string& bytes);

// One line per update when stderr is not a terminal; a redrawn bar otherwise.
class ProgressPrinter {
 public:
  explicit ProgressPrinter(bool enabled);
  ~ProgressPrinter();
  void Update(const std::string& state, const std::string& phase, uint64_t vertices,
              uint64_t queue_size, double largest_radius, double target_radius,
              double elapsed_seconds);
  // Ends a bar line.
  void Done();

 private:
  bool enabled_;
  bool tty_;
  bool open_line_ = false;
  double first_radius_ = 0;
};

}  // namespace svrc::cli
