#include "server/service.h"

#include <mutex>
#include <string>
#include <utility>

#include "absl/strings/str_cat.h"
#include "proto/convert.h"
#include "server/log.h"
#include "server/status_util.h"
#include "server/watch_stream.h"

namespace svrc::server {
namespace {

// Finishes a unary call with the outcome of `result` copied into `response`.
template <typename T>
grpc::ServerUnaryReactor* FinishUnary(grpc::CallbackServerContext* context,
                                      absl::StatusOr<T> result, T* response) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  if (result.ok()) *response = std::move(*result);
  reactor->Finish(ToGrpcStatus(result.status()));
  return reactor;
}

// UploadJob: a header message, then chunks appended to the file; submitted
// when the client half-closes.
class UploadReactor final : public grpc::ServerReadReactor<v1::UploadJobRequest> {
 public:
  UploadReactor(grpc::CallbackServerContext* context, JobManager* manager, uint64_t max_bytes,
                v1::Job* response, absl::StatusOr<std::string> owner)
      : context_(context), manager_(manager), max_bytes_(max_bytes), response_(response) {
    if (!owner.ok()) {
      Finish(ToGrpcStatus(owner.status()));
      return;
    }
    owner_ = *std::move(owner);
    StartRead(&message_);
  }

  void OnReadDone(bool ok) override {
    if (!ok) {  // the client finished sending (or the call broke: then OnDone follows)
      Submit();
      return;
    }
    if (!have_header_) {
      if (message_.part_case() != v1::UploadJobRequest::kHeader ||
          message_.header().input_case() != v1::SubmitJobRequest::kFile) {
        Finish(grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                            "the first UploadJob message must be a header with an input file"));
        return;
      }
      request_ = std::move(*message_.mutable_header());
      total_bytes_ = message_.total_bytes();
      if (total_bytes_ > max_bytes_) {
        Finish(grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                            absl::StrCat("upload of ", total_bytes_, " bytes exceeds the server's limit of ",
                                         max_bytes_, " bytes")));
        return;
      }
      request_.mutable_file()->mutable_data()->reserve(total_bytes_);
      have_header_ = true;
    } else {
      if (message_.part_case() != v1::UploadJobRequest::kChunk) {
        Finish(grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                            "only data chunks may follow the UploadJob header"));
        return;
      }
      std::string* data = request_.mutable_file()->mutable_data();
      if (data->size() + message_.chunk().size() > max_bytes_) {
        Finish(grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                            absl::StrCat("upload exceeds the server's limit of ", max_bytes_,
                                         " bytes")));
        return;
      }
      data->append(message_.chunk());
    }
    message_.Clear();
    StartRead(&message_);
  }

  void OnDone() override { delete this; }

 private:
  void Submit() {
    if (context_->IsCancelled()) {
      Finish(grpc::Status::CANCELLED);
      return;
    }
    if (!have_header_) {
      Finish(grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, "empty upload: no header"));
      return;
    }
    const uint64_t got = request_.file().data().size();
    if (total_bytes_ != 0 && got != total_bytes_) {
      Finish(grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                          absl::StrCat("upload ended after ", got, " of ", total_bytes_, " bytes")));
      return;
    }
    absl::StatusOr<v1::Job> job = manager_->Submit(std::move(request_), owner_);
    if (job.ok()) *response_ = std::move(*job);
    Finish(ToGrpcStatus(job.status()));
  }

  grpc::CallbackServerContext* context_;
  JobManager* manager_;
  const uint64_t max_bytes_;
  uint64_t total_bytes_ = 0;
  v1::Job* response_;
  std::string owner_;
  v1::UploadJobRequest message_;
  v1::SubmitJobRequest request_;
  bool have_header_ = false;
};

