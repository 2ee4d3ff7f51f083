// The job service without gRPC: a table of jobs, the queue, the workers that
// run core::MeshPlc, progress fanned out to watchers, cancellation through
// core::CancelToken, deadlines, retention. service.cc adapts it to gRPC;
// tests drive it directly. With a Journal, every accepted job survives a
// crash (kill -9) of the server: see Recover() and docs/service.md
// "Persistence". Jobs belong to the client that submitted them (`owner`,
// "" without authentication); another client's job is NOT_FOUND.
// DESIGN.md "Data flow".
#pragma once

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "absl/container/flat_hash_map.h"
#include "absl/random/random.h"
#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "core/api.h"
#include "server/job_queue.h"
#include "server/journal.h"
#include "server/result_store.h"
#include "server/worker_pool.h"
#include "svrc/v1/service.pb.h"

namespace svrc::server {

struct JobManagerOptions {
  int workers = 2;
  // Longest input accepted (bytes of the file or the serialized PLC).
  uint64_t max_input_bytes = uint64_t{2} << 30;
  // Progress events reach watchers at most this often (state changes always).
  absl::Duration progress_interval = absl::Milliseconds(100);
  // Finished jobs and their results are forgotten this long after they end.
  absl::Duration retention = absl::Hours(24);
  // How often queued deadlines and retention are checked.
  absl::Duration janitor_interval = absl::Milliseconds(200);
  // A job that was running when the server died this many times is FAILED
  // at recovery instead of being run again (a job that crashes the server
  // must not crash it forever).
  int max_attempts = 2;
  // The journal is compacted (rewritten as one snapshot per job) after this
  // many appended records.
  uint64_t compact_every = 4096;
  // Queued + running jobs one client may have; 0: unlimited.
  int max_jobs_per_client = 0;
  // Heap bytes one job may hold (accounted per worker thread, see
  // server/memory_accounting.h); 0: unlimited. Over it the job ends
  // FAILED with RESOURCE_EXHAUSTED.
  uint64_t max_job_memory_bytes = 0;
};

class JobManager {
 public:
  // Called with every change of a job, under the manager's lock: it must not
  // block or call back into the manager.
  using Listener = std::function<void(const v1::JobEvent& event)>;

  // With a `journal`, the jobs it holds are recovered first: finished ones
  // are served again, interrupted ones re-queued (or FAILED after
  // max_attempts crashes), and every later change is journaled.
  JobManager(JobManagerOptions options, std::unique_ptr<JobQueue> queue,
             std::unique_ptr<ResultStore> store, std::unique_ptr<Journal> journal = nullptr);
  // Calls Shutdown(zero) if it was not called.
  ~JobManager();

  // Validates the request shape and parameters, then queues the job. The
  // input is moved out of `request`. Same request_id as an earlier job: that
  // job. RESOURCE_EXHAUSTED when the queue is full, UNAVAILABLE when draining.
  // RESOURCE_EXHAUSTED too when `owner` has max_jobs_per_client unfinished
  // jobs. Request ids are per owner.
  absl::StatusOr<v1::Job> Submit(v1::SubmitJobRequest request, const std::string& owner = "");
  absl::StatusOr<v1::Job> Get(const std::string& job_id, const std::string& owner = "");
  absl::StatusOr<v1::ListJobsResponse> List(const v1::ListJobsRequest& request,
                                            const std::string& owner = "");
  absl::StatusOr<v1::Job> Cancel(const std::string& job_id, const std::string& owner = "");
  absl::Status Delete(const std::string& job_id, const std::string& owner = "");

  // Calls `listener` at once with the current state, then on every change
  // until Unsubscribe. Returns the subscription token.
  absl::StatusOr<uint64_t> Subscribe(const std::string& job_id, Listener listener,
                                     const std::string& owner = "");
  void Unsubscribe(const std::string& job_id, uint64_t token);

  // The stored result of a SUCCEEDED job (FAILED_PRECONDITION otherwise).
  absl::StatusOr<StoredResult> Result(const std::string& job_id, const std::string& owner = "");
  ResultStore* store() { return store_.get(); }

  // Stops accepting jobs, cancels the queued ones, lets running jobs finish
  // for up to `grace`, then cancels them and joins the workers.
  void Shutdown(absl::Duration grace);
  bool accepting() const;
  int running() const;

 private:
  struct JobRecord;

  // Functions marked "mu_ held" must be called with mu_ locked (GCC has no
  // thread-safety analysis and std::mutex carries no capability attribute,
  // so this is a comment, not an annotation).

  // The job `job_id` if it exists and belongs to `owner`. mu_ held.
  JobRecord* Find(const std::string& job_id, const std::string& owner);
  // Rebuilds the job table from the journal (constructor, before the workers).
  void Recover();
  // Journal helpers; failures are logged (the in-memory state stays right).
  // mu_ held.
  void JournalAppend(v1::JournalRecord record, bool sync);
  v1::JournalRecord SnapshotOf(const JobRecord& rec) const;  // mu_ held
  void Compact();                                             // mu_ held
  static std::string RequestKey(const std::string& owner, const std::string& request_id);

  void RunJob(const std::string& job_id);
  absl::Status Execute(JobRecord* rec, const v1::SubmitJobRequest& request,
                       StoredResult* stored, v1::ResultInfo* info);
  // Moves a job to a terminal state from `status` and notifies. mu_ held.
  void Finish(JobRecord* rec, const absl::Status& status);
  // Calls the job's listeners with its current state. mu_ held.
  void Notify(JobRecord* rec);
  void OnProgress(JobRecord* rec, const core::Progress& progress);
  // Cancels a running job whose accounted heap exceeds max_job_memory_bytes.
  void CheckMemory(JobRecord* rec);
  void JanitorLoop();

  const JobManagerOptions options_;
  std::unique_ptr<JobQueue> queue_;
  std::unique_ptr<ResultStore> store_;
  std::unique_ptr<Journal> journal_;  // null: nothing survives a restart
  std::string crash_input_name_;  // test hook SVRC_TEST_CRASH_ON_INPUT (docs/service.md)

  // std::mutex, not absl::Mutex: TSan intercepts pthread mutexes and
  // condition variables, while Debian's Abseil is not TSan-built
  // (docs/service.md "TSan"). mu_ guards every field from here to draining_,
  // and every JobRecord in jobs_ except its atomics (memory,
  // memory_exceeded, cancel), which the running worker also reads unlocked.
  mutable std::mutex mu_;
  // Notified (all) whenever running_ drops and when stopped_ is set:
  // Shutdown waits for running_ == 0, the janitor sleeps until stopped_.
  std::condition_variable state_changed_;
  absl::flat_hash_map<std::string, std::unique_ptr<JobRecord>> jobs_;
  std::map<uint64_t, std::string> order_;  // submission seq -> id
  absl::flat_hash_map<std::string, std::string> by_request_id_;
  absl::BitGen bitgen_;
  uint64_t next_seq_ = 1;
  uint64_t next_token_ = 1;
  int running_ = 0;
  bool accepting_ = true;
  bool stopped_ = false;
  bool draining_ = false;  // Shutdown with a journal: jobs stay queued

  std::unique_ptr<WorkerPool> workers_;
  std::thread janitor_;
};

}  // namespace svrc::server
