// WorkerPool: N threads run N jobs at once, every queued job runs exactly
// once, and Join returns after the queue closes.
#include "server/worker_pool.h"

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <set>
#include <thread>

#include "gtest/gtest.h"

namespace svrc::server {
namespace {

TEST(WorkerPoolTest, RunsNJobsConcurrently) {
  InMemoryJobQueue q(16);
  std::atomic<int> inside{0}, peak{0};
  std::mutex mu;
  std::condition_variable released;
  bool release = false;
  WorkerPool pool(3, &q, [&](const std::string&) {
    const int now = inside.fetch_add(1) + 1;
    int p = peak.load();
    while (now > p && !peak.compare_exchange_weak(p, now)) {}
    std::unique_lock lock(mu);
    released.wait(lock, [&] { return release; });
    inside.fetch_sub(1);
  });
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(q.Push(std::to_string(i)).ok());
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (pool.busy() < 3 && std::chrono::steady_clock::now() < end) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_EQ(pool.busy(), 3);
  EXPECT_EQ(q.Size(), 2u);  // two wait for a free worker
  {
    std::scoped_lock lock(mu);
    release = true;
  }
  released.notify_all();
  while (q.Size() > 0 || pool.busy() > 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  q.Close();
  pool.Join();
  EXPECT_EQ(peak.load(), 3);
}

TEST(WorkerPoolTest, EveryJobRunsExactlyOnce) {
  InMemoryJobQueue q(1000);
  std::mutex mu;
  std::multiset<std::string> ran;
  {
    WorkerPool pool(4, &q, [&](const std::string& id) {
      std::scoped_lock lock(mu);
      ran.insert(id);
    });
    for (int i = 0; i < 500; ++i) ASSERT_TRUE(q.Push(std::to_string(i)).ok());
    while (q.Size() > 0) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    while (pool.busy() > 0) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    q.Close();
  }  // ~WorkerPool joins
  ASSERT_EQ(ran.size(), 500u);
  for (int i = 0; i < 500; ++i) EXPECT_EQ(ran.count(std::to_string(i)), 1u) << i;
}

}  // namespace
}  // namespace svrc::server
