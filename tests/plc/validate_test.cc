// Validation: every g_bad file is rejected with the right kind, the offending
// ids and (where there is one) the line; valid inputs a-f pass.
#include <cmath>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "core/plc/readers.h"
#include "core/plc/validate.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/test_support.h"

namespace svrc::plc {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using svrc::testing::CorpusPath;

Plc MustRead(const std::string& rel) {
  absl::StatusOr<Plc> plc = ReadPlcFile(CorpusPath(rel));
  EXPECT_TRUE(plc.ok()) << rel << ": " << plc.status();
  return plc.ok() ? *std::move(plc) : Plc{};
}

std::set<std::pair<uint32_t, uint32_t>> Pairs(const std::vector<uint32_t>& ids) {
  std::set<std::pair<uint32_t, uint32_t>> s;
  for (size_t i = 0; i + 1 < ids.size(); i += 2) s.insert({ids[i], ids[i + 1]});
  return s;
}

TEST(Validate, BadNanCoords) {
  const ValidationReport r = ValidatePlc(MustRead("g_bad/bad_nan_coords.poly"));
  ASSERT_EQ(r.errors.size(), 1u);
  const Problem& p = r.errors[0];
  EXPECT_EQ(p.kind, ProblemKind::kNonFinite);
  EXPECT_THAT(p.ids, ElementsAre(2, 6));  // 0-based; the file numbers them 3 and 7
  EXPECT_EQ(p.line, 7u);
  EXPECT_THAT(p.message, HasSubstr("vertices 3, 7 have a non-finite coordinate"));
  EXPECT_THAT(p.message, HasSubstr("lines 7, 11"));
  EXPECT_EQ(r.ToStatus().code(), absl::StatusCode::kInvalidArgument);
}

TEST(Validate, BadNonplanarFacet) {
  const ValidationReport r = ValidatePlc(MustRead("g_bad/bad_nonplanar_facet.poly"));
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].kind, ProblemKind::kNonPlanarFacet);
  EXPECT_THAT(r.errors[0].ids, ElementsAre(1));
  EXPECT_EQ(r.errors[0].line, 17u);
  EXPECT_THAT(r.errors[0].message, HasSubstr("facet 2 is not planar"));
  EXPECT_THAT(r.errors[0].message, HasSubstr("tolerance 1e-08"));
}

TEST(Validate, BadOpenCube) {
  const ValidationReport r = ValidatePlc(MustRead("g_bad/bad_open_cube.poly"));
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].kind, ProblemKind::kOpenBoundary);
  EXPECT_EQ(r.errors[0].ids.size(), 4u);  // the four edges of the missing top
  EXPECT_THAT(r.errors[0].message, HasSubstr("enclose no volume: 4 boundary edges"));
  EXPECT_THAT(r.errors[0].message, HasSubstr("5-6, 5-8, 6-7, 7-8"));
  EXPECT_EQ(r.errors[0].line, 17u);  // facet 2 (1 2 6 5), the first owning edge 5-6
}

TEST(Validate, BadSelfintTwoCubes) {
  const ValidationReport r = ValidatePlc(MustRead("g_bad/bad_selfint_two_cubes.poly"));
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].kind, ProblemKind::kIntersection);
  // Cube A's top (2), x=1 (4) and y=1 (5) faces cross cube B's bottom (7),
  // y=0.5 (9) and x=0.5 (12) faces (1-based facet numbers of the file).
  const std::set<std::pair<uint32_t, uint32_t>> expected = {{1, 8}, {1, 11}, {3, 6},
                                                            {3, 8}, {4, 6}, {4, 11}};
  EXPECT_EQ(Pairs(r.errors[0].ids), expected);
  EXPECT_THAT(r.errors[0].message, HasSubstr("facet 2 and facet 9"));
}

TEST(Validate, BadZeroAreaFacet) {
  const ValidationReport r = ValidatePlc(MustRead("g_bad/bad_zero_area_facet.poly"));
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].kind, ProblemKind::kZeroAreaFacet);
  EXPECT_THAT(r.errors[0].ids, ElementsAre(6));
  EXPECT_EQ(r.errors[0].line, 28u);
  EXPECT_THAT(r.errors[0].message, HasSubstr("facet 7 has zero area"));
}

