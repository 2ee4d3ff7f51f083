// svrc-server --listen=HOST:PORT --workers=N --queue-capacity=N --data-dir=DIR
// Prints "listening on HOST:PORT" as the first stdout line once it serves.
// SIGTERM/SIGINT: stop accepting, let running jobs finish within the grace
// period, cancel the rest, exit 0.
#include <signal.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/time/time.h"
#include "core/api.h"
#include "core/util/huge_pages.h"
#include "server/log.h"
#include "server/server.h"

namespace {

constexpr char kUsage[] =
    "usage: svrc-server [--listen=HOST:PORT] [--workers=N] [--queue-capacity=N]\n"
    "                   [--data-dir=DIR] [--retention=DURATION] [--disk-quota-mb=N]\n"
    "                   [--grace-period=DURATION] [--max-upload-mb=N]\n"
    "                   [--tls-cert=PEM --tls-key=PEM [--tls-client-ca=PEM]]\n"
    "                   [--token-file=FILE] [--max-jobs-per-client=N]\n"
    "                   [--max-job-memory-mb=N] [--version]\n"
    "defaults: --listen=127.0.0.1:50051 --workers=2 --queue-capacity=64\n"
    "          --data-dir=./svrc-data --retention=24h --disk-quota-mb=0 (unlimited)\n"
    "          --grace-period=30s --max-upload-mb=2048 --max-jobs-per-client=0 (unlimited)\n"
    "          --max-job-memory-mb=0 (unlimited)\n"
    "          no TLS, no authentication (docs/security.md: do not expose that)\n";

bool ParseFlag(const std::string& arg, const char* name, std::string* value) {
  const std::string prefix = absl::StrCat("--", name, "=");
  if (arg.rfind(prefix, 0) != 0) return false;
  *value = arg.substr(prefix.size());
  return true;
}

int Usage(const std::string& why) {
  std::fprintf(stderr, "svrc-server: %s\n%s", why.c_str(), kUsage);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  // Large arrays go back to the system when a job frees them, whatever size
  // an earlier job freed (core/util/huge_pages.h).
  svrc::util::FixMmapThreshold();
  // The workers' heaps on transparent huge pages only when the operator asks
  // (SVRC_HUGE_PAGES=1; core/util/huge_pages.h): one heap serves every job,
  // and collar jobs ran 1.3-1.8x slower on it (docs/svrc-design.md §8 item 49).
  // Returns only if it did not re-execute.
  if (const char* hp = std::getenv("SVRC_HUGE_PAGES"); hp != nullptr && std::string_view(hp) == "1") {
    svrc::util::ReexecWithHugePageHeap(argv);
  }
  using svrc::server::ServerOptions;
  ServerOptions options;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    std::string v;
    int64_t n = 0;
    absl::Duration d;
    if (arg == "--help" || arg == "-h") {
      std::printf("%s", kUsage);
      return 0;
    } else if (arg == "--version") {
      std::printf("%s\n", svrc::core::Version().c_str());
      return 0;
    } else if (ParseFlag(arg, "listen", &v)) {
      options.listen = v;
    } else if (ParseFlag(arg, "workers", &v)) {
      if (!absl::SimpleAtoi(v, &n) || n < 1 || n > 1024) return Usage("bad --workers " + v);
      options.workers = static_cast<int>(n);
    } else if (ParseFlag(arg, "queue-capacity", &v)) {
      if (!absl::SimpleAtoi(v, &n) || n < 1) return Usage("bad --queue-capacity " + v);
      options.queue_capacity = static_cast<size_t>(n);
    } else if (ParseFlag(arg, "data-dir", &v)) {
      options.data_dir = v;
    } else if (ParseFlag(arg, "retention", &v)) {
      if (!absl::ParseDuration(v, &d) || d <= absl::ZeroDuration()) return Usage("bad --retention " + v);
      options.retention = d;
    } else if (ParseFlag(arg, "grace-period", &v)) {
      if (!absl::ParseDuration(v, &d) || d < absl::ZeroDuration()) return Usage("bad --grace-period " + v);
      options.grace_period = d;
    } else if (ParseFlag(arg, "disk-quota-mb", &v)) {
      if (!absl::SimpleAtoi(v, &n) || n < 0) return Usage("bad --disk-quota-mb " + v);
      options.disk_quota_bytes = static_cast<uint64_t>(n) << 20;
    } else if (ParseFlag(arg, "max-upload-mb", &v)) {
      if (!absl::SimpleAtoi(v, &n) || n < 1) return Usage("bad --max-upload-mb " + v);
      options.max_upload_bytes = static_cast<uint64_t>(n) << 20;
    } else if (ParseFlag(arg, "tls-cert", &v)) {
      options.tls_cert = v;
    } else if (ParseFlag(arg, "tls-key", &v)) {
      options.tls_key = v;
    } else if (ParseFlag(arg, "tls-client-ca", &v)) {
      options.tls_client_ca = v;
    } else if (ParseFlag(arg, "token-file", &v)) {
      options.token_file = v;
    } else if (ParseFlag(arg, "max-job-memory-mb", &v)) {
      if (!absl::SimpleAtoi(v, &n) || n < 0) return Usage("bad --max-job-memory-mb " + v);
      options.max_job_memory_bytes = static_cast<uint64_t>(n) << 20;
    } else if (ParseFlag(arg, "max-jobs-per-client", &v)) {
      if (!absl::SimpleAtoi(v, &n) || n < 0) return Usage("bad --max-jobs-per-client " + v);
      options.max_jobs_per_client = static_cast<int>(n);
    } else {
      return Usage("unknown argument '" + arg + "'");
    }
  }

  // Block the stop signals before any thread starts, then wait for them here.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGTERM);
  sigaddset(&stop_signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);
  signal(SIGPIPE, SIG_IGN);

  absl::StatusOr<std::unique_ptr<svrc::server::Server>> server = svrc::server::Server::Start(options);
  if (!server.ok()) {
    std::fprintf(stderr, "svrc-server: %s\n", std::string(server.status().message()).c_str());
    return 1;
  }
  std::printf("listening on %s\n", (*server)->address().c_str());
  std::fflush(stdout);

  int sig = 0;
  sigwait(&stop_signals, &sig);
  svrc::server::ServerLog().info("received signal {}", sig);
  (*server)->Shutdown();
  return 0;
}
