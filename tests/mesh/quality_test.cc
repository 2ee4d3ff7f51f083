#include "core/mesh/quality.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "gtest/gtest.h"

namespace svrc::mesh {
namespace {

const Vec3 kReg[4] = {Vec3(1, 1, 1), Vec3(-1, 1, -1), Vec3(1, -1, -1), Vec3(-1, -1, 1)};

TEST(TetQuality, RegularTetrahedron) {
  const TetQuality q = ComputeTetQuality(kReg[0], kReg[1], kReg[2], kReg[3]);
  EXPECT_GT(q.volume, 0);
  EXPECT_NEAR(q.volume, 8.0 / 3.0, 1e-12);
  EXPECT_NEAR(q.radius_edge, std::sqrt(6.0) / 4.0, 1e-12);
  const double dih = std::acos(1.0 / 3.0) * 180 / M_PI;  // 70.5288
  EXPECT_NEAR(dih, 70.5288, 1e-4);
  for (double a : q.dihedral_deg) EXPECT_NEAR(a, dih, 1e-9);
  EXPECT_NEAR(q.min_dihedral_deg, dih, 1e-9);
  EXPECT_NEAR(q.max_dihedral_deg, dih, 1e-9);
  EXPECT_NEAR(q.aspect, 1.0, 1e-12);
}

TEST(TetQuality, InvariantUnderScaleAndTranslation) {
  const Vec3 off(1e3, -7, 2.5);
  const TetQuality a = ComputeTetQuality(kReg[0], kReg[1], kReg[2], kReg[3]);
  const TetQuality b = ComputeTetQuality(1e-3 * kReg[0] + off, 1e-3 * kReg[1] + off,
                                         1e-3 * kReg[2] + off, 1e-3 * kReg[3] + off);
  EXPECT_NEAR(a.radius_edge, b.radius_edge, 1e-6);
  EXPECT_NEAR(a.aspect, b.aspect, 1e-6);
  EXPECT_NEAR(a.min_dihedral_deg, b.min_dihedral_deg, 1e-6);
}

TEST(TetQuality, CornerTetrahedron) {
  const TetQuality q =
      ComputeTetQuality(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1));
  EXPECT_NEAR(q.volume, 1.0 / 6.0, 1e-15);
  EXPECT_NEAR(q.radius_edge, std::sqrt(3.0) / 2.0, 1e-12);  // R = √3/2, shortest edge 1
  const double other = std::acos(1 / std::sqrt(3.0)) * 180 / M_PI;  // 54.7356
  // Edges (0,1) (0,2) (0,3) are the axes: 90 degrees; the others 54.7356.
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(q.dihedral_deg[k], 90.0, 1e-9) << k;
  for (int k = 3; k < 6; ++k) EXPECT_NEAR(q.dihedral_deg[k], other, 1e-9) << k;
}

TEST(TetQuality, Sliver) {
  // Four nearly coplanar points on a square: the radius-edge ratio stays
  // small, the dihedral angles go to 0 and 180 and the aspect ratio explodes.
  const double h = 1e-3;
  const TetQuality q =
      ComputeTetQuality(Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(0, 1, h), Vec3(0, -1, h));
  EXPECT_LT(q.radius_edge, 0.75);
  EXPECT_LT(q.min_dihedral_deg, 0.2);
  EXPECT_GT(q.max_dihedral_deg, 179.8);
  EXPECT_GT(q.aspect, 100);
  // Flat: infinite ratios, no NaN.
  const TetQuality flat =
      ComputeTetQuality(Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(0, 1, 0), Vec3(0, -1, 0));
  EXPECT_TRUE(std::isinf(flat.radius_edge));
  EXPECT_TRUE(std::isinf(flat.aspect));
  EXPECT_EQ(flat.volume, 0);
}

TEST(Distribution, NearestRank) {
  std::vector<double> v;
  for (int i = 100; i >= 1; --i) v.push_back(i);
  const Distribution d = Distribution::Of(v);
  EXPECT_EQ(d.count, 100u);
  EXPECT_EQ(d.min, 1);
  EXPECT_EQ(d.p1, 1);
  EXPECT_EQ(d.p5, 5);
  EXPECT_EQ(d.p50, 50);
  EXPECT_EQ(d.p95, 95);
  EXPECT_EQ(d.p99, 99);
  EXPECT_EQ(d.max, 100);
  EXPECT_EQ(Distribution::Of({}).count, 0u);
  EXPECT_EQ(Distribution::Of({3}).p1, 3);
}

// The selection (nth_element, rank by rank) returns what the sorted
// definition gives, on every size from 1 to 300 (ranks that coincide at small
// sizes), with many duplicates and with infinities (flat tets' aspect).
TEST(Distribution, SelectionEqualsTheSortedDefinition) {
  std::mt19937 rng(7);
  for (size_t n = 1; n <= 300; ++n) {
    for (int trial = 0; trial < 3; ++trial) {
      std::vector<double> v(n);
      for (double& x : v) x = trial == 0 ? static_cast<double>(rng() % 5) : std::ldexp(rng() % 100000, -7);
      if (trial == 2) v[rng() % n] = std::numeric_limits<double>::infinity();
      std::vector<double> sorted = v;
      std::sort(sorted.begin(), sorted.end());
      auto rank = [&](double pct) {
        const double r = std::ceil(pct / 100.0 * static_cast<double>(n));
        return sorted[std::min<size_t>(r < 1 ? 0 : static_cast<size_t>(r) - 1, n - 1)];
      };
      const Distribution d = Distribution::Of(v);
      ASSERT_EQ(d.count, n);
      EXPECT_EQ(d.min, sorted.front()) << n;
      EXPECT_EQ(d.p1, rank(1)) << n;
      EXPECT_EQ(d.p5, rank(5)) << n;
      EXPECT_EQ(d.p50, rank(50)) << n;
      EXPECT_EQ(d.p95, rank(95)) << n;
      EXPECT_EQ(d.p99, rank(99)) << n;
      EXPECT_EQ(d.max, sorted.back()) << n;
    }
  }
}

// A tet's largest dihedral less its rounding allowance never exceeds the angle
// of the unrounded tet: small random tets (edges ~1e-7, some flat) measured
// near the origin and again moved to coordinates ~1e4, where rounding moves
// their angles (near+rot+far 5 of the random sweep: 3.9e-5 degrees).
TEST(QualityReport, MaxDihedralLessRoundingCoversTheRoundingOfFarCoordinates) {
  std::mt19937_64 rng(39);
  std::uniform_real_distribution<double> u(-1, 1);
  const Vec3 far(12345.678, -9876.54, 4321.0);
  int rounded_over = 0;
  for (int i = 0; i < 2000; ++i) {
    TetMesh near, moved;
    for (int k = 0; k < 4; ++k) {
      Vec3 p(u(rng), u(rng), (i % 2 == 0 ? 0.05 : 1) * u(rng));
      near.positions.push_back(1e-7 * p);
      moved.positions.push_back(far + 1e-7 * p);
    }
    near.tets = moved.tets = {{0, 1, 2, 3}};
    const std::vector<uint8_t> all(4, 1);
    const double exact = ComputeTetQuality(near.positions[0], near.positions[1], near.positions[2],
                                           near.positions[3]).max_dihedral_deg;
    const double measured = ComputeTetQuality(moved.positions[0], moved.positions[1], moved.positions[2],
                                              moved.positions[3]).max_dihedral_deg;
    rounded_over += measured > exact + 1e-6 ? 1 : 0;
    EXPECT_LE(MaxDihedralLessRounding(moved, all), exact + 1e-9) << i;
    // Near the origin the allowance is negligible.
    EXPECT_NEAR(MaxDihedralLessRounding(near, all), exact, 1e-6) << i;
  }
  EXPECT_GT(rounded_over, 100);  // the rounding does move angles there
  TetMesh none;
  EXPECT_EQ(MaxDihedralLessRounding(none, {}), 0);
}

TEST(QualityReport, SplitsByCreaseVertex) {
  TetMesh m;
  for (const Vec3& p : kReg) m.positions.push_back(p);
  // A sliver on four more vertices.
  m.positions.push_back(Vec3(11, 0, 0));
  m.positions.push_back(Vec3(9, 0, 0));
  m.positions.push_back(Vec3(10, 1, 0.001));
  m.positions.push_back(Vec3(10, -1, 0.001));
  m.tets = {{0, 1, 2, 3}, {4, 5, 6, 7}};
  std::vector<uint8_t> crease(8, 0);
  crease[6] = 1;
  const QualityReport r = ComputeQuality(m, crease);
  EXPECT_EQ(r.all.num_tets, 2u);
  EXPECT_EQ(r.other.num_tets, 1u);
  EXPECT_EQ(r.crease.num_tets, 1u);
  EXPECT_NEAR(r.other.radius_edge.max, std::sqrt(6.0) / 4, 1e-12);
  EXPECT_NEAR(r.other.min_dihedral_deg.min, 70.5288, 1e-4);
  EXPECT_LT(r.crease.min_dihedral_deg.min, 0.2);
  EXPECT_EQ(r.all.dihedral_deg.count, 12u);
  // The largest volume per group (svrc_plc_check's max_volume test).
  const double reg = ComputeTetQuality(m.positions[0], m.positions[1], m.positions[2], m.positions[3]).volume;
  const double sliver = ComputeTetQuality(m.positions[4], m.positions[5], m.positions[6], m.positions[7]).volume;
  EXPECT_GT(reg, sliver);
  EXPECT_EQ(r.other.max_volume, reg);
  EXPECT_EQ(r.crease.max_volume, sliver);
  EXPECT_EQ(r.all.max_volume, reg);
  const std::string text = FormatQualityReport(r);
  EXPECT_NE(text.find("touching a crease: 1 tets"), std::string::npos) << text;
  EXPECT_NE(text.find("radius-edge"), std::string::npos);
  // Without crease flags everything is "other".
  const QualityReport r2 = ComputeQuality(m);
  EXPECT_EQ(r2.other.num_tets, 2u);
  EXPECT_EQ(r2.crease.num_tets, 0u);
}

}  // namespace
}  // namespace svrc::mesh
