// The job journal on its own: records round-trip, a torn or corrupt tail is
// dropped (and later appends follow the last good record), compaction
// replaces the log atomically, inputs are stored and removed; and a
// JobManager restarted on the same journal serves its finished jobs.
#include "server/journal.h"

#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include "absl/strings/str_cat.h"
#include "gtest/gtest.h"
#include "server/job_manager.h"
#include "tests/server/service_test_util.h"
#include "tests/test_support.h"

namespace svrc::server {
namespace {

v1::JournalRecord Rec(v1::JournalRecord::Kind kind, const std::string& id, uint32_t attempt = 0) {
  v1::JournalRecord r;
  r.set_kind(kind);
  r.set_job_id(id);
  r.set_attempt(attempt);
  return r;
}

TEST(JournalTest, Crc32cKnownValue) {
  // RFC 3720 B.4 check value of CRC-32C over "123456789".
  EXPECT_EQ(Crc32c("123456789"), 0xE3069283u);
}

TEST(JournalTest, TornAndCorruptTailsAreDroppedAndAppendsContinue) {
  const std::string dir = testing::MakeTempDir("journal");
  {
    auto j = Journal::Open(dir);
    ASSERT_TRUE(j.ok()) << j.status();
    EXPECT_TRUE((*j)->TakeReplayed().empty());
    ASSERT_TRUE((*j)->Append(Rec(v1::JournalRecord::SUBMITTED, "a"), true).ok());
    ASSERT_TRUE((*j)->Append(Rec(v1::JournalRecord::STARTED, "a", 1), true).ok());
  }
  const std::string log = dir + "/journal/journal.log";
  const auto good_size = std::filesystem::file_size(log);
  {
    std::ofstream out(log, std::ios::app | std::ios::binary);
    out.write("SVJ1\x40\x00\x00\x00garbage", 15);  // a torn third record
  }
  {
    auto j = Journal::Open(dir);
    ASSERT_TRUE(j.ok()) << j.status();
    std::vector<v1::JournalRecord> recs = (*j)->TakeReplayed();
    ASSERT_EQ(recs.size(), 2u);
    EXPECT_EQ(recs[1].attempt(), 1u);
    EXPECT_EQ((*j)->dropped_tail_bytes(), 15u);
    EXPECT_EQ(std::filesystem::file_size(log), good_size);
    ASSERT_TRUE((*j)->Append(Rec(v1::JournalRecord::FINISHED, "a"), true).ok());
  }
  {
    // Flip one payload byte of the last record: its CRC no longer matches.
    const auto size = std::filesystem::file_size(log);
    int fd = ::open(log.c_str(), O_RDWR);
    ASSERT_GE(fd, 0);
    char c;
    ASSERT_EQ(::pread(fd, &c, 1, static_cast<off_t>(size - 1)), 1);
    c ^= 0x01;
    ASSERT_EQ(::pwrite(fd, &c, 1, static_cast<off_t>(size - 1)), 1);
    ::close(fd);
    auto j = Journal::Open(dir);
    ASSERT_TRUE(j.ok());
    EXPECT_EQ((*j)->TakeReplayed().size(), 2u);
    EXPECT_GT((*j)->dropped_tail_bytes(), 0u);
    // Compaction replaces everything.
    ASSERT_TRUE((*j)->Rewrite({Rec(v1::JournalRecord::SNAPSHOT, "b", 1)}).ok());
    EXPECT_EQ((*j)->appended_since_rewrite(), 0u);
    ASSERT_TRUE((*j)->Append(Rec(v1::JournalRecord::DELETED, "b"), false).ok());
  }
  auto j = Journal::Open(dir);
  ASSERT_TRUE(j.ok());
  std::vector<v1::JournalRecord> recs = (*j)->TakeReplayed();
  ASSERT_EQ(recs.size(), 2u);
  EXPECT_EQ(recs[0].kind(), v1::JournalRecord::SNAPSHOT);
  EXPECT_EQ(recs[1].kind(), v1::JournalRecord::DELETED);
  // Inputs.
  v1::SubmitJobRequest req;
  req.mutable_file()->set_data(std::string("1 3 0 0\n1 0 0 0\n\0binary", 23));
  ASSERT_TRUE((*j)->PutInput("jx", req).ok());
  absl::StatusOr<v1::SubmitJobRequest> back = (*j)->GetInput("jx");
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->file().data(), req.file().data());
  EXPECT_EQ((*j)->ListInputs(), std::vector<std::string>{"jx"});
  (*j)->DeleteInput("jx");
  EXPECT_EQ((*j)->GetInput("jx").status().code(), absl::StatusCode::kNotFound);
  std::filesystem::remove_all(dir);
}

TEST(JournalTest, ManagerRestartedOnTheJournalServesFinishedJobsAndCompacts) {
  const std::string dir = testing::MakeTempDir("journal_jm");
  JobManagerOptions options;
  options.workers = 1;
  options.compact_every = 3;  // compact several times on the way
  std::string id;
  std::string sha;
  {
    auto store = DiskResultStore::Open(dir, 0);
    auto journal = Journal::Open(dir);
    ASSERT_TRUE(store.ok() && journal.ok());
    JobManager m(options, std::make_unique<InMemoryJobQueue>(8), *std::move(store),
                 *std::move(journal));
    for (int i = 0; i < 4; ++i) {
      v1::SubmitJobRequest r;
      r.set_request_id(absl::StrCat("r", i));
      r.mutable_file()->set_format(v1::NODE);
      r.mutable_file()->set_name("p.node");
      r.mutable_file()->set_data(testing::RandomNodeFile(200, i + 1));
      absl::StatusOr<v1::Job> job = m.Submit(r, "alice");
      ASSERT_TRUE(job.ok()) << job.status();
      id = job->job_id();
    }
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (m.Get(id, "alice")->state() != v1::SUCCEEDED && std::chrono::steady_clock::now() < end) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ASSERT_EQ(m.Get(id, "alice")->state(), v1::SUCCEEDED);
    sha = m.Get(id, "alice")->result().sha256();
    m.Shutdown(absl::Seconds(30));
  }
  auto store = DiskResultStore::Open(dir, 0);
  auto journal = Journal::Open(dir);
  ASSERT_TRUE(store.ok() && journal.ok());
  JobManager m(options, std::make_unique<InMemoryJobQueue>(8), *std::move(store),
               *std::move(journal));
  absl::StatusOr<v1::Job> job = m.Get(id, "alice");
  ASSERT_TRUE(job.ok()) << job.status();
  EXPECT_EQ(job->result().sha256(), sha);
  EXPECT_TRUE(m.Result(id, "alice").ok());
  EXPECT_EQ(m.Get(id, "bob").status().code(), absl::StatusCode::kNotFound);
  absl::StatusOr<v1::ListJobsResponse> list = m.List(v1::ListJobsRequest(), "alice");
  ASSERT_TRUE(list.ok());
  EXPECT_EQ(list->jobs_size(), 4);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace svrc::server
