// svrc — the command-line tool. Dispatches to the registered subcommands.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "client/command.h"
#include "core/api.h"

namespace svrc::cli {

std::vector<Command>& Commands() {
  static std::vector<Command> commands;
  return commands;
}

namespace {

void PrintUsage(FILE* out) {
  std::vector<Command> cmds = Commands();
  std::sort(cmds.begin(), cmds.end(),
            [](const Command& a, const Command& b) { return std::strcmp(a.name, b.name) < 0; });
  std::fprintf(out, "usage: svrc COMMAND [ARGS]\n\ncommands:\n");
  for (const Command& c : cmds) std::fprintf(out, "  svrc %s\n", c.usage);
  std::fprintf(out, "  svrc --version\n");
}

}  // namespace
}  // namespace svrc::cli

int main(int argc, char** argv) {
  using namespace svrc::cli;
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
  std::fprintf(stderr, "svrc: unknown command '%s' (see svrc --help)\n", name.c_str());
  return kExitUsage;
}