// WatchJob: the manager calls the listener with every snapshot of the job
// (under its lock, so it never blocks); WatchStream (server/watch_stream.h)
// decides what to write: one write in flight, the newest unsent snapshot
// next, the call finished after the terminal one.
class WatchReactor final : public grpc::ServerWriteReactor<v1::JobEvent> {
 public:
  WatchReactor(JobManager* manager, const std::string& job_id,
               const absl::StatusOr<std::string>& owner)
      : manager_(manager), job_id_(job_id) {
    if (!owner.ok()) {
      stream_.Close();
      Finish(ToGrpcStatus(owner.status()));
      return;
    }
    absl::StatusOr<uint64_t> token = manager_->Subscribe(
        job_id_,
        [this](const v1::JobEvent& e) {
          if (stream_.Offer(e) == WatchStream::Action::kWrite) StartWrite(&stream_.in_flight());
        },
        *owner);
    if (!token.ok()) {
      stream_.Close();
      Finish(ToGrpcStatus(token.status()));
      return;
    }
    std::scoped_lock lock(token_mu_);
    token_ = *token;
  }

  void OnWriteDone(bool ok) override {
    if (!ok) return;  // the stream broke: OnCancel/OnDone follow
    switch (stream_.WriteDone()) {
      case WatchStream::Action::kWrite:
        StartWrite(&stream_.in_flight());
        break;
      case WatchStream::Action::kFinish:
        Finish(grpc::Status::OK);
        break;
      case WatchStream::Action::kNone:
        break;
    }
  }

  void OnCancel() override {
    if (stream_.Close()) Finish(grpc::Status::CANCELLED);
  }

  void OnDone() override {
    uint64_t token;
    {
      std::scoped_lock lock(token_mu_);
      token = token_;
    }
    if (token != 0) manager_->Unsubscribe(job_id_, token);
    delete this;
  }

 private:
  JobManager* manager_;
  const std::string job_id_;
  WatchStream stream_;
  // std::mutex (intercepted by TSan, unlike Debian's absl::Mutex): token_ is
  // set in the constructor and read in OnDone, on another thread.
  std::mutex token_mu_;
  uint64_t token_ = 0;
};

// FetchResult: chunks read from the result store one at a time (a read of
// <= 1 MiB from the local disk; an object-store implementation would read
// ahead on its own thread).
class FetchReactor final : public grpc::ServerWriteReactor<v1::ResultChunk> {
 public:
  FetchReactor(JobManager* manager, const v1::FetchResultRequest& request,
               const absl::StatusOr<std::string>& owner)
      : manager_(manager), job_id_(request.job_id()), offset_(request.offset()) {
    if (!owner.ok()) {
      Finish(ToGrpcStatus(owner.status()));
      return;
    }
    chunk_bytes_ = request.max_chunk_bytes() == 0 ||
                           request.max_chunk_bytes() > MeshingServiceImpl::kMaxChunkBytes
                       ? MeshingServiceImpl::kMaxChunkBytes
                       : request.max_chunk_bytes();
    absl::StatusOr<StoredResult> stored = manager_->Result(job_id_, *owner);
    if (!stored.ok()) {
      Finish(ToGrpcStatus(stored.status()));
      return;
    }
    if (offset_ > stored->size) {
      Finish(grpc::Status(grpc::StatusCode::OUT_OF_RANGE,
                          absl::StrCat("offset ", offset_, " is past the end of the result (",
                                       stored->size, " bytes)")));
      return;
    }
    total_ = stored->size;
    sha256_ = stored->sha256;
    NextChunk();
  }

  void OnWriteDone(bool ok) override {
    if (!ok) {  // the client went away: every RPC must still be finished
      Finish(grpc::Status::CANCELLED);
      return;
    }
    NextChunk();
  }

  void OnDone() override { delete this; }

 private:
  void NextChunk() {
    if (offset_ >= total_ && sent_any_) {
      Finish(grpc::Status::OK);
      return;
    }
    absl::StatusOr<std::string> data = manager_->store()->Read(job_id_, offset_, chunk_bytes_);
    if (!data.ok()) {
      Finish(ToGrpcStatus(data.status()));
      return;
    }
    chunk_.Clear();
    chunk_.set_offset(offset_);
    chunk_.set_total_size(total_);
    chunk_.set_sha256(sha256_);
    offset_ += data->size();
    *chunk_.mutable_data() = std::move(*data);
    sent_any_ = true;
    StartWrite(&chunk_);
  }

