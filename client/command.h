// The `svrc` command-line tool: subcommands register themselves here, each in
// its own cmd_*.cc file. Exit status contract (issue #4): 0 success; 2 usage;
// 3 invalid input; 4 server or connection error; 5 job failed; 6 cancelled or
// deadline exceeded — each with a one-line reason on stderr.
#pragma once

#include <string>
#include <vector>

namespace svrc::cli {

enum ExitCode : int {
  kExitOk = 0,
  kExitUsage = 2,
  kExitInvalidInput = 3,
  kExitServer = 4,
  kExitJobFailed = 5,
  kExitCancelled = 6,
};

struct Command {
  const char* name;
  const char* usage;  // one line: "mesh IN -o OUT [--radius-edge X] ..."
  // args excludes the program and command names.
  int (*run)(const std::vector<std::string>& args);
};

std::vector<Command>& Commands();

// Static registration: `static const RegisterCommand kReg{{"mesh", "...", &RunMesh}};`
struct RegisterCommand {
  explicit RegisterCommand(Command c) { Commands().push_back(c); }
};

}  // namespace svrc::cli
