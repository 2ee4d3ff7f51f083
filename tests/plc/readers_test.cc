// Readers: every corpus file of categories a-f reads with its documented
// counts; the five cube files give one PLC; knife_edge.obj equals its .poly;
// malformed inputs give INVALID_ARGUMENT with file:line.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "core/plc/readers.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/test_support.h"

namespace svrc::plc {
namespace {

using ::testing::HasSubstr;
using svrc::testing::CorpusPath;

Plc MustRead(const std::string& rel, ReadOptions opt = {}) {
  absl::StatusOr<Plc> plc = ReadPlcFile(CorpusPath(rel), opt);
  EXPECT_TRUE(plc.ok()) << rel << ": " << plc.status();
  return plc.ok() ? *std::move(plc) : Plc{};
}

using Key = std::array<double, 3>;
Key K(const Vec3& p) { return {p.x, p.y, p.z}; }

// A polygon as a canonical coordinate cycle (start at the smallest point,
// direction with the smaller second point): independent of numbering and
// orientation.
std::vector<Key> CanonicalLoop(const Plc& plc, const Polygon& poly) {
  std::vector<Key> loop;
  for (uint32_t v : poly.vertices) loop.push_back(K(plc.vertices[v]));
  const size_t n = loop.size();
  auto rotated = [&](bool reverse) {
    std::vector<Key> l = loop;
    if (reverse) std::reverse(l.begin(), l.end());
    std::rotate(l.begin(), std::min_element(l.begin(), l.end()), l.end());
    return l;
  };
  (void)n;
  return std::min(rotated(false), rotated(true));
}

// The geometry of a PLC: vertex set and the set of facets, each a set of
// canonical loops.
struct Geometry {
  std::set<Key> vertices;
  std::multiset<std::multiset<std::vector<Key>>> facets;
  bool operator==(const Geometry&) const = default;
};

Geometry GeometryOf(const Plc& plc) {
  Geometry g;
  for (const Vec3& p : plc.vertices) g.vertices.insert(K(p));
  for (const Facet& f : plc.facets) {
    std::multiset<std::vector<Key>> loops;
    for (const Polygon& p : f.polygons) loops.insert(CanonicalLoop(plc, p));
    g.facets.insert(loops);
  }
  return g;
}

TEST(Readers, FiveCubeFilesGiveOnePlc) {
  const Plc poly = MustRead("a_convex/cube.poly");
  ASSERT_EQ(poly.vertices.size(), 8u);
  ASSERT_EQ(poly.facets.size(), 6u);
  for (const Facet& f : poly.facets) {
    ASSERT_EQ(f.polygons.size(), 1u);
    EXPECT_EQ(f.polygons[0].vertices.size(), 4u);
  }
  const Geometry ref = GeometryOf(poly);
  for (const char* rel : {"a_convex/cube.off", "a_convex/cube.obj", "a_convex/cube_ascii.stl",
                          "a_convex/cube_binary.stl"}) {
    SCOPED_TRACE(rel);
    const Plc plc = MustRead(rel);
    EXPECT_EQ(plc.vertices.size(), 8u);
    EXPECT_EQ(plc.facets.size(), 6u);
    EXPECT_TRUE(plc.is_surface);
    EXPECT_TRUE(GeometryOf(plc) == ref);
    for (const Facet& f : plc.facets) {
      ASSERT_EQ(f.polygons.size(), 1u);
      EXPECT_EQ(f.polygons[0].vertices.size(), 4u);
      EXPECT_TRUE(f.holes.empty());
    }
  }
  // STL: 12 triangles in the file, 36 vertex records merged to 8.
  EXPECT_EQ(MustRead("a_convex/cube_ascii.stl").input_face_count, 12u);
  EXPECT_EQ(MustRead("a_convex/cube_binary.stl").input_face_count, 12u);
  // Without merging the STL cube stays 12 triangles.
  ReadOptions no_merge;
  no_merge.merge_coplanar = false;
  EXPECT_EQ(MustRead("a_convex/cube_binary.stl", no_merge).facets.size(), 12u);
}

// An OFF text of `pts` and triangles `tris`.
std::string OffText(const std::vector<std::array<double, 3>>& pts, const std::vector<std::array<int, 3>>& tris) {
  std::string s = "OFF\n" + std::to_string(pts.size()) + " " + std::to_string(tris.size()) + " 0\n";
  char buf[128];
  for (const auto& p : pts) {
    std::snprintf(buf, sizeof buf, "%.17g %.17g %.17g\n", p[0], p[1], p[2]);
    s += buf;
  }
  for (const auto& t : tris) s += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + "\n";
  return s;
}

// A surface turned or moved in floating point is coplanar only up to rounding:
// hinge.stl turned by a random rotation kept 1,159 facets instead of 562, and
// every split quad's 45-degree corners became crease points (session 39).
// Nearly coplanar neighbours now merge (ReadOptions::coplanar_tolerance).
TEST(Readers, NearlyCoplanarTrianglesMerge) {
  // The cube's 12 triangles turned about (1, 2, 3) by 0.3 rad and moved to ~1e4:
  // none of its faces is exactly planar any more.
  const double ax[3] = {1 / std::sqrt(14.0), 2 / std::sqrt(14.0), 3 / std::sqrt(14.0)};
  const double c = std::cos(0.3), s = std::sin(0.3);
  std::vector<std::array<double, 3>> pts;
  for (int i = 0; i < 8; ++i) {
    const double p[3] = {double(i & 1) - 0.5, double((i >> 1) & 1) - 0.5, double((i >> 2) & 1) - 0.5};
    const double d = ax[0] * p[0] + ax[1] * p[1] + ax[2] * p[2];
    const double x[3] = {ax[1] * p[2] - ax[2] * p[1], ax[2] * p[0] - ax[0] * p[2], ax[0] * p[1] - ax[1] * p[0]};
    std::array<double, 3> q;
    for (int k = 0; k < 3; ++k) q[k] = p[k] * c + x[k] * s + ax[k] * d * (1 - c);
    pts.push_back({12345.678 + q[0], -9876.54 + q[1], 4321.0 + q[2]});
  }
  // Outward, two triangles per face (corner i = x + 2y + 4z).
  const std::vector<std::array<int, 3>> tris = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                                                {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  const std::string text = OffText(pts, tris);
  ReadOptions exact;
  exact.coplanar_tolerance = 0;
  absl::StatusOr<Plc> e = ReadPlcBytes(text, InputFormat::kOff, "turned_cube.off", exact);
  ASSERT_TRUE(e.ok()) << e.status();
  EXPECT_EQ(e->facets.size(), 12u);
  absl::StatusOr<Plc> n = ReadPlcBytes(text, InputFormat::kOff, "turned_cube.off");
  ASSERT_TRUE(n.ok()) << n.status();
  ASSERT_EQ(n->facets.size(), 6u);
  for (const Facet& f : n->facets) {
    ASSERT_EQ(f.polygons.size(), 1u);
    EXPECT_EQ(f.polygons[0].vertices.size(), 4u);
  }
}

// Nearly coplanar pairs merge only into a group that is flat as a whole: a
// strip of 40 exactly planar quads (two triangles each), consecutive quads
// turned by 4e-9 rad, is curved by ~1e-8 of its length, so it stays 40 facets;
// unbent it is one.
TEST(Readers, NearlyCoplanarGroupMustBeFlatAsAWhole) {
  for (const double bend : {0.0, 2e-9}) {
    std::vector<std::array<double, 3>> pts;
    std::vector<std::array<int, 3>> tris;
    const int n = 40;
    for (int i = 0; i <= n; ++i) {
      const double z = bend * i * i;  // z depends on x only: every quad exactly planar
      pts.push_back({double(i), 0, z});
      pts.push_back({double(i), 1, z});
    }
    for (int i = 0; i < n; ++i) {
      tris.push_back({2 * i, 2 * i + 2, 2 * i + 3});
      tris.push_back({2 * i, 2 * i + 3, 2 * i + 1});
    }
    absl::StatusOr<Plc> p = ReadPlcBytes(OffText(pts, tris), InputFormat::kOff, "strip.off");
    ASSERT_TRUE(p.ok()) << p.status();
    EXPECT_EQ(p->facets.size(), bend == 0 ? 1u : size_t(n)) << bend;
  }
}

// A group joined by nearly coplanar pairs whose boundary is not simple falls
// back to its exactly coplanar subgroups, not to single faces: a ring of seven
// unit cells (two triangles each) that touches itself at a vertex (a pinch),
// on z = c·x², so each column of cells is exactly planar and the columns are
// nearly coplanar. Exactly flat (c = 0) it is one exact group with a pinch:
// 14 triangles, as before.
TEST(Readers, NearlyCoplanarGroupThatPinchesFallsBackToExactGroups) {
  for (const double c : {0.0, 1e-10}) {
    std::vector<std::array<double, 3>> pts;
    auto id = [](int x, int y) { return 4 * (y + 1) + x; };  // x in 0..3, y in -1..2
    for (int y = -1; y <= 2; ++y) {
      for (int x = 0; x <= 3; ++x) pts.push_back({double(x), double(y), c * x * x});
    }
    std::vector<std::array<int, 3>> tris;
    for (const auto& [i, j] : std::vector<std::pair<int, int>>{{0, 0}, {0, -1}, {1, -1}, {2, -1}, {2, 0}, {2, 1}, {1, 1}}) {
      tris.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      tris.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
    absl::StatusOr<Plc> p = ReadPlcBytes(OffText(pts, tris), InputFormat::kOff, "ring.off");
    ASSERT_TRUE(p.ok()) << p.status();
    // c > 0: columns x = 0 (2 cells), x = 1 (two separate cells), x = 2 (3 cells).
    EXPECT_EQ(p->facets.size(), c == 0 ? 14u : 4u) << c;
  }
}

// A nearly coplanar group with a vertex inside it (a fan's centre) does not
// merge: the merged facet would keep only its boundary, and the centre would
// be a point 1e-12 off the facet, not on it. Exactly coplanar, the fan merges
// into a hexagon and the centre is a point of the facet's interior, as before.
TEST(Readers, NearlyCoplanarFanKeepsItsCentre) {
  for (const double lift : {0.0, 1e-12}) {
    std::vector<std::array<double, 3>> pts = {{0, 0, lift}};
    std::vector<std::array<int, 3>> tris;
    for (int k = 0; k < 6; ++k) {
      pts.push_back({std::cos(k * M_PI / 3), std::sin(k * M_PI / 3), 0});
      tris.push_back({0, 1 + k, 1 + (k + 1) % 6});
    }
    absl::StatusOr<Plc> p = ReadPlcBytes(OffText(pts, tris), InputFormat::kOff, "fan.off");
    ASSERT_TRUE(p.ok()) << p.status();
    EXPECT_EQ(p->facets.size(), lift == 0 ? 1u : 6u) << lift;
  }
}

TEST(Readers, KnifeEdgeObjEqualsPoly) {
  const Plc poly = MustRead("c_creases/knife_edge.poly");
  const Plc obj = MustRead("c_creases/knife_edge.obj");
  EXPECT_EQ(poly.vertices.size(), 14u);
  EXPECT_EQ(poly.facets.size(), 9u);
  EXPECT_TRUE(GeometryOf(poly) == GeometryOf(obj));
  EXPECT_EQ(poly.vertices, obj.vertices);  // same order too
}

struct Counts {
  const char* file;
  size_t vertices;
  size_t faces;     // input faces (before coplanar merging) or .poly facets
  size_t segments;  // free segments
  size_t holes = 0;
  size_t regions = 0;
};

TEST(Readers, CorpusCounts) {
  // Counts from LICENSE-SOURCES.md (V / F for the OFF files, triangles for
  // hinge.stl) and from the files' own headers for the generated ones.
  const Counts kCounts[] = {
      {"a_convex/cube.poly", 8, 6, 0},
      {"a_convex/cube.off", 8, 6, 0},
      {"a_convex/cube.obj", 8, 6, 0},
      {"a_convex/cube_ascii.stl", 8, 12, 0},
      {"a_convex/cube_binary.stl", 8, 12, 0},
      {"a_convex/tetra.poly", 4, 4, 0},
      {"b_internal/example.poly", 28, 23, 0, 2, 2},
      {"b_internal/box_internal_facet.poly", 12, 11, 0, 0, 2},
      {"b_internal/box_in_box.poly", 20, 12, 1, 0, 2},
      {"c_creases/wedge-1.smesh", 6, 5, 0},
      {"c_creases/knife_edge.poly", 14, 9, 0},
      {"c_creases/knife_edge.obj", 14, 9, 0},
      {"c_creases/fandisk.off", 6475, 12946, 0},
      {"c_creases/schonhardt.off", 6, 8, 0},
      {"d_small_angles/segment_fan.poly", 19, 6, 2},
      {"e_spread/tiny_cube_in_box.poly", 16, 12, 0, 0, 2},
      {"e_spread/far_offset_close_points.poly", 10, 6, 0},
      {"f_real/elephant.off", 2775, 5558, 0},
      {"f_real/armadillo.off", 26002, 52000, 0},
      {"f_real/bunny.off", 3485, 6966, 0},
      {"f_real/hinge.stl", 598, 1212, 0}  // genus 5: V = F/2 + 2 - 2g,
  };
  for (const Counts& c : kCounts) {
    SCOPED_TRACE(c.file);
    const Plc plc = MustRead(c.file);
    EXPECT_EQ(plc.vertices.size(), c.vertices);
    EXPECT_EQ(plc.segments.size(), c.segments);
    EXPECT_EQ(plc.holes.size(), c.holes);
    EXPECT_EQ(plc.regions.size(), c.regions);
    if (plc.is_surface) {
      EXPECT_EQ(plc.input_face_count, c.faces);
      // Every input face lands in exactly one facet.
      std::vector<int> seen(c.faces, 0);
      for (const Facet& f : plc.facets) {
        for (uint32_t x : f.input_faces) ++seen[x];
      }
      EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), static_cast<long>(c.faces));
    } else {
      EXPECT_EQ(plc.facets.size(), c.faces);
    }
    EXPECT_EQ(plc.input_sha256.size(), 64u);
  }
}

TEST(Readers, PolyDetails) {
  const Plc ex = MustRead("b_internal/example.poly");
  EXPECT_EQ(ex.index_base, 1u);
  ASSERT_EQ(ex.vertex_markers.size(), 28u);
  EXPECT_EQ(ex.vertex_markers[4], 9);
  // Facet 3: outer quad + hole boundary quad + one hole seed, marker 3.
  ASSERT_EQ(ex.facets[2].polygons.size(), 2u);
  ASSERT_EQ(ex.facets[2].holes.size(), 1u);
  EXPECT_EQ(ex.facets[2].holes[0], Vec3(1, 0, 2.25));
  EXPECT_EQ(ex.facets[2].marker, 3);
  EXPECT_EQ(ex.regions[1].attribute, 20);
  EXPECT_EQ(ex.regions[1].max_volume, 0.01);
  EXPECT_EQ(ex.holes[0], Vec3(1, 0.4, 2.25));

  const Plc w = MustRead("c_creases/wedge-1.smesh");
  EXPECT_EQ(w.index_base, 0u);
  EXPECT_EQ(w.facets[4].polygons[0].vertices, (std::vector<uint32_t>{2, 3, 5, 4}));
  EXPECT_EQ(w.facets[4].marker, 5);

  const Plc bb = MustRead("b_internal/box_in_box.poly");
  ASSERT_EQ(bb.segments.size(), 1u);
  EXPECT_EQ(bb.segments[0].a, 16u);
  EXPECT_EQ(bb.segments[0].b, 17u);
  EXPECT_EQ(bb.segments[0].marker, 3);

  const Plc fan = MustRead("d_small_angles/segment_fan.poly");
  ASSERT_EQ(fan.facets[1].polygons.size(), 7u);  // 9-gon, 5 in-facet segments, a triangle
  EXPECT_EQ(fan.facets[1].polygons[1].vertices.size(), 2u);
}

TEST(Readers, PolyFacetLinesAsTetgenReadsThem) {
  // Marker flag 0 with a marker present on the facet line (ignored, as in
  // TetGen), a polygon continued on the next line, a facet hole.
  const std::string poly =
      "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n"
      "1 0\n2 1 7\n4 1 2\n 3 4\n2 2 4\n1 0.9 0.1 0\n";
  absl::StatusOr<Plc> plc = ReadPlcBytes(poly, InputFormat::kPoly, "t.poly");
  ASSERT_TRUE(plc.ok()) << plc.status();
  ASSERT_EQ(plc->facets.size(), 1u);
  EXPECT_EQ(plc->facets[0].marker, 0);
  EXPECT_EQ(plc->facets[0].polygons[0].vertices, (std::vector<uint32_t>{0, 1, 2, 3}));
  EXPECT_EQ(plc->facets[0].polygons[1].vertices, (std::vector<uint32_t>{1, 3}));
  ASSERT_EQ(plc->facets[0].holes.size(), 1u);
  EXPECT_EQ(plc->facets[0].holes[0], Vec3(0.9, 0.1, 0));
}

TEST(Readers, StlSolidNamesBecomeMarkers) {
  const std::string two =
      "solid a\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n"
      "   vertex 0 1 0\n  endloop\n endfacet\nendsolid a\n"
      "solid b\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 1\n   vertex 1 0 1\n"
      "   vertex 0 1 1\n  endloop\n endfacet\nendsolid b\n";
  absl::StatusOr<Plc> plc = ReadPlcBytes(two, InputFormat::kStl, "two.stl");
  ASSERT_TRUE(plc.ok()) << plc.status();
  ASSERT_EQ(plc->facets.size(), 2u);
  EXPECT_EQ(plc->facets[0].marker, 1);
  EXPECT_EQ(plc->facets[1].marker, 2);
  EXPECT_EQ(plc->marker_names[2], "b");
}

TEST(Readers, ObjForms) {
  const std::string obj =
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\ng top\nf 1/1/1 2//2 -2/3\nf -4 -2 -1\n"
      "o side\nl 1 3\n";
  absl::StatusOr<Plc> plc = ReadPlcBytes(obj, InputFormat::kObj, "x.obj");
  ASSERT_TRUE(plc.ok()) << plc.status();
  // Two coplanar triangles with the same group merge into the unit square.
  ASSERT_EQ(plc->facets.size(), 1u);
  EXPECT_EQ(plc->facets[0].polygons[0].vertices.size(), 4u);
  EXPECT_EQ(plc->facets[0].marker, 1);
  ASSERT_EQ(plc->segments.size(), 1u);
  EXPECT_EQ(plc->segments[0].marker, 2);
}

TEST(Readers, MergedFacetWithHoleGetsSeed) {
  // A 3x3 grid of unit squares (as triangles) minus the centre square: one
  // facet with an outer loop, a hole loop and a hole seed in the centre.
  std::string off = "OFF\n16 16 0\n";
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) off += std::to_string(i) + " " + std::to_string(j) + " 0\n";
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 3; ++i) {
      if (i == 1 && j == 1) continue;
      const int a = j * 4 + i, b = a + 1, c = a + 5, d = a + 4;
      off += "3 " + std::to_string(a) + " " + std::to_string(b) + " " + std::to_string(c) + "\n";
      off += "3 " + std::to_string(a) + " " + std::to_string(c) + " " + std::to_string(d) + "\n";
    }
  }
  absl::StatusOr<Plc> plc = ReadPlcBytes(off, InputFormat::kOff, "grid.off");
  ASSERT_TRUE(plc.ok()) << plc.status();
  ASSERT_EQ(plc->facets.size(), 1u);
  const Facet& f = plc->facets[0];
  ASSERT_EQ(f.polygons.size(), 2u);
  EXPECT_EQ(f.polygons[0].vertices.size(), 12u);  // outer: collinear vertices kept
  EXPECT_EQ(f.polygons[1].vertices.size(), 4u);
  ASSERT_EQ(f.holes.size(), 1u);
  EXPECT_GT(f.holes[0].x, 1);
  EXPECT_LT(f.holes[0].x, 2);
  EXPECT_GT(f.holes[0].y, 1);
  EXPECT_LT(f.holes[0].y, 2);
}

