#include "core/api.h"

#include <thread>

#include "gtest/gtest.h"

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

TEST(VersionTest, NamesTheProject) { EXPECT_EQ(Version().rfind("svrc ", 0), 0u); }

}  // namespace
}  // namespace svrc::core