TEST(Validate, BadDanglingAndTruncatedAreReaderErrors) {
  // The readers reject these with file:line (see readers_test.cc); here the
  // same defect built in memory is caught by validation.
  EXPECT_EQ(ReadPlcFile(CorpusPath("g_bad/bad_dangling_index.poly")).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(ReadPlcFile(CorpusPath("g_bad/bad_truncated.poly")).status().code(),
            absl::StatusCode::kInvalidArgument);
  Plc plc = MustRead("a_convex/cube.poly");
  plc.facets[1].polygons[0].vertices[3] = 41;  // "node 42" in the file's numbering
  const ValidationReport r = ValidatePlc(plc);
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].kind, ProblemKind::kDanglingIndex);
  EXPECT_THAT(r.errors[0].ids, ElementsAre(1));
  EXPECT_EQ(r.errors[0].line, 17u);
  EXPECT_THAT(r.errors[0].message, HasSubstr("facet 2 polygon 1 references vertex 42"));
}

TEST(Validate, SharkOpenHas304BoundaryEdges) {
  const ValidationReport r = ValidatePlc(MustRead("g_bad/mech-holes-shark_open.off"));
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].kind, ProblemKind::kOpenBoundary);
  EXPECT_EQ(r.errors[0].ids.size(), 304u);
  EXPECT_THAT(r.errors[0].message, HasSubstr("open surface: 304 boundary edges"));
  EXPECT_GT(r.errors[0].line, 5248u);  // a face line (after the 5246 vertex lines)
}

TEST(Validate, ThingiSelfIntersections) {
  const ValidationReport r = ValidatePlc(MustRead("g_bad/thingi10k_93068.stl"));
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].kind, ProblemKind::kIntersection);
  // 6 intersecting triangle pairs (LICENSE-SOURCES.md); tetgen -d names the
  // first as "Facet #4 intersects facet #18" (1-based, as we print).
  const auto pairs = Pairs(r.errors[0].ids);
  EXPECT_EQ(pairs.size(), 6u);
  EXPECT_TRUE(pairs.count({3, 17}));
  EXPECT_THAT(r.errors[0].message, HasSubstr("facet 4 and facet 18"));
  EXPECT_EQ(r.errors[0].line, 16u);  // "facet normal" line of the 3rd triangle (facet 3)
}

TEST(Validate, ValidCorpusInputsPass) {
  for (const char* rel :
       {"a_convex/cube.poly", "a_convex/cube.off", "a_convex/cube.obj", "a_convex/cube_ascii.stl",
        "a_convex/cube_binary.stl", "a_convex/tetra.poly", "b_internal/example.poly",
        "b_internal/box_internal_facet.poly", "b_internal/box_in_box.poly",
        "c_creases/wedge-1.smesh", "c_creases/knife_edge.poly", "c_creases/knife_edge.obj",
        "c_creases/schonhardt.off", "d_small_angles/segment_fan.poly",
        "e_spread/tiny_cube_in_box.poly", "e_spread/far_offset_close_points.poly",
        "f_real/hinge.stl"}) {
    SCOPED_TRACE(rel);
    const ValidationReport r = ValidatePlc(MustRead(rel));
    EXPECT_TRUE(r.ok()) << r.ToStatus();
    EXPECT_TRUE(r.warnings.empty()) << r.warnings[0].message;
  }
}

// Hand-built PLCs for the rules the corpus does not reach.
Plc Square() {
  Plc plc;
  plc.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  plc.facets.push_back({{Polygon{{0, 1, 2, 3}}}, {}, 1, {}});
  return plc;
}

TEST(Validate, DuplicateVerticesAreMergedWithAWarning) {
  Plc plc = MustRead("a_convex/cube.poly");
  plc.vertices.push_back(plc.vertices[6]);  // vertex 9 = vertex 7
  plc.facets[1].polygons[0].vertices[2] = 8;
  const ValidationReport r = ValidatePlc(plc);
  EXPECT_TRUE(r.ok()) << r.ToStatus();
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_EQ(r.warnings[0].kind, ProblemKind::kDuplicateVertex);
  EXPECT_THAT(r.warnings[0].ids, ElementsAre(8));
  EXPECT_THAT(r.warnings[0].message, HasSubstr("9 = 7"));
}