  JobManager* manager_;
  const std::string job_id_;
  uint64_t offset_;
  uint64_t chunk_bytes_;
  uint64_t total_ = 0;
  std::string sha256_;
  bool sent_any_ = false;
  v1::ResultChunk chunk_;
};

}  // namespace

grpc::ServerUnaryReactor* MeshingServiceImpl::SubmitJob(grpc::CallbackServerContext* context,
                                                        const v1::SubmitJobRequest* request,
                                                        v1::Job* response) {
  absl::StatusOr<std::string> owner = Caller(context);
  if (!owner.ok()) return FinishUnary<v1::Job>(context, owner.status(), response);
  // One copy of the (<= 4 MiB) request; the manager owns it from here.
  return FinishUnary(context, manager_->Submit(*request, *owner), response);
}

grpc::ServerReadReactor<v1::UploadJobRequest>* MeshingServiceImpl::UploadJob(
    grpc::CallbackServerContext* context, v1::Job* response) {
  return new UploadReactor(context, manager_, max_upload_bytes_, response, Caller(context));
}

grpc::ServerWriteReactor<v1::JobEvent>* MeshingServiceImpl::WatchJob(
    grpc::CallbackServerContext* context, const v1::WatchJobRequest* request) {
  return new WatchReactor(manager_, request->job_id(), Caller(context));
}

grpc::ServerUnaryReactor* MeshingServiceImpl::GetJob(grpc::CallbackServerContext* context,
                                                     const v1::GetJobRequest* request,
                                                     v1::Job* response) {
  absl::StatusOr<std::string> owner = Caller(context);
  if (!owner.ok()) return FinishUnary<v1::Job>(context, owner.status(), response);
  return FinishUnary(context, manager_->Get(request->job_id(), *owner), response);
}

grpc::ServerUnaryReactor* MeshingServiceImpl::ListJobs(grpc::CallbackServerContext* context,
                                                       const v1::ListJobsRequest* request,
                                                       v1::ListJobsResponse* response) {
  absl::StatusOr<std::string> owner = Caller(context);
  if (!owner.ok()) return FinishUnary<v1::ListJobsResponse>(context, owner.status(), response);
  return FinishUnary(context, manager_->List(*request, *owner), response);
}

grpc::ServerUnaryReactor* MeshingServiceImpl::CancelJob(grpc::CallbackServerContext* context,
                                                        const v1::CancelJobRequest* request,
                                                        v1::Job* response) {
  absl::StatusOr<std::string> owner = Caller(context);
  if (!owner.ok()) return FinishUnary<v1::Job>(context, owner.status(), response);
  return FinishUnary(context, manager_->Cancel(request->job_id(), *owner), response);
}

grpc::ServerUnaryReactor* MeshingServiceImpl::DeleteJob(grpc::CallbackServerContext* context,
                                                        const v1::DeleteJobRequest* request,
                                                        v1::DeleteJobResponse* response) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  absl::StatusOr<std::string> owner = Caller(context);
  reactor->Finish(ToGrpcStatus(owner.ok() ? manager_->Delete(request->job_id(), *owner)
                                          : owner.status()));
  return reactor;
}

grpc::ServerWriteReactor<v1::ResultChunk>* MeshingServiceImpl::FetchResult(
    grpc::CallbackServerContext* context, const v1::FetchResultRequest* request) {
  return new FetchReactor(manager_, *request, Caller(context));
}

absl::StatusOr<std::string> MeshingServiceImpl::Caller(grpc::CallbackServerContext* context) const {
  if (auth_ == nullptr) return std::string();
  absl::StatusOr<std::string> client = auth_->Authenticate(*context);
  if (!client.ok()) {
    ServerLog().warn("refused a call from {}: {}", context->peer(),
                     std::string(client.status().message()));
  }
  return client;
}

}  // namespace svrc::server
