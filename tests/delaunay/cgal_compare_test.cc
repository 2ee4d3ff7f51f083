// The 3D kernel against CGAL's Delaunay_triangulation_3 (test oracle only:
// CGAL is never linked into shipped targets). On 10^5 uniform random points
// the Delaunay tetrahedralization is unique, so the tet sets must be equal.
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <random>
#include <utility>
#include <vector>

#include "core/delaunay/point_set.h"
#include "tests/delaunay/tet_check.h"

namespace svrc::delaunay {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Triangulation_vertex_base_with_info_3<uint32_t, K>;
using Tds = CGAL::Triangulation_data_structure_3<Vb>;
using CgalDt = CGAL::Delaunay_triangulation_3<K, Tds>;
using Tet = std::array<uint32_t, 4>;

std::vector<Tet> CgalTets(const std::vector<Vec3>& pts) {
  std::vector<std::pair<K::Point_3, uint32_t>> in;
  in.reserve(pts.size());
  for (uint32_t i = 0; i < pts.size(); ++i) in.emplace_back(K::Point_3(pts[i].x, pts[i].y, pts[i].z), i);
  CgalDt dt(in.begin(), in.end());
  std::vector<Tet> tets;
  for (auto c = dt.finite_cells_begin(); c != dt.finite_cells_end(); ++c) {
    tets.push_back(CanonicalRotation({c->vertex(0)->info(), c->vertex(1)->info(), c->vertex(2)->info(),
                                      c->vertex(3)->info()}));
  }
  std::sort(tets.begin(), tets.end());
  return tets;
}

TEST(CgalCompareTest, Uniform100kEqualsCgal) {
  std::mt19937_64 rng(2024);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vec3> pts(100000);
  for (auto& p : pts) p = Vec3(u(rng), u(rng), u(rng));
  auto t0 = std::chrono::steady_clock::now();
  auto ours = TetrahedralizePointSet(pts);
  const double s_ours = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_TRUE(ours.ok()) << ours.status();
  t0 = std::chrono::steady_clock::now();
  const auto cgal = CgalTets(pts);
  const double s_cgal = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("svrc %zu tets %.3f s, CGAL %zu tets %.3f s\n", ours->tets.size(), s_ours, cgal.size(), s_cgal);
  ASSERT_EQ(ours->tets.size(), cgal.size());
  EXPECT_TRUE(ours->tets == cgal);
  // Independent empty-sphere check of the final result (per face, linear).
  EXPECT_EQ(testing::CheckDelaunayTets(pts, ours->tets), "");
}

TEST(CgalCompareTest, ClusteredPointsEqualCgal) {
  // Non-uniform: Gaussian clusters at very different scales.
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Vec3> pts;
  for (int c = 0; c < 20; ++c) {
    const Vec3 centre(g(rng) * 100, g(rng) * 100, g(rng) * 100);
    const double s = std::pow(10.0, -(c % 6));
    for (int i = 0; i < 1000; ++i) pts.push_back(centre + s * Vec3(g(rng), g(rng), g(rng)));
  }
  auto ours = TetrahedralizePointSet(pts);
  ASSERT_TRUE(ours.ok()) << ours.status();
  EXPECT_TRUE(ours->tets == CgalTets(pts));
  EXPECT_EQ(testing::CheckDelaunayTets(pts, ours->tets), "");
}

}  // namespace
}  // namespace svrc::delaunay
