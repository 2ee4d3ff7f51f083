#include "tests/test_support.h"

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <string_view>
#include <system_error>
#include <unistd.h>
#include <vector>

#include "absl/strings/str_cat.h"
#include "gtest/gtest.h"

namespace svrc::testing {

std::string CorpusPath(const std::string& relative) {
  const std::filesystem::path dir(SVRC_CORPUS_DIR);
  if (!std::filesystem::exists(dir / "MANIFEST.csv")) {
    ADD_FAILURE() << "corpus not found at " << dir
                  << " (clone ../shared beside the checkout)";
  }
  return (dir / relative).string();
}

std::string ReadFileOrFail(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    ADD_FAILURE() << "cannot read " << path;
    return {};
  }
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

namespace {

// The directories MakeTempDir handed out in this process.
struct TempDirs {
  std::mutex mu;
  std::vector<std::filesystem::path> dirs;
};

TempDirs& Registry() {
  static TempDirs* r = new TempDirs;  // never destroyed: read by the environment's TearDown
  return *r;
}

// After the last test of the process: when every test passed, removes the
// directories and the files beside them named after them (the servers' logs,
// "<dir>.<n>.log"); when one failed, keeps them all for reading and says
// where they are. SVRC_KEEP_TEST_DIRS=1 keeps them either way.
class RemoveTempDirs : public ::testing::Environment {
 public:
  void TearDown() override {
    TempDirs& r = Registry();
    std::lock_guard<std::mutex> lock(r.mu);
    if (r.dirs.empty()) return;
    const char* keep = std::getenv("SVRC_KEEP_TEST_DIRS");
    if (!::testing::UnitTest::GetInstance()->Passed() || (keep != nullptr && std::string_view(keep) == "1")) {
      std::fprintf(stderr, "kept %zu test directories, e.g. %s\n", r.dirs.size(), r.dirs.front().c_str());
      return;
    }
    for (const std::filesystem::path& d : r.dirs) {
      std::error_code ec;
      std::filesystem::remove_all(d, ec);
      const std::string prefix = d.filename().string() + ".";
      for (const auto& e : std::filesystem::directory_iterator(d.parent_path(), ec)) {
        const std::string name = e.path().filename().string();
        if (name.size() > prefix.size() && name.compare(0, prefix.size(), prefix) == 0 &&
            name.ends_with(".log")) {
          std::filesystem::remove(e.path(), ec);
        }
      }
    }
    r.dirs.clear();
  }
};

// Registered before main runs RUN_ALL_TESTS (gtest allows it from a static
// initializer); linked into every test binary that calls MakeTempDir.
[[maybe_unused]] ::testing::Environment* const kRemoveTempDirs =
    ::testing::AddGlobalTestEnvironment(new RemoveTempDirs);

}  // namespace

std::string MakeTempDir(const std::string& tag) {
  static std::atomic<int> counter{0};
  const char* base = std::getenv("TEST_TMPDIR");
  std::filesystem::path root = base ? base : std::filesystem::temp_directory_path();
  std::filesystem::path dir =
      root / absl::StrCat("svrc_", tag, "_", getpid(), "_", counter.fetch_add(1));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  {
    TempDirs& r = Registry();
    std::lock_guard<std::mutex> lock(r.mu);
    r.dirs.push_back(dir);
  }
  return dir.string();
}

}  // namespace svrc::testing
