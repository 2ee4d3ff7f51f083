// Crash recovery against a real svrc-server process: kill -9 with jobs
// finished, running and queued, restart on the same data dir, and check that
// nothing is lost or duplicated, finished results are still served and
// request ids still deduplicate; a job that kills the server twice
// (SVRC_TEST_CRASH_ON_INPUT, docs/service.md) ends FAILED instead of looping.
#include <chrono>
#include <filesystem>
#include <set>
#include <thread>

#include "client/remote_client.h"
#include "core/util/sha256.h"
#include "gtest/gtest.h"
#include "tests/server/job_test_util.h"
#include "tests/server/service_test_util.h"
#include "tests/test_support.h"

namespace svrc {
namespace {

using testing::NodeRequest;
using testing::WaitTerminal;

using cli::RemoteClient;
using testing::ServerProcess;
using Clock = std::chrono::steady_clock;



class DataDir {
 public:
  DataDir() : path_(testing::MakeTempDir("persist")) {}
  ~DataDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

TEST(PersistenceTest, KillNineLosesNothingAndServesFinishedResults) {
  DataDir dir;
  const std::string small = testing::RandomNodeFile(2000, 1);
  std::string done_id, done_bytes;
  std::vector<std::string> pending;  // accepted, not finished at the crash
  {
    ServerProcess server({"--workers=1"}, dir.path());
    ASSERT_TRUE(server.ok());
    RemoteClient c(server.address());
    absl::StatusOr<v1::Job> a = c.Submit(NodeRequest(small, "req-a", "a.node"));
    ASSERT_TRUE(a.ok()) << a.status();
    done_id = a->job_id();
    ASSERT_EQ(WaitTerminal(c, done_id).state(), v1::SUCCEEDED);
    absl::StatusOr<cli::FetchedResult> fetched = c.Fetch(done_id);
    ASSERT_TRUE(fetched.ok()) << fetched.status();
    done_bytes = fetched->bytes;
    // One long job occupies the only worker; three more wait behind it.
    absl::StatusOr<v1::Job> big =
        c.Submit(NodeRequest(testing::RandomNodeFile(300000, 2), "req-big", "big.node"));
    ASSERT_TRUE(big.ok()) << big.status();
    pending.push_back(big->job_id());
    for (int i = 0; i < 3; ++i) {
      absl::StatusOr<v1::Job> j = c.Submit(NodeRequest(testing::RandomNodeFile(1500, 10 + i),
                                                       "req-q" + std::to_string(i), "q.node"));
      ASSERT_TRUE(j.ok()) << j.status();
      pending.push_back(j->job_id());
    }
    const auto t0 = Clock::now();
    while (c.Get(pending[0])->state() != v1::RUNNING &&
           Clock::now() - t0 < std::chrono::seconds(30)) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ASSERT_EQ(c.Get(pending[0])->state(), v1::RUNNING);
    ASSERT_EQ(c.Get(pending[3])->state(), v1::QUEUED);
    server.Kill9();
  }
  ServerProcess server({"--workers=2"}, dir.path());
  ASSERT_TRUE(server.ok());
  RemoteClient c(server.address());
  // The job finished before the crash: same state, same bytes.
  absl::StatusOr<v1::Job> a = c.Get(done_id);
  ASSERT_TRUE(a.ok()) << a.status();
  EXPECT_EQ(a->state(), v1::SUCCEEDED);
  absl::StatusOr<cli::FetchedResult> fetched = c.Fetch(done_id);
  ASSERT_TRUE(fetched.ok()) << fetched.status();
  EXPECT_EQ(fetched->bytes, done_bytes);
  // Its request id still deduplicates.
  absl::StatusOr<v1::Job> again = c.Submit(NodeRequest(small, "req-a", "a.node"));
  ASSERT_TRUE(again.ok()) << again.status();
  EXPECT_EQ(again->job_id(), done_id);
  // Every interrupted job runs to the end; its result is served and intact.
  for (const std::string& id : pending) {
    v1::Job job = WaitTerminal(c, id);
    EXPECT_EQ(job.state(), v1::SUCCEEDED) << id << " " << job.error().message();
    absl::StatusOr<cli::FetchedResult> r = c.Fetch(id);
    ASSERT_TRUE(r.ok()) << r.status();
    EXPECT_EQ(util::Sha256Hex(r->bytes), job.result().sha256());
  }
  EXPECT_EQ(c.Get(pending[0])->result().num_vertices(), 300000u);
  // Nothing lost, nothing duplicated.
  absl::StatusOr<v1::ListJobsResponse> list = c.List(v1::ListJobsRequest());
  ASSERT_TRUE(list.ok()) << list.status();
  std::set<std::string> ids;
  for (const v1::Job& j : list->jobs()) ids.insert(j.job_id());
  EXPECT_EQ(list->jobs_size(), 5);
  EXPECT_EQ(ids.size(), 5u);
  EXPECT_TRUE(ids.count(done_id));
  for (const std::string& id : pending) EXPECT_TRUE(ids.count(id)) << id;
}

TEST(PersistenceTest, JobThatKillsTheServerTwiceEndsFailed) {
  DataDir dir;
  const std::vector<std::string> crash_env = {"SVRC_TEST_CRASH_ON_INPUT=crash.node"};
  {
    ServerProcess server({"--workers=1"}, dir.path(), crash_env);
    ASSERT_TRUE(server.ok());
    RemoteClient c(server.address(), absl::Seconds(5));
    // The reply may or may not arrive before the worker kills the server.
    c.Submit(NodeRequest(testing::RandomNodeFile(100, 3), "req-crash", "crash.node"), 1)
        .IgnoreError();
    ASSERT_TRUE(server.WaitKilled(30)) << "attempt 1 did not crash the server";
  }
  {
    // Recovery re-queues it (attempt 2) and it crashes the server again.
    ServerProcess server({"--workers=1"}, dir.path(), crash_env, /*may_die=*/true);
    ASSERT_TRUE(server.WaitKilled(30)) << "attempt 2 did not crash the server";
  }
  // Third start (the hook still armed): the job is FAILED, not run again.
  ServerProcess server({"--workers=1"}, dir.path(), crash_env);
  ASSERT_TRUE(server.ok());
  RemoteClient c(server.address());
  absl::StatusOr<v1::ListJobsResponse> list = c.List(v1::ListJobsRequest());
  ASSERT_TRUE(list.ok()) << list.status();
  ASSERT_EQ(list->jobs_size(), 1);
  const v1::Job& crashed = list->jobs(0);
  EXPECT_EQ(crashed.state(), v1::FAILED);
  EXPECT_EQ(crashed.error().code(), static_cast<int>(absl::StatusCode::kInternal));
  EXPECT_NE(crashed.error().message().find("died 2 times"), std::string::npos)
      << crashed.error().message();
  // The server is alive and runs the next job.
  absl::StatusOr<v1::Job> next = c.Submit(NodeRequest(testing::RandomNodeFile(500, 4), "", "ok.node"));
  ASSERT_TRUE(next.ok()) << next.status();
  EXPECT_EQ(WaitTerminal(c, next->job_id()).state(), v1::SUCCEEDED);
  EXPECT_EQ(server.Terminate(30), 0);
}

TEST(PersistenceTest, GracefulRestartKeepsQueuedJobsQueued) {
  DataDir dir;
  std::vector<std::string> ids;
  {
    ServerProcess server({"--workers=1", "--grace-period=0s"}, dir.path());
    ASSERT_TRUE(server.ok());
    RemoteClient c(server.address());
    for (int i = 0; i < 3; ++i) {
      absl::StatusOr<v1::Job> j = c.Submit(
          NodeRequest(testing::RandomNodeFile(i == 0 ? 300000 : 1000, 20 + i), "", "g.node"));
      ASSERT_TRUE(j.ok()) << j.status();
      ids.push_back(j->job_id());
    }
    EXPECT_EQ(server.Terminate(60), 0);
  }
  ServerProcess server({"--workers=2"}, dir.path());
  ASSERT_TRUE(server.ok());
  RemoteClient c(server.address());
  for (const std::string& id : ids) {
    v1::Job job = WaitTerminal(c, id);
    EXPECT_EQ(job.state(), v1::SUCCEEDED) << id << " " << job.error().message();
  }
}

}  // namespace
}  // namespace svrc
