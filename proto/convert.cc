#include "proto/convert.h"

#include <cmath>
#include <vector>

#include "absl/strings/str_cat.h"
#include "google/protobuf/util/time_util.h"

namespace svrc::api {
namespace {

absl::Status ReadTriples(const google::protobuf::RepeatedField<double>& values,
                         const char* what, std::vector<geom::Vec3>* out) {
  if (values.size() % 3 != 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("plc.", what, " has ", values.size(), " numbers, not a multiple of 3"));
  }
  out->reserve(values.size() / 3);
  for (int i = 0; i < values.size(); i += 3) {
    out->push_back(geom::Vec3(values[i], values[i + 1], values[i + 2]));
  }
  return absl::OkStatus();
}

void WriteTriples(const std::vector<geom::Vec3>& points,
                  google::protobuf::RepeatedField<double>* out) {
  out->Reserve(static_cast<int>(points.size() * 3));
  for (const geom::Vec3& p : points) {
    out->Add(p.x);
    out->Add(p.y);
    out->Add(p.z);
  }
}

}  // namespace

absl::StatusOr<cli::MeshOptions> OptionsFromRequest(const v1::SubmitJobRequest& request) {
  const v1::MeshParameters& p = request.parameters();
  cli::MeshOptions o;
  if (p.has_radius_edge()) o.radius_edge = p.radius_edge();
  if (p.has_theta()) o.theta = p.theta();
  if (p.has_max_rep_angle()) o.max_rep_angle = p.max_rep_angle();
  if (p.has_max_volume()) o.max_volume = p.max_volume();
  if (p.has_min_dihedral()) o.min_dihedral = p.min_dihedral();
  if (p.has_keep_bounding_box()) o.keep_bounding_box = p.keep_bounding_box();
  if (p.has_collar_size_eps()) o.collar_size_eps = p.collar_size_eps();
  if (p.has_collar_cell_test()) o.collar_cell_test = p.collar_cell_test();
  o.max_vertices = request.limits().max_vertices();
  if (request.limits().has_deadline()) {
    const auto& d = request.limits().deadline();
    if (d.seconds() < 0 || d.nanos() < 0 || d.nanos() > 999999999 ||
        d.seconds() > google::protobuf::util::TimeUtil::kDurationMaxSeconds) {
      return absl::InvalidArgumentError("limits.deadline must be a valid non-negative duration");
    }
    o.deadline = absl::Seconds(d.seconds()) + absl::Nanoseconds(d.nanos());
  }
  if (request.encoding().quantization_bits() > 24) {
    return absl::InvalidArgumentError(absl::StrCat(
        "quantization_bits must be 0 (lossless) or 1..24, got ",
        request.encoding().quantization_bits()));
  }
  o.quantization_bits = static_cast<int>(request.encoding().quantization_bits());
  if (absl::Status s = cli::ValidateOptions(o); !s.ok()) return s;
  return o;
}

void OptionsToRequest(const cli::MeshOptions& o, v1::SubmitJobRequest* request) {
  v1::MeshParameters* p = request->mutable_parameters();
  if (o.radius_edge) p->set_radius_edge(*o.radius_edge);
  if (o.theta) p->set_theta(*o.theta);
  if (o.max_rep_angle) p->set_max_rep_angle(*o.max_rep_angle);
  if (o.max_volume) p->set_max_volume(*o.max_volume);
  if (o.min_dihedral) p->set_min_dihedral(*o.min_dihedral);
  if (o.keep_bounding_box) p->set_keep_bounding_box(*o.keep_bounding_box);
  if (o.collar_size_eps) p->set_collar_size_eps(*o.collar_size_eps);
  if (o.collar_cell_test) p->set_collar_cell_test(*o.collar_cell_test);
  if (o.max_vertices > 0) request->mutable_limits()->set_max_vertices(o.max_vertices);
  if (o.deadline > absl::ZeroDuration()) {
    const int64_t ns = absl::ToInt64Nanoseconds(o.deadline);
    request->mutable_limits()->mutable_deadline()->set_seconds(ns / 1000000000);
    request->mutable_limits()->mutable_deadline()->set_nanos(static_cast<int32_t>(ns % 1000000000));
  }
  if (o.quantization_bits > 0) {
    request->mutable_encoding()->set_quantization_bits(static_cast<uint32_t>(o.quantization_bits));
  }
}

