#include "client/remote_client.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <fstream>
#include <sstream>
#include <thread>

#include "absl/random/random.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/plc/readers.h"
#include "core/util/sha256.h"
#include "grpc/health/v1/health.grpc.pb.h"
#include "grpcpp/client_context.h"
#include "grpcpp/create_channel.h"
#include "grpcpp/security/credentials.h"
#include "proto/convert.h"

namespace svrc::cli {

absl::Status FromGrpcStatus(const grpc::Status& status) {
  if (status.ok()) return absl::OkStatus();
  return absl::Status(static_cast<absl::StatusCode>(status.error_code()), status.error_message());
}

absl::StatusOr<v1::SubmitJobRequest> RequestForFile(const std::string& path) {
  absl::StatusOr<plc::InputFormat> format = plc::FormatFromPath(path);
  if (!format.ok()) return format.status();
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::NotFoundError(absl::StrCat("cannot read ", path));
  std::ostringstream data;
  data << in.rdbuf();
  if (in.bad()) return absl::DataLossError(absl::StrCat("error reading ", path));
  v1::SubmitJobRequest request;
  request.mutable_file()->set_format(api::FormatToProto(*format));
  request.mutable_file()->set_data(std::move(data).str());
  request.mutable_file()->set_name(std::filesystem::path(path).filename().string());
  return request;
}

std::string NewRequestId() {
  absl::BitGen gen;
  return absl::StrFormat("%016x%016x", absl::Uniform<uint64_t>(gen), absl::Uniform<uint64_t>(gen));
}

RemoteClient::RemoteClient(const std::string& target, absl::Duration rpc_timeout)
    : channel_(grpc::CreateChannel(target, grpc::InsecureChannelCredentials())),
      stub_(v1::MeshingService::NewStub(channel_)),
      rpc_timeout_(rpc_timeout) {}

namespace {

std::string ReadOrEmpty(const std::string& path, bool* ok) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    *ok = false;
    return "";
  }
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::shared_ptr<grpc::ChannelCredentials> Credentials(const ClientSecurity& s) {
  if (s.tls_ca.empty() && s.tls_cert.empty()) return grpc::InsecureChannelCredentials();
  grpc::SslCredentialsOptions options;
  bool ok = true;
  if (!s.tls_ca.empty()) options.pem_root_certs = ReadOrEmpty(s.tls_ca, &ok);
  if (!s.tls_cert.empty()) options.pem_cert_chain = ReadOrEmpty(s.tls_cert, &ok);
  if (!s.tls_key.empty()) options.pem_private_key = ReadOrEmpty(s.tls_key, &ok);
  if (!ok) std::fprintf(stderr, "svrc: cannot read a TLS file (--tls-ca/--tls-cert/--tls-key)\n");
  return grpc::SslCredentials(options);
}

}  // namespace

absl::StatusOr<ClientSecurity> SecurityFromFlags(const std::string& tls_ca,
                                                 const std::string& tls_cert,
                                                 const std::string& tls_key,
                                                 const std::string& token_file) {
  ClientSecurity s;
  s.tls_ca = tls_ca;
  s.tls_cert = tls_cert;
  s.tls_key = tls_key;
  if (tls_cert.empty() != tls_key.empty()) {
    return absl::InvalidArgumentError("--tls-cert and --tls-key go together");
  }
  for (const std::string* path : {&tls_ca, &tls_cert, &tls_key}) {
    if (!path->empty() && !std::filesystem::exists(*path)) {
      return absl::NotFoundError(absl::StrCat("cannot read ", *path));
    }
  }
  if (!token_file.empty()) {
    bool ok = true;
    s.token = ReadOrEmpty(token_file, &ok);
    if (!ok) return absl::NotFoundError(absl::StrCat("cannot read ", token_file));
    while (!s.token.empty() && (s.token.back() == '\n' || s.token.back() == '\r' ||
                                s.token.back() == ' ')) {
      s.token.pop_back();
    }
    if (s.token.empty()) return absl::InvalidArgumentError(absl::StrCat(token_file, " is empty"));
  } else if (const char* env = std::getenv("SVRC_TOKEN"); env != nullptr) {
    s.token = env;
  }
  return s;
}

