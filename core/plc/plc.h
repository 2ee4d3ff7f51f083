// The input complex: a piecewise linear complex (PLC) of vertices, segments
// and polygonal facets with holes, plus region and hole seeds (thesis §2.1,
// TetGen's .poly model). Unit-free coordinates; volumes in input units³.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/geometry/vec3.h"

namespace svrc::plc {

using geom::Vec3;

// A closed polygon (>= 3 vertices) or, inside a facet, a 2-vertex in-facet
// segment. Indices are 0-based into Plc::vertices.
struct Polygon {
  std::vector<uint32_t> vertices;
};

// A planar facet: its polygons (outer boundaries, hole boundaries, in-facet
// segments) and the hole seeds that remove areas of the facet (TetGen .poly).
struct Facet {
  std::vector<Polygon> polygons;
  std::vector<Vec3> holes;
  int32_t marker = 0;
  // Provenance for messages (may be empty): the input faces (0-based, file
  // order) merged into this facet by a surface reader.
  std::vector<uint32_t> input_faces;
};

// A free segment in the volume (a lone 2-vertex polygon in a .poly file).
struct Segment {
  uint32_t a = 0, b = 0;
  int32_t marker = 0;
};

// A region seed: every tetrahedron of the region containing `point` gets
// `attribute`; `max_volume` <= 0 means no per-region bound.
struct RegionSeed {
  Vec3 point;
  double attribute = 0;
  double max_volume = 0;
};

struct Plc {
  std::vector<Vec3> vertices;
  std::vector<int32_t> vertex_markers;  // empty or one per vertex
  std::vector<Segment> segments;        // free segments (not facet edges)
  std::vector<Facet> facets;
  std::vector<Vec3> holes;              // volume hole seeds
  std::vector<RegionSeed> regions;
  std::string source_name;              // file name or "<memory>", for messages
  std::string input_sha256;             // hex sha256 of the bytes read, "" if built in memory

  // Provenance for messages, filled by the readers (all may be empty):
  uint32_t index_base = 0;              // first vertex/facet number in the file (1 in .poly/.obj)
  std::vector<uint32_t> vertex_lines;   // source line of each vertex (0 = unknown)
  std::vector<uint32_t> facet_lines;    // source line of each facet (first input face)
  // True for surface formats (.off .stl .obj .mesh): the facets are meant to
  // bound a volume, so validation requires a closed surface (docs/plc.md).
  bool is_surface = false;
  uint32_t input_face_count = 0;        // faces in the file before coplanar merging
  std::vector<std::string> marker_names;  // marker m -> STL solid / OBJ group name ("" if none)

  bool IsPointSet() const { return segments.empty() && facets.empty(); }
};

}  // namespace svrc::plc
