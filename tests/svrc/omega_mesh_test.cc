// M_Ω's cell sizes (core/svrc/feature_meshes.h): OmegaMesh::ShrunkSize, the
// star-walk-free size of a cavity cell after an insertion, must equal Size()
// computed from scratch bit for bit (the refiner's verdicts and output
// depend on it), including on a lattice where farthest corners tie.
#include <bit>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "core/geometry/predicates.h"
#include "core/svrc/feature_meshes.h"
#include "gtest/gtest.h"

namespace svrc::refine {
namespace {

using geom::Vec3;

bool SameBits(double a, double b) { return std::bit_cast<uint64_t>(a) == std::bit_cast<uint64_t>(b); }

struct Counts {
  size_t shrunk = 0;
  size_t cavity_cells = 0;
  size_t shrunk_outside = 0;  // ... of cells with tets outside (labelled)
  uint64_t a_circumcentres = 0, b_circumcentres = 0;  // computed (cache misses)
  uint64_t a_sizes_computed = 0;                      // a's Size() answers not from its memo
};

// Inserts `pts` into two copies of M_Ω. In `a`, every cavity cell is sized
// by ShrunkSize when it answers (Size() otherwise, which keeps its memo
// current, as ForceInsertOmega does); in `b`, always by Size() on a star it
// has never seen. Every answer of `a` must equal `b`'s.
// With `labelled`, every tet gets a label when it is made (kept: its
// centroid has x > 0.45; both meshes make the same tets in the same slots),
// and the kept_* fields are compared too.
// `a` holds at most 2^cc_log2 circumcentres and 2^memo_log2 memos (0: no
// bound, a half to one per slot / vertex; OmegaMesh::SetCacheLimits), `b`
// has no bound.
Counts CompareSizes(const std::vector<Vec3>& pts, bool skip_every_third, bool labelled = false, uint32_t cc_log2 = 0,
                    uint32_t memo_log2 = 0) {
  OmegaMesh a(Vec3{0.5, 0.5, 0.5}, 2.0), b(Vec3{0.5, 0.5, 0.5}, 2.0);
  a.SetCacheLimits(cc_log2, memo_log2, size_t{1} << 20);
  b.SetCacheLimits(0, 0, 0);
  util::PodVector<TetLabel> labels;
  if (labelled) {
    a.SetLabels(&labels);
    b.SetLabels(&labels);
  }
  std::array<PointId, 8> corners;
  for (uint32_t i = 0; i < 8; ++i) corners[i] = PointId(i);
  a.SeedCorners(corners);
  b.SeedCorners(corners);
  Counts out;
  auto count_work = [&] {
    out.a_circumcentres = a.stats().circumcentres;
    out.b_circumcentres = b.stats().circumcentres;
    out.a_sizes_computed = a.stats().computed_sizes;
  };
  std::vector<uint32_t> pos(pts.size() + 16, UINT32_MAX);
  for (size_t n = 0; n < pts.size(); ++n) {
    const PointId id(static_cast<uint32_t>(8 + n));
    const auto ra = a.dt().Insert(pts[n], id.value());
    const auto rb = b.dt().Insert(pts[n], id.value());
    EXPECT_EQ(ra.vertex, rb.vertex);
    a.AddVertex(ra.vertex, id);
    b.AddVertex(rb.vertex, id);
    if (labelled) {
      for (size_t k = 0; k < ra.created.size(); ++k) {
        const delaunay::TetId t = ra.created[k];
        EXPECT_EQ(t, rb.created[k]);
        if (labels.size() <= t.value()) labels.resize(t.value() + 1024);
        if (a.dt().IsGhost(t)) continue;
        double x = 0;
        for (int i = 0; i < 4; ++i) x += a.dt().Point(a.dt().TetVertex(t, i)).x / 4;
        labels[t.value()] = TetLabel::Make(a.dt().Generation(t) + 1, x > 0.45, 0);
      }
    }
    const std::vector<VertexId> cav(ra.cavity_vertices.begin(), ra.cavity_vertices.end());
    // What the insertion added to each cavity vertex's star, as the refiner
    // collects it (ForceInsertOmega).
    std::vector<OmegaMesh::NewTets> added(cav.size());
    for (size_t i = 0; i < cav.size(); ++i) pos[cav[i].value()] = static_cast<uint32_t>(i);
    for (delaunay::TetId t : ra.created) {
      Vec3 cc;
      const bool plain = !a.dt().IsGhost(t) && a.PlainCorner(t, &cc);
      for (int k = 0; k < 4; ++k) {
        const VertexId u = a.dt().TetVertex(t, k);
        if (u == ra.vertex || u.value() >= pos.size() || pos[u.value()] == UINT32_MAX) continue;
        added[pos[u.value()]].Add(plain ? geom::Dist(cc, a.dt().Point(u)) : HUGE_VAL, a.KnownOutside(t));
      }
    }
    for (size_t i = 0; i < cav.size(); ++i) {
      const VertexId u = cav[i];
      pos[u.value()] = UINT32_MAX;
      ++out.cavity_cells;
      // Leave some cells unsized: their memo goes stale, and ShrunkSize
      // must notice the star changes it did not see.
      if (skip_every_third && (n + i) % 3 == 0) continue;
      CellSize sa;
      const bool shrunk = a.ShrunkSize(u, pts[n], added[i], &sa);
      if (shrunk) {
        ++out.shrunk;
      } else {
        sa = a.Size(u);
      }
      const CellSize sb = b.Size(u);
      EXPECT_TRUE(SameBits(sa.outradius, sb.outradius)) << "vertex " << u.value() << " after point " << n;
      EXPECT_TRUE(SameBits(sa.inradius, sb.inradius)) << "vertex " << u.value() << " after point " << n;
      for (int k = 0; k < 3; ++k) EXPECT_TRUE(SameBits(sa.corner[k], sb.corner[k]));
      EXPECT_EQ(sa.hint, sb.hint);
      EXPECT_EQ(sa.clipped, sb.clipped);
      EXPECT_EQ(sa.saw_flat, sb.saw_flat);
      EXPECT_TRUE(SameBits(sa.kept_outradius, sb.kept_outradius)) << "vertex " << u.value() << " after point " << n;
      for (int k = 0; k < 3; ++k) EXPECT_TRUE(SameBits(sa.kept_corner[k], sb.kept_corner[k]));
      EXPECT_EQ(sa.kept_hint, sb.kept_hint);
      // ShrunkSize may keep the flag after the last outside tet went.
      EXPECT_GE(sa.outside_tets, sb.outside_tets);
      if (shrunk && sb.outside_tets) ++out.shrunk_outside;
      if (testing::Test::HasFailure()) return out;
    }
    a.Size(ra.vertex);
    b.Size(rb.vertex);
  }
  count_work();
  return out;
}

// n uniform random points in the unit cube.
std::vector<Vec3> RandomPoints(uint64_t seed, size_t n) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vec3> pts(n);
  for (Vec3& p : pts) p = {u(rng), u(rng), u(rng)};
  return pts;
}

TEST(OmegaMeshTest, ShrunkSizeEqualsSizeOnRandomPoints) {
  const Counts c = CompareSizes(RandomPoints(12, 3000), false);
  // Most cavity cells keep their farthest corner: the shortcut must answer
  // often, or the refiner gains nothing.
  EXPECT_GT(c.shrunk, c.cavity_cells / 5) << c.shrunk << " of " << c.cavity_cells;
}

TEST(OmegaMeshTest, ShrunkSizeOfLabelledCells) {
  const Counts c = CompareSizes(RandomPoints(78, 3000), false, /*labelled=*/true);
  EXPECT_GT(c.shrunk_outside, 100u) << c.shrunk << " of " << c.cavity_cells;
}

TEST(OmegaMeshTest, ShrunkSizeNoticesStaleMemos) {
  const Counts c = CompareSizes(RandomPoints(34, 2000), true);
  EXPECT_GT(c.shrunk, 0u);
}

// The circumcentre cache and the memos bounded and direct-mapped (§8 item
// 44): a record holding another tet's circumcentre or another vertex's
// memo must never answer, and an evicted memo must only cost a star walk.
// Tiny tables (32 circumcentres, 16 memos) make every lookup collide; a
// larger one (2^10 / 2^8) grows through its sizes while the mesh does and
// then stops.
TEST(OmegaMeshTest, BoundedCachesGiveTheSameSizes) {
  for (const auto& [cc_log2, memo_log2] : {std::pair<uint32_t, uint32_t>{5, 4}, {10, 8}}) {
    const Counts c = CompareSizes(RandomPoints(91, 3000), false, false, cc_log2, memo_log2);
    EXPECT_GT(c.shrunk, 0u);
    // The bound was in force: a computed more circumcentres than b.
    EXPECT_GT(c.a_circumcentres, c.b_circumcentres + c.b_circumcentres / 10) << cc_log2;
  }
  const Counts labelled = CompareSizes(RandomPoints(92, 2000), true, true, 6, 3);
  EXPECT_GT(labelled.a_circumcentres, labelled.b_circumcentres);
}

TEST(OmegaMeshTest, ShrunkSizeOnALatticeWithTiedCorners) {
  // A shuffled 9³ lattice: cospherical points everywhere, so farthest
  // corners tie and circumcentres coincide.
  std::vector<Vec3> pts;
  for (int i = 0; i < 9; ++i) {
    for (int j = 0; j < 9; ++j) {
      for (int k = 0; k < 9; ++k) pts.push_back({i / 8.0, j / 8.0, k / 8.0});
    }
  }
  std::shuffle(pts.begin(), pts.end(), std::mt19937_64(56));
  const Counts c = CompareSizes(pts, false);
  EXPECT_GT(c.shrunk, 0u);
}

// ClipPolygonToBox skips the planes no vertex is outside of (session 25:
// clipping was 4.4% of cube --max-volume 1e-5's instructions, six passes per
// Voronoi facet). Against all six Sutherland–Hodgman passes, bit for bit:
// random convex polygons around the box's faces, edges and corners, some
// vertices moved exactly onto a bound, some polygons wholly inside, outside,
// or flat on a face. Checked broken: testing the other side's bit fails.
// Not reached here: the outcode recomputed after a pass, for a rounded
// crossing point outside a plane no input vertex was outside of (these
// trials never draw one; a search of 2 M random edges found none either).
std::vector<Vec3> ClipAllSixPasses(const geom::Box3& box, std::vector<Vec3> poly) {
  for (int k = 0; k < 3 && !poly.empty(); ++k) {
    for (int side = 0; side < 2 && !poly.empty(); ++side) {
      const double bound = side == 0 ? box.lo[k] : box.hi[k];
      auto inside = [&](const Vec3& p) {
        return side == 0 ? geom::Orient1d(bound, p[k]) >= 0 : geom::Orient1d(p[k], bound) >= 0;
      };
      std::vector<Vec3> out;
      for (size_t i = 0; i < poly.size(); ++i) {
        const Vec3& a = poly[i];
        const Vec3& b = poly[(i + 1) % poly.size()];
        if (inside(a)) out.push_back(a);
        if (inside(a) != inside(b)) {
          Vec3 q = a + ((bound - a[k]) / (b[k] - a[k])) * (b - a);
          q[k] = bound;
          out.push_back(q);
        }
      }
      poly = out;
    }
  }
  return poly;
}

// Size()'s memo table rounds down to a power of two (between a half and one
// record per vertex, session 44), so vertices past its end share records
// with low ones. Their memos must still answer: a memo written for such a
// vertex is found again by the next lookup (a lookup that gave up on every
// vertex past the table's end recomputed them all, silently).
TEST(OmegaMeshTest, MemosOfVerticesPastTheTableAnswer) {
  OmegaMesh m(Vec3{0.5, 0.5, 0.5}, 2.0);
  m.SetCacheLimits(0, 0, size_t{1} << 20);
  std::array<PointId, 8> corners;
  for (uint32_t i = 0; i < 8; ++i) corners[i] = PointId(i);
  m.SeedCorners(corners);
  // 2,200 vertices: the table of 2,200 + 16 rounded down is 2,048, so
  // vertices 2,048 … 2,199 lie past it.
  const std::vector<Vec3> pts = RandomPoints(44, 2200 - 8);
  for (size_t n = 0; n < pts.size(); ++n) {
    const PointId id(static_cast<uint32_t>(8 + n));
    const auto r = m.dt().Insert(pts[n], id.value());
    m.AddVertex(r.vertex, id);
  }
  ASSERT_EQ(m.dt().NumVertices(), 2200u);
  for (uint32_t v = 0; v < m.dt().NumVertices(); ++v) {
    const uint64_t before = m.stats().computed_sizes;
    const CellSize first = m.Size(VertexId(v));
    const CellSize again = m.Size(VertexId(v));
    EXPECT_EQ(m.stats().computed_sizes, before + 1) << "vertex " << v;
    EXPECT_TRUE(SameBits(first.outradius, again.outradius)) << "vertex " << v;
  }
}

TEST(OmegaMeshTest, ClipPolygonToBoxEqualsAllSixPasses) {
  geom::Box3 box;
  box.Add(Vec3{-1.5, -0.75, 0.25});
  box.Add(Vec3{2.5, 1.25, 3.0 / 7});
  std::mt19937_64 rng(25);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  int clipped = 0, emptied = 0, unchanged = 0, on_bound = 0;
  std::vector<Vec3> poly, scratch;
  for (int trial = 0; trial < 20000; ++trial) {
    // A centre near a random corner, edge midpoint or face of the box.
    Vec3 c;
    for (int k = 0; k < 3; ++k) {
      const double pick = u01(rng);
      c[k] = pick < 0.35 ? box.lo[k] : pick < 0.7 ? box.hi[k] : box.lo[k] + u01(rng) * (box.hi[k] - box.lo[k]);
      c[k] += (u01(rng) - 0.5) * 0.3;
    }
    // A convex polygon: points on an ellipse in a random plane, or (flat)
    // in the plane x_k = bound.
    const int flat = trial % 10 == 0 ? static_cast<int>(rng() % 3) : -1;
    Vec3 e1{u01(rng) - 0.5, u01(rng) - 0.5, u01(rng) - 0.5};
    Vec3 e2{u01(rng) - 0.5, u01(rng) - 0.5, u01(rng) - 0.5};
    if (flat >= 0) {
      c[flat] = box.hi[flat];
      e1[flat] = 0;
      e2[flat] = 0;
    }
    if (trial % 5 == 1) c = 0.5 * (box.lo + box.hi);  // wholly inside
    const double scale = trial % 5 == 1 ? 0.05 : trial % 7 == 0 ? 3.0 : 0.4;
    const int n = 3 + static_cast<int>(rng() % 8);
    poly.clear();
    for (int i = 0; i < n; ++i) {
      const double a = 2 * M_PI * (i + 0.3 * u01(rng)) / n;
      Vec3 p = c + (scale * std::cos(a)) * e1 + (scale * std::sin(a)) * e2;
      if (rng() % 6 == 0) {  // exactly on a bound
        const int k = static_cast<int>(rng() % 3);
        p[k] = rng() % 2 ? box.lo[k] : box.hi[k];
        ++on_bound;
      }
      poly.push_back(p);
    }
    const std::vector<Vec3> want = ClipAllSixPasses(box, poly);
    const std::vector<Vec3> before = poly;
    ClipPolygonToBox(box, &poly, &scratch);
    ASSERT_EQ(poly.size(), want.size()) << "trial " << trial;
    for (size_t i = 0; i < want.size(); ++i) {
      for (int k = 0; k < 3; ++k) ASSERT_TRUE(SameBits(poly[i][k], want[i][k])) << "trial " << trial;
    }
    if (want.empty()) {
      ++emptied;
    } else if (want == before) {
      ++unchanged;
    } else {
      ++clipped;
    }
  }
  // Every kind of case was drawn.
  EXPECT_GT(clipped, 5000);
  EXPECT_GT(emptied, 500);
  EXPECT_GT(unchanged, 500);
  EXPECT_GT(on_bound, 5000);
}

}  // namespace
}  // namespace svrc::refine
