#include "proto/convert.h"

#include <cmath>
#include <vector>

#include "absl/strings/str_cat.h"
#include "google/protobuf/util/time_util.h"

namespace svrc::api {
namespace {

absl::Status CheckFinite(const char* name, double value) {
  if (!std::isfinite(value)) {
    return absl::InvalidArgumentError(absl::StrCat(name, " must be finite, got ", value));
  }
  return absl::OkStatus();
}

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

absl::StatusOr<core::MeshParams> ParamsFromProto(const v1::MeshParameters& params,
                                                 const v1::JobLimits& limits) {
  core::MeshParams out;
  if (params.has_radius_edge()) {
    if (auto s = CheckFinite("radius_edge", params.radius_edge()); !s.ok()) return s;
    if (params.radius_edge() <= 0) {
      return absl::InvalidArgumentError(
          absl::StrCat("radius_edge must be > 0, got ", params.radius_edge()));
    }
    out.radius_edge = params.radius_edge();
  }
  if (params.has_theta()) {
    if (auto s = CheckFinite("theta", params.theta()); !s.ok()) return s;
    if (params.theta() < 0 || params.theta() > 1) {
      return absl::InvalidArgumentError(
          absl::StrCat("theta must be in [0, 1], got ", params.theta()));
    }
    out.theta = params.theta();
  }
  if (params.has_max_rep_angle()) {
    if (auto s = CheckFinite("max_rep_angle", params.max_rep_angle()); !s.ok()) return s;
    if (params.max_rep_angle() <= 0 || params.max_rep_angle() >= 180) {
      return absl::InvalidArgumentError(
          absl::StrCat("max_rep_angle must be in (0, 180) degrees, got ", params.max_rep_angle()));
    }
    out.max_rep_angle = params.max_rep_angle();
  }
  if (params.has_max_volume()) {
    if (auto s = CheckFinite("max_volume", params.max_volume()); !s.ok()) return s;
    out.max_volume = params.max_volume();
  }
  if (params.has_min_dihedral()) {
    if (auto s = CheckFinite("min_dihedral", params.min_dihedral()); !s.ok()) return s;
    if (params.min_dihedral() >= 90) {
      return absl::InvalidArgumentError(
          absl::StrCat("min_dihedral must be < 90 degrees, got ", params.min_dihedral()));
    }
    out.min_dihedral = params.min_dihedral();
  }
  if (params.has_keep_bounding_box()) out.keep_bounding_box = params.keep_bounding_box();
  out.max_vertices = limits.max_vertices();
  return out;
}

absl::Status CheckImplemented(const v1::MeshParameters& params, const plc::Plc& plc) {
  if (!plc.IsPointSet()) return absl::OkStatus();  // the mesher decides
  std::vector<const char*> set;
  if (params.has_radius_edge()) set.push_back("radius_edge");
  if (params.has_theta()) set.push_back("theta");
  if (params.has_max_rep_angle()) set.push_back("max_rep_angle");
  if (params.has_max_volume() && params.max_volume() > 0) set.push_back("max_volume");
  if (params.has_min_dihedral() && params.min_dihedral() > 0) set.push_back("min_dihedral");
  if (params.has_keep_bounding_box() && params.keep_bounding_box()) {
    set.push_back("keep_bounding_box");
  }
  if (set.empty()) return absl::OkStatus();
  std::string names;
  for (const char* n : set) absl::StrAppend(&names, names.empty() ? "" : ", ", n);
  return absl::UnimplementedError(absl::StrCat(
      "parameter(s) ", names,
      " not implemented for point sets (a point set is tetrahedralized as given, "
      "without refinement)"));
}

absl::Status ValidateEncoding(const v1::EncodingOptions& encoding) {
  if (encoding.quantization_bits() > 24) {
    return absl::InvalidArgumentError(absl::StrCat(
        "quantization_bits must be 0 (lossless) or 1..24, got ", encoding.quantization_bits()));
  }
  return absl::OkStatus();
}

absl::StatusOr<absl::Duration> DeadlineFromProto(const v1::JobLimits& limits) {
  if (!limits.has_deadline()) return absl::ZeroDuration();
  const auto& d = limits.deadline();
  if (d.seconds() < 0 || d.nanos() < 0 || d.nanos() > 999999999 ||
      d.seconds() > google::protobuf::util::TimeUtil::kDurationMaxSeconds) {
    return absl::InvalidArgumentError("limits.deadline must be a valid non-negative duration");
  }
  return absl::Seconds(d.seconds()) + absl::Nanoseconds(d.nanos());
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

namespace svrc::api {

absl::StatusOr<mesh::TetMesh> MeshWithParameters(const plc::Plc& plc,
                                                 const v1::MeshParameters& params,
                                                 const v1::JobLimits& limits,
                                                 const core::ProgressCallback& progress,
                                                 const core::CancelToken* cancel) {
  absl::StatusOr<core::MeshParams> core_params = ParamsFromProto(params, limits);
  if (!core_params.ok()) return core_params.status();
  if (absl::Status s = CheckImplemented(params, plc); !s.ok()) return s;
  if (limits.max_vertices() > 0 && plc.vertices.size() > limits.max_vertices()) {
    return absl::ResourceExhaustedError(
        absl::StrCat("the input has ", plc.vertices.size(), " vertices, more than max_vertices=",
                     limits.max_vertices()));
  }
  if (cancel != nullptr) {
    if (absl::Status s = cancel->Check(); !s.ok()) return s;
  }
  return core::MeshPlc(plc, *core_params, progress, cancel);
}

}  // namespace svrc::api
