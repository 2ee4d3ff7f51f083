// FastCollarSize (Figure 3.8) equals the brute-force g(v) on random PLC-like
// configurations; cells explored stay bounded (Lemma 35).
#include "core/svrc/collar_size.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "core/delaunay/delaunay3.h"
#include "gtest/gtest.h"

namespace svrc::refine {
namespace {

using delaunay::Delaunay3;
using delaunay::VertexId;

struct Scene {
  std::vector<OracleFeature> features;
  Delaunay3 dt;
  std::vector<uint32_t> feature_of_vertex;  // feature a vertex was sampled on, or kNone
  std::vector<std::vector<uint32_t>> cell_features;  // conservative per-cell feature lists
};

constexpr uint32_t kNone = 0xFFFFFFFFu;

// Random segments and triangles in [0,1]³, `per_feature` sample points on each,
// `volume` random points, and the corners of [-2,3]³ so that cells near the
// features are bounded. Cell → features: every feature within R_u of u (V(u) ⊆
// B(u, R_u)), a superset of the features meeting V(u), as the BLG's ConfBall
// links would be.
Scene MakeScene(uint64_t seed, int num_segments, int num_triangles, int per_feature, int volume) {
  Scene s;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Vec3> pts;
  auto rp = [&] { return Vec3(u(rng), u(rng), u(rng)); };
  for (int i = 0; i < num_segments; ++i) {
    OracleFeature f;
    f.id = static_cast<uint32_t>(s.features.size());
    f.kind = 1;
    f.p[0] = rp();
    f.p[1] = f.p[0] + 0.4 * (rp() - Vec3(0.5, 0.5, 0.5));
    s.features.push_back(f);
  }
  for (int i = 0; i < num_triangles; ++i) {
    OracleFeature f;
    f.id = static_cast<uint32_t>(s.features.size());
    f.kind = 2;
    f.p[0] = rp();
    f.p[1] = f.p[0] + 0.4 * (rp() - Vec3(0.5, 0.5, 0.5));
    f.p[2] = f.p[0] + 0.4 * (rp() - Vec3(0.5, 0.5, 0.5));
    s.features.push_back(f);
  }
  std::vector<uint32_t> owner;
  for (const OracleFeature& f : s.features) {
    for (int k = 0; k < per_feature; ++k) {
      Vec3 p;
      if (f.kind == 1) {
        p = f.p[0] + u(rng) * (f.p[1] - f.p[0]);
      } else {
        double a = u(rng), b = u(rng);
        if (a + b > 1) { a = 1 - a; b = 1 - b; }
        p = f.p[0] + a * (f.p[1] - f.p[0]) + b * (f.p[2] - f.p[0]);
      }
      pts.push_back(p);
      owner.push_back(f.id);
    }
  }
  for (int i = 0; i < volume; ++i) {
    pts.push_back(rp());
    owner.push_back(kNone);
  }
  for (int c = 0; c < 8; ++c) {
    pts.push_back(Vec3(c & 1 ? 3 : -2, c & 2 ? 3 : -2, c & 4 ? 3 : -2));
    owner.push_back(kNone);
  }
  for (uint32_t i = 0; i < pts.size(); ++i) {
    const auto r = s.dt.Insert(pts[i], i);
    EXPECT_EQ(r.vertex.value(), i);  // no duplicates in random data
  }
  s.feature_of_vertex = owner;
  s.cell_features.resize(pts.size());
  for (uint32_t i = 0; i < pts.size(); ++i) {
    const double R = s.dt.OutRadius(VertexId(i));
    for (const OracleFeature& f : s.features) {
      if (!(OracleFeatureDistance(f, pts[i]) > R)) s.cell_features[i].push_back(f.id);
    }
  }
  return s;
}

TEST(FastCollarSizeTest, EqualsBruteForceOnRandomPlcLikeScenes) {
  std::vector<uint32_t> explored;
  std::vector<double> ratio;
  int queries = 0;
  for (uint64_t seed = 1; seed <= 6; ++seed) {
    Scene s = MakeScene(seed, 6, 6, 25, 150);
    for (uint32_t vi = 0; vi < s.feature_of_vertex.size(); ++vi) {
      if (s.feature_of_vertex[vi] == kNone) continue;
      if (vi % 3 != 0) continue;  // a third of the feature samples as queries
      const Vec3 v = s.dt.Point(VertexId(vi));
      const uint32_t own = s.feature_of_vertex[vi];
      const std::vector<uint32_t> excluded = {own};
      uint32_t oracle_feature = kNone;
      const double oracle = BruteForceCollarG(s.features, v, excluded, &oracle_feature);
      const CollarSizeResult r = FastCollarSize(
          s.dt, v, VertexId(vi),
          [&](VertexId u, std::vector<uint32_t>* out) {
            for (uint32_t f : s.cell_features[u.value()]) out->push_back(f);
          },
          [&](uint32_t f, const Vec3& p) {
            return f == own ? std::numeric_limits<double>::infinity()
                            : OracleFeatureDistance(s.features[f], p);
          });
      ASSERT_EQ(r.g, oracle) << "seed " << seed << " vertex " << vi;
      EXPECT_EQ(r.nearest_feature, oracle_feature);
      EXPECT_NEAR(r.radius, oracle / 3, 1e-9 * oracle);
      EXPECT_LE(r.radius, oracle / 3);
      explored.push_back(r.cells_explored);
      // Locality: cells explored vs vertices within g of v (the cells B(v, g)
      // must touch at least contain those), i.e. how much the search overshoots.
      uint32_t inside = 0;
      for (uint32_t w = 0; w < s.dt.NumVertices(); ++w) {
        if (geom::Dist(s.dt.Point(VertexId(w)), v) < oracle) ++inside;
      }
      ratio.push_back(static_cast<double>(r.cells_explored) / std::max<uint32_t>(inside, 1));
      ++queries;
    }
  }
  ASSERT_GT(queries, 200);
  std::sort(explored.begin(), explored.end());
  const auto pct = [&](double p) {
    return explored[std::min(explored.size() - 1, static_cast<size_t>(p * explored.size()))];
  };
  std::printf("FastCollarSize cells explored over %d queries: min %u median %u p90 %u p99 %u max %u\n",
              queries, explored.front(), pct(0.5), pct(0.9), pct(0.99), explored.back());
  std::sort(ratio.begin(), ratio.end());
  std::printf("cells explored / vertices within g: median %.2f p90 %.2f max %.2f\n",
              ratio[ratio.size() / 2], ratio[ratio.size() * 9 / 10], ratio.back());
  // Random (not well-spaced) meshes: Lemma 35's constant does not apply (g is
  // often comparable to the scene, 458 vertices); what must hold is locality —
  // the search explores about the cells of B(v, g), not the whole mesh.
  // Measured: median 4.4, max 8.5 (the key uses only the bisector with q, a
  // weak bound for cells far from q).
  EXPECT_LT(ratio[ratio.size() / 2], 10.0);
  EXPECT_LT(pct(0.5), 458u / 2);
}

TEST(FastCollarSizeTest, StartCellNotVertexAndNoFeature) {
  // v need not be a vertex: q = NearestVertex(v). With no other feature, g = +inf.
  Scene s = MakeScene(42, 1, 0, 20, 50);
  const Vec3 v(0.5, 0.5, 0.5);
  const VertexId q = s.dt.NearestVertex(v);
  const CollarSizeResult r = FastCollarSize(
      s.dt, v, q, [&](VertexId u, std::vector<uint32_t>* out) {
        for (uint32_t f : s.cell_features[u.value()]) out->push_back(f);
      },
      [&](uint32_t f, const Vec3& p) { return OracleFeatureDistance(s.features[f], p); });
  const std::vector<uint32_t> none;
  EXPECT_EQ(r.g, BruteForceCollarG(s.features, v, none));
  const CollarSizeResult r2 = FastCollarSize(
      s.dt, v, q, [&](VertexId, std::vector<uint32_t>*) {},
      [&](uint32_t, const Vec3&) { return 0.0; });
  EXPECT_TRUE(std::isinf(r2.g));
  EXPECT_EQ(r2.cells_explored, s.dt.NumVertices());  // nothing stops the search
}

}  // namespace
}  // namespace svrc::refine
