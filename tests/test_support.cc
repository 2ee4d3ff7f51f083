#include "tests/test_support.h"

#include <atomic>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

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

std::string MakeTempDir(const std::string& tag) {
  static std::atomic<int> counter{0};
  const char* base = std::getenv("TEST_TMPDIR");
  std::filesystem::path root = base ? base : std::filesystem::temp_directory_path();
  std::filesystem::path dir =
      root / absl::StrCat("svrc_", tag, "_", getpid(), "_", counter.fetch_add(1));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

}  // namespace svrc::testing
