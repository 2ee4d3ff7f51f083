// Helpers for the service tests: a real svrc-server process on a free
// loopback port, running the svrc CLI binary, and generated point sets.
#pragma once

#include <sys/types.h>

#include <string>
#include <vector>

namespace svrc::testing {

// Starts `svrc-server --listen=127.0.0.1:0 --data-dir=<temp> <extra args>`
// and reads the bound address from its first stdout line.
class ServerProcess {
 public:
  explicit ServerProcess(const std::vector<std::string>& extra_args = {});
  // On an existing data dir (a restart); `env` adds NAME=VALUE variables.
  // The dir is left in place (its owner removes it).
  // `may_die`: the process may exit before it reports its address (a test
  // crash hook) without failing the test.
  ServerProcess(const std::vector<std::string>& extra_args, const std::string& data_dir,
                const std::vector<std::string>& env = {}, bool may_die = false);
  // SIGTERM, then SIGKILL if it has not exited after 30 s.
  ~ServerProcess();

  bool ok() const { return !address_.empty(); }
  const std::string& address() const { return address_; }
  const std::string& data_dir() const { return data_dir_; }
  pid_t pid() const { return pid_; }
  // Sends SIGTERM and waits up to `timeout_s`; returns the exit status
  // (-1 on timeout or signal death).
  int Terminate(double timeout_s);
  // SIGKILL, and reaps it.
  void Kill9();
  // Waits up to `timeout_s` for the process to exit on its own; returns true
  // if it died by SIGKILL (a test crash hook), false otherwise.
  bool WaitKilled(double timeout_s);
  // The server's stderr so far (its log).
  std::string Log() const;

 private:
  void Start(const std::vector<std::string>& extra_args, const std::vector<std::string>& env,
             bool may_die);

  pid_t pid_ = -1;
  bool own_data_dir_ = true;
  std::string address_;
  std::string data_dir_;
  std::string log_path_;
};

struct CommandResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

// Runs `argv` (argv[0] a path) with stdout/stderr captured; waits for it.
CommandResult RunCommand(const std::vector<std::string>& argv);
// Runs the svrc CLI binary with `args`.
CommandResult RunSvrc(const std::vector<std::string>& args);
// The svrc CLI binary's path.
std::string SvrcCliPath();

// A TetGen .node file of `n` uniform random points in the unit cube
// (deterministic for a seed, 6 decimals).
std::string RandomNodeFile(int n, unsigned seed);
void WriteFileOrDie(const std::string& path, const std::string& bytes);

// Last non-empty line of `text`.
std::string LastLine(const std::string& text);

}  // namespace svrc::testing