TEST(Readers, BadDanglingIndexNamesLineFacetAndIndex) {
  absl::StatusOr<Plc> plc = ReadPlcFile(CorpusPath("g_bad/bad_dangling_index.poly"));
  ASSERT_EQ(plc.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(plc.status().message(), HasSubstr("bad_dangling_index.poly:18:"));
  EXPECT_THAT(plc.status().message(), HasSubstr("facet 2 "));
  EXPECT_THAT(plc.status().message(), HasSubstr("vertex index 42 out of range"));
}

TEST(Readers, BadTruncatedGivesLine) {
  absl::StatusOr<Plc> plc = ReadPlcFile(CorpusPath("g_bad/bad_truncated.poly"));
  ASSERT_EQ(plc.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(plc.status().message(), HasSubstr("bad_truncated.poly:18: unexpected end of file"));
}

TEST(Readers, NanAndInfAreKeptForValidation) {
  const Plc plc = MustRead("g_bad/bad_nan_coords.poly");
  ASSERT_EQ(plc.vertices.size(), 8u);
  EXPECT_TRUE(std::isnan(plc.vertices[2].x));
  EXPECT_TRUE(std::isinf(plc.vertices[6].y));
  EXPECT_EQ(plc.vertex_lines[2], 7u);
}

TEST(Readers, MalformedInputs) {
  struct Case {
    InputFormat format;
    const char* bytes;
    const char* expect;
  };
  const Case kCases[] = {
      {InputFormat::kPoly, "", "x:0: empty file"},
      {InputFormat::kPoly, "99999999999 3 0 0\n1 0 0 0\n", "x:1: invalid number of points"},
      {InputFormat::kPoly, "-4 3 0 0\n", "x:1: invalid number of points"},
      {InputFormat::kPoly, "1000000 3 0 0\n1 0 0 0\n", "x:2: unexpected end of file: expected 1000000 points, found 1"},
      {InputFormat::kPoly, "2 3 0 0\n1 0 0 0\n2 0 zz 0\n", "x:3: expected a number, got 'zz'"},
      {InputFormat::kPoly, "1 3 0 0\n1 0 0\n", "x:2: point 1 has no z coordinate"},
      {InputFormat::kPoly, "3 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n1 0\n1\n3 1 2\n", "x:7: unexpected end of file"},
      {InputFormat::kSmesh, "3 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n1 0\n3 0 1 3\n", "vertex index 3 out of range"},
      {InputFormat::kOff, "OFF\n3 1 0\n0 0 0\n1 0 0\n", "x:4: unexpected end of file"},
      {InputFormat::kOff, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n", "x:6: face 0: vertex index 5"},
      {InputFormat::kOff, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n-3 0 1 2\n", "invalid number of corners -3"},
      {InputFormat::kStl, "solid x\n facet normal 0 0 1\n outer loop\n vertex 0 0 0\n", "unexpected end of file"},
      {InputFormat::kStl, "\x01\x02garbage", "neither ASCII STL"},
      {InputFormat::kObj, "v 0 0 0\nf 1 2 3\n", "x.obj:2: vertex reference 2 out of range"},
      {InputFormat::kObj, "v 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 0 2\n", "vertex reference 0 out of range"},
      {InputFormat::kMedit, "MeshVersionFormatted 1\nDimension 3\nVertices\n2\n0 0 0 0\n", "unexpected end of file"},
      {InputFormat::kMedit, "MeshVersionFormatted 1\nDimension 3\nBogus 3\n", "unknown Medit keyword 'Bogus'"},
  };
  for (const Case& c : kCases) {
    SCOPED_TRACE(c.bytes);
    const std::string name = c.format == InputFormat::kObj ? "x.obj" : "x";
    absl::StatusOr<Plc> plc = ReadPlcBytes(c.bytes, c.format, name);
    ASSERT_EQ(plc.status().code(), absl::StatusCode::kInvalidArgument) << plc.status();
    EXPECT_THAT(plc.status().message(), HasSubstr(c.expect));
  }
}

TEST(Readers, MeditSurface) {
  const std::string mesh =
      "MeshVersionFormatted 2\nDimension 3\nVertices\n4\n0 0 0 1\n1 0 0 1\n1 1 0 1\n0 1 0 7\n"
      "Quadrilaterals\n1\n1 2 3 4 5\nTriangles\n1\n1 2 4 9\nEdges\n1\n1 3 2\nCorners\n1\n1\nEnd\n";
  absl::StatusOr<Plc> plc = ReadPlcBytes(mesh, InputFormat::kMedit, "m.mesh");
  ASSERT_TRUE(plc.ok()) << plc.status();
  EXPECT_EQ(plc->vertices.size(), 4u);
  EXPECT_EQ(plc->vertex_markers[3], 7);
  ASSERT_EQ(plc->facets.size(), 2u);  // different refs: not merged
  EXPECT_EQ(plc->facets[0].marker, 5);
  EXPECT_EQ(plc->facets[1].marker, 9);
  ASSERT_EQ(plc->segments.size(), 1u);
}

TEST(Readers, FormatFromPath) {
  EXPECT_EQ(*FormatFromPath("a/b/C.POLY"), InputFormat::kPoly);
  EXPECT_EQ(*FormatFromPath("x.mesh"), InputFormat::kMedit);
  EXPECT_EQ(FormatFromPath("x.ply").status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(FormatFromPath("dir.d/noext").status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(FormatName(InputFormat::kSmesh), "smesh");
}

}  // namespace
}  // namespace svrc::plc

namespace svrc::plc {
namespace {

TEST(Readers, PolyWithSeparateNodeFile) {
  const std::string dir = svrc::testing::MakeTempDir("plc_node");
  {
    std::ofstream(dir + "/t.node") << "4 3 0 1\n1 0 0 0 5\n2 1 0 0 5\n3 0 1 0 5\n4 0 0 1 6\n";
    std::ofstream(dir + "/t.poly") << "0 3 0 0\n4 0\n1\n3 1 2 3\n1\n3 1 2 4\n1\n3 1 3 4\n1\n3 2 3 4\n";
  }
  absl::StatusOr<Plc> plc = ReadPlcFile(dir + "/t.poly");
  ASSERT_TRUE(plc.ok()) << plc.status();
  EXPECT_EQ(plc->vertices.size(), 4u);
  EXPECT_EQ(plc->facets.size(), 4u);
  EXPECT_EQ(plc->vertex_markers[3], 6);
  EXPECT_EQ(plc->facets[3].polygons[0].vertices, (std::vector<uint32_t>{1, 2, 3}));
  // Without the .node file: a clear error.
  absl::StatusOr<Plc> bytes_only = ReadPlcBytes("0 3 0 0\n1 0\n1\n3 1 2 3\n", InputFormat::kPoly, "m.poly");
  EXPECT_EQ(bytes_only.status().code(), absl::StatusCode::kInvalidArgument);
  const absl::StatusOr<Plc> node = ReadPlcFile(dir + "/t.node");
  ASSERT_TRUE(node.ok()) << node.status();
  EXPECT_TRUE(node->IsPointSet());
}

}  // namespace
}  // namespace svrc::plc
