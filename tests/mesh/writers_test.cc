#include "core/mesh/writers.h"

#include <sys/stat.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <random>

#include "core/mesh/read_tetgen.h"
#include "core/mesh/writer_util.h"
#include "gtest/gtest.h"
#include "tests/mesh/mesh_test_util.h"
#include "tests/test_support.h"

namespace svrc::mesh {
namespace {

namespace fs = std::filesystem;

// A mesh with coordinates that need all 17 digits, two regions and markers
// including 0 and a negative one.
TetMesh Sample() {
  const plc::Plc p = testing::BoxPlc(Vec3(0.1, -1.0 / 3, 1e6), Vec3(2.0 / 3, 1.0 / 7, 1e6 + 1));
  TetMesh m = testing::KuhnBoxMesh(p, 2);
  m.regions = {Region{1.5, 0}, Region{7, 0}};
  for (size_t i = 0; i < m.tets.size(); ++i) m.tet_region[i] = i % 3 == 0 ? 1 : 0;
  for (size_t i = 0; i < m.triangles.size(); ++i) {
    m.triangle_marker[i] = m.triangle_marker[i] == 1 ? 0 : (m.triangle_marker[i] == 2 ? -4 : m.triangle_marker[i]);
  }
  m.provenance = {"0.1.0", "radius_edge=2 theta=0.9", "abc123"};
  return m;
}

TEST(OutputFormat, FromPath) {
  EXPECT_EQ(*OutputFormatFromPath("a/b.node"), OutputFormat::kTetgen);
  EXPECT_EQ(*OutputFormatFromPath("b.VTU"), OutputFormat::kVtu);
  EXPECT_EQ(*OutputFormatFromPath("x.y/b.msh"), OutputFormat::kMsh);
  EXPECT_EQ(*OutputFormatFromPath("b.mesh"), OutputFormat::kMedit);
  EXPECT_FALSE(OutputFormatFromPath("b.stl").ok());
  EXPECT_FALSE(OutputFormatFromPath("x.y/b").ok());
}

// Every text writer prints coordinates with internal::AppendDouble (the
// shortest round-trip decimal since session 13; %.17g before): strtod must
// give back the same bits, for the extremes and for random bit patterns.
TEST(Writers, AppendDoubleReadsBackBitForBit) {
  std::vector<double> values = {0.0, -0.0, 0.1, -1.0 / 3, 1e6 + 1.0 / 7, 5e-324, -5e-324,
                                std::numeric_limits<double>::min(), std::numeric_limits<double>::max(),
                                -std::numeric_limits<double>::max(), std::nextafter(1.0, 2.0), std::nextafter(1.0, 0.0),
                                9007199254740993.0, 123456789012345678.0, 1e-300, 2.2250738585072009e-308};
  std::mt19937_64 rng(13);
  for (int i = 0; i < 20000; ++i) {
    const uint64_t bits = rng();
    double d;
    std::memcpy(&d, &bits, sizeof d);
    if (std::isfinite(d)) values.push_back(d);
  }
  for (double v : values) {
    std::string s;
    internal::AppendDouble(&s, v);
    ASSERT_LE(s.size(), 24u) << s;
    const double back = std::strtod(s.c_str(), nullptr);
    uint64_t a, b;
    std::memcpy(&a, &v, sizeof v);
    std::memcpy(&b, &back, sizeof back);
    EXPECT_EQ(a, b) << s;
  }
}

TEST(Writers, TetgenRoundTripIsExact) {
  const TetMesh m = Sample();
  const std::string dir = svrc::testing::MakeTempDir("writers");
  const std::string path = dir + "/out.node";
  ASSERT_TRUE(WriteMeshFile(m, path).ok());
  auto r = ReadTetgenMesh(path);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(r->positions, m.positions);  // bit-exact (shortest round-trip decimals)
  EXPECT_EQ(r->tets, m.tets);
  EXPECT_EQ(r->triangles, m.triangles);
  EXPECT_EQ(r->triangle_marker, m.triangle_marker);
  ASSERT_EQ(r->regions.size(), 2u);
  EXPECT_EQ(r->regions[0].attribute, 1.5);
  EXPECT_EQ(r->regions[1].attribute, 7);
  EXPECT_EQ(r->tet_region, m.tet_region);
  const std::string node = svrc::testing::ReadFileOrFail(path);
  EXPECT_NE(node.find("# svrc 0.1.0\n# parameters: radius_edge=2 theta=0.9\n# input sha256: abc123\n"),
            std::string::npos);
  // No temporaries left behind.
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    EXPECT_EQ(e.path().string().find(".tmp."), std::string::npos) << e.path();
    ++files;
  }
  EXPECT_EQ(files, 3);
}

TEST(Writers, ReportsIoErrors) {
  const TetMesh m = Sample();
  const absl::Status s = WriteMeshFile(m, "/nonexistent-dir/x/out.msh");
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("/nonexistent-dir/x/out.msh"), std::string::npos) << s;
  const std::string dir = svrc::testing::MakeTempDir("writers_ro");
  // A directory where the target file should be: the rename fails and the
  // temporary is removed.
  fs::create_directories(dir + "/out.mesh/inner");
  const absl::Status s2 = WriteMeshFile(m, dir + "/out.mesh");
  EXPECT_FALSE(s2.ok());
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    (void)e;
    ++files;
  }
  EXPECT_EQ(files, 1);
  EXPECT_FALSE(WriteMeshFile(m, dir + "/out.ply").ok());
}

TEST(Writers, ReplacesExistingFileAtomically) {
  const std::string dir = svrc::testing::MakeTempDir("writers_replace");
  const std::string path = dir + "/out.mesh";
  TetMesh m = Sample();
  ASSERT_TRUE(WriteMeshFile(m, path).ok());
  m.provenance.parameters = "second";
  ASSERT_TRUE(WriteMeshFile(m, path).ok());
  EXPECT_NE(svrc::testing::ReadFileOrFail(path).find("# parameters: second\n"), std::string::npos);
}

}  // namespace
}  // namespace svrc::mesh
