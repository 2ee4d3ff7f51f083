#include "core/util/huge_pages.h"

#include <malloc.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

namespace svrc::util {

namespace {

constexpr const char* kTunable = "glibc.malloc.hugetlb";

// "always [madvise] never": the bracketed word is the mode.
bool ThpInMadviseMode() {
  std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string line;
  return std::getline(in, line) && line.find("[madvise]") != std::string::npos;
}

// Whether a heap setting of ours is left alone: its switch `env` is "0", or
// the user's GLIBC_TUNABLES already names `tunable`.
bool LeftToTheUser(const char* env, const char* tunable) {
  const char* off = std::getenv(env);
  if (off != nullptr && std::strcmp(off, "0") == 0) return true;
  const char* current = std::getenv("GLIBC_TUNABLES");
  return current != nullptr && std::strstr(current, tunable) != nullptr;
}

}  // namespace

void ReexecWithHugePageHeap(char** argv) {
  if (LeftToTheUser("SVRC_HUGE_PAGES", kTunable) || !ThpInMadviseMode()) return;
  const char* current = std::getenv("GLIBC_TUNABLES");
  const std::string saved = current != nullptr ? current : "";
  const std::string value =
      (current != nullptr && *current != '\0' ? saved + ":" : std::string()) + kTunable + "=1";
  if (setenv("GLIBC_TUNABLES", value.c_str(), 1) != 0) return;
  execv("/proc/self/exe", argv);
  // exec failed (no /proc, say): go on as we are.
  if (current != nullptr) {
    setenv("GLIBC_TUNABLES", saved.c_str(), 1);
  } else {
    unsetenv("GLIBC_TUNABLES");
  }
}

void FixMmapThreshold() {
  if (LeftToTheUser("SVRC_MMAP_THRESHOLD", "glibc.malloc.mmap_threshold")) return;
  mallopt(M_MMAP_THRESHOLD, kMmapThreshold);
}

bool HugePageHeapRequested() {
  const char* current = std::getenv("GLIBC_TUNABLES");
  return current != nullptr && std::strstr(current, "glibc.malloc.hugetlb=1") != nullptr;
}

}  // namespace svrc::util
