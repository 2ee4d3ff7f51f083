#include "server/status_util.h"

#include <string>

namespace svrc::server {

grpc::Status ToGrpcStatus(const absl::Status& status) {
  if (status.ok()) return grpc::Status::OK;
  // Codes 1..16 are the same in both (absl/status/status.h says so).
  return grpc::Status(static_cast<grpc::StatusCode>(status.raw_code()),
                      std::string(status.message()));
}

v1::Status ToProtoStatus(const absl::Status& status) {
  v1::Status out;
  out.set_code(status.raw_code());
  out.set_message(std::string(status.message()));
  return out;
}

}  // namespace svrc::server
