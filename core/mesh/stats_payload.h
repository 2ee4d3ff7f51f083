// A failed run's counters travel with its status: the refiner attaches its
// MeshStats to a non-OK absl::Status as a payload, so `svrc mesh --stats` and
// tests can read how far a run got and where its work went (vertices, yields,
// collar rounds, ...) when it hit a deadline, the vertex budget or a
// precondition. Text payload: one "name<TAB>value" line per counter, values
// printed with 17 significant digits (round-trip exact for doubles).
#pragma once

#include <optional>
#include "absl/strings/string_view.h"

#include "absl/status/status.h"
#include "core/mesh/tet_mesh.h"

namespace svrc::mesh {

inline constexpr char kStatsPayloadUrl[] = "type.svrc.dev/svrc.MeshStats";

// Sets (or replaces) the stats payload of a non-OK status; no-op on OK.
void AttachStats(const MeshStats& stats, absl::Status* status);

// The stats payload of `status`, if any (nullopt also for a malformed one).
std::optional<MeshStats> StatsOf(const absl::Status& status);

// A status with `code` and `message` that keeps every payload of `from`
// (callers that re-word an error must not drop its counters).
absl::Status Rewrap(absl::StatusCode code, absl::string_view message, const absl::Status& from);

}  // namespace svrc::mesh
