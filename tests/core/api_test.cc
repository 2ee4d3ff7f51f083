#include "core/api.h"

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <string>
#include <thread>

#include "core/plc/readers.h"
#include "gtest/gtest.h"
#include "tests/test_support.h"

namespace svrc::core {
namespace {

TEST(CancelTokenTest, ReportsCancelAndDeadline) {
  CancelToken token;
  EXPECT_TRUE(token.Check().ok());
  token.Cancel();
  EXPECT_EQ(token.Check().code(), absl::StatusCode::kCancelled);

  CancelToken timed(std::chrono::steady_clock::now() + std::chrono::milliseconds(5));
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(timed.Check().code(), absl::StatusCode::kDeadlineExceeded);
}

// The process's address space (VmSize), bytes.
uint64_t AddressSpaceBytes() {
  std::ifstream in("/proc/self/status");
  std::string key;
  while (in >> key) {
    if (key == "VmSize:") {
      uint64_t kb = 0;
      in >> kb;
      return kb * 1024;
    }
  }
  return 0;
}

// An allocation that fails ends the job with RESOURCE_EXHAUSTED, not the
// process (two facets at 0.1° under a 13 GB limit died of an uncaught
// std::bad_alloc, SIGABRT). In a child process whose address space may grow
// by 300 MB: a job needing gigabytes, ahead of its vertex budget.
TEST(MeshPlcTest, OutOfMemoryIsAnErrorNotACrash) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  GTEST_SKIP() << "sanitizers reserve the address space themselves";
#endif
  absl::StatusOr<plc::Plc> plc = plc::ReadPlcFile(testing::CorpusPath("a_convex/cube.poly"));
  ASSERT_TRUE(plc.ok()) << plc.status();
  MeshParams params;
  params.max_volume = 1e-8;  // ~10^8 tets
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const rlim_t cap = AddressSpaceBytes() + (300u << 20);
    const rlimit lim{cap, cap};
    if (setrlimit(RLIMIT_AS, &lim) != 0) _exit(10);
    const absl::StatusOr<mesh::TetMesh> m = MeshPlc(*plc, params);
    if (m.ok()) _exit(11);
    if (m.status().code() != absl::StatusCode::kResourceExhausted) _exit(12);
    if (m.status().message().find("out of memory") == std::string_view::npos) _exit(13);
    _exit(0);
  }
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status)) << "the child died of signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  EXPECT_EQ(WEXITSTATUS(status), 0) << "10: setrlimit, 11: meshed, 12: another code, 13: another message";
}

TEST(VersionTest, NamesTheProject) { EXPECT_EQ(Version().rfind("svrc ", 0), 0u); }

}  // namespace
}  // namespace svrc::core
