// JobManager without gRPC: the job life cycle, watchers, idempotent submit,
// validation at submit, cancel of queued and running jobs, delete, paging,
// and shutdown. Results are compared byte for byte with a local run.
#include "server/job_manager.h"
#include "server/memory_accounting.h"

#include <filesystem>
#include <mutex>
#include <thread>

#include "client/mesh_job.h"
#include "core/codec/container.h"
#include "core/plc/readers.h"
#include "core/util/pod_vector.h"
#include "gtest/gtest.h"
#include "tests/server/job_test_util.h"
#include "tests/server/service_test_util.h"
#include "tests/test_support.h"

namespace svrc::server {
namespace {

using testing::NodeRequest;
using testing::WaitTerminal;

std::unique_ptr<JobManager> MakeManager(int workers, size_t capacity, std::string* dir = nullptr) {
  const std::string d = testing::MakeTempDir("manager");
  if (dir) *dir = d;
  auto store = DiskResultStore::Open(d, 0);
  EXPECT_TRUE(store.ok());
  JobManagerOptions options;
  options.workers = workers;
  return std::make_unique<JobManager>(options, std::make_unique<InMemoryJobQueue>(capacity),
                                      *std::move(store));
}



void WaitRunning(JobManager& m, const std::string& id) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < end && m.Get(id)->state() == v1::QUEUED) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_EQ(m.Get(id)->state(), v1::RUNNING);
}

std::string LocalContainer(const std::string& node) {
  absl::StatusOr<plc::Plc> plc = plc::ReadPlcBytes(node, plc::InputFormat::kNode, "points.node");
  EXPECT_TRUE(plc.ok()) << plc.status();
  absl::StatusOr<mesh::TetMesh> mesh = cli::RunMeshing(*plc, cli::MeshOptions(), nullptr, nullptr);
  EXPECT_TRUE(mesh.ok()) << mesh.status();
  absl::StatusOr<std::string> bytes = codec::EncodeTetMesh(*mesh, codec::EncodeOptions());
  EXPECT_TRUE(bytes.ok()) << bytes.status();
  return *bytes;
}

// The per-job heap budget counts util::PodVector's blocks (the refinement's
// largest arrays: Delaunay tets, points, location-graph pools), which come
// from realloc and bypassed the operator new count before session 23.
TEST(JobMemoryTest, PodVectorBlocksCountOnTheJobsThread) {
  if (!MemoryAccountingActive()) GTEST_SKIP() << "the sanitizer owns the allocator";
  JobMemory memory;
  BindThreadMemory(&memory);
  int64_t held = 0;
  {
    util::PodVector<double> v;
    v.resize(1 << 20);  // 8 MiB
    held = memory.bytes.load();
  }
  const int64_t after = memory.bytes.load();
  BindThreadMemory(nullptr);
  EXPECT_GE(held, int64_t{8} << 20);
  EXPECT_GE(memory.peak.load(), int64_t{8} << 20);
  EXPECT_LT(after, int64_t{1} << 20);
}

TEST(JobManagerTest, PointSetJobSucceedsWithTheLocalBytes) {
  auto m = MakeManager(2, 8);
  const std::string node = testing::RandomNodeFile(500, 1);
  absl::StatusOr<v1::Job> job = m->Submit(NodeRequest(node));
  ASSERT_TRUE(job.ok()) << job.status();
  EXPECT_EQ(job->state(), v1::QUEUED);
  EXPECT_EQ(job->input_bytes(), node.size());
  v1::Job done = WaitTerminal(*m, job->job_id());
  ASSERT_EQ(done.state(), v1::SUCCEEDED) << done.error().message();
  EXPECT_EQ(done.result().num_vertices(), 500u);
  EXPECT_GT(done.result().num_tets(), 500u);
  absl::StatusOr<StoredResult> stored = m->Result(job->job_id());
  ASSERT_TRUE(stored.ok()) << stored.status();
  absl::StatusOr<std::string> bytes = m->store()->Read(job->job_id(), 0, stored->size);
  ASSERT_TRUE(bytes.ok());
  EXPECT_EQ(*bytes, LocalContainer(node));
  EXPECT_EQ(done.result().sha256(), stored->sha256);
}

