// The big corpus surfaces (label corpus only: seconds in release, too slow
// under sanitizers): closed and free of self-intersections, as tetgen finds
// them (corpus/REFERENCE.md meshes all of them).
#include <string>

#include "core/plc/readers.h"
#include "core/plc/validate.h"
#include "gtest/gtest.h"
#include "tests/test_support.h"

namespace svrc::plc {
namespace {

TEST(CorpusBig, RealSurfacesAreValid) {
  for (const char* rel : {"c_creases/fandisk.off", "f_real/elephant.off", "f_real/bunny.off",
                          "f_real/armadillo.off"}) {
    SCOPED_TRACE(rel);
    absl::StatusOr<Plc> plc = ReadPlcFile(svrc::testing::CorpusPath(rel));
    ASSERT_TRUE(plc.ok()) << plc.status();
    ValidationReport report;
    absl::StatusOr<FeatureComplex> fc = PreparePlc(*plc, {}, {}, &report);
    ASSERT_TRUE(fc.ok()) << fc.status();
    EXPECT_TRUE(report.warnings.empty()) << report.warnings[0].message;
    // Closed triangulated surfaces: every segment lies on exactly two facets.
    for (const FeatureSegment& s : fc->segments) ASSERT_EQ(s.facets.size(), 2u);
    EXPECT_GT(fc->spread, 1.0);
  }
}

TEST(CorpusBig, FandiskMergesCoplanarTriangles) {
  absl::StatusOr<Plc> plc = ReadPlcFile(svrc::testing::CorpusPath("c_creases/fandisk.off"));
  ASSERT_TRUE(plc.ok());
  EXPECT_EQ(plc->input_face_count, 12946u);
  // Nearly coplanar neighbours merged (ReadOptions::coplanar_tolerance, since
  // session 39); exactly coplanar ones only: 8035.
  EXPECT_EQ(plc->facets.size(), 7798u);
  ReadOptions exact;
  exact.coplanar_tolerance = 0;
  absl::StatusOr<Plc> e = ReadPlcFile(svrc::testing::CorpusPath("c_creases/fandisk.off"), exact);
  ASSERT_TRUE(e.ok());
  EXPECT_EQ(e->facets.size(), 8035u);
}

}  // namespace
}  // namespace svrc::plc
