// The commands that talk to a server: their names and usage lines, shared by
// the two CLI binaries. `svrc` holds the local commands only (mesh,
// validate): it links no gRPC, Protobuf or TLS library, which made it start
// in 3 ms instead of 10 (59 shared libraries and ~18k symbol bindings; bench/
// RESULTS.md "Session 16"). For one of these commands it executes
// `svrc-remote` (all commands, cmd_remote.cc) with the same arguments.
#pragma once

#include <cstring>

namespace svrc::cli {

struct RemoteCommandInfo {
  const char* name;
  const char* usage;
};

inline constexpr RemoteCommandInfo kRemoteCommands[] = {
    {"submit",
     "submit IN [--server HOST:PORT] [--watch] [-o OUT] [--request-id ID] [mesh flags as for "
     "`svrc mesh`]   (prints the job id; --watch shows progress; -o waits and writes the result)"},
    {"watch", "watch ID [--server HOST:PORT] [-o OUT]"},
    {"get", "get ID [--server HOST:PORT] [-o OUT]   (without -o: the job's state)"},
    {"cancel", "cancel ID [--server HOST:PORT]"},
    {"delete", "delete ID [--server HOST:PORT]   (forgets a finished job and its result)"},
    {"list", "list [--server HOST:PORT] [--state QUEUED,RUNNING,...] [--page-size N]"},
    {"health", "health [--server HOST:PORT] [--tls-ca PEM] [--token-file F]   (exit 0 only when SERVING)"},
};

// The usage line of remote command `name`; nullptr when it is not one.
inline const char* RemoteUsage(const char* name) {
  for (const RemoteCommandInfo& c : kRemoteCommands) {
    if (std::strcmp(c.name, name) == 0) return c.usage;
  }
  return nullptr;
}

// The binary that runs the remote commands, next to the `svrc` binary.
inline constexpr const char* kRemoteBinary = "svrc-remote";

}  // namespace svrc::cli