TEST(Validate, OpenSurfaceAndFreeSegmentCrossings) {
  Plc sq = Square();
  sq.is_surface = true;
  ValidationReport r = ValidatePlc(sq);
  ASSERT_NE(r.Find(ProblemKind::kOpenBoundary), nullptr);
  EXPECT_EQ(r.Find(ProblemKind::kOpenBoundary)->ids.size(), 4u);

  // A free segment piercing the square; another touching it at a vertex; a
  // third ending inside it (the end becomes an interior point: fine).
  Plc plc = Square();
  plc.vertices.insert(plc.vertices.end(), {{0.5, 0.5, -1}, {0.5, 0.5, 1}, {0.2, 0.2, 0}, {0.2, 0.2, 1}});
  plc.segments = {{4, 5, 0}};
  r = ValidatePlc(plc);
  const Problem* x = r.Find(ProblemKind::kIntersection);
  ASSERT_NE(x, nullptr);
  EXPECT_THAT(x->message, HasSubstr("segment 4-5 and facet 0"));
  plc.segments = {{6, 7, 0}, {0, 7, 0}};
  r = ValidatePlc(plc);
  EXPECT_EQ(r.Find(ProblemKind::kIntersection), nullptr) << r.ToStatus();
  // Two free segments crossing at an interior point.
  plc.segments = {{4, 5, 0}, {6, 7, 0}};
  plc.vertices[6] = {0.5, 0.2, 0.5};
  plc.vertices[7] = {0.5, 0.8, -0.5};
  plc.facets.clear();
  r = ValidatePlc(plc);
  x = r.Find(ProblemKind::kIntersection);
  ASSERT_NE(x, nullptr);
  EXPECT_THAT(x->message, HasSubstr("free segments cross or overlap"));
}

TEST(Validate, CoplanarOverlapAndTouchingInterior) {
  // Two coplanar squares overlapping in a quarter.
  Plc plc = Square();
  plc.vertices.insert(plc.vertices.end(), {{0.5, 0.5, 0}, {1.5, 0.5, 0}, {1.5, 1.5, 0}, {0.5, 1.5, 0}});
  plc.facets.push_back({{Polygon{{4, 5, 6, 7}}}, {}, 2, {}});
  ValidationReport r = ValidatePlc(plc);
  ASSERT_NE(r.Find(ProblemKind::kIntersection), nullptr);
  // A triangle touching the square's interior with one vertex (T-contact).
  plc = Square();
  plc.vertices.insert(plc.vertices.end(), {{0.5, 0.5, 0}, {0.5, 0, 1}, {0.5, 1, 1}});
  plc.facets.push_back({{Polygon{{4, 5, 6}}}, {}, 2, {}});
  r = ValidatePlc(plc);
  ASSERT_NE(r.Find(ProblemKind::kIntersection), nullptr);
  // The same triangle standing on the square's edge midpoint: allowed (the
  // edge is split there).
  plc.vertices[4] = {0.5, 0, 0};
  plc.vertices[5] = {0.5, -1, 1};
  plc.vertices[6] = {0.5, 0, 1};
  r = ValidatePlc(plc);
  EXPECT_EQ(r.Find(ProblemKind::kIntersection), nullptr) << r.ToStatus();
}

// The input of random_plcs.py holed 2 reduced: a facet's hole loop crosses
// its outer loop, with the facet's hole point inside both. The loop nesting
// (decided by one vertex of the hole loop, which lies outside) made the hole
// loop nobody's hole, the outer loop triangulated alone, and the validator
// called the input VALID; meshing it ended "refined to the resolution of
// doubles" (its spread was 3e16).
TEST(Validate, HoleLoopCrossingItsOuterLoopIsRejected) {
  Plc plc = Square();
  plc.vertices.insert(plc.vertices.end(), {{1.25, 0.35, 0}, {1.25, 0.65, 0}, {0.75, 0.65, 0}, {0.75, 0.35, 0}});
  plc.facets[0].polygons.push_back(Polygon{{4, 5, 6, 7}});
  plc.facets[0].holes.push_back({0.9, 0.5, 0});
  ValidationReport r = ValidatePlc(plc);
  const Problem* x = r.Find(ProblemKind::kUntriangulable);
  ASSERT_NE(x, nullptr) << r.ToStatus();
  EXPECT_THAT(x->ids, ElementsAre(0));
  EXPECT_THAT(x->message, HasSubstr("facet 0: edges of its polygons cross each other"));
  // The same loop moved inside: a proper hole (a lone facet bounds no
  // volume, the only error left).
  for (uint32_t v = 4; v < 8; ++v) plc.vertices[v].x -= 0.3;
  plc.facets[0].holes[0].x -= 0.3;
  r = ValidatePlc(plc);
  EXPECT_EQ(r.Find(ProblemKind::kUntriangulable), nullptr) << r.ToStatus();
  EXPECT_EQ(r.Find(ProblemKind::kIntersection), nullptr) << r.ToStatus();
  EXPECT_EQ(r.errors.size(), 1u) << r.ToStatus();
}

