#include "tests/server/service_test_util.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <thread>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "gtest/gtest.h"
#include "tests/test_support.h"

namespace svrc::testing {
namespace {

std::vector<char*> CArgs(const std::vector<std::string>& argv) {
  std::vector<char*> out;
  for (const std::string& a : argv) out.push_back(const_cast<char*>(a.c_str()));
  out.push_back(nullptr);
  return out;
}

int WaitFor(pid_t pid, double timeout_s) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < end) {
    int status = 0;
    pid_t r = waitpid(pid, &status, WNOHANG);
    if (r == pid) return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    if (r < 0) return -1;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return -2;
}

}  // namespace

ServerProcess::ServerProcess(const std::vector<std::string>& extra_args) {
  data_dir_ = MakeTempDir("server_data");
  Start(extra_args, {}, false);
}

ServerProcess::ServerProcess(const std::vector<std::string>& extra_args,
                             const std::string& data_dir, const std::vector<std::string>& env,
                             bool may_die) {
  data_dir_ = data_dir;
  own_data_dir_ = false;
  Start(extra_args, env, may_die);
}

void ServerProcess::Kill9() {
  if (pid_ <= 0) return;
  kill(pid_, SIGKILL);
  waitpid(pid_, nullptr, 0);
  pid_ = -1;
}

bool ServerProcess::WaitKilled(double timeout_s) {
  if (pid_ <= 0) return false;
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < end) {
    int status = 0;
    pid_t r = waitpid(pid_, &status, WNOHANG);
    if (r == pid_) {
      pid_ = -1;
      return WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

void ServerProcess::Start(const std::vector<std::string>& extra_args,
                          const std::vector<std::string>& env, bool may_die) {
  static int restarts = 0;
  log_path_ = data_dir_ + "/../" + std::filesystem::path(data_dir_).filename().string() + "." +
              std::to_string(restarts++) + ".log";
  std::vector<std::string> argv = {SVRC_SERVER_BIN, "--listen=127.0.0.1:0",
                                   "--data-dir=" + data_dir_};
  argv.insert(argv.end(), extra_args.begin(), extra_args.end());
  int pipefd[2];
  if (pipe(pipefd) != 0) {
    ADD_FAILURE() << "pipe: " << std::strerror(errno);
    return;
  }
  pid_ = fork();
  if (pid_ == 0) {
    dup2(pipefd[1], 1);
    int log = open(log_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (log >= 0) dup2(log, 2);
    close(pipefd[0]);
    close(pipefd[1]);
    for (const std::string& e : env) putenv(const_cast<char*>(e.c_str()));
    std::vector<char*> args = CArgs(argv);
    execv(args[0], args.data());
    _exit(127);
  }
  close(pipefd[1]);
  // The first line: "listening on HOST:PORT".
  std::string line;
  pollfd pfd{pipefd[0], POLLIN, 0};
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (line.find('\n') == std::string::npos && std::chrono::steady_clock::now() < end) {
    if (poll(&pfd, 1, 100) > 0) {
      char buf[256];
      ssize_t n = read(pipefd[0], buf, sizeof buf);
      if (n <= 0) break;
      line.append(buf, n);
    }
  }
  close(pipefd[0]);
  const std::string prefix = "listening on ";
  if (line.rfind(prefix, 0) != 0 || line.find('\n') == std::string::npos) {
    if (may_die) return;
    ADD_FAILURE() << "svrc-server did not report its address; stdout: '" << line
                  << "' log: " << Log();
    return;
  }
  address_ = line.substr(prefix.size(), line.find('\n') - prefix.size());
}

ServerProcess::~ServerProcess() {
  if (pid_ > 0 && Terminate(30) == -2) {
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
  std::error_code ec;
  if (own_data_dir_) std::filesystem::remove_all(data_dir_, ec);
  std::filesystem::remove(log_path_, ec);
}

int ServerProcess::Terminate(double timeout_s) {
  if (pid_ <= 0) return -1;
  kill(pid_, SIGTERM);
  const int r = WaitFor(pid_, timeout_s);
  if (r != -2) pid_ = -1;
  return r;
}

std::string ServerProcess::Log() const {
  std::ifstream in(log_path_);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

CommandResult RunCommand(const std::vector<std::string>& argv) {
  CommandResult result;
  const std::string dir = MakeTempDir("cmd");
  const std::string out_path = dir + "/stdout", err_path = dir + "/stderr";
  pid_t pid = fork();
  if (pid == 0) {
    int out = open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    int err = open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(out, 1);
    dup2(err, 2);
    std::vector<char*> args = CArgs(argv);
    execv(args[0], args.data());
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream o(out_path), e(err_path);
  std::stringstream so, se;
  so << o.rdbuf();
  se << e.rdbuf();
  result.out = so.str();
  result.err = se.str();
  std::filesystem::remove_all(dir);
  return result;
}

std::string SvrcCliPath() { return SVRC_CLI_BIN; }

CommandResult RunSvrc(const std::vector<std::string>& args) {
  std::vector<std::string> argv = {SVRC_CLI_BIN};
  argv.insert(argv.end(), args.begin(), args.end());
  return RunCommand(argv);
}

std::string RandomNodeFile(int n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::string out = absl::StrCat(n, " 3 0 0\n");
  out.reserve(static_cast<size_t>(n) * 34);
  for (int i = 0; i < n; ++i) {
    const double x = u(rng), y = u(rng), z = u(rng);
    absl::StrAppend(&out, absl::StrFormat("%d %.6f %.6f %.6f\n", i + 1, x, y, z));
  }
  return out;
}

void WriteFileOrDie(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  ASSERT_TRUE(out.good()) << "cannot write " << path;
}

std::string LastLine(const std::string& text) {
  std::string t = text;
  while (!t.empty() && (t.back() == '\n' || t.back() == '\r')) t.pop_back();
  const size_t nl = t.rfind('\n');
  return nl == std::string::npos ? t : t.substr(nl + 1);
}

}  // namespace svrc::testing
