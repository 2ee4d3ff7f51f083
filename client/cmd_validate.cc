// `svrc validate IN`: reads a PLC, validates it, prints its summary (counts,
// creases, spread) and every problem found. Exit 0 valid, 3 invalid, 2 usage.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "client/command.h"
#include "core/plc/features.h"
#include "core/plc/readers.h"
#include "core/plc/validate.h"

namespace svrc::cli {
namespace {

int RunValidate(const std::vector<std::string>& args) {
  std::string in;
  bool quiet = false;
  for (const std::string& a : args) {
    if (a == "-q" || a == "--quiet") {
      quiet = true;
    } else if (a == "-h" || a == "--help") {
      std::printf("usage: svrc validate IN [-q]\n");
      return kExitOk;
    } else if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr, "svrc validate: unknown option '%s'\n", a.c_str());
      return kExitUsage;
    } else if (in.empty()) {
      in = a;
    } else {
      std::fprintf(stderr, "svrc validate: one input file expected\n");
      return kExitUsage;
    }
  }
  if (in.empty()) {
    std::fprintf(stderr, "usage: svrc validate IN [-q]\n");
    return kExitUsage;
  }
  absl::StatusOr<plc::Plc> p = plc::ReadPlcFile(in);
  if (!p.ok()) {
    std::fprintf(stderr, "svrc validate: %s\n", std::string(p.status().message()).c_str());
    if (p.status().code() == absl::StatusCode::kInvalidArgument) {
      std::printf("INVALID: %s\n", std::string(p.status().message()).c_str());
      return kExitInvalidInput;
    }
    return kExitUsage;  // cannot open / unknown extension
  }
  size_t polygons = 0, facet_holes = 0;
  for (const plc::Facet& f : p->facets) {
    polygons += f.polygons.size();
    facet_holes += f.holes.size();
  }
  std::printf("input      %s (%s, sha256 %s)\n", in.c_str(),
              std::string(plc::FormatName(*plc::FormatFromPath(in))).c_str(), p->input_sha256.c_str());
  std::printf("vertices   %zu\n", p->vertices.size());
  std::printf("segments   %zu free\n", p->segments.size());
  std::printf("facets     %zu (%zu polygons, %zu facet holes", p->facets.size(), polygons, facet_holes);
  if (p->is_surface) std::printf("; %u input faces", p->input_face_count);
  std::printf(")\n");
  std::printf("regions    %zu\n", p->regions.size());
  std::printf("holes      %zu\n", p->holes.size());
  plc::ValidationReport report;
  absl::StatusOr<plc::FeatureComplex> fc =
      plc::PreparePlc(*p, plc::ValidationOptions{}, plc::FeatureOptions{}, &report);
  if (fc.ok()) {
    size_t isolated = 0;
    for (const plc::FeaturePoint& q : fc->points) isolated += q.isolated;
    std::printf("complex    %zu points (%zu isolated), %zu segments, %zu facets\n", fc->points.size(),
                isolated, fc->segments.size(), fc->facets.size());
    std::printf("creases    %zu segments, %zu vertices (angle < 90 deg)\n", fc->NumCreaseSegments(),
                fc->NumCreasePoints());
    std::string where;
    const double sharpest = fc->SharpestAngleDeg(&where);
    if (std::isfinite(sharpest)) std::printf("sharpest   %.6g deg at %s\n", sharpest, where.c_str());
    std::printf("spread     %.6g (diameter %.6g / min distance between disjoint features %.6g)\n",
                fc->spread, fc->diameter, fc->min_feature_distance);
    if (!fc->closest_features.empty()) std::printf("closest    %s\n", fc->closest_features.c_str());
  }
  for (const plc::Problem& w : report.warnings) std::printf("warning: %s\n", w.message.c_str());
  for (const plc::Problem& e : report.errors) std::printf("error: %s\n", e.message.c_str());
  if (!report.ok()) {
    std::printf("INVALID (%zu errors)\n", report.errors.size());
    if (!quiet) std::fprintf(stderr, "svrc validate: %s is invalid\n", in.c_str());
    return kExitInvalidInput;
  }
  std::printf("VALID\n");
  return kExitOk;
}

const RegisterCommand kRegValidate{{"validate", "validate IN [-q]", &RunValidate}};

}  // namespace
}  // namespace svrc::cli
