// Replays, through the libFuzzer targets' own bodies (fuzz_bodies.h), every
// committed crasher under tests/fuzz/regressions/<target>/ and every seed
// from the corpus: each must keep every contract (no crash, no sanitizer
// report — this suite runs under ASan/UBSan in CI — only the allowed status
// codes, lossless re-encoding of what decodes) within a time bound.
#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include "core/codec/container.h"
#include "gtest/gtest.h"
#include "tests/fuzz/fuzz_bodies.h"
#include "tests/test_support.h"

namespace svrc::fuzz {
namespace {

using Clock = std::chrono::steady_clock;

// libFuzzer runs with -timeout=5; a replayed input gets the same budget
// (sanitized build) plus 5 s per MB for the big corpus surfaces.
double BudgetSeconds(size_t bytes) { return 5.0 + 5.0 * static_cast<double>(bytes) / 1e6; }

void ExpectKeepsContracts(Target target, const std::string& label, const std::string& bytes) {
  const auto t0 = Clock::now();
  const std::string err = RunOne(target, bytes);
  const double secs = std::chrono::duration<double>(Clock::now() - t0).count();
  EXPECT_EQ(err, "") << TargetName(target) << " on " << label;
  EXPECT_LT(secs, BudgetSeconds(bytes.size())) << TargetName(target) << " on " << label;
}

std::string RegressionDir(Target target) {
  return std::string(SVRC_SOURCE_DIR) + "/tests/fuzz/regressions/" + std::string(TargetName(target));
}

std::vector<std::string> FilesIn(const std::string& dir) {
  std::vector<std::string> files;
  if (!std::filesystem::is_directory(dir)) return files;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    if (e.is_regular_file()) files.push_back(e.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::string ReferenceContainer() {
  return svrc::testing::ReadFileOrFail(std::string(SVRC_SOURCE_DIR) +
                                       "/tests/codec/data/reference_v1.svrc");
}

class FuzzReplay : public ::testing::TestWithParam<Target> {};

TEST_P(FuzzReplay, CommittedRegressions) {
  for (const std::string& path : FilesIn(RegressionDir(GetParam()))) {
    ExpectKeepsContracts(GetParam(), path, svrc::testing::ReadFileOrFail(path));
  }
}

TEST_P(FuzzReplay, CorpusSeeds) {
  const Target target = GetParam();
  if (target == Target::kDecode || target == Target::kDecodeRehash) {
    const std::string ref = ReferenceContainer();
    ASSERT_TRUE(codec::DecodeTetMesh(ref).ok()) << "the reference container must decode";
    ExpectKeepsContracts(target, "reference_v1.svrc", ref);
    // Every corpus file is garbage to the decoder: rejected, never a crash.
    for (const std::string& path : SeedFiles(Target::kValidate, svrc::testing::CorpusPath(""))) {
      ExpectKeepsContracts(target, path, svrc::testing::ReadFileOrFail(path));
    }
    return;
  }
  const std::vector<std::string> seeds = SeedFiles(target, svrc::testing::CorpusPath(""));
  if (target != Target::kNode && target != Target::kMedit) {
    // The corpus has no .node or .mesh files; every other reader has seeds.
    EXPECT_FALSE(seeds.empty()) << TargetName(target);
  }
  for (const std::string& path : seeds) {
    ExpectKeepsContracts(target, path,
                         SeedBytes(target, path, svrc::testing::ReadFileOrFail(path)));
  }
}

INSTANTIATE_TEST_SUITE_P(AllTargets, FuzzReplay, ::testing::ValuesIn(kAllTargets),
                         [](const ::testing::TestParamInfo<Target>& info) {
                           return std::string(TargetName(info.param));
                         });

}  // namespace
}  // namespace svrc::fuzz
