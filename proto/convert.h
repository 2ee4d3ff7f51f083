// Conversions between the API messages (proto/svrc/v1) and the core's types
// (core::MeshParams, plc::Plc, plc::InputFormat), shared by the server and
// the client so that a remote job and `svrc mesh` run the same parameters.
#pragma once

#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "core/api.h"
#include "core/plc/plc.h"
#include "core/plc/readers.h"
#include "svrc/v1/service.pb.h"

namespace svrc::api {

// Unset fields keep the core's defaults; limits.max_vertices becomes
// MeshParams::max_vertices. INVALID_ARGUMENT for non-finite or out-of-domain
// values (the field is named).
absl::StatusOr<core::MeshParams> ParamsFromProto(const v1::MeshParameters& params,
                                                 const v1::JobLimits& limits);

// Rejects (UNIMPLEMENTED) parameters the mesher would otherwise ignore for
// this input: a point set is tetrahedralized as given, so the refinement
// parameters set explicitly in `params` have no implementation for it.
// Called by the server's workers and by `svrc mesh` alike.
absl::Status CheckImplemented(const v1::MeshParameters& params, const plc::Plc& plc);

// INVALID_ARGUMENT when quantization_bits is out of 0..24.
absl::Status ValidateEncoding(const v1::EncodingOptions& encoding);

// Zero when unset; INVALID_ARGUMENT when negative or malformed.
absl::StatusOr<absl::Duration> DeadlineFromProto(const v1::JobLimits& limits);

// Structural checks only (coordinate count a multiple of 3, hole/seed arrays
// of triples); the mesher validates the geometry and the indices.
absl::StatusOr<plc::Plc> PlcFromProto(const v1::Plc& proto);
void PlcToProto(const plc::Plc& plc, v1::Plc* proto);

absl::StatusOr<plc::InputFormat> FormatFromProto(v1::InputFormat format);
v1::InputFormat FormatToProto(plc::InputFormat format);

// "QUEUED", "RUNNING", ... (the enum names).
std::string JobStateName(v1::JobState state);
bool IsTerminal(v1::JobState state);

}  // namespace svrc::api

namespace svrc::api {

// The one meshing pipeline the server's workers and `svrc mesh` share:
// CheckImplemented, the max_vertices limit against the input (the output
// keeps every input vertex), ParamsFromProto, then core::MeshPlc.
absl::StatusOr<mesh::TetMesh> MeshWithParameters(const plc::Plc& plc,
                                                 const v1::MeshParameters& params,
                                                 const v1::JobLimits& limits,
                                                 const core::ProgressCallback& progress,
                                                 const core::CancelToken* cancel);

}  // namespace svrc::api
