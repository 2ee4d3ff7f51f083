#include "core/mesh/stats_payload.h"

#include <cstdio>
#include <cstdlib>
#include <string>

#include "absl/strings/cord.h"
#include "absl/strings/str_split.h"

namespace svrc::mesh {

void AttachStats(const MeshStats& stats, absl::Status* status) {
  if (status->ok()) return;
  std::string text;
  char buf[64];
  for (const auto& [name, value] : stats.counters) {
    std::snprintf(buf, sizeof buf, "%.17g", value);
    text.append(name).append("\t").append(buf).append("\n");
  }
  status->SetPayload(kStatsPayloadUrl, absl::Cord(text));
}

std::optional<MeshStats> StatsOf(const absl::Status& status) {
  const auto payload = status.GetPayload(kStatsPayloadUrl);
  if (!payload.has_value()) return std::nullopt;
  MeshStats stats;
  const std::string text(*payload);
  for (absl::string_view line : absl::StrSplit(text, '\n', absl::SkipEmpty())) {
    const size_t tab = line.find('\t');
    if (tab == absl::string_view::npos || tab == 0) return std::nullopt;
    const std::string value(line.substr(tab + 1));
    char* end = nullptr;
    const double v = std::strtod(value.c_str(), &end);  // %.17g round-trips, subnormals included
    if (end == value.c_str() || *end != '\0') return std::nullopt;
    stats.counters.emplace_back(std::string(line.substr(0, tab)), v);
  }
  return stats;
}

absl::Status Rewrap(absl::StatusCode code, absl::string_view message, const absl::Status& from) {
  absl::Status out(code, message);
  from.ForEachPayload([&](absl::string_view url, const absl::Cord& payload) { out.SetPayload(url, payload); });
  return out;
}

}  // namespace svrc::mesh
