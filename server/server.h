// svrc-server as a library: options with documented defaults, Start (binds,
// starts the workers), Shutdown in the order STYLE.md asks for (stop
// accepting, drain within a grace period, cancel, join).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "grpcpp/server.h"
#include "server/job_manager.h"
#include "server/service.h"

namespace svrc::server {

struct ServerOptions {
  // HOST:PORT; port 0 picks a free port (see Server::address()).
  std::string listen = "127.0.0.1:50051";
  int workers = 2;
  size_t queue_capacity = 64;
  // Results live under DATA_DIR/results.
  std::string data_dir = "./svrc-data";
  // Result store quota in bytes; 0: unlimited.
  uint64_t disk_quota_bytes = 0;
  // Finished jobs and their results are forgotten after this time.
  absl::Duration retention = absl::Hours(24);
  // On Shutdown: how long running jobs may take before they are cancelled.
  absl::Duration grace_period = absl::Seconds(30);
  // Largest input accepted through UploadJob.
  uint64_t max_upload_bytes = uint64_t{2} << 30;
  absl::Duration progress_interval = absl::Milliseconds(100);
  // TLS: server certificate chain and private key (PEM files); with
  // tls_client_ca too, clients must present a certificate it signed (mTLS).
  std::string tls_cert, tls_key, tls_client_ca;
  // "TOKEN CLIENT_NAME" lines; empty: no authentication (docs/security.md).
  std::string token_file;
  // Queued + running jobs per client; 0: unlimited.
  int max_jobs_per_client = 0;
  // Heap one job may hold (server/memory_accounting.h); 0: unlimited.
  uint64_t max_job_memory_bytes = 0;
};

class Server {
 public:
  // Binds, registers the service, the health service (SERVING) and
  // reflection, and starts the workers. UNAVAILABLE when it cannot listen.
  static absl::StatusOr<std::unique_ptr<Server>> Start(const ServerOptions& options);
  ~Server();

  // "host:port" actually bound.
  const std::string& address() const { return address_; }
  int port() const { return port_; }
  JobManager& manager() { return *manager_; }

  // Health NOT_SERVING, no new jobs, running jobs get `options.grace_period`,
  // then the RPC server stops. Idempotent.
  void Shutdown();
  void Wait();

 private:
  Server() = default;

  ServerOptions options_;
  std::string address_;
  int port_ = 0;
  std::unique_ptr<TokenAuth> auth_;
  std::unique_ptr<JobManager> manager_;
  std::unique_ptr<MeshingServiceImpl> service_;
  std::unique_ptr<grpc::Server> grpc_server_;
  bool shut_down_ = false;
};

}  // namespace svrc::server
