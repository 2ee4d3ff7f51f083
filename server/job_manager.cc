#include "server/job_manager.h"

#include <signal.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <mutex>
#include <optional>
#include <utility>
#include <vector>

#include "absl/random/random.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/codec/container.h"
#include "core/mesh/stats_payload.h"
#include "core/plc/readers.h"
#include "google/protobuf/util/time_util.h"
#include "proto/convert.h"
#include "server/log.h"
#include "server/memory_accounting.h"
#include "server/status_util.h"

namespace svrc::server {
namespace {

using google::protobuf::util::TimeUtil;

google::protobuf::Timestamp ToTimestamp(absl::Time t) {
  return TimeUtil::NanosecondsToTimestamp(absl::ToUnixNanos(t));
}

// Waits on `cv` (with `lock` held) until `pred` holds or `timeout` has
// passed; returns pred(). An infinite or absurdly long timeout (e.g.
// --grace-period=inf) waits without one: wait_for(now + huge) would
// overflow the clock. Zero or negative: just evaluates pred.
template <typename Pred>
bool WaitFor(std::condition_variable& cv, std::unique_lock<std::mutex>& lock,
             absl::Duration timeout, Pred pred) {
  if (timeout >= absl::Hours(24 * 365 * 100)) {
    cv.wait(lock, pred);
    return true;
  }
  const auto deadline = std::chrono::steady_clock::now() +
                        absl::ToChronoNanoseconds(std::max(timeout, absl::ZeroDuration()));
  return cv.wait_until(lock, deadline, pred);
}

v1::JobState StateFor(const absl::Status& status) {
  if (status.ok()) return v1::SUCCEEDED;
  if (status.code() == absl::StatusCode::kCancelled) return v1::CANCELLED;
  return v1::FAILED;
}

// The mesher's counters into a Job's repeated Counter field, in its order.
void AddCounters(const mesh::MeshStats& stats, google::protobuf::RepeatedPtrField<v1::Counter>* out) {
  for (const auto& [name, value] : stats.counters) {
    v1::Counter* c = out->Add();
    c->set_name(name);
    c->set_value(value);
  }
}

}  // namespace

struct JobManager::JobRecord {
  uint64_t seq = 0;
  std::string owner;
  uint32_t attempts = 0;          // runs started (journaled before each)
  bool requeue_on_restart = false;  // cancelled by Shutdown: journaled as QUEUED
  JobMemory memory;                       // heap held by the job's thread
  std::atomic<bool> memory_exceeded{false};  // cancelled for its memory budget
  v1::Job job;
  uint64_t event_seq = 0;
  v1::SubmitJobRequest request;  // the input; moved out when the job starts
  core::CancelToken cancel;
  absl::Time deadline = absl::InfiniteFuture();
  absl::Time started;
  absl::Time ended = absl::InfiniteFuture();
  absl::Time last_progress_event = absl::InfinitePast();
  std::map<uint64_t, Listener> listeners;
};

JobManager::JobManager(JobManagerOptions options, std::unique_ptr<JobQueue> queue,
                       std::unique_ptr<ResultStore> store, std::unique_ptr<Journal> journal)
    : options_(options),
      queue_(std::move(queue)),
      store_(std::move(store)),
      journal_(std::move(journal)) {
  if (const char* crash = std::getenv("SVRC_TEST_CRASH_ON_INPUT"); crash != nullptr) {
    crash_input_name_ = crash;
  }
  if (journal_ != nullptr) Recover();
  workers_ = std::make_unique<WorkerPool>(options_.workers, queue_.get(),
                                          [this](const std::string& id) { RunJob(id); });
  janitor_ = std::thread([this] { JanitorLoop(); });
}

JobManager::~JobManager() { Shutdown(absl::ZeroDuration()); }

std::string JobManager::RequestKey(const std::string& owner, const std::string& request_id) {
  return absl::StrCat(owner.size(), ":", owner, request_id);
}

JobManager::JobRecord* JobManager::Find(const std::string& job_id, const std::string& owner) {
  auto it = jobs_.find(job_id);
  // Another client's job looks exactly like a missing one (docs/security.md).
  if (it == jobs_.end() || it->second->owner != owner) return nullptr;
  return it->second.get();
}

absl::StatusOr<v1::Job> JobManager::Submit(v1::SubmitJobRequest request, const std::string& owner) {
  std::string input_name;
  uint64_t input_bytes = 0;
  v1::InputFormat input_format = v1::INPUT_FORMAT_UNSPECIFIED;
  switch (request.input_case()) {
    case v1::SubmitJobRequest::kFile: {
      if (absl::Status s = api::FormatFromProto(request.file().format()).status(); !s.ok()) return s;
      if (request.file().data().empty()) return absl::InvalidArgumentError("the input file is empty");
      input_name = request.file().name();
      input_bytes = request.file().data().size();
      input_format = request.file().format();
      break;
    }
    case v1::SubmitJobRequest::kPlc:
      input_name = "<plc message>";
      input_bytes = request.plc().ByteSizeLong();
      break;
    default:
      return absl::InvalidArgumentError("the request has no input (plc or file)");
  }
  if (input_bytes > options_.max_input_bytes) {
    return absl::ResourceExhaustedError(absl::StrCat("input of ", input_bytes,
                                                     " bytes exceeds the server's limit of ",
                                                     options_.max_input_bytes));
  }
  absl::StatusOr<cli::MeshOptions> options = api::OptionsFromRequest(request);
  if (!options.ok()) return options.status();
  const absl::Duration deadline = options->deadline;

  const std::string request_key = RequestKey(owner, request.request_id());
  // Checks done before and again after the input is stored (outside the lock).
  auto admit = [&]() -> absl::StatusOr<const JobRecord*> {  // mu_ held
    if (!accepting_) return absl::UnavailableError("server is shutting down; not accepting jobs");
    if (!request.request_id().empty()) {
      auto it = by_request_id_.find(request_key);
      if (it != by_request_id_.end()) return jobs_.at(it->second).get();
    }
    if (options_.max_jobs_per_client > 0) {
      int active = 0;
      for (const auto& [jid, r] : jobs_) {
        if (r->owner == owner && !api::IsTerminal(r->job.state())) ++active;
      }
      if (active >= options_.max_jobs_per_client) {
        return absl::ResourceExhaustedError(absl::StrCat(
            "this client already has ", active, " unfinished jobs (the limit is ",
            options_.max_jobs_per_client, "); wait for one to finish"));
      }
    }
    return nullptr;
  };
  std::string id;
  {
    std::scoped_lock lock(mu_);
    absl::StatusOr<const JobRecord*> existing = admit();
    if (!existing.ok()) return existing.status();
    if (*existing != nullptr) {
      ServerLog().info("job {}: resubmission of its request id returns the existing job",
                       (*existing)->job.job_id());
      return (*existing)->job;
    }
    do {
      id = absl::StrFormat("j%016x", absl::Uniform<uint64_t>(bitgen_));
    } while (jobs_.contains(id));
  }
  // The input is on disk before the job is acknowledged, so that a re-queued
  // job can run again after a crash. Written outside the lock: it may be big.
  if (journal_ != nullptr) {
    if (absl::Status s = journal_->PutInput(id, request); !s.ok()) {
      ServerLog().error("job {}: cannot store its input: {}", id, std::string(s.message()));
      return absl::UnavailableError(absl::StrCat("cannot store the input: ", s.message()));
    }
  }
  std::scoped_lock lock(mu_);
  {
    absl::StatusOr<const JobRecord*> existing = admit();
    if (!existing.ok() || *existing != nullptr) {
      if (journal_ != nullptr) journal_->DeleteInput(id);
      if (!existing.ok()) return existing.status();
      return (*existing)->job;
    }
  }
  if (absl::Status s = queue_->Push(id); !s.ok()) {
    ServerLog().warn("submission refused: {}", std::string(s.message()));
    if (journal_ != nullptr) journal_->DeleteInput(id);
    return s;
  }
  auto rec = std::make_unique<JobRecord>();
  rec->seq = next_seq_++;
  rec->owner = owner;
  const absl::Time now = absl::Now();
  if (deadline > absl::ZeroDuration()) {
    rec->deadline = now + deadline;
    rec->cancel.SetDeadline(std::chrono::steady_clock::now() +
                            absl::ToChronoNanoseconds(deadline));
  }
  v1::Job& job = rec->job;
  job.set_job_id(id);
  job.set_request_id(request.request_id());
  job.set_state(v1::QUEUED);
  job.mutable_progress()->set_phase("queued");
  *job.mutable_create_time() = ToTimestamp(now);
  job.set_input_name(input_name);
  job.set_input_format(input_format);
  job.set_input_bytes(input_bytes);
  *job.mutable_parameters() = request.parameters();
  *job.mutable_encoding() = request.encoding();
  *job.mutable_limits() = request.limits();
  if (journal_ != nullptr) {
    // Accepted means durable: the record is on disk before the reply.
    v1::JournalRecord r;
    r.set_kind(v1::JournalRecord::SUBMITTED);
    r.set_job_id(id);
    *r.mutable_job() = job;
    r.set_owner(owner);
    if (absl::Status s = journal_->Append(r, /*sync=*/true); !s.ok()) {
      queue_->Remove(id);
      journal_->DeleteInput(id);
      ServerLog().error("job {}: cannot journal the submission: {}", id, std::string(s.message()));
      return absl::UnavailableError(absl::StrCat("cannot journal the job: ", s.message()));
    }
  }
  rec->request = std::move(request);
  if (!job.request_id().empty()) by_request_id_[request_key] = id;
  order_[rec->seq] = id;
  ServerLog().info("job {}: queued ({} {} bytes, queue {}/{})", id, input_name, input_bytes,
                   queue_->Size(), queue_->Capacity());
  v1::Job snapshot = job;
  jobs_[id] = std::move(rec);
  if (journal_ != nullptr && journal_->appended_since_rewrite() >= options_.compact_every) Compact();
  return snapshot;
}

absl::StatusOr<v1::Job> JobManager::Get(const std::string& job_id, const std::string& owner) {
  std::scoped_lock lock(mu_);
  JobRecord* rec = Find(job_id, owner);
  if (rec == nullptr) return absl::NotFoundError(absl::StrCat("no job ", job_id));
  return rec->job;
}

absl::StatusOr<v1::ListJobsResponse> JobManager::List(const v1::ListJobsRequest& request,
                                                      const std::string& owner) {
  int page_size = request.page_size() <= 0 ? 100 : std::min(request.page_size(), 1000);
  uint64_t start = 0;
  if (!request.page_token().empty() && !absl::SimpleAtoi(request.page_token(), &start)) {
    return absl::InvalidArgumentError(absl::StrCat("bad page_token '", request.page_token(), "'"));
  }
  auto wanted = [&](v1::JobState s) {
    if (request.states().empty()) return true;
    for (int st : request.states()) {
      if (st == s) return true;
    }
    return false;
  };
  v1::ListJobsResponse out;
  std::scoped_lock lock(mu_);
  for (auto it = order_.lower_bound(start); it != order_.end(); ++it) {
    const JobRecord& rec = *jobs_.at(it->second);
    const v1::Job& job = rec.job;
    if (rec.owner != owner || !wanted(job.state())) continue;
    if (out.jobs_size() == page_size) {
      out.set_next_page_token(absl::StrCat(it->first));
      break;
    }
    *out.add_jobs() = job;
  }
  return out;
}

absl::StatusOr<v1::Job> JobManager::Cancel(const std::string& job_id, const std::string& owner) {
  std::scoped_lock lock(mu_);
  JobRecord* rec = Find(job_id, owner);
  if (rec == nullptr) return absl::NotFoundError(absl::StrCat("no job ", job_id));
  if (api::IsTerminal(rec->job.state())) return rec->job;
  rec->cancel.Cancel();
  rec->job.set_cancel_requested(true);
  ServerLog().info("job {}: cancel requested ({})", job_id, api::JobStateName(rec->job.state()));
  if (rec->job.state() == v1::QUEUED && queue_->Remove(job_id)) {
    Finish(rec, absl::CancelledError("job cancelled before it started"));
  } else {
    Notify(rec);  // running (or popped, about to start): the worker ends it
  }
  return rec->job;
}

absl::Status JobManager::Delete(const std::string& job_id, const std::string& owner) {
  std::scoped_lock lock(mu_);
  JobRecord* rec = Find(job_id, owner);
  if (rec == nullptr) return absl::NotFoundError(absl::StrCat("no job ", job_id));
  auto it = jobs_.find(job_id);
  if (!api::IsTerminal(rec->job.state())) {
    return absl::FailedPreconditionError(absl::StrCat(
        "job ", job_id, " is ", api::JobStateName(rec->job.state()), "; cancel it first"));
  }
  if (absl::Status s = store_->Delete(job_id); !s.ok()) return s;
  v1::JournalRecord r;
  r.set_kind(v1::JournalRecord::DELETED);
  r.set_job_id(job_id);
  JournalAppend(std::move(r), /*sync=*/false);
  order_.erase(rec->seq);
  if (!rec->job.request_id().empty()) by_request_id_.erase(RequestKey(rec->owner, rec->job.request_id()));
  jobs_.erase(it);
  ServerLog().info("job {}: deleted", job_id);
  return absl::OkStatus();
}

absl::StatusOr<uint64_t> JobManager::Subscribe(const std::string& job_id, Listener listener,
                                               const std::string& owner) {
  std::scoped_lock lock(mu_);
  JobRecord* rec = Find(job_id, owner);
  if (rec == nullptr) return absl::NotFoundError(absl::StrCat("no job ", job_id));
  const uint64_t token = next_token_++;
  v1::JobEvent event;
  *event.mutable_job() = rec->job;
  event.set_sequence(rec->event_seq);
  listener(event);
  rec->listeners.emplace(token, std::move(listener));
  return token;
}

void JobManager::Unsubscribe(const std::string& job_id, uint64_t token) {
  std::scoped_lock lock(mu_);
  auto it = jobs_.find(job_id);
  if (it != jobs_.end()) it->second->listeners.erase(token);
}

absl::StatusOr<StoredResult> JobManager::Result(const std::string& job_id,
                                               const std::string& owner) {
  std::scoped_lock lock(mu_);
  JobRecord* rec = Find(job_id, owner);
  if (rec == nullptr) return absl::NotFoundError(absl::StrCat("no job ", job_id));
  const v1::Job& job = rec->job;
  if (job.state() != v1::SUCCEEDED) {
    std::string why = absl::StrCat("job ", job_id, " is ", api::JobStateName(job.state()));
    if (job.has_error()) absl::StrAppend(&why, ": ", job.error().message());
    return absl::FailedPreconditionError(absl::StrCat(why, "; it has no result"));
  }
  absl::StatusOr<StoredResult> stored = store_->Stat(job_id);
  if (!stored.ok()) {
    return absl::NotFoundError(absl::StrCat("the result of job ", job_id, " is gone (",
                                            stored.status().message(), ")"));
  }
  return stored;
}

bool JobManager::accepting() const {
  std::scoped_lock lock(mu_);
  return accepting_;
}

int JobManager::running() const {
  std::scoped_lock lock(mu_);
  return running_;
}

void JobManager::Notify(JobRecord* rec) {
  ++rec->event_seq;
  if (rec->listeners.empty()) return;
  v1::JobEvent event;
  *event.mutable_job() = rec->job;
  event.set_sequence(rec->event_seq);
  for (auto& [token, listener] : rec->listeners) listener(event);
}

void JobManager::Finish(JobRecord* rec, const absl::Status& status) {
  v1::Job& job = rec->job;
  if (journal_ != nullptr && rec->requeue_on_restart && !status.ok()) {
    // Cancelled by a shutdown: the job is not over; the next server runs it
    // again (the interrupted attempt does not count as a crash).
    if (job.state() == v1::RUNNING && rec->attempts > 0) --rec->attempts;
    job.set_state(v1::QUEUED);
    job.set_cancel_requested(false);  // set by Shutdown, not by the client
    job.mutable_progress()->set_phase("queued");
    JournalAppend(SnapshotOf(*rec), /*sync=*/true);
    ServerLog().info("job {}: interrupted by the shutdown; queued for the next start", job.job_id());
    Notify(rec);
    return;
  }
  job.set_state(StateFor(status));
  if (status.ok()) job.mutable_progress()->set_phase("done");
  if (!status.ok()) {
    *job.mutable_error() = ToProtoStatus(status);
    // How far the mesher got (core/mesh/stats_payload.h).
    if (const std::optional<mesh::MeshStats> partial = mesh::StatsOf(status); partial.has_value()) {
      AddCounters(*partial, job.mutable_failure_stats());
    }
  }
  rec->ended = absl::Now();
  *job.mutable_end_time() = ToTimestamp(rec->ended);
  rec->request.Clear();
  if (journal_ != nullptr) {
    v1::JournalRecord r;
    r.set_kind(v1::JournalRecord::FINISHED);
    r.set_job_id(job.job_id());
    *r.mutable_job() = job;
    JournalAppend(std::move(r), /*sync=*/true);
    journal_->DeleteInput(job.job_id());
  }
  if (status.ok()) {
    ServerLog().info("job {}: SUCCEEDED ({} vertices, {} tets, {} bytes) in {:.3f} s",
                     job.job_id(), job.result().num_vertices(), job.result().num_tets(),
                     job.result().size_bytes(), job.progress().elapsed_seconds());
  } else {
    ServerLog().info("job {}: {} ({}: {})", job.job_id(), api::JobStateName(job.state()),
                     absl::StatusCodeToString(status.code()), std::string(status.message()));
  }
  Notify(rec);
}

void JobManager::CheckMemory(JobRecord* rec) {
  const uint64_t budget = options_.max_job_memory_bytes;
  if (budget == 0 || rec->memory.bytes.load(std::memory_order_relaxed) <= static_cast<int64_t>(budget)) {
    return;
  }
  if (!rec->memory_exceeded.exchange(true)) rec->cancel.Cancel();
}

void JobManager::OnProgress(JobRecord* rec, const core::Progress& progress) {
  CheckMemory(rec);
  std::scoped_lock lock(mu_);
  v1::Progress* p = rec->job.mutable_progress();
  const bool phase_changed = p->phase() != progress.phase;
  p->set_phase(progress.phase);
  p->set_vertices(progress.vertices);
  p->set_queue_size(progress.queue_size);
  p->set_largest_work_radius(progress.largest_work_radius);
  p->set_target_radius(progress.target_radius);
  const absl::Time now = absl::Now();
  p->set_elapsed_seconds(absl::ToDoubleSeconds(now - rec->started));
  if (phase_changed || now - rec->last_progress_event >= options_.progress_interval) {
    rec->last_progress_event = now;
    Notify(rec);
  }
}

void JobManager::RunJob(const std::string& job_id) {
  JobRecord* rec = nullptr;
  v1::SubmitJobRequest request;
  {
    std::scoped_lock lock(mu_);
    auto it = jobs_.find(job_id);
    if (it == jobs_.end() || it->second->job.state() != v1::QUEUED) return;
    rec = it->second.get();
    if (!accepting_) {
      if (draining_) return;  // stays QUEUED in the journal: the next server runs it
      Finish(rec, absl::CancelledError("server shutting down"));
      return;
    }
    if (absl::Status s = rec->cancel.Check(); !s.ok()) {
      Finish(rec, s.code() == absl::StatusCode::kDeadlineExceeded
                      ? absl::DeadlineExceededError("job deadline exceeded while queued")
                      : absl::CancelledError("job cancelled before it started"));
      return;
    }
    ++rec->attempts;
    if (journal_ != nullptr) {
      // On disk before the run: if this attempt takes the server down, the
      // next start counts it (max_attempts) instead of looping.
      v1::JournalRecord r;
      r.set_kind(v1::JournalRecord::STARTED);
      r.set_job_id(job_id);
      r.set_attempt(rec->attempts);
      JournalAppend(std::move(r), /*sync=*/true);
    }
    if (!crash_input_name_.empty() && rec->job.input_name() == crash_input_name_) {
      ServerLog().warn("job {}: SVRC_TEST_CRASH_ON_INPUT matches; killing the server", job_id);
      ::raise(SIGKILL);
    }
    rec->started = absl::Now();
    rec->job.set_state(v1::RUNNING);
    *rec->job.mutable_start_time() = ToTimestamp(rec->started);
    rec->job.mutable_progress()->set_phase("read");
    request = std::move(rec->request);
    rec->request.Clear();
    ++running_;
    ServerLog().info("job {}: running ({} workers busy)", job_id, running_);
    Notify(rec);
  }
  StoredResult stored;
  v1::ResultInfo info;
  BindThreadMemory(&rec->memory);
  absl::Status status = Execute(rec, request, &stored, &info);
  request.Clear();
  BindThreadMemory(nullptr);
  if (rec->memory_exceeded.load() && !status.ok()) {
    status = absl::ResourceExhaustedError(absl::StrCat(
        "the job exceeded the server's per-job memory budget of ", options_.max_job_memory_bytes,
        " bytes (it held ", rec->memory.peak.load(), " bytes)"));
  }
  std::scoped_lock lock(mu_);
  --running_;
  rec->job.mutable_progress()->set_elapsed_seconds(absl::ToDoubleSeconds(absl::Now() - rec->started));
  if (status.ok()) {
    info.set_size_bytes(stored.size);
    info.set_sha256(stored.sha256);
    *rec->job.mutable_result() = std::move(info);
  }
  Finish(rec, status);
  // Shutdown may be waiting for running_ == 0. Notified under the lock, after
  // Finish: once Shutdown sees 0 the job's FINISHED record is journaled.
  state_changed_.notify_all();
}

absl::Status JobManager::Execute(JobRecord* rec, const v1::SubmitJobRequest& request,
                                 StoredResult* stored, v1::ResultInfo* info) {
  const std::string& id = rec->job.job_id();
  auto phase = [&](const char* name) {
    core::Progress p;
    {
      std::scoped_lock lock(mu_);
      const v1::Progress& cur = rec->job.progress();
      p.vertices = cur.vertices();
      p.queue_size = cur.queue_size();
      p.largest_work_radius = cur.largest_work_radius();
      p.target_radius = cur.target_radius();
    }
    p.phase = name;
    OnProgress(rec, p);
  };
  absl::StatusOr<plc::Plc> plc;
  if (request.has_file()) {
    absl::StatusOr<plc::InputFormat> format = api::FormatFromProto(request.file().format());
    if (!format.ok()) return format.status();
    const std::string name = request.file().name().empty() ? id : request.file().name();
    plc = plc::ReadPlcBytes(request.file().data(), *format, name);
  } else {
    plc = api::PlcFromProto(request.plc());
  }
  if (!plc.ok()) return plc.status();
  ServerLog().info("job {}: input read ({} vertices, {} segments, {} facets)", id,
                   plc->vertices.size(), plc->segments.size(), plc->facets.size());
  absl::StatusOr<cli::MeshOptions> options = api::OptionsFromRequest(request);
  if (!options.ok()) return options.status();
  absl::StatusOr<mesh::TetMesh> mesh = cli::RunMeshing(
      *plc, *options,
      [this, rec](const core::Progress& p) { OnProgress(rec, p); }, &rec->cancel);
  *plc = plc::Plc();  // the job's memory goes as soon as it is not needed
  if (!mesh.ok()) return mesh.status();
  if (absl::Status s = rec->cancel.Check(); !s.ok()) return s;
  phase("encode");
  codec::EncodeOptions encode_options;
  encode_options.position_quantization_bits = options->quantization_bits;
  codec::EncodeReport report;
  absl::StatusOr<std::string> bytes = codec::EncodeTetMesh(*mesh, encode_options, &report);
  if (!bytes.ok()) return bytes.status();
  info->set_num_vertices(mesh->num_vertices());
  info->set_num_tets(mesh->num_tets());
  info->set_num_triangles(mesh->triangles.size());
  info->set_max_position_error(report.max_position_error);
  AddCounters(mesh->stats, info->mutable_stats());
  *mesh = mesh::TetMesh();
  if (absl::Status s = rec->cancel.Check(); !s.ok()) return s;
  phase("store");
  absl::StatusOr<StoredResult> put = store_->Put(id, *bytes);
  if (!put.ok()) return put.status();
  *stored = *put;
  return absl::OkStatus();
}

void JobManager::JanitorLoop() {
  absl::Time last_sweep = absl::Now();
  std::unique_lock lock(mu_);
  while (!stopped_) {
    // Woken early by Shutdown (stopped_ is set then notified).
    WaitFor(state_changed_, lock, options_.janitor_interval, [this] { return stopped_; });
    if (stopped_) break;
    const absl::Time now = absl::Now();
    std::vector<std::string> expired;
    for (auto& [id, rec] : jobs_) {
      if (rec->job.state() == v1::RUNNING) CheckMemory(rec.get());
      if (rec->job.state() == v1::QUEUED && rec->deadline <= now && queue_->Remove(id)) {
        Finish(rec.get(), absl::DeadlineExceededError("job deadline exceeded while queued"));
      }
      if (api::IsTerminal(rec->job.state()) && rec->ended + options_.retention <= now) {
        expired.push_back(id);
      }
    }
    for (const std::string& id : expired) {
      auto it = jobs_.find(id);
      store_->Delete(id).IgnoreError();
      v1::JournalRecord r;
      r.set_kind(v1::JournalRecord::DELETED);
      r.set_job_id(id);
      JournalAppend(std::move(r), /*sync=*/false);
      order_.erase(it->second->seq);
      if (!it->second->job.request_id().empty()) {
        by_request_id_.erase(RequestKey(it->second->owner, it->second->job.request_id()));
      }
      jobs_.erase(it);
      ServerLog().info("job {}: expired after the retention time", id);
    }
    if (now - last_sweep >= absl::Minutes(1)) {
      last_sweep = now;
      // Results no job refers to (from an earlier server run) expire by age.
      for (const std::string& key : store_->RemoveOlderThan(now - options_.retention)) {
        ServerLog().info("result {} expired", key);
      }
    }
  }
}

void JobManager::JournalAppend(v1::JournalRecord record, bool sync) {
  if (journal_ == nullptr) return;
  if (absl::Status s = journal_->Append(record, sync); !s.ok()) {
    ServerLog().error("journal: cannot record job {}: {}", record.job_id(), std::string(s.message()));
  }
}

v1::JournalRecord JobManager::SnapshotOf(const JobRecord& rec) const {
  v1::JournalRecord r;
  r.set_kind(v1::JournalRecord::SNAPSHOT);
  r.set_job_id(rec.job.job_id());
  *r.mutable_job() = rec.job;
  r.set_owner(rec.owner);
  r.set_attempt(rec.attempts);
  return r;
}

void JobManager::Compact() {
  std::vector<v1::JournalRecord> records;
  records.reserve(order_.size());
  for (const auto& [seq, id] : order_) records.push_back(SnapshotOf(*jobs_.at(id)));
  if (absl::Status s = journal_->Rewrite(records); !s.ok()) {
    ServerLog().error("journal: compaction failed: {}", std::string(s.message()));
  } else {
    ServerLog().info("journal: compacted to {} job snapshots", records.size());
  }
}

void JobManager::Recover() {
  struct Replayed {
    v1::Job job;
    std::string owner;
    uint32_t attempts = 0;
  };
  std::vector<std::string> order;  // first appearance = submission order
  absl::flat_hash_map<std::string, Replayed> replayed;
  std::vector<v1::JournalRecord> records = journal_->TakeReplayed();
  if (journal_->dropped_tail_bytes() > 0) {
    ServerLog().warn("journal: dropped a torn or corrupt tail of {} bytes",
                     journal_->dropped_tail_bytes());
  }
  for (v1::JournalRecord& r : records) {
    auto it = replayed.find(r.job_id());
    switch (r.kind()) {
      case v1::JournalRecord::SUBMITTED:
      case v1::JournalRecord::SNAPSHOT:
        if (it == replayed.end()) {
          order.push_back(r.job_id());
          it = replayed.emplace(r.job_id(), Replayed{}).first;
        }
        it->second.job = std::move(*r.mutable_job());
        it->second.owner = r.owner();
        it->second.attempts = r.attempt();
        break;
      case v1::JournalRecord::STARTED:
        if (it != replayed.end()) {
          it->second.attempts = r.attempt();
          it->second.job.set_state(v1::RUNNING);
        }
        break;
      case v1::JournalRecord::FINISHED:
        if (it != replayed.end()) it->second.job = std::move(*r.mutable_job());
        break;
      case v1::JournalRecord::DELETED:
        if (it != replayed.end()) replayed.erase(it);
        break;
      default:
        break;
    }
  }
  const absl::Time now = absl::Now();
  int requeued = 0, failed = 0, kept = 0;
  std::scoped_lock lock(mu_);
  for (const std::string& id : order) {
    auto it = replayed.find(id);
    if (it == replayed.end() || jobs_.contains(id)) continue;
    Replayed& r = it->second;
    auto rec = std::make_unique<JobRecord>();
    rec->seq = next_seq_++;
    rec->owner = r.owner;
    rec->attempts = r.attempts;
    rec->job = std::move(r.job);
    v1::Job& job = rec->job;
    if (api::IsTerminal(job.state())) {
      rec->ended = absl::FromUnixNanos(TimeUtil::TimestampToNanoseconds(job.end_time()));
      if (rec->ended + options_.retention <= now) {
        store_->Delete(id).IgnoreError();
        continue;
      }
      ++kept;
    }
    JobRecord* p = rec.get();
    order_[p->seq] = id;
    if (!job.request_id().empty()) by_request_id_[RequestKey(p->owner, job.request_id())] = id;
    jobs_[id] = std::move(rec);
    if (api::IsTerminal(job.state())) continue;

    // An interrupted job: run it again unless it keeps killing the server.
    const bool was_running = job.state() == v1::RUNNING;
    job.set_state(v1::QUEUED);
    job.mutable_progress()->Clear();
    job.mutable_progress()->set_phase("queued");
    job.clear_start_time();
    store_->Delete(id).IgnoreError();  // a result the crashed attempt may have left
    ++failed;
    if (was_running && static_cast<int>(p->attempts) >= options_.max_attempts) {
      Finish(p, absl::InternalError(absl::StrCat(
                    "the server died ", p->attempts,
                    " times while running this job; it is not run again")));
      continue;
    }
    if (job.cancel_requested()) {
      Finish(p, absl::CancelledError("job cancelled before the server restarted"));
      continue;
    }
    if (job.limits().has_deadline()) {
      const absl::Duration d = absl::Nanoseconds(TimeUtil::DurationToNanoseconds(job.limits().deadline()));
      if (d > absl::ZeroDuration()) {
        p->deadline = absl::FromUnixNanos(TimeUtil::TimestampToNanoseconds(job.create_time())) + d;
        if (p->deadline <= now) {
          Finish(p, absl::DeadlineExceededError("job deadline passed while the server was down"));
          continue;
        }
        p->cancel.SetDeadline(std::chrono::steady_clock::now() +
                              absl::ToChronoNanoseconds(p->deadline - now));
      }
    }
    absl::StatusOr<v1::SubmitJobRequest> input = journal_->GetInput(id);
    if (!input.ok()) {
      Finish(p, absl::DataLossError(std::string(input.status().message())));
      continue;
    }
    p->request = *std::move(input);
    if (absl::Status s = queue_->Push(id); !s.ok()) {
      Finish(p, absl::ResourceExhaustedError(
                    absl::StrCat("cannot re-queue the job after a restart: ", s.message())));
      continue;
    }
    --failed;
    ++requeued;
    ServerLog().info("job {}: re-queued after a restart ({} attempts so far)", id, p->attempts);
  }
  // Inputs no unfinished job refers to (their job finished or was deleted
  // just before a crash).
  for (const std::string& id : journal_->ListInputs()) {
    auto it = jobs_.find(id);
    if (it == jobs_.end() || api::IsTerminal(it->second->job.state())) journal_->DeleteInput(id);
  }
  Compact();
  ServerLog().info("journal: recovered {} finished jobs, re-queued {}, failed {}", kept, requeued,
                   failed);
}

void JobManager::Shutdown(absl::Duration grace) {
  {
    std::scoped_lock lock(mu_);
    if (stopped_) return;
    accepting_ = false;
    draining_ = journal_ != nullptr;
  }
  std::vector<std::string> queued = queue_->Close();
  {
    std::unique_lock lock(mu_);
    for (const std::string& id : queued) {
      auto it = jobs_.find(id);
      // With a journal, queued jobs stay queued for the next start.
      if (it != jobs_.end() && !draining_) {
        Finish(it->second.get(), absl::CancelledError("server shutting down"));
      }
    }
    ServerLog().info("shutdown: {} queued jobs cancelled, waiting up to {} for {} running",
                     queued.size(), absl::FormatDuration(grace), running_);
    // RunJob notifies state_changed_ after every --running_.
    if (!WaitFor(state_changed_, lock, grace, [this] { return running_ == 0; })) {
      for (auto& [id, rec] : jobs_) {
        if (rec->job.state() == v1::RUNNING) {
          ServerLog().info("job {}: cancelled at the end of the shutdown grace period", id);
          rec->requeue_on_restart = draining_;
          rec->cancel.Cancel();
          rec->job.set_cancel_requested(true);
        }
      }
    }
  }
  workers_->Join();
  {
    std::scoped_lock lock(mu_);
    stopped_ = true;
  }
  state_changed_.notify_all();  // the janitor leaves its wait at once
  if (janitor_.joinable()) janitor_.join();
}

}  // namespace svrc::server
