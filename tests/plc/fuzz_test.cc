// Reader fuzzing with a fixed seed: truncated, byte-flipped and token-spliced
// variants of every corpus file must give OK or INVALID_ARGUMENT (never a
// crash, hang or other code), quickly; OK results must survive validation.
#include <chrono>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "core/plc/readers.h"
#include "core/plc/validate.h"
#include "gtest/gtest.h"
#include "tests/test_support.h"

namespace svrc::plc {
namespace {

using Clock = std::chrono::steady_clock;

std::vector<std::string> CorpusFiles() {
  std::vector<std::string> files;
  const std::filesystem::path root(svrc::testing::CorpusPath(""));
  for (const auto& dir : std::filesystem::directory_iterator(root)) {
    if (!dir.is_directory()) continue;
    for (const auto& f : std::filesystem::directory_iterator(dir.path())) {
      if (FormatFromPath(f.path().string()).ok()) files.push_back(f.path().string());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::string Mutate(const std::string& in, std::mt19937& rng) {
  std::string s = in;
  if (s.empty()) return s;
  auto pos = [&](size_t n) { return std::uniform_int_distribution<size_t>(0, n - 1)(rng); };
  static const char* kTokens[] = {"nan", "-1", "99999999999", "1e999", "-inf", "0", "#",
                                  "\n", "  ", "1.5.5", "\x00", "\xff\xfe", "4294967297", "+"};
  switch (std::uniform_int_distribution<int>(0, 3)(rng)) {
    case 0:  // truncate
      s.resize(pos(s.size()));
      break;
    case 1: {  // flip 1-8 bytes
      const int n = std::uniform_int_distribution<int>(1, 8)(rng);
      for (int i = 0; i < n; ++i) s[pos(s.size())] = static_cast<char>(rng() & 0xff);
      break;
    }
    case 2: {  // splice a token
      const char* t = kTokens[pos(sizeof(kTokens) / sizeof(kTokens[0]))];
      s.insert(pos(s.size()), std::string(t, t[0] ? std::strlen(t) : 1));
      break;
    }
    default: {  // duplicate or delete a chunk
      const size_t a = pos(s.size()), len = std::min<size_t>(s.size() - a, 1 + pos(64));
      if (rng() & 1) s.erase(a, len);
      else s.insert(a, s.substr(a, len));
      break;
    }
  }
  return s;
}

TEST(ReaderFuzz, MutatedCorpusFilesNeverCrash) {
  std::mt19937 rng(20261120);
  size_t ok = 0, invalid = 0, validated = 0;
  double worst = 0;
  std::string worst_case;
  for (const std::string& path : CorpusFiles()) {
    const std::string bytes = svrc::testing::ReadFileOrFail(path);
    const InputFormat format = *FormatFromPath(path);
    // Small files get many variants; the big surfaces a few (ASan budget).
    const int n = bytes.size() < 20000 ? 40 : (bytes.size() < 500000 ? 3 : 1);
    for (int i = 0; i < n; ++i) {
      const std::string variant = Mutate(bytes, rng);
      const auto t0 = Clock::now();
      absl::StatusOr<Plc> plc = ReadPlcBytes(variant, format, std::filesystem::path(path).filename().string());
      ASSERT_TRUE(plc.ok() || plc.status().code() == absl::StatusCode::kInvalidArgument)
          << path << " variant " << i << ": " << plc.status();
      if (plc.ok()) {
        ++ok;
        if (plc->vertices.size() <= 2000) {
          ValidationReport report;
          absl::StatusOr<FeatureComplex> fc = PreparePlc(*plc, {}, {}, &report);
          ASSERT_TRUE(fc.ok() || fc.status().code() == absl::StatusCode::kInvalidArgument)
              << path << " variant " << i << ": " << fc.status();
          EXPECT_EQ(fc.ok(), report.ok());
          ++validated;
        }
      } else {
        ++invalid;
        // Every reader error names the input and a line.
        EXPECT_NE(plc.status().message().find(std::filesystem::path(path).filename().string() + ":"),
                  std::string::npos)
            << plc.status();
      }
      const double secs = std::chrono::duration<double>(Clock::now() - t0).count();
      if (secs > worst) {
        worst = secs;
        worst_case = path + " variant " + std::to_string(i);
      }
    }
  }
  EXPECT_GT(ok, 0u);
  EXPECT_GT(invalid, 0u);
  EXPECT_LT(worst, 10.0) << worst_case;  // generous for sanitizer builds
  std::printf("fuzz: %zu OK (%zu validated), %zu INVALID_ARGUMENT, slowest %.3f s (%s)\n", ok,
              validated, invalid, worst, worst_case.c_str());
}

TEST(ReaderFuzz, HugeCountsDoNotAllocate) {
  // Counts far beyond the bytes present must fail fast, not reserve memory.
  // The last two end without a line ending (regression: the bytes left
  // after the last line wrapped around and the reservation cap vanished).
  const std::string cases[] = {
      "2000000000 3 0 0\n1 0 0 0\n",
      "OFF\n2000000000 2000000000 0\n0 0 0\n",
      "MeshVersionFormatted 1\nDimension 3\nVertices\n2000000000\n0 0 0 0\n",
      "2000000000 3 0 0",
      "OFF\n2000000000 2000000000 0",
  };
  const InputFormat formats[] = {InputFormat::kPoly, InputFormat::kOff, InputFormat::kMedit,
                                 InputFormat::kPoly, InputFormat::kOff};
  for (int i = 0; i < 5; ++i) {
    const auto t0 = Clock::now();
    absl::StatusOr<Plc> plc = ReadPlcBytes(cases[i], formats[i], "huge");
    EXPECT_EQ(plc.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_LT(std::chrono::duration<double>(Clock::now() - t0).count(), 1.0);
  }
  // A binary STL header claiming more triangles than the bytes hold is not
  // binary; it is then rejected as ASCII.
  std::string stl(84, '\0');
  stl[80] = '\x10';
  stl[81] = '\x27';
  EXPECT_EQ(ReadPlcBytes(stl, InputFormat::kStl, "h.stl").status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace svrc::plc