RemoteClient::RemoteClient(const std::string& target, const ClientSecurity& security,
                           absl::Duration rpc_timeout)
    : channel_(grpc::CreateChannel(target, Credentials(security))),
      stub_(v1::MeshingService::NewStub(channel_)),
      rpc_timeout_(rpc_timeout),
      token_(security.token) {}

void RemoteClient::Authorize(grpc::ClientContext* context) const {
  if (!token_.empty()) context->AddMetadata("authorization", "Bearer " + token_);
}

void RemoteClient::SetDeadline(grpc::ClientContext* context) const {
  context->set_deadline(std::chrono::system_clock::now() + absl::ToChronoMilliseconds(rpc_timeout_));
  Authorize(context);
}

absl::StatusOr<v1::Job> RemoteClient::SubmitOnce(const v1::SubmitJobRequest& request) {
  grpc::ClientContext context;
  SetDeadline(&context);
  v1::Job job;
  if (!request.has_file() || request.file().data().size() <= kUnaryInputLimit) {
    absl::Status status = FromGrpcStatus(stub_->SubmitJob(&context, request, &job));
    if (!status.ok()) return status;
    return job;
  }
  std::unique_ptr<grpc::ClientWriter<v1::UploadJobRequest>> writer = stub_->UploadJob(&context, &job);
  v1::UploadJobRequest header;
  *header.mutable_header() = request;
  header.mutable_header()->mutable_file()->clear_data();
  header.set_total_bytes(request.file().data().size());
  bool ok = writer->Write(header);
  const std::string& data = request.file().data();
  v1::UploadJobRequest chunk;
  for (uint64_t off = 0; ok && off < data.size(); off += kUploadChunkBytes) {
    chunk.set_chunk(data.substr(off, kUploadChunkBytes));
    ok = writer->Write(chunk);
  }
  writer->WritesDone();
  absl::Status status = FromGrpcStatus(writer->Finish());
  if (!status.ok()) return status;
  return job;
}

absl::StatusOr<v1::Job> RemoteClient::Submit(v1::SubmitJobRequest request, int attempts) {
  if (request.request_id().empty()) request.set_request_id(NewRequestId());
  absl::Status last;
  for (int i = 0; i < std::max(1, attempts); ++i) {
    if (i > 0) std::this_thread::sleep_for(std::chrono::milliseconds(200 << i));
    absl::StatusOr<v1::Job> job = SubmitOnce(request);
    if (job.ok() || job.status().code() != absl::StatusCode::kUnavailable) return job;
    last = job.status();
  }
  return last;
}

absl::StatusOr<v1::Job> RemoteClient::Get(const std::string& job_id) {
  grpc::ClientContext context;
  SetDeadline(&context);
  v1::GetJobRequest request;
  request.set_job_id(job_id);
  v1::Job job;
  absl::Status s = FromGrpcStatus(stub_->GetJob(&context, request, &job));
  if (!s.ok()) return s;
  return job;
}

absl::StatusOr<v1::ListJobsResponse> RemoteClient::List(const v1::ListJobsRequest& request) {
  grpc::ClientContext context;
  SetDeadline(&context);
  v1::ListJobsResponse response;
  absl::Status s = FromGrpcStatus(stub_->ListJobs(&context, request, &response));
  if (!s.ok()) return s;
  return response;
}

absl::StatusOr<v1::Job> RemoteClient::Cancel(const std::string& job_id) {
  grpc::ClientContext context;
  SetDeadline(&context);
  v1::CancelJobRequest request;
  request.set_job_id(job_id);
  v1::Job job;
  absl::Status s = FromGrpcStatus(stub_->CancelJob(&context, request, &job));
  if (!s.ok()) return s;
  return job;
}

