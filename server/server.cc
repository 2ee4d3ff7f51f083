#include "server/server.h"

#include "absl/strings/str_cat.h"
#include "grpcpp/ext/proto_server_reflection_plugin.h"
#include "grpcpp/health_check_service_interface.h"
#include "grpcpp/security/server_credentials.h"
#include "grpc/grpc.h"
#include "grpcpp/server_builder.h"
#include "server/log.h"

namespace svrc::server {

absl::StatusOr<std::unique_ptr<Server>> Server::Start(const ServerOptions& options) {
  if (options.workers < 1) return absl::InvalidArgumentError("--workers must be >= 1");
  if (options.queue_capacity < 1) return absl::InvalidArgumentError("--queue-capacity must be >= 1");
  const size_t colon = options.listen.rfind(':');
  if (colon == std::string::npos || colon == 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("--listen must be HOST:PORT, got '", options.listen, "'"));
  }
  absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> credentials =
      MakeServerCredentials(options.tls_cert, options.tls_key, options.tls_client_ca);
  if (!credentials.ok()) return credentials.status();
  std::unique_ptr<TokenAuth> auth;
  if (!options.token_file.empty()) {
    absl::StatusOr<std::unique_ptr<TokenAuth>> loaded = TokenAuth::Load(options.token_file);
    if (!loaded.ok()) return loaded.status();
    auth = *std::move(loaded);
  }
  absl::StatusOr<std::unique_ptr<DiskResultStore>> store =
      DiskResultStore::Open(options.data_dir, options.disk_quota_bytes);
  if (!store.ok()) return store.status();
  absl::StatusOr<std::unique_ptr<Journal>> journal = Journal::Open(options.data_dir);
  if (!journal.ok()) return journal.status();

  std::unique_ptr<Server> server(new Server());
  server->options_ = options;
  server->auth_ = std::move(auth);
  JobManagerOptions jm;
  jm.workers = options.workers;
  jm.max_input_bytes = options.max_upload_bytes;
  jm.retention = options.retention;
  jm.progress_interval = options.progress_interval;
  jm.max_jobs_per_client = options.max_jobs_per_client;
  jm.max_job_memory_bytes = options.max_job_memory_bytes;
  server->manager_ = std::make_unique<JobManager>(
      jm, std::make_unique<InMemoryJobQueue>(options.queue_capacity), *std::move(store),
      *std::move(journal));
  server->service_ =
      std::make_unique<MeshingServiceImpl>(server->manager_.get(), options.max_upload_bytes,
                                           server->auth_.get());

  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder builder;
  // Without this, a second server on a busy port would share it silently.
  builder.AddChannelArgument(GRPC_ARG_ALLOW_REUSEPORT, 0);
  builder.AddListeningPort(options.listen, *credentials, &server->port_);
  builder.RegisterService(server->service_.get());
  server->grpc_server_ = builder.BuildAndStart();
  if (server->grpc_server_ == nullptr || server->port_ == 0) {
    server->manager_->Shutdown(absl::ZeroDuration());
    server->shut_down_ = true;
    return absl::UnavailableError(absl::StrCat("cannot listen on ", options.listen));
  }
  server->address_ = absl::StrCat(options.listen.substr(0, colon), ":", server->port_);
  server->grpc_server_->GetHealthCheckService()->SetServingStatus(true);
  ServerLog().info("listening on {} ({} workers, queue capacity {}, data dir {}, {}, {})",
                   server->address_, options.workers, options.queue_capacity, options.data_dir,
                   options.tls_cert.empty() ? "plaintext"
                                            : (options.tls_client_ca.empty() ? "TLS" : "mTLS"),
                   server->auth_ ? absl::StrCat(server->auth_->size(), " bearer tokens")
                                 : std::string("no authentication"));
  return server;
}

Server::~Server() { Shutdown(); }

void Server::Shutdown() {
  if (shut_down_) return;
  shut_down_ = true;
  ServerLog().info("shutting down: no new jobs, {} s grace for running jobs",
                   absl::ToDoubleSeconds(options_.grace_period));
  grpc_server_->GetHealthCheckService()->SetServingStatus(false);
  // Jobs end first (watchers receive their terminal states), then the RPCs.
  manager_->Shutdown(options_.grace_period);
  grpc_server_->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(2));
  grpc_server_->Wait();
  ServerLog().info("stopped");
}

void Server::Wait() { grpc_server_->Wait(); }

}  // namespace svrc::server