// The same on a slanted facet (random_plcs.py holed 85 and 89: a hole loop
// crossing the outer loop of a tilted facet was VALID, and meshing ended
// "refined to the resolution of doubles" / INTERNAL "segment 18 piece too
// short to split"). A slanted facet's rounded points are not exactly
// coplanar, so the 3D segment test never saw its edges cross; they are now
// tested in the facet's projection.
TEST(Validate, HoleLoopCrossingItsOuterLoopOnASlantedFacetIsRejected) {
  Plc plc = Square();
  plc.vertices.insert(plc.vertices.end(), {{1.25, 0.35, 0}, {1.25, 0.65, 0}, {0.75, 0.65, 0}, {0.75, 0.35, 0}});
  plc.facets[0].polygons.push_back(Polygon{{4, 5, 6, 7}});
  plc.facets[0].holes.push_back({0.9, 0.5, 0});
  // Tilt everything by 0.7 rad about x, then 0.4 rad about y.
  const auto tilt = [](geom::Vec3 p) {
    const double y = p.y * std::cos(0.7) - p.z * std::sin(0.7), z1 = p.y * std::sin(0.7) + p.z * std::cos(0.7);
    return geom::Vec3{p.x * std::cos(0.4) + z1 * std::sin(0.4), y, -p.x * std::sin(0.4) + z1 * std::cos(0.4)};
  };
  Plc tilted = plc;
  for (geom::Vec3& v : tilted.vertices) v = tilt(v);
  tilted.facets[0].holes[0] = tilt(tilted.facets[0].holes[0]);
  ValidationReport r = ValidatePlc(tilted);
  const Problem* x = r.Find(ProblemKind::kUntriangulable);
  ASSERT_NE(x, nullptr) << r.ToStatus();
  EXPECT_THAT(x->message, HasSubstr("facet 0: edges of its polygons cross each other"));
  // Moved inside: valid up to the lone facet bounding no volume.
  for (uint32_t v = 4; v < 8; ++v) plc.vertices[v].x -= 0.3;
  plc.facets[0].holes[0].x -= 0.3;
  tilted = plc;
  for (geom::Vec3& v : tilted.vertices) v = tilt(v);
  tilted.facets[0].holes[0] = tilt(tilted.facets[0].holes[0]);
  r = ValidatePlc(tilted);
  EXPECT_EQ(r.Find(ProblemKind::kUntriangulable), nullptr) << r.ToStatus();
  EXPECT_EQ(r.Find(ProblemKind::kIntersection), nullptr) << r.ToStatus();
  EXPECT_EQ(r.errors.size(), 1u) << r.ToStatus();
}

TEST(Validate, FinsInsideAClosedBoxAreAWarning) {
  Plc plc = MustRead("a_convex/cube.poly");
  // An internal fin attached to the bottom face's diagonal-free interior line x=0.5.
  plc.vertices.insert(plc.vertices.end(), {{0.5, 0.2, 0}, {0.5, 0.8, 0}, {0.5, 0.8, 0.5}, {0.5, 0.2, 0.5}});
  plc.facets[0].polygons.push_back(Polygon{{8, 9}});  // in-facet segment on the bottom
  plc.facets.push_back({{Polygon{{8, 9, 10, 11}}}, {}, 9, {}});
  const ValidationReport r = ValidatePlc(plc);
  EXPECT_TRUE(r.ok()) << r.ToStatus();
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_EQ(r.warnings[0].kind, ProblemKind::kDanglingFacet);
  EXPECT_THAT(r.warnings[0].ids, ElementsAre(6));
}

}  // namespace
}  // namespace svrc::plc