TEST(JobManagerTest, WatchersGetTheCurrentStateFirstThenIncreasingSequences) {
  auto m = MakeManager(1, 8);
  absl::StatusOr<v1::Job> job = m->Submit(NodeRequest(testing::RandomNodeFile(2000, 2)));
  ASSERT_TRUE(job.ok());
  std::mutex mu;
  std::vector<v1::JobEvent> a, b;
  absl::StatusOr<uint64_t> ta = m->Subscribe(job->job_id(), [&](const v1::JobEvent& e) {
    std::scoped_lock l(mu);
    a.push_back(e);
  });
  ASSERT_TRUE(ta.ok());
  absl::StatusOr<uint64_t> tb = m->Subscribe(job->job_id(), [&](const v1::JobEvent& e) {
    std::scoped_lock l(mu);
    b.push_back(e);
  });
  ASSERT_TRUE(tb.ok());
  WaitTerminal(*m, job->job_id());
  // A watcher arriving after the end gets the terminal state at once.
  std::vector<v1::JobEvent> late;
  absl::StatusOr<uint64_t> tl =
      m->Subscribe(job->job_id(), [&](const v1::JobEvent& e) { late.push_back(e); });
  ASSERT_TRUE(tl.ok());
  ASSERT_EQ(late.size(), 1u);
  EXPECT_EQ(late[0].job().state(), v1::SUCCEEDED);
  m->Unsubscribe(job->job_id(), *ta);
  m->Unsubscribe(job->job_id(), *tb);
  m->Unsubscribe(job->job_id(), *tl);
  std::scoped_lock l(mu);
  for (auto* events : {&a, &b}) {
    ASSERT_GE(events->size(), 2u);
    EXPECT_EQ(events->back().job().state(), v1::SUCCEEDED);
    for (size_t i = 1; i < events->size(); ++i) {
      EXPECT_GT((*events)[i].sequence(), (*events)[i - 1].sequence());
    }
  }
}

TEST(JobManagerTest, SameRequestIdReturnsTheSameJob) {
  auto m = MakeManager(1, 8);
  const std::string node = testing::RandomNodeFile(50, 3);
  absl::StatusOr<v1::Job> first = m->Submit(NodeRequest(node, "req-42"));
  absl::StatusOr<v1::Job> again = m->Submit(NodeRequest(node, "req-42"));
  absl::StatusOr<v1::Job> other = m->Submit(NodeRequest(node, "req-43"));
  ASSERT_TRUE(first.ok() && again.ok() && other.ok());
  EXPECT_EQ(first->job_id(), again->job_id());
  EXPECT_NE(first->job_id(), other->job_id());
  EXPECT_EQ(m->List(v1::ListJobsRequest())->jobs_size(), 2);
}

TEST(JobManagerTest, MalformedRequestsAreRejectedAtSubmit) {
  auto m = MakeManager(1, 8);
  v1::SubmitJobRequest none;
  EXPECT_EQ(m->Submit(none).status().code(), absl::StatusCode::kInvalidArgument);
  v1::SubmitJobRequest no_format = NodeRequest("1 3 0 0\n1 0 0 0\n");
  no_format.mutable_file()->set_format(v1::INPUT_FORMAT_UNSPECIFIED);
  EXPECT_EQ(m->Submit(no_format).status().code(), absl::StatusCode::kInvalidArgument);
  v1::SubmitJobRequest bad_param = NodeRequest("1 3 0 0\n1 0 0 0\n");
  bad_param.mutable_parameters()->set_radius_edge(-1);
  absl::Status s = m->Submit(bad_param).status();
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("radius_edge"), absl::string_view::npos) << s;
  v1::SubmitJobRequest bad_bits = NodeRequest("1 3 0 0\n1 0 0 0\n");
  bad_bits.mutable_encoding()->set_quantization_bits(40);
  EXPECT_EQ(m->Submit(bad_bits).status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(m->List(v1::ListJobsRequest())->jobs_size(), 0);
}

TEST(JobManagerTest, RefinementParameterOnAPointSetIsUnimplementedNotIgnored) {
  auto m = MakeManager(1, 8);
  v1::SubmitJobRequest r = NodeRequest(testing::RandomNodeFile(50, 4));
  r.mutable_parameters()->set_max_volume(0.01);
  absl::StatusOr<v1::Job> job = m->Submit(r);
  ASSERT_TRUE(job.ok());
  v1::Job done = WaitTerminal(*m, job->job_id());
  EXPECT_EQ(done.state(), v1::FAILED);
  EXPECT_EQ(done.error().code(), static_cast<int>(absl::StatusCode::kUnimplemented));
  EXPECT_NE(done.error().message().find("max_volume"), std::string::npos);
}

TEST(JobManagerTest, CancelQueuedAtOnceAndRunningSoon) {
  auto m = MakeManager(1, 8);
  absl::StatusOr<v1::Job> big = m->Submit(NodeRequest(testing::RandomNodeFile(300000, 5)));
  absl::StatusOr<v1::Job> small = m->Submit(NodeRequest(testing::RandomNodeFile(20, 6)));
  ASSERT_TRUE(big.ok() && small.ok());
  WaitRunning(*m, big->job_id());
  absl::StatusOr<v1::Job> c = m->Cancel(small->job_id());
  ASSERT_TRUE(c.ok());
  EXPECT_EQ(c->state(), v1::CANCELLED);  // never ran
  EXPECT_EQ(c->start_time().seconds(), 0);
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_TRUE(m->Cancel(big->job_id()).ok());
  v1::Job done = WaitTerminal(*m, big->job_id());
  EXPECT_EQ(done.state(), v1::CANCELLED) << done.error().message();
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
  // Cancelling a finished job changes nothing.
  EXPECT_EQ(m->Cancel(big->job_id())->state(), v1::CANCELLED);
}

