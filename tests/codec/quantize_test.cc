// Quantized positions: the error bound, exact lattice decoding, and the
// collapsed/inverted tet counts on crafted meshes.
#include <cmath>

#include "core/codec/container.h"
#include "core/codec/quantize.h"
#include "gtest/gtest.h"
#include "tests/codec/grid_mesh.h"

namespace svrc::codec {
namespace {

using testing::GridMeshOptions;
using testing::MakeGridMesh;

struct Quantized {
  EncodeReport report;
  mesh::TetMesh decoded;
};

Quantized EncodeQuantized(const mesh::TetMesh& m, int bits) {
  EncodeOptions o;
  o.position_quantization_bits = bits;
  Quantized q;
  absl::StatusOr<std::string> bytes = EncodeTetMesh(m, o, &q.report);
  EXPECT_TRUE(bytes.ok()) << bytes.status();
  if (!bytes.ok()) return q;
  absl::StatusOr<mesh::TetMesh> back = DecodeTetMesh(*bytes);
  EXPECT_TRUE(back.ok()) << back.status();
  if (back.ok()) q.decoded = std::move(*back);
  return q;
}

double MaxExtent(const mesh::TetMesh& m) {
  geom::Box3 box;
  for (const mesh::Vec3& p : m.positions) box.Add(p);
  const mesh::Vec3 e = box.hi - box.lo;
  return std::fmax(e.x, std::fmax(e.y, e.z));
}

TEST(QuantizeTest, ErrorBoundRespectedAndTopologyExact) {
  GridMeshOptions o;
  o.nx = 6;
  o.ny = 5;
  o.nz = 4;
  o.jitter = 0.3;
  o.origin = {1e6, -7, 0.001};
  o.spacing = 0.37;
  o.hilbert_order = true;
  const mesh::TetMesh m = MakeGridMesh(o);
  const double extent = MaxExtent(m);
  for (int bits : {1, 4, 8, 12, 16, 17, 20, 24}) {
    SCOPED_TRACE(bits);
    const Quantized q = EncodeQuantized(m, bits);
    ASSERT_EQ(q.decoded.positions.size(), m.positions.size());
    // The a-priori bound: half a spacing, spacing <= 2 * extent / (2^bits - 1)
    // (but never finer than the float64 spacing near 1e6).
    const double ulp = std::nextafter(2e6, 3e6) - 2e6;
    EXPECT_LE(q.report.position_error_bound,
              std::fmax(extent / (std::ldexp(1.0, bits) - 1), ulp));
    EXPECT_GT(q.report.position_error_bound, 0);
    double measured = 0;
    for (size_t i = 0; i < m.positions.size(); ++i) {
      for (int a = 0; a < 3; ++a) {
        measured = std::fmax(measured, std::fabs(q.decoded.positions[i][a] - m.positions[i][a]));
      }
    }
    EXPECT_EQ(q.report.max_position_error, measured);
    EXPECT_LE(measured, q.report.position_error_bound);
    // Everything but the positions is untouched.
    EXPECT_EQ(q.decoded.tets, m.tets);
    EXPECT_EQ(q.decoded.tet_region, m.tet_region);
    EXPECT_EQ(q.decoded.triangles, m.triangles);
    EXPECT_EQ(q.decoded.triangle_marker, m.triangle_marker);
    EXPECT_EQ(q.decoded.num_input_vertices, m.num_input_vertices);
  }
}

TEST(QuantizeTest, FinerBitsShrinkTheError) {
  GridMeshOptions o;
  o.nx = o.ny = o.nz = 4;
  o.jitter = 0.3;
  const mesh::TetMesh m = MakeGridMesh(o);
  const Quantized q16 = EncodeQuantized(m, 16), q20 = EncodeQuantized(m, 20);
  EXPECT_EQ(q16.report.position_error_bound, 16 * q20.report.position_error_bound);
  EXPECT_LT(q20.report.max_position_error, q16.report.max_position_error);
  EXPECT_EQ(q16.report.collapsed_tets + q16.report.inverted_tets, 0u);
}

TEST(QuantizeTest, LatticeIsExactAndDeterministic) {
  // Unit box at 4 bits: spacing 1/8 (the finest power of two with at most 16
  // lattice points spanning [0, 1]), so every decoded coordinate is k/8.
  mesh::TetMesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.3, 0.7, 0.55}};
  m.tets = {{0, 1, 2, 3}};
  const Quantized q = EncodeQuantized(m, 4);
  EXPECT_EQ(q.report.position_error_bound, 1.0 / 16);
  const mesh::Vec3 p = q.decoded.positions[4];
  EXPECT_EQ(p.x, 0.25);    // 2.4/8 -> 2/8
  EXPECT_EQ(p.y, 0.75);    // 5.6/8 -> 6/8
  EXPECT_EQ(p.z, 0.5);     // 4.4/8 -> 4/8
  EXPECT_EQ(q.decoded.positions[1].x, 1.0);
  EXPECT_NEAR(q.report.max_position_error, 0.05, 1e-15);
}

