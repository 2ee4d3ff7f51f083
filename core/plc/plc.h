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

  bool IsPointSet() const { return segments.empty() && facets.empty(); }
};

}  // namespace svrc::plc
