// The gRPC face of the job service (proto/svrc/v1/service.proto): a thin
// callback-API adapter over JobManager. No reaction blocks: long work runs on
// the manager's worker threads; watchers get coalesced snapshots.
#pragma once

#include <cstdint>

#include "server/auth.h"
#include "server/job_manager.h"
#include "svrc/v1/service.grpc.pb.h"

namespace svrc::server {

class MeshingServiceImpl final : public v1::MeshingService::CallbackService {
 public:
  // Result chunks are at most this big (the API promises <= 1 MiB).
  static constexpr uint32_t kMaxChunkBytes = 1 << 20;

  // With `auth` (may be null: no authentication, every caller is client ""),
  // every call needs a valid bearer token and sees only its client's jobs.
  MeshingServiceImpl(JobManager* manager, uint64_t max_upload_bytes,
                     const TokenAuth* auth = nullptr)
      : manager_(manager), max_upload_bytes_(max_upload_bytes), auth_(auth) {}

  grpc::ServerUnaryReactor* SubmitJob(grpc::CallbackServerContext* context,
                                      const v1::SubmitJobRequest* request,
                                      v1::Job* response) override;
  grpc::ServerReadReactor<v1::UploadJobRequest>* UploadJob(grpc::CallbackServerContext* context,
                                                           v1::Job* response) override;
  grpc::ServerWriteReactor<v1::JobEvent>* WatchJob(grpc::CallbackServerContext* context,
                                                   const v1::WatchJobRequest* request) override;
  grpc::ServerUnaryReactor* GetJob(grpc::CallbackServerContext* context,
                                   const v1::GetJobRequest* request, v1::Job* response) override;
  grpc::ServerUnaryReactor* ListJobs(grpc::CallbackServerContext* context,
                                     const v1::ListJobsRequest* request,
                                     v1::ListJobsResponse* response) override;
  grpc::ServerUnaryReactor* CancelJob(grpc::CallbackServerContext* context,
                                      const v1::CancelJobRequest* request,
                                      v1::Job* response) override;
  grpc::ServerUnaryReactor* DeleteJob(grpc::CallbackServerContext* context,
                                      const v1::DeleteJobRequest* request,
                                      v1::DeleteJobResponse* response) override;
  grpc::ServerWriteReactor<v1::ResultChunk>* FetchResult(
      grpc::CallbackServerContext* context, const v1::FetchResultRequest* request) override;

 private:
  // The calling client's name ("" without auth) or UNAUTHENTICATED.
  absl::StatusOr<std::string> Caller(grpc::CallbackServerContext* context) const;

  JobManager* manager_;
  const uint64_t max_upload_bytes_;
  const TokenAuth* auth_;
};

}  // namespace svrc::server
