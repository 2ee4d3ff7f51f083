// The one place an absl::Status becomes a grpc::Status (or the API's Status
// message). Abseil's canonical codes and gRPC's share their numbering.
#pragma once

#include "absl/status/status.h"
#include "grpcpp/support/status.h"
#include "svrc/v1/service.pb.h"

namespace svrc::server {

grpc::Status ToGrpcStatus(const absl::Status& status);
v1::Status ToProtoStatus(const absl::Status& status);

}  // namespace svrc::server
