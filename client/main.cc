// svrc — the command-line tool. Dispatches to the registered subcommands.
// The same main() builds `svrc` (local commands; a remote one is handed to
// svrc-remote, client/remote_commands.h) and `svrc-remote` (every command).
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "client/command.h"
#include "client/remote_commands.h"
#include "core/api.h"
#include "core/util/huge_pages.h"

namespace svrc::cli {

std::vector<Command>& Commands() {
  static std::vector<Command> commands;
  return commands;
}

namespace {

bool Registered(const char* name) {
  for (const Command& c : Commands()) {
    if (std::strcmp(c.name, name) == 0) return true;
  }
  return false;
}

void PrintUsage(FILE* out) {
  std::vector<Command> cmds = Commands();
  for (const RemoteCommandInfo& r : kRemoteCommands) {
    if (!Registered(r.name)) cmds.push_back(Command{r.name, r.usage, nullptr});
  }
  std::sort(cmds.begin(), cmds.end(),
            [](const Command& a, const Command& b) { return std::strcmp(a.name, b.name) < 0; });
  std::fprintf(out, "usage: svrc COMMAND [ARGS]\n\ncommands:\n");
  for (const Command& c : cmds) std::fprintf(out, "  svrc %s\n", c.usage);
  std::fprintf(out, "  svrc --version\n");
}

#ifndef SVRC_CLI_REMOTE_BINARY
// Runs a remote command in svrc-remote: first the one beside this binary,
// then the one on PATH. Returns only when neither could be executed.
int ExecRemote(char** argv) {
  std::vector<std::string> tried;
  char self[4096];
  const ssize_t n = readlink("/proc/self/exe", self, sizeof(self) - 1);
  if (n > 0) {
    std::string path(self, static_cast<size_t>(n));
    const size_t slash = path.rfind('/');
    path = (slash == std::string::npos ? std::string() : path.substr(0, slash + 1)) + kRemoteBinary;
    argv[0] = path.data();
    execv(path.c_str(), argv);
    tried.push_back(path + " (" + std::strerror(errno) + ")");
  }
  argv[0] = const_cast<char*>(kRemoteBinary);
  execvp(kRemoteBinary, argv);
  tried.push_back(std::string(kRemoteBinary) + " on PATH (" + std::strerror(errno) + ")");
  std::string where;
  for (const std::string& t : tried) where += (where.empty() ? "" : ", ") + t;
  std::fprintf(stderr,
               "svrc: '%s' talks to a server and runs in %s, which could not be executed: %s "
               "(it is built with -DSVRC_BUILD_SERVICE=ON and installed beside svrc)\n",
               argv[1], kRemoteBinary, where.c_str());
  return kExitServer;
}
#endif

}  // namespace
}  // namespace svrc::cli

int main(int argc, char** argv) {
  using namespace svrc::cli;
  svrc::util::FixMmapThreshold();  // large arrays go back to the system when freed (core/util/huge_pages.h)
  if (argc < 2) {
    PrintUsage(stderr);
    return kExitUsage;
  }
  const std::string name = argv[1];
  if (name == "--version" || name == "version") {
    std::printf("%s\n", svrc::core::Version().c_str());
    return kExitOk;
  }
  if (name == "--help" || name == "-h" || name == "help") {
    PrintUsage(stdout);
    return kExitOk;
  }
  for (const Command& c : Commands()) {
    if (name == c.name) return c.run(std::vector<std::string>(argv + 2, argv + argc));
  }
#ifndef SVRC_CLI_REMOTE_BINARY  // svrc-remote registers them all: never hand a command back
  if (RemoteUsage(name.c_str()) != nullptr) return ExecRemote(argv);
#endif
  std::fprintf(stderr, "svrc: unknown command '%s' (see svrc --help)\n", name.c_str());
  return kExitUsage;
}