TEST(JobManagerTest, DeleteFreesTheResultAndOnlyFinishedJobs) {
  std::string dir;
  auto m = MakeManager(1, 8, &dir);
  absl::StatusOr<v1::Job> job = m->Submit(NodeRequest(testing::RandomNodeFile(30, 7)));
  ASSERT_TRUE(job.ok());
  WaitTerminal(*m, job->job_id());
  EXPECT_TRUE(std::filesystem::exists(dir + "/results/" + job->job_id() + ".svrc"));
  ASSERT_TRUE(m->Delete(job->job_id()).ok());
  EXPECT_FALSE(std::filesystem::exists(dir + "/results/" + job->job_id() + ".svrc"));
  EXPECT_EQ(m->Get(job->job_id()).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(m->Delete(job->job_id()).code(), absl::StatusCode::kNotFound);
}

TEST(JobManagerTest, ListPagesAndFilters) {
  auto m = MakeManager(2, 16);
  std::vector<std::string> ids;
  for (int i = 0; i < 5; ++i) ids.push_back(m->Submit(NodeRequest(testing::RandomNodeFile(20, 10 + i)))->job_id());
  for (const std::string& id : ids) WaitTerminal(*m, id);
  v1::ListJobsRequest req;
  req.set_page_size(2);
  std::vector<std::string> seen;
  int pages = 0;
  do {
    absl::StatusOr<v1::ListJobsResponse> page = m->List(req);
    ASSERT_TRUE(page.ok());
    for (const v1::Job& j : page->jobs()) seen.push_back(j.job_id());
    req.set_page_token(page->next_page_token());
    ++pages;
  } while (!req.page_token().empty());
  EXPECT_EQ(seen, ids);  // submission order
  EXPECT_EQ(pages, 3);
  v1::ListJobsRequest running;
  running.add_states(v1::RUNNING);
  EXPECT_EQ(m->List(running)->jobs_size(), 0);
  v1::ListJobsRequest succeeded;
  succeeded.add_states(v1::SUCCEEDED);
  EXPECT_EQ(m->List(succeeded)->jobs_size(), 5);
}

// Shutdown waits for running jobs on a condition variable (running_ == 0)
// and stops the janitor through another wait: both must be woken, not left
// to time out. Grace and janitor interval are 100 s, so a lost wake-up makes
// Shutdown take >= 100 s; with both notifies it returns when the job ends.
TEST(JobManagerTest, ShutdownReturnsWhenTheRunningJobEndsNotAtTheGraceEnd) {
  const std::string d = testing::MakeTempDir("manager");
  auto store = DiskResultStore::Open(d, 0);
  ASSERT_TRUE(store.ok());
  JobManagerOptions options;
  options.workers = 1;
  options.janitor_interval = absl::Seconds(100);
  JobManager m(options, std::make_unique<InMemoryJobQueue>(4), *std::move(store));
  absl::StatusOr<v1::Job> job = m.Submit(NodeRequest(testing::RandomNodeFile(30000, 20)));
  ASSERT_TRUE(job.ok());
  WaitRunning(m, job->job_id());
  EXPECT_EQ(m.running(), 1);  // (~0.1 s of meshing in release, ~10x that under TSan)
  const auto t0 = std::chrono::steady_clock::now();
  m.Shutdown(absl::Seconds(100));
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(took, 60.0);
  EXPECT_EQ(m.Get(job->job_id())->state(), v1::SUCCEEDED);  // finished within the grace
  EXPECT_EQ(m.running(), 0);
}

TEST(JobManagerTest, ShutdownCancelsQueuedJobsAndRefusesNewOnes) {
  auto m = MakeManager(1, 8);
  absl::StatusOr<v1::Job> big = m->Submit(NodeRequest(testing::RandomNodeFile(300000, 8)));
  absl::StatusOr<v1::Job> queued = m->Submit(NodeRequest(testing::RandomNodeFile(20, 9)));
  ASSERT_TRUE(big.ok() && queued.ok());
  WaitRunning(*m, big->job_id());
  m->Shutdown(absl::Milliseconds(100));  // too short for the big job: it is cancelled
  EXPECT_EQ(m->Get(queued->job_id())->state(), v1::CANCELLED);
  EXPECT_EQ(m->Get(big->job_id())->state(), v1::CANCELLED);
  EXPECT_EQ(m->Submit(NodeRequest("1 3 0 0\n1 0 0 0\n")).status().code(),
            absl::StatusCode::kUnavailable);
}

}  // namespace
}  // namespace svrc::server
