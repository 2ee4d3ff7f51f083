#include "server/job_manager.h"

#include <utility>
#include <vector>

#include "absl/random/random.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/codec/container.h"
#include "core/plc/readers.h"
#include "google/protobuf/util/time_util.h"
#include "proto/convert.h"
#include "server/log.h"
#include "server/status_util.h"

namespace svrc::server {
namespace {

using google::protobuf::util::TimeUtil;

google::protobuf::Timestamp ToTimestamp(absl::Time t) {
  return TimeUtil::NanosecondsToTimestamp(absl::ToUnixNanos(t));
}

v1::JobState StateFor(const absl::Status& status) {
  if (status.ok()) return v1::SUCCEEDED;
  if (status.code() == absl::StatusCode::kCancelled) return v1::CANCELLED;
  return v1::FAILED;
}

}  // namespace

struct JobManager::JobRecord {
  uint64_t seq = 0;
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
                       std::unique_ptr<ResultStore> store)
    : options_(options), queue_(std::move(queue)), store_(std::move(store)) {
  workers_ = std::make_unique<WorkerPool>(options_.workers, queue_.get(),
                                          [this](const std::string& id) { RunJob(id); });
  janitor_ = std::thread([this] { JanitorLoop(); });
}

JobManager::~JobManager() { Shutdown(absl::ZeroDuration()); }

absl::StatusOr<v1::Job> JobManager::Submit(v1::SubmitJobRequest request) {
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

  absl::MutexLock lock(&mu_);
  if (!accepting_) return absl::UnavailableError("server is shutting down; not accepting jobs");
  if (!request.request_id().empty()) {
    auto it = by_request_id_.find(request.request_id());
    if (it != by_request_id_.end()) {
      ServerLog().info("job {}: resubmission of request {} returns the existing job", it->second,
                       request.request_id());
      return jobs_.at(it->second)->job;
    }
  }
  std::string id;
  do {
    id = absl::StrFormat("j%016x", absl::Uniform<uint64_t>(bitgen_));
  } while (jobs_.contains(id));
  if (absl::Status s = queue_->Push(id); !s.ok()) {
    ServerLog().warn("submission refused: {}", std::string(s.message()));
    return s;
  }
  auto rec = std::make_unique<JobRecord>();
  rec->seq = next_seq_++;
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
  rec->request = std::move(request);
  if (!job.request_id().empty()) by_request_id_[job.request_id()] = id;
  order_[rec->seq] = id;
  ServerLog().info("job {}: queued ({} {} bytes, queue {}/{})", id, input_name, input_bytes,
                   queue_->Size(), queue_->Capacity());
  v1::Job snapshot = job;
  jobs_[id] = std::move(rec);
  return snapshot;
}

absl::StatusOr<v1::Job> JobManager::Get(const std::string& job_id) {
  absl::MutexLock lock(&mu_);
  auto it = jobs_.find(job_id);
  if (it == jobs_.end()) return absl::NotFoundError(absl::StrCat("no job ", job_id));
  return it->second->job;
}

absl::StatusOr<v1::ListJobsResponse> JobManager::List(const v1::ListJobsRequest& request) {
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
  absl::MutexLock lock(&mu_);
  for (auto it = order_.lower_bound(start); it != order_.end(); ++it) {
    const v1::Job& job = jobs_.at(it->second)->job;
    if (!wanted(job.state())) continue;
    if (out.jobs_size() == page_size) {
      out.set_next_page_token(absl::StrCat(it->first));
      break;
    }
    *out.add_jobs() = job;
  }
  return out;
}

absl::StatusOr<v1::Job> JobManager::Cancel(const std::string& job_id) {
  absl::MutexLock lock(&mu_);
  auto it = jobs_.find(job_id);
  if (it == jobs_.end()) return absl::NotFoundError(absl::StrCat("no job ", job_id));
  JobRecord* rec = it->second.get();
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

absl::Status JobManager::Delete(const std::string& job_id) {
  absl::MutexLock lock(&mu_);
  auto it = jobs_.find(job_id);
  if (it == jobs_.end()) return absl::NotFoundError(absl::StrCat("no job ", job_id));
  JobRecord* rec = it->second.get();
  if (!api::IsTerminal(rec->job.state())) {
    return absl::FailedPreconditionError(absl::StrCat(
        "job ", job_id, " is ", api::JobStateName(rec->job.state()), "; cancel it first"));
  }
  if (absl::Status s = store_->Delete(job_id); !s.ok()) return s;
  order_.erase(rec->seq);
  if (!rec->job.request_id().empty()) by_request_id_.erase(rec->job.request_id());
  jobs_.erase(it);
  ServerLog().info("job {}: deleted", job_id);
  return absl::OkStatus();
}

absl::StatusOr<uint64_t> JobManager::Subscribe(const std::string& job_id, Listener listener) {
  absl::MutexLock lock(&mu_);
  auto it = jobs_.find(job_id);
  if (it == jobs_.end()) return absl::NotFoundError(absl::StrCat("no job ", job_id));
  JobRecord* rec = it->second.get();
  const uint64_t token = next_token_++;
  v1::JobEvent event;
  *event.mutable_job() = rec->job;
  event.set_sequence(rec->event_seq);
  listener(event);
  rec->listeners.emplace(token, std::move(listener));
  return token;
}

void JobManager::Unsubscribe(const std::string& job_id, uint64_t token) {
  absl::MutexLock lock(&mu_);
  auto it = jobs_.find(job_id);
  if (it != jobs_.end()) it->second->listeners.erase(token);
}

absl::StatusOr<StoredResult> JobManager::Result(const std::string& job_id) {
  absl::MutexLock lock(&mu_);
  auto it = jobs_.find(job_id);
  if (it == jobs_.end()) return absl::NotFoundError(absl::StrCat("no job ", job_id));
  const v1::Job& job = it->second->job;
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
  absl::MutexLock lock(&mu_);
  return accepting_;
}

int JobManager::running() const {
  absl::MutexLock lock(&mu_);
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
  job.set_state(StateFor(status));
  if (status.ok()) job.mutable_progress()->set_phase("done");
  if (!status.ok()) *job.mutable_error() = ToProtoStatus(status);
  rec->ended = absl::Now();
  *job.mutable_end_time() = ToTimestamp(rec->ended);
  rec->request.Clear();
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

void JobManager::OnProgress(JobRecord* rec, const core::Progress& progress) {
  absl::MutexLock lock(&mu_);
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
    absl::MutexLock lock(&mu_);
    auto it = jobs_.find(job_id);
    if (it == jobs_.end() || it->second->job.state() != v1::QUEUED) return;
    rec = it->second.get();
    if (!accepting_) {
      Finish(rec, absl::CancelledError("server shutting down"));
      return;
    }
    if (absl::Status s = rec->cancel.Check(); !s.ok()) {
      Finish(rec, s.code() == absl::StatusCode::kDeadlineExceeded
                      ? absl::DeadlineExceededError("job deadline exceeded while queued")
                      : absl::CancelledError("job cancelled before it started"));
      return;
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
  absl::Status status = Execute(rec, request, &stored, &info);
  request.Clear();
  absl::MutexLock lock(&mu_);
  --running_;
  rec->job.mutable_progress()->set_elapsed_seconds(absl::ToDoubleSeconds(absl::Now() - rec->started));
  if (status.ok()) {
    info.set_size_bytes(stored.size);
    info.set_sha256(stored.sha256);
    *rec->job.mutable_result() = std::move(info);
  }
  Finish(rec, status);
}

absl::Status JobManager::Execute(JobRecord* rec, const v1::SubmitJobRequest& request,
                                 StoredResult* stored, v1::ResultInfo* info) {
  const std::string& id = rec->job.job_id();
  auto phase = [&](const char* name) {
    core::Progress p;
    {
      absl::MutexLock lock(&mu_);
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
  for (const auto& [name, value] : mesh->stats.counters) {
    v1::Counter* c = info->add_stats();
    c->set_name(name);
    c->set_value(value);
  }
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
  absl::MutexLock lock(&mu_);
  while (!stopped_) {
    mu_.AwaitWithTimeout(absl::Condition(&stopped_), options_.janitor_interval);
    if (stopped_) break;
    const absl::Time now = absl::Now();
    std::vector<std::string> expired;
    for (auto& [id, rec] : jobs_) {
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
      order_.erase(it->second->seq);
      if (!it->second->job.request_id().empty()) by_request_id_.erase(it->second->job.request_id());
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

void JobManager::Shutdown(absl::Duration grace) {
  {
    absl::MutexLock lock(&mu_);
    if (stopped_) return;
    accepting_ = false;
  }
  std::vector<std::string> queued = queue_->Close();
  {
    absl::MutexLock lock(&mu_);
    for (const std::string& id : queued) {
      auto it = jobs_.find(id);
      if (it != jobs_.end()) Finish(it->second.get(), absl::CancelledError("server shutting down"));
    }
    ServerLog().info("shutdown: {} queued jobs cancelled, waiting up to {} for {} running",
                     queued.size(), absl::FormatDuration(grace), running_);
    if (!mu_.AwaitWithTimeout(absl::Condition(+[](int* running) { return *running == 0; }, &running_),
                              grace)) {
      for (auto& [id, rec] : jobs_) {
        if (rec->job.state() == v1::RUNNING) {
          ServerLog().info("job {}: cancelled at the end of the shutdown grace period", id);
          rec->cancel.Cancel();
          rec->job.set_cancel_requested(true);
        }
      }
    }
  }
  workers_->Join();
  {
    absl::MutexLock lock(&mu_);
    stopped_ = true;
  }
  if (janitor_.joinable()) janitor_.join();
}

}  // namespace svrc::server
