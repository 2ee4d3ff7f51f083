// util::FixMmapThreshold (core/util/huge_pages.h): with it, a large block is
// mapped on its own even after a larger one was freed; without it glibc's
// dynamic threshold moves up to the freed block's size and the next blocks
// below that come from the main heap (what kept cube 1e-6's RSS 66 MB above
// what it needed, session 45).
#include <malloc.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>

#include "core/util/huge_pages.h"
#include "gtest/gtest.h"

namespace svrc::util {
namespace {

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr bool kOwnAllocator = true;  // the sanitizer's allocator, not glibc's
#else
constexpr bool kOwnAllocator = false;
#endif

// glibc marks a chunk it mapped on its own with bit 1 (IS_MMAPPED) of the
// size word in front of the pointer it returns.
bool Mapped(const void* p) {
  const size_t* q = static_cast<const size_t*>(p) - 1;
  asm volatile("" : "+r"(q));  // opaque to the compiler: the word is malloc's, not uninitialised
  return (*q & 2) != 0;
}

enum class Setup { kNone, kFixed, kFixedWithUserTunable };

// In a child process (the test's own heap stays as it is): frees a mapped
// 24 MB block (below glibc's 32 MiB cap of the dynamic threshold), then
// exits 0 if an 8 MB block is mapped, 1 if it came from the main heap.
int ChildMapsAfterLargeFree(Setup setup) {
  const pid_t pid = fork();
  if (pid == 0) {
    unsetenv("SVRC_MMAP_THRESHOLD");
    if (setup == Setup::kFixedWithUserTunable) {
      setenv("GLIBC_TUNABLES", "glibc.malloc.mmap_threshold=33554432", 1);
    } else {
      unsetenv("GLIBC_TUNABLES");
    }
    if (setup != Setup::kNone) FixMmapThreshold();
    void* big = std::malloc(24u << 20);
    std::memset(big, 1, 4096);
    const bool big_mapped = Mapped(big);
    std::free(big);
    void* p = std::malloc(8u << 20);
    std::memset(p, 1, 4096);
    const bool mapped = Mapped(p);
    std::free(p);
    _exit(!big_mapped ? 2 : mapped ? 0 : 1);
  }
  int status = 0;
  if (waitpid(pid, &status, 0) != pid) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(FixMmapThresholdTest, LargeBlocksStayMappedAfterALargerOneWasFreed) {
  if (kOwnAllocator) GTEST_SKIP() << "glibc's allocator only";
  EXPECT_EQ(ChildMapsAfterLargeFree(Setup::kNone), 1) << "glibc's dynamic threshold (the behaviour fixed)";
  EXPECT_EQ(ChildMapsAfterLargeFree(Setup::kFixed), 0);
  // A user's own glibc.malloc.mmap_threshold is left alone.
  EXPECT_EQ(ChildMapsAfterLargeFree(Setup::kFixedWithUserTunable), 1);
}

}  // namespace
}  // namespace svrc::util
