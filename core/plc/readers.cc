#include "core/plc/readers.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "core/plc/read_internal.h"
#include "core/plc/read_util.h"
#include "core/util/sha256.h"

namespace svrc::plc {

using internal::Cat;

absl::StatusOr<InputFormat> FormatFromPath(std::string_view path) {
  const size_t dot = path.rfind('.');
  const size_t slash = path.find_last_of("/\\");
  if (dot == std::string_view::npos || (slash != std::string_view::npos && dot < slash)) {
    return absl::InvalidArgumentError(Cat("'", path, "': no file extension (expected .poly .smesh .node .off .stl .obj .mesh)"));
  }
  const std::string ext = internal::Lower(path.substr(dot + 1));
  if (ext == "poly") return InputFormat::kPoly;
  if (ext == "smesh") return InputFormat::kSmesh;
  if (ext == "node") return InputFormat::kNode;
  if (ext == "off") return InputFormat::kOff;
  if (ext == "stl") return InputFormat::kStl;
  if (ext == "obj") return InputFormat::kObj;
  if (ext == "mesh") return InputFormat::kMedit;
  return absl::InvalidArgumentError(Cat("'", path, "': unknown extension '.", ext,
                                                 "' (expected .poly .smesh .node .off .stl .obj .mesh)"));
}

std::string_view FormatName(InputFormat format) {
  switch (format) {
    case InputFormat::kPoly: return "poly";
    case InputFormat::kSmesh: return "smesh";
    case InputFormat::kNode: return "node";
    case InputFormat::kOff: return "off";
    case InputFormat::kStl: return "stl";
    case InputFormat::kObj: return "obj";
    case InputFormat::kMedit: return "mesh";
  }
  return "unknown";
}

namespace {

absl::StatusOr<std::string> ReadWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::NotFoundError(Cat(path, ": cannot open"));
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) return absl::DataLossError(Cat(path, ": read error"));
  return ss.str();
}

absl::StatusOr<Plc> Read(std::string_view bytes, InputFormat format, std::string_view name,
                         const ReadOptions& options, const internal::NodeLoader& nodes) {
  const std::string sname(name);
  Plc plc;
  switch (format) {
    case InputFormat::kPoly:
    case InputFormat::kSmesh:
    case InputFormat::kNode: {
      plc.source_name = sname;
      if (absl::Status s = internal::ReadTetgen(bytes, format, &plc, nodes); !s.ok()) return s;
      break;
    }
    default: {
      internal::SurfaceSoup soup;
      absl::Status s;
      if (format == InputFormat::kOff) s = internal::ReadOff(bytes, sname, &soup);
      if (format == InputFormat::kStl) s = internal::ReadStl(bytes, sname, &soup);
      if (format == InputFormat::kObj) s = internal::ReadObj(bytes, sname, &soup);
      if (format == InputFormat::kMedit) s = internal::ReadMedit(bytes, sname, &soup);
      if (!s.ok()) return s;
      plc = internal::BuildSurfacePlc(std::move(soup), format == InputFormat::kStl,
                                      options.merge_coplanar, options.coplanar_tolerance);
      plc.source_name = sname;
      break;
    }
  }
  if (format != InputFormat::kPoly && format != InputFormat::kSmesh && format != InputFormat::kNode) {
    plc.is_surface = true;
  }
  plc.input_sha256 = util::Sha256Hex(bytes);
  return plc;
}

}  // namespace

absl::StatusOr<Plc> ReadPlcBytes(std::string_view bytes, InputFormat format, std::string_view name,
                                 const ReadOptions& options) {
  return Read(bytes, format, name, options, nullptr);
}

absl::StatusOr<Plc> ReadPlcBytes(std::string_view bytes, InputFormat format,
                                 std::string_view name) {
  return ReadPlcBytes(bytes, format, name, ReadOptions{});
}

absl::StatusOr<Plc> ReadPlcFile(const std::string& path, const ReadOptions& options) {
  absl::StatusOr<InputFormat> format = FormatFromPath(path);
  if (!format.ok()) return format.status();
  absl::StatusOr<std::string> bytes = ReadWholeFile(path);
  if (!bytes.ok()) return bytes.status();
  const std::string name = std::filesystem::path(path).filename().string();
  auto nodes = [&]() -> absl::StatusOr<std::string> {
    const std::string node_path = std::filesystem::path(path).replace_extension(".node").string();
    return ReadWholeFile(node_path);
  };
  return Read(*bytes, *format, name, options, nodes);
}

absl::StatusOr<Plc> ReadPlcFile(const std::string& path) { return ReadPlcFile(path, ReadOptions{}); }

}  // namespace svrc::plc
