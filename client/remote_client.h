// The C++ client of the job service (proto/svrc/v1/service.proto), used by
// the `svrc` remote commands and the integration tests: submit (unary or
// streamed upload by size, idempotent retries), watch, fetch (resumable,
// sha256-checked), and the standard health check.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "grpcpp/channel.h"
#include "grpcpp/support/status.h"
#include "svrc/v1/service.grpc.pb.h"

namespace svrc::cli {

// gRPC status → absl::Status (same code numbering).
absl::Status FromGrpcStatus(const grpc::Status& status);

// A SubmitJobRequest for the file at `path`: its bytes, its format (from the
// extension) and its base name. INVALID_ARGUMENT / NOT_FOUND when unreadable.
absl::StatusOr<v1::SubmitJobRequest> RequestForFile(const std::string& path);

// A fresh random request id (128 bits, hex).
std::string NewRequestId();

// How the client proves who it is and checks the server (docs/security.md).
struct ClientSecurity {
  std::string tls_ca;    // PEM file of the CA that signed the server; TLS when set
  std::string tls_cert;  // client certificate + key (PEM files) for mTLS
  std::string tls_key;
  std::string token;     // bearer token sent as "authorization: Bearer ..."
};

// A ClientSecurity from the CLI's --tls-ca/--tls-cert/--tls-key/--token-file
// values (empty: unset); without --token-file the token comes from the
// environment variable SVRC_TOKEN when set. Reads the token file.
absl::StatusOr<ClientSecurity> SecurityFromFlags(const std::string& tls_ca,
                                                 const std::string& tls_cert,
                                                 const std::string& tls_key,
                                                 const std::string& token_file);

struct FetchedResult {
  std::string bytes;   // the whole container
  std::string sha256;  // hex, checked against `bytes`
};

class RemoteClient {
 public:
  // Files larger than this go through UploadJob (the default gRPC message
  // limit is 4 MiB; the rest of the request needs room too).
  static constexpr uint64_t kUnaryInputLimit = 3 << 20;
  static constexpr uint64_t kUploadChunkBytes = 1 << 20;

  // "host:port"; connects lazily on the first call.
  explicit RemoteClient(const std::string& target,
                        absl::Duration rpc_timeout = absl::Seconds(60));
  // With TLS and/or a bearer token. TLS files that cannot be read make every
  // call fail with the reading error (status()).
  RemoteClient(const std::string& target, const ClientSecurity& security,
               absl::Duration rpc_timeout = absl::Seconds(60));

  // Fills request_id when empty so that retries (UNAVAILABLE, up to
  // `attempts` calls) are idempotent; large files are streamed.
  absl::StatusOr<v1::Job> Submit(v1::SubmitJobRequest request, int attempts = 3);
  absl::StatusOr<v1::Job> Get(const std::string& job_id);
  absl::StatusOr<v1::ListJobsResponse> List(const v1::ListJobsRequest& request);
  absl::StatusOr<v1::Job> Cancel(const std::string& job_id);
  absl::Status Delete(const std::string& job_id);

  // Streams the job's events to `on_event` (may be null) until its terminal
  // state, which is returned. A broken stream is re-opened (the server sends
  // the current state first) up to `reconnects` times.
  absl::StatusOr<v1::Job> Watch(const std::string& job_id,
                                const std::function<void(const v1::JobEvent&)>& on_event,
                                int reconnects = 3);

  // One FetchResult stream from `offset`, appending to *bytes; returns the
  // total size and sha256 the server announced (without checking them).
  absl::Status FetchFrom(const std::string& job_id, uint64_t offset, std::string* bytes,
                         uint64_t* total_size, std::string* sha256,
                         uint32_t max_chunk_bytes = 0);
  // The whole result: resumes from the bytes it has when a stream breaks
  // (up to `attempts` streams), then checks size and sha256 (DATA_LOSS).
  absl::StatusOr<FetchedResult> Fetch(const std::string& job_id, int attempts = 3);

  // True when the server's health service reports SERVING.
  absl::StatusOr<bool> Serving();

  v1::MeshingService::Stub& stub() { return *stub_; }

 private:
  // Sets the per-call deadline and the bearer token.
  void SetDeadline(grpc::ClientContext* context) const;
  void Authorize(grpc::ClientContext* context) const;
  absl::StatusOr<v1::Job> SubmitOnce(const v1::SubmitJobRequest& request);

  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::MeshingService::Stub> stub_;
  absl::Duration rpc_timeout_;
  std::string token_;
};

}  // namespace svrc::cli
