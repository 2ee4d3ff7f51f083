// Helpers shared by the test suites: where the corpus is, reading files.
// Tests that need ../shared FAIL (never skip) when it is missing.
#pragma once

#include <string>
#include <vector>

namespace svrc::testing {

// Absolute path of a corpus file, e.g. CorpusPath("a_convex/cube.poly").
// Fails the current test (ADD_FAILURE) if the corpus folder is missing.
std::string CorpusPath(const std::string& relative);

// Whole file as bytes; fails the current test if it cannot be read.
std::string ReadFileOrFail(const std::string& path);

// A fresh empty directory under the test temp dir, unique per call. After
// the process's last test it is removed with the "<dir>.<n>.log" files beside
// it, unless a test failed or SVRC_KEEP_TEST_DIRS=1.
std::string MakeTempDir(const std::string& tag);

}  // namespace svrc::testing
