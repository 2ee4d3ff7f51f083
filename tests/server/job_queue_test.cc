// JobQueue: bounded FIFO, RESOURCE_EXHAUSTED when full, Remove, Close wakes
// blocked Pop() callers and hands back what was still queued.
#include "server/job_queue.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>

#include "gtest/gtest.h"

namespace svrc::server {
namespace {

TEST(InMemoryJobQueueTest, FifoAndCapacity) {
  InMemoryJobQueue q(2);
  ASSERT_TRUE(q.Push("a").ok());
  ASSERT_TRUE(q.Push("b").ok());
  absl::Status full = q.Push("c");
  EXPECT_EQ(full.code(), absl::StatusCode::kResourceExhausted);
  EXPECT_EQ(q.Size(), 2u);
  EXPECT_EQ(q.Pop(), "a");
  ASSERT_TRUE(q.Push("c").ok());  // room again
  EXPECT_EQ(q.Pop(), "b");
  EXPECT_EQ(q.Pop(), "c");
  EXPECT_EQ(q.Size(), 0u);
}

TEST(InMemoryJobQueueTest, RemoveTakesOutOnlyQueuedIds) {
  InMemoryJobQueue q(4);
  ASSERT_TRUE(q.Push("a").ok());
  ASSERT_TRUE(q.Push("b").ok());
  ASSERT_TRUE(q.Push("c").ok());
  EXPECT_TRUE(q.Remove("b"));
  EXPECT_FALSE(q.Remove("b"));
  EXPECT_FALSE(q.Remove("zzz"));
  EXPECT_EQ(q.Pop(), "a");
  EXPECT_EQ(q.Pop(), "c");
}

TEST(InMemoryJobQueueTest, CloseWakesPoppersAndReturnsTheRest) {
  InMemoryJobQueue q(4);
  std::atomic<int> woke{0};
  std::vector<std::thread> poppers;
  for (int i = 0; i < 3; ++i) {
    poppers.emplace_back([&] {
      if (!q.Pop().has_value()) woke.fetch_add(1);
    });
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_EQ(woke.load(), 0);  // blocked: nothing queued
  std::vector<std::string> rest = q.Close();
  EXPECT_TRUE(rest.empty());
  for (std::thread& t : poppers) t.join();
  EXPECT_EQ(woke.load(), 3);
  EXPECT_EQ(q.Push("x").code(), absl::StatusCode::kUnavailable);
}

// Pop() waits on a condition variable: every Push must wake a blocked Pop
// (a missing notify leaves the id queued and the popper asleep).
TEST(InMemoryJobQueueTest, EachPushWakesABlockedPop) {
  InMemoryJobQueue q(8);
  std::mutex mu;
  std::vector<std::string> got;
  std::vector<std::thread> poppers;
  for (int i = 0; i < 3; ++i) {
    poppers.emplace_back([&] {
      std::optional<std::string> id = q.Pop();
      std::scoped_lock lock(mu);
      got.push_back(id.value_or("<closed>"));
    });
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(50));  // all three blocked
  for (const char* id : {"a", "b", "c"}) {
    ASSERT_TRUE(q.Push(id).ok());
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  for (;;) {
    {
      std::scoped_lock lock(mu);
      if (got.size() == 3 || std::chrono::steady_clock::now() > end) break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  q.Close();  // frees any popper a lost wake-up left behind, so the joins end
  for (std::thread& t : poppers) t.join();
  std::sort(got.begin(), got.end());
  EXPECT_EQ(got, (std::vector<std::string>{"a", "b", "c"}));
}

TEST(InMemoryJobQueueTest, CloseHandsBackQueuedIdsInOrder) {
  InMemoryJobQueue q(4);
  ASSERT_TRUE(q.Push("a").ok());
  ASSERT_TRUE(q.Push("b").ok());
  EXPECT_EQ(q.Close(), (std::vector<std::string>{"a", "b"}));
  EXPECT_FALSE(q.Pop().has_value());
}

}  // namespace
}  // namespace svrc::server