TEST(QuantizeTest, CollapsedAndInvertedCounts) {
  // Bits 4 over x in [0, 15]: spacing 1, origin 0, so coordinates round to
  // integers. The base triangle sits near z = 0.5; apexes just above it
  // either round onto its plane (collapse) or below it (inversion).
  mesh::TetMesh m;
  m.positions = {
      {0, 0, 0.45},   // 0 -> z 0
      {15, 0, 0.45},  // 1 -> z 0
      {0, 15, 0.45},  // 2 -> z 0
      {5, 5, 0.49},   // 3 -> z 0: on the rounded base plane
      {5, 5, 3.2},    // 4 -> z 3: comfortably above
      {15, 0, 0.55},  // 5 -> z 1
      {0, 15, 0.55},  // 6 -> z 1
      {10, 10, 0.6},  // 7 -> z 1; above the tilted base (plane z = 0.5833 there),
                      //    below its rounded image (z = 1.333 there)
  };
  m.tets = {{0, 1, 2, 3},   // collapses
            {0, 1, 2, 4},   // survives
            {0, 5, 6, 7},   // inverts
            {0, 5, 6, 4}};  // survives
  const Quantized q = EncodeQuantized(m, 4);
  EXPECT_EQ(q.report.position_error_bound, 0.5);
  EXPECT_EQ(q.report.collapsed_tets, 1u);
  EXPECT_EQ(q.report.inverted_tets, 1u);
  // Cross-check the decoded geometry directly.
  EXPECT_EQ(q.decoded.positions[3].z, 0);
  EXPECT_EQ(q.decoded.positions[7].z, 1);
  EXPECT_EQ(q.decoded.positions[5].z, 1);
}

TEST(QuantizeTest, Rejections) {
  mesh::TetMesh m;
  m.positions = {{0, 0, 0}, {std::nan(""), 0, 0}};
  EncodeOptions o;
  o.position_quantization_bits = 16;
  EXPECT_EQ(EncodeTetMesh(m, o).status().code(), absl::StatusCode::kInvalidArgument);
  m.positions[1].x = HUGE_VAL;
  EXPECT_EQ(EncodeTetMesh(m, o).status().code(), absl::StatusCode::kInvalidArgument);
  // A box spanning most of the float64 range (1.2e308 = 2.67 * 2^1022) does
  // not fit in 2 bits (4 lattice points cannot span [-3, 3] * 2^1022) ...
  m.positions = {{-1.2e308, 0, 0}, {1.2e308, 0, 0}};
  o.position_quantization_bits = 2;
  EXPECT_EQ(EncodeTetMesh(m, o).status().code(), absl::StatusCode::kInvalidArgument);
  // ... but does in 3 bits: spacing 2^1022, lattice [-3, 4] * 2^1022 whose
  // top end overflows, while the vertices round to -+3 * 2^1022.
  o.position_quantization_bits = 3;
  absl::StatusOr<std::string> bytes = EncodeTetMesh(m, o);
  ASSERT_TRUE(bytes.ok()) << bytes.status();
  absl::StatusOr<mesh::TetMesh> back = DecodeTetMesh(*bytes);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_TRUE(std::isfinite(back->positions[0].x) && std::isfinite(back->positions[1].x));
  EXPECT_EQ(back->positions[1].x, std::ldexp(3.0, 1022));
  EXPECT_EQ(back->positions[0].x, -std::ldexp(3.0, 1022));
}

TEST(QuantizeTest, EmptyAndSinglePoint) {
  mesh::TetMesh m;
  Quantized q = EncodeQuantized(m, 12);
  EXPECT_TRUE(q.decoded.positions.empty());
  // A zero-extent box gets the finest lattice holding the point exactly.
  m.positions = {{0.5, -3.25, 8}};
  q = EncodeQuantized(m, 12);
  ASSERT_EQ(q.decoded.positions.size(), 1u);
  EXPECT_EQ(q.decoded.positions[0], m.positions[0]);
  EXPECT_EQ(q.report.max_position_error, 0);
  // One spacing serves all axes: wildly different magnitudes stay within
  // the (then huge) bound and finite.
  m.positions = {{1e-310, -3.25, 7e300}};
  q = EncodeQuantized(m, 12);
  ASSERT_EQ(q.decoded.positions.size(), 1u);
  EXPECT_LE(q.report.max_position_error, q.report.position_error_bound);
  EXPECT_TRUE(geom::IsFinite(q.decoded.positions[0]));
}

}  // namespace
}  // namespace svrc::codec
