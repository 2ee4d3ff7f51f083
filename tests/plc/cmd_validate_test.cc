// `svrc validate IN`: exit codes and the printed summary (the command is
// compiled into this test; Commands() is normally defined by client/main.cc).
#include <string>
#include <vector>

#include "client/command.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/test_support.h"

namespace svrc::cli {
std::vector<Command>& Commands() {
  static std::vector<Command> commands;
  return commands;
}
}  // namespace svrc::cli

namespace svrc::plc {
namespace {

using ::testing::HasSubstr;

int RunValidateCmd(const std::vector<std::string>& args, std::string* out) {
  for (const cli::Command& c : cli::Commands()) {
    if (std::string(c.name) == "validate") {
      ::testing::internal::CaptureStdout();
      const int rc = c.run(args);
      *out = ::testing::internal::GetCapturedStdout();
      return rc;
    }
  }
  ADD_FAILURE() << "validate is not registered";
  return -1;
}

TEST(CmdValidate, ExitCodesAndSummary) {
  std::string out;
  EXPECT_EQ(RunValidateCmd({}, &out), cli::kExitUsage);
  EXPECT_EQ(RunValidateCmd({"a", "b"}, &out), cli::kExitUsage);
  EXPECT_EQ(RunValidateCmd({"--bogus"}, &out), cli::kExitUsage);
  EXPECT_EQ(RunValidateCmd({"/nonexistent/x.poly"}, &out), cli::kExitUsage);

  EXPECT_EQ(RunValidateCmd({svrc::testing::CorpusPath("c_creases/wedge-1.smesh")}, &out), cli::kExitOk);
  EXPECT_THAT(out, HasSubstr("vertices   6\n"));
  EXPECT_THAT(out, HasSubstr("facets     5 (5 polygons"));
  EXPECT_THAT(out, HasSubstr("creases    2 segments, 4 vertices"));
  EXPECT_THAT(out, HasSubstr("sharpest   0.99"));  // the 1° wedge, seen from its apex (session 51)
  EXPECT_THAT(out, HasSubstr("spread     81.05"));
  EXPECT_THAT(out, HasSubstr("VALID\n"));

  EXPECT_EQ(RunValidateCmd({svrc::testing::CorpusPath("g_bad/bad_selfint_two_cubes.poly"), "-q"}, &out),
            cli::kExitInvalidInput);
  EXPECT_THAT(out, HasSubstr("error: bad_selfint_two_cubes.poly: 6 pairs of facets intersect"));
  EXPECT_THAT(out, HasSubstr("INVALID (1 errors)"));

  EXPECT_EQ(RunValidateCmd({svrc::testing::CorpusPath("g_bad/bad_truncated.poly"), "-q"}, &out),
            cli::kExitInvalidInput);
  EXPECT_THAT(out, HasSubstr("INVALID: bad_truncated.poly:18: unexpected end of file"));
}

}  // namespace
}  // namespace svrc::plc