absl::Status RemoteClient::Delete(const std::string& job_id) {
  grpc::ClientContext context;
  SetDeadline(&context);
  v1::DeleteJobRequest request;
  request.set_job_id(job_id);
  v1::DeleteJobResponse response;
  return FromGrpcStatus(stub_->DeleteJob(&context, request, &response));
}

absl::StatusOr<v1::Job> RemoteClient::Watch(
    const std::string& job_id, const std::function<void(const v1::JobEvent&)>& on_event,
    int reconnects) {
  v1::WatchJobRequest request;
  request.set_job_id(job_id);
  absl::Status last;
  for (int attempt = 0; attempt <= reconnects; ++attempt) {
    if (attempt > 0) std::this_thread::sleep_for(std::chrono::milliseconds(200 << attempt));
    grpc::ClientContext context;
    Authorize(&context);
    std::unique_ptr<grpc::ClientReader<v1::JobEvent>> reader = stub_->WatchJob(&context, request);
    v1::JobEvent event;
    std::optional<v1::Job> terminal;
    while (reader->Read(&event)) {
      if (on_event) on_event(event);
      if (api::IsTerminal(event.job().state())) terminal = event.job();
    }
    last = FromGrpcStatus(reader->Finish());
    if (terminal) return *terminal;
    if (last.ok()) last = absl::InternalError("watch stream ended before the job finished");
    if (last.code() != absl::StatusCode::kUnavailable && last.code() != absl::StatusCode::kInternal) {
      return last;
    }
  }
  return last;
}

absl::Status RemoteClient::FetchFrom(const std::string& job_id, uint64_t offset, std::string* bytes,
                                     uint64_t* total_size, std::string* sha256,
                                     uint32_t max_chunk_bytes) {
  grpc::ClientContext context;
  Authorize(&context);
  v1::FetchResultRequest request;
  request.set_job_id(job_id);
  request.set_offset(offset);
  request.set_max_chunk_bytes(max_chunk_bytes);
  std::unique_ptr<grpc::ClientReader<v1::ResultChunk>> reader = stub_->FetchResult(&context, request);
  v1::ResultChunk chunk;
  uint64_t expect = offset;
  absl::Status status;
  while (reader->Read(&chunk)) {
    if (chunk.offset() != expect) {
      context.TryCancel();
      status = absl::DataLossError(absl::StrCat("result chunk at offset ", chunk.offset(),
                                                ", expected ", expect));
      break;
    }
    *total_size = chunk.total_size();
    *sha256 = chunk.sha256();
    bytes->append(chunk.data());
    expect += chunk.data().size();
  }
  absl::Status finish = FromGrpcStatus(reader->Finish());
  return status.ok() ? finish : status;
}

absl::StatusOr<FetchedResult> RemoteClient::Fetch(const std::string& job_id, int attempts) {
  FetchedResult out;
  uint64_t total = 0;
  absl::Status last;
  for (int i = 0; i < std::max(1, attempts); ++i) {
    last = FetchFrom(job_id, out.bytes.size(), &out.bytes, &total, &out.sha256);
    if (last.ok()) break;
    if (last.code() != absl::StatusCode::kUnavailable) return last;
  }
  if (!last.ok()) return last;
  if (out.bytes.size() != total) {
    return absl::DataLossError(
        absl::StrCat("result has ", out.bytes.size(), " bytes, the server announced ", total));
  }
  if (util::Sha256Hex(out.bytes) != out.sha256) {
    return absl::DataLossError("result sha256 does not match the server's");
  }
  return out;
}

absl::StatusOr<bool> RemoteClient::Serving() {
  std::unique_ptr<grpc::health::v1::Health::Stub> health = grpc::health::v1::Health::NewStub(channel_);
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(5));
  grpc::health::v1::HealthCheckRequest request;
  grpc::health::v1::HealthCheckResponse response;
  absl::Status s = FromGrpcStatus(health->Check(&context, request, &response));
  if (!s.ok()) return s;
  return response.status() == grpc::health::v1::HealthCheckResponse::SERVING;
}

}  // namespace svrc::cli
