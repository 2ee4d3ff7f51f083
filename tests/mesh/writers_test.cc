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
    ASSERT_LE(s.size(), internal::kMaxDoubleChars) << s;
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

// The .ele/.face/.node lines are built in a line buffer with the region
// attribute's text formatted once per value (session 25). Against the plain
// per-field formatting: region attributes 0 and -0 (different text, equal
// as doubles), alternating, a huge one and a negative one; vertex indices
// past 10^9; negative markers.
TEST(Writers, TetgenLinesAreTheFieldByFieldText) {
  TetMesh m = Sample();
  m.regions = {Region{0.0, 0}, Region{-0.0, 0}, Region{1e300, 0}, Region{-2.5, 0}};
  for (size_t i = 0; i < m.tets.size(); ++i) m.tet_region[i] = static_cast<int32_t>((i * 7 / 3) % 4);
  m.tet_region.back() = 9;  // no such region: attribute 0
  m.tets[1] = {4000000000u, 1, 2, 999999999u};
  m.triangle_marker[0] = -2147483647 - 1;
  const std::string dir = svrc::testing::MakeTempDir("writers_lines");
  ASSERT_TRUE(WriteMeshFile(m, dir + "/out.node").ok());
  std::string header = "# svrc 0.1.0\n# parameters: radius_edge=2 theta=0.9\n# input sha256: abc123\n";
  std::string node = header + std::to_string(m.positions.size()) + " 3 0 0\n";
  for (size_t i = 0; i < m.positions.size(); ++i) {
    node += std::to_string(i + 1);
    for (int a = 0; a < 3; ++a) {
      node += ' ';
      internal::AppendDouble(&node, m.positions[i][a]);
    }
    node += '\n';
  }
  std::string ele = header + std::to_string(m.tets.size()) + " 4 1\n";
  for (size_t i = 0; i < m.tets.size(); ++i) {
    ele += std::to_string(i + 1);
    for (int k = 0; k < 4; ++k) ele += " " + std::to_string(uint64_t{m.tets[i][k]} + 1);
    ele += ' ';
    const int32_t r = m.tet_region[i];
    internal::AppendDouble(&ele, r >= 0 && r < 4 ? m.regions[r].attribute : 0.0);
    ele += '\n';
  }
  std::string face = header + std::to_string(m.triangles.size()) + " 1\n";
  for (size_t i = 0; i < m.triangles.size(); ++i) {
    face += std::to_string(i + 1);
    for (int k = 0; k < 3; ++k) face += " " + std::to_string(m.triangles[i][k] + 1);
    face += " " + std::to_string(m.triangle_marker[i]) + "\n";
  }
  EXPECT_EQ(svrc::testing::ReadFileOrFail(dir + "/out.node"), node);
  const std::string ele_written = svrc::testing::ReadFileOrFail(dir + "/out.ele");
  EXPECT_EQ(ele_written, ele);
  EXPECT_NE(ele_written.find(" -0\n"), std::string::npos);
  EXPECT_NE(ele_written.find(" 4000000001 "), std::string::npos);
  EXPECT_EQ(svrc::testing::ReadFileOrFail(dir + "/out.face"), face);
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
