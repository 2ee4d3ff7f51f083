// Conversions between the API messages (proto/svrc/v1) and the types the
// core and the shared job pipeline use (cli::MeshOptions, plc::Plc,
// plc::InputFormat), for the server and the client library alike.
#pragma once

#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "client/mesh_job.h"
#include "core/plc/plc.h"
#include "core/plc/readers.h"
#include "svrc/v1/service.pb.h"

namespace svrc::api {

// Parameters, limits and encoding of a request; validated (INVALID_ARGUMENT
// naming the field).
absl::StatusOr<cli::MeshOptions> OptionsFromRequest(const v1::SubmitJobRequest& request);
// Sets parameters/limits/encoding of `request` (only the fields `options` sets).
void OptionsToRequest(const cli::MeshOptions& options, v1::SubmitJobRequest* request);

// Structural checks only (coordinate count a multiple of 3, hole arrays of
// triples); the mesher validates geometry and indices.
absl::StatusOr<plc::Plc> PlcFromProto(const v1::Plc& proto);
void PlcToProto(const plc::Plc& plc, v1::Plc* proto);

absl::StatusOr<plc::InputFormat> FormatFromProto(v1::InputFormat format);
v1::InputFormat FormatToProto(plc::InputFormat format);

// "QUEUED", "RUNNING", ... (the enum names).
std::string JobStateName(v1::JobState state);
bool IsTerminal(v1::JobState state);

}  // namespace svrc::api