absl::StatusOr<plc::Plc> PlcFromProto(const v1::Plc& proto) {
  plc::Plc out;
  if (auto s = ReadTriples(proto.coordinates(), "coordinates", &out.vertices); !s.ok()) return s;
  if (!proto.vertex_markers().empty() &&
      static_cast<size_t>(proto.vertex_markers_size()) != out.vertices.size()) {
    return absl::InvalidArgumentError(absl::StrCat("plc.vertex_markers has ",
                                                   proto.vertex_markers_size(), " entries for ",
                                                   out.vertices.size(), " vertices"));
  }
  out.vertex_markers.assign(proto.vertex_markers().begin(), proto.vertex_markers().end());
  out.segments.reserve(proto.segments_size());
  for (const v1::Segment& s : proto.segments()) {
    out.segments.push_back(plc::Segment{s.a(), s.b(), s.marker()});
  }
  out.facets.reserve(proto.facets_size());
  for (int f = 0; f < proto.facets_size(); ++f) {
    const v1::Facet& pf = proto.facets(f);
    plc::Facet facet;
    facet.marker = pf.marker();
    for (const v1::Polygon& poly : pf.polygons()) {
      facet.polygons.push_back(plc::Polygon{{poly.vertices().begin(), poly.vertices().end()}});
    }
    if (pf.holes_size() % 3 != 0) {
      return absl::InvalidArgumentError(
          absl::StrCat("plc.facets[", f, "].holes is not a list of x y z triples"));
    }
    for (int i = 0; i < pf.holes_size(); i += 3) {
      facet.holes.push_back(geom::Vec3(pf.holes(i), pf.holes(i + 1), pf.holes(i + 2)));
    }
    out.facets.push_back(std::move(facet));
  }
  if (auto s = ReadTriples(proto.holes(), "holes", &out.holes); !s.ok()) return s;
  for (const v1::RegionSeed& r : proto.regions()) {
    out.regions.push_back(
        plc::RegionSeed{geom::Vec3(r.x(), r.y(), r.z()), r.attribute(), r.max_volume()});
  }
  out.source_name = "<memory>";
  return out;
}

void PlcToProto(const plc::Plc& plc, v1::Plc* proto) {
  proto->Clear();
  WriteTriples(plc.vertices, proto->mutable_coordinates());
  proto->mutable_vertex_markers()->Add(plc.vertex_markers.begin(), plc.vertex_markers.end());
  for (const plc::Segment& s : plc.segments) {
    v1::Segment* ps = proto->add_segments();
    ps->set_a(s.a);
    ps->set_b(s.b);
    ps->set_marker(s.marker);
  }
  for (const plc::Facet& f : plc.facets) {
    v1::Facet* pf = proto->add_facets();
    pf->set_marker(f.marker);
    for (const plc::Polygon& poly : f.polygons) {
      pf->add_polygons()->mutable_vertices()->Add(poly.vertices.begin(), poly.vertices.end());
    }
    WriteTriples(f.holes, pf->mutable_holes());
  }
  WriteTriples(plc.holes, proto->mutable_holes());
  for (const plc::RegionSeed& r : plc.regions) {
    v1::RegionSeed* pr = proto->add_regions();
    pr->set_x(r.point.x);
    pr->set_y(r.point.y);
    pr->set_z(r.point.z);
    pr->set_attribute(r.attribute);
    pr->set_max_volume(r.max_volume);
  }
}

absl::StatusOr<plc::InputFormat> FormatFromProto(v1::InputFormat format) {
  switch (format) {
    case v1::POLY: return plc::InputFormat::kPoly;
    case v1::SMESH: return plc::InputFormat::kSmesh;
    case v1::NODE: return plc::InputFormat::kNode;
    case v1::OFF: return plc::InputFormat::kOff;
    case v1::STL: return plc::InputFormat::kStl;
    case v1::OBJ: return plc::InputFormat::kObj;
    case v1::MEDIT: return plc::InputFormat::kMedit;
    default:
      return absl::InvalidArgumentError(
          absl::StrCat("input file format missing or unknown (", static_cast<int>(format), ")"));
  }
}

v1::InputFormat FormatToProto(plc::InputFormat format) {
  switch (format) {
    case plc::InputFormat::kPoly: return v1::POLY;
    case plc::InputFormat::kSmesh: return v1::SMESH;
    case plc::InputFormat::kNode: return v1::NODE;
    case plc::InputFormat::kOff: return v1::OFF;
    case plc::InputFormat::kStl: return v1::STL;
    case plc::InputFormat::kObj: return v1::OBJ;
    case plc::InputFormat::kMedit: return v1::MEDIT;
  }
  return v1::INPUT_FORMAT_UNSPECIFIED;
}

std::string JobStateName(v1::JobState state) { return v1::JobState_Name(state); }

bool IsTerminal(v1::JobState state) {
  return state == v1::SUCCEEDED || state == v1::FAILED || state == v1::CANCELLED;
}

}  // namespace svrc::api
