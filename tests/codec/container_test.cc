// Lossless round trips, determinism and the committed reference container.
#include "core/codec/container.h"

#include <cfloat>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>

#include "core/mesh/canonical.h"
#include "gtest/gtest.h"
#include "tests/codec/grid_mesh.h"
#include "tests/test_support.h"

namespace svrc::codec {
namespace {

using testing::GridMeshOptions;
using testing::MakeGridMesh;

uint64_t Bits(double x) {
  uint64_t b;
  std::memcpy(&b, &x, 8);
  return b;
}

// Everything the container carries, compared exactly (positions and region
// doubles bit for bit, so -0.0 and NaN payloads count).
void ExpectSameMesh(const mesh::TetMesh& a, const mesh::TetMesh& b) {
  ASSERT_EQ(a.positions.size(), b.positions.size());
  for (size_t i = 0; i < a.positions.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(Bits(a.positions[i][k]), Bits(b.positions[i][k])) << "vertex " << i << " axis " << k;
    }
  }
  EXPECT_EQ(a.num_input_vertices, b.num_input_vertices);
  EXPECT_EQ(a.tets, b.tets);
  EXPECT_EQ(a.tet_region, b.tet_region);
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(a.triangle_marker, b.triangle_marker);
  ASSERT_EQ(a.regions.size(), b.regions.size());
  for (size_t i = 0; i < a.regions.size(); ++i) {
    EXPECT_EQ(Bits(a.regions[i].attribute), Bits(b.regions[i].attribute));
    EXPECT_EQ(Bits(a.regions[i].max_volume), Bits(b.regions[i].max_volume));
  }
  EXPECT_EQ(a.provenance.svrc_version, b.provenance.svrc_version);
  EXPECT_EQ(a.provenance.parameters, b.provenance.parameters);
  EXPECT_EQ(a.provenance.input_sha256, b.provenance.input_sha256);
}

// Encodes, decodes, compares; returns the bytes.
std::string RoundTrip(const mesh::TetMesh& m) {
  EncodeReport report;
  absl::StatusOr<std::string> bytes = EncodeTetMesh(m, EncodeOptions(), &report);
  EXPECT_TRUE(bytes.ok()) << bytes.status();
  if (!bytes.ok()) return {};
  EXPECT_EQ(report.bytes, bytes->size());
  EXPECT_EQ(report.max_position_error, 0);
  EXPECT_EQ(report.collapsed_tets, 0u);
  EXPECT_EQ(report.inverted_tets, 0u);
  absl::StatusOr<mesh::TetMesh> back = DecodeTetMesh(*bytes);
  EXPECT_TRUE(back.ok()) << back.status();
  if (back.ok()) ExpectSameMesh(m, *back);
  return *bytes;
}

mesh::TetMesh OneTet() {
  mesh::TetMesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  m.num_input_vertices = 4;
  m.tets = {{0, 1, 2, 3}};
  m.tet_region = {0};
  m.regions = {{7.0, 0.25}};
  m.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  m.triangle_marker = {1, 2, 3, -4};
  m.provenance = {"svrc 0.1.0", "radius_edge=2 theta=0.9", std::string(64, 'a')};
  return m;
}

TEST(ContainerTest, EmptyMesh) {
  mesh::TetMesh m;
  RoundTrip(m);
  m.provenance = {"svrc 0.1.0", "", ""};
  RoundTrip(m);
}

TEST(ContainerTest, OneTet) { RoundTrip(OneTet()); }

TEST(ContainerTest, OneTetWithoutLabels) {
  mesh::TetMesh m = OneTet();
  m.tet_region.clear();
  m.triangle_marker.clear();
  m.regions.clear();
  RoundTrip(m);
}

TEST(ContainerTest, VerticesWithoutTets) {
  mesh::TetMesh m;
  m.positions = {{1, 2, 3}, {4, 5, 6}};
  m.num_input_vertices = 2;
  RoundTrip(m);
}

TEST(ContainerTest, GridMesh) {
  GridMeshOptions o;
  o.nx = 5;
  o.ny = 4;
  o.nz = 3;
  o.jitter = 0.2;
  RoundTrip(MakeGridMesh(o));
  o.hilbert_order = true;
  o.origin = {-3.5, 1e-3, 42};
  o.spacing = 0.1;
  RoundTrip(MakeGridMesh(o));
}

TEST(ContainerTest, NonCanonicalTetsAndLabelExtremes) {
  // Tets in arbitrary order and rotation, ids far apart, negative labels:
  // the delta coding must wrap correctly, not just work for canonical input.
  mesh::TetMesh m;
  for (int i = 0; i < 70000; ++i) m.positions.push_back({double(i), double(i % 7), double(i % 13)});
  m.tets = {{69999, 0, 35000, 1}, {5, 4, 3, 2}, {0, 69999, 1, 2}, {3, 3, 3, 3}};
  m.tet_region = {-1, std::numeric_limits<int32_t>::max(), std::numeric_limits<int32_t>::min(), 0};
  m.triangles = {{69999, 0, 1}, {2, 1, 0}};
  m.triangle_marker = {std::numeric_limits<int32_t>::min(), 65536};
  RoundTrip(m);
}

TEST(ContainerTest, FarFromOriginStaysDistinct) {
  // 1e6 + k*1e-3: float32 spacing at 1e6 is 0.0625, so float32 would merge
  // these; the container must keep every one distinct and exact.
  mesh::TetMesh m;
  for (int k = 0; k < 64; ++k) {
    const double d = 1e-3 * k;
    m.positions.push_back({1e6 + d, -1e6 - d, 1e6 + 0.5 * d});
  }
  ASSERT_EQ(static_cast<float>(m.positions[0].x), static_cast<float>(m.positions[1].x));
  for (uint32_t k = 0; k + 3 < 64; k += 4) m.tets.push_back({k, k + 1, k + 2, k + 3});
  m.tet_region.assign(m.tets.size(), 0);
  m.regions = {{0, 0}};
  const std::string bytes = RoundTrip(m);
  absl::StatusOr<mesh::TetMesh> back = DecodeTetMesh(bytes);
  ASSERT_TRUE(back.ok());
  std::set<double> xs;
  for (const mesh::Vec3& p : back->positions) xs.insert(p.x);
  EXPECT_EQ(xs.size(), 64u);
}

TEST(ContainerTest, SpecialValuesBitExact) {
  const double nan_payload = [] {
    const uint64_t b = 0x7FF8DEADBEEF1234ull;
    double x;
    std::memcpy(&x, &b, 8);
    return x;
  }();
  const double specials[] = {0.0,
                             -0.0,
                             std::numeric_limits<double>::denorm_min(),
                             -std::numeric_limits<double>::denorm_min(),
                             DBL_MIN,
                             DBL_MIN / 3,
                             DBL_MAX,
                             -DBL_MAX,
                             1e-300,
                             -1e300,
                             std::numeric_limits<double>::infinity(),
                             -std::numeric_limits<double>::infinity(),
                             std::numeric_limits<double>::quiet_NaN(),
                             nan_payload,
                             0.1,
                             1.0 + DBL_EPSILON};
  mesh::TetMesh m;
  for (double a : specials) {
    for (double b : {-0.0, 1e-310, 3.0}) m.positions.push_back({a, b, -a});
  }
  m.num_input_vertices = static_cast<uint32_t>(m.positions.size());
  m.tets = {{0, 1, 2, 3}, {4, 5, 6, 7}};
  m.tet_region = {0, 1};
  m.regions = {{-0.0, nan_payload}, {std::numeric_limits<double>::denorm_min(), DBL_MAX}};
  RoundTrip(m);
}

TEST(ContainerTest, Deterministic) {
  GridMeshOptions o;
  o.nx = o.ny = o.nz = 4;
  o.jitter = 0.25;
  o.hilbert_order = true;
  const mesh::TetMesh m = MakeGridMesh(o);
  const absl::StatusOr<std::string> a = EncodeTetMesh(m, EncodeOptions());
  const absl::StatusOr<std::string> b = EncodeTetMesh(MakeGridMesh(o), EncodeOptions());
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(*a, *b);
  // Decoding and re-encoding gives the same bytes too.
  absl::StatusOr<mesh::TetMesh> back = DecodeTetMesh(*a);
  ASSERT_TRUE(back.ok());
  const absl::StatusOr<std::string> c = EncodeTetMesh(*back, EncodeOptions());
  ASSERT_TRUE(c.ok());
  EXPECT_EQ(*a, *c);
}

TEST(ContainerTest, CompressesCanonicalMeshes) {
  // Guards the delta-friendly tet columns and the prediction choice: a
  // Hilbert-ordered jittered grid must come out well below raw binary.
  GridMeshOptions o;
  o.nx = o.ny = o.nz = 12;
  o.jitter = 0.2;
  o.hilbert_order = true;
  const mesh::TetMesh m = MakeGridMesh(o);
  const absl::StatusOr<std::string> bytes = EncodeTetMesh(m, EncodeOptions());
  ASSERT_TRUE(bytes.ok());
  const size_t raw = m.positions.size() * 24 + m.tets.size() * 20 + m.triangles.size() * 16;
  EXPECT_LT(bytes->size(), raw / 2) << "raw " << raw;
}

TEST(ContainerTest, RejectsInconsistentMeshes) {
  mesh::TetMesh m = OneTet();
  m.tets[0][2] = 4;
  EXPECT_EQ(EncodeTetMesh(m, EncodeOptions()).status().code(), absl::StatusCode::kInvalidArgument);
  m = OneTet();
  m.triangles[1][0] = 99;
  EXPECT_EQ(EncodeTetMesh(m, EncodeOptions()).status().code(), absl::StatusCode::kInvalidArgument);
  m = OneTet();
  m.tet_region = {0, 0};
  EXPECT_EQ(EncodeTetMesh(m, EncodeOptions()).status().code(), absl::StatusCode::kInvalidArgument);
  m = OneTet();
  m.triangle_marker.pop_back();
  EXPECT_EQ(EncodeTetMesh(m, EncodeOptions()).status().code(), absl::StatusCode::kInvalidArgument);
  m = OneTet();
  m.num_input_vertices = 5;
  EXPECT_EQ(EncodeTetMesh(m, EncodeOptions()).status().code(), absl::StatusCode::kInvalidArgument);
  m = OneTet();
  for (int bits : {-1, 25, 64}) {
    EncodeOptions opt;
    opt.position_quantization_bits = bits;
    EXPECT_EQ(EncodeTetMesh(m, opt).status().code(), absl::StatusCode::kInvalidArgument) << bits;
  }
}

// ---- The committed reference container ----------------------------------
// tests/codec/data/reference_v1.svrc is the encoding of ReferenceMesh(). Any
// change to the byte format (or to Draco's output) fails here; a deliberate
// change bumps the format version and regenerates the file with
//   SVRC_REGENERATE_CODEC_REFERENCE=1 build/<dir>/tests/codec/svrc_codec_tests
//       --gtest_filter='ReferenceContainer*'

mesh::TetMesh ReferenceMesh() {
  GridMeshOptions o;
  o.nx = 3;
  o.ny = 2;
  o.nz = 2;
  o.origin = {1e6, -2.5, 1e-3};
  o.spacing = 0.125;
  o.jitter = 0.2;
  o.seed = 20261120;
  o.hilbert_order = true;
  mesh::TetMesh m = MakeGridMesh(o);
  m.positions[0].z = -0.0;  // a special value on the record as well
  m.provenance = {"svrc 0.1.0", "radius_edge=2 theta=0.9 max_rep_angle=30",
                  "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"};
  return m;
}

std::string ReferencePath() {
  return std::string(SVRC_SOURCE_DIR) + "/tests/codec/data/reference_v1.svrc";
}

TEST(ReferenceContainer, EncoderReproducesTheFile) {
  const absl::StatusOr<std::string> bytes = EncodeTetMesh(ReferenceMesh(), EncodeOptions());
  ASSERT_TRUE(bytes.ok()) << bytes.status();
  if (std::getenv("SVRC_REGENERATE_CODEC_REFERENCE") != nullptr) {
    std::filesystem::create_directories(std::filesystem::path(ReferencePath()).parent_path());
    std::ofstream(ReferencePath(), std::ios::binary) << *bytes;
  }
  const std::string file = svrc::testing::ReadFileOrFail(ReferencePath());
  EXPECT_TRUE(*bytes == file) << "the encoder's bytes differ from " << ReferencePath() << " ("
                              << bytes->size() << " vs " << file.size()
                              << " bytes): a format change must be deliberate (see the comment)";
}

TEST(ReferenceContainer, DecoderReadsTheFile) {
  const std::string file = svrc::testing::ReadFileOrFail(ReferencePath());
  absl::StatusOr<mesh::TetMesh> m = DecodeTetMesh(file);
  ASSERT_TRUE(m.ok()) << m.status();
  ExpectSameMesh(ReferenceMesh(), *m);
  EXPECT_EQ(m->tets.size(), 3u * 2 * 2 * 6);
  EXPECT_EQ(Bits(m->positions[0].z), Bits(-0.0));
}

}  // namespace
}  // namespace svrc::codec
