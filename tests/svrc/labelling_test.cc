// Region labelling (core/svrc/labelling.h): components, seeds, holes, ∂Ω,
// constrained faces, warnings and errors, on Kuhn grids where the expected
// answer follows from each tet's centroid.
#include "core/svrc/labelling.h"

#include <algorithm>
#include <map>
#include <random>

#include "absl/strings/str_cat.h"
#include "core/geometry/predicates.h"
#include "gtest/gtest.h"
#include "tests/svrc/output_test_util.h"

namespace svrc::refine {
namespace {

using geom::Vec3;
using testing::ConvexFacet;
using testing::Grid;

Vec3 Centroid(const Grid& g, const std::array<uint32_t, 4>& t) {
  return (g.positions[t[0]] + g.positions[t[1]] + g.positions[t[2]] + g.positions[t[3]]) / 4.0;
}

bool Inside(const Vec3& p, double lo, double hi) {
  return p.x > lo && p.x < hi && p.y > lo && p.y < hi && p.z > lo && p.z < hi;
}

bool HasIssue(const Labelling& l, LabelIssueKind k) {
  return std::any_of(l.issues.begin(), l.issues.end(), [&](const LabelIssue& i) { return i.kind == k; });
}

// Three nested boxes in an 8^3 grid (Ω = [0,8]^3): outer [1,7] (marker 1),
// middle [2,6] (marker 2), inner [3,5] (marker 3).
struct Nested {
  Grid grid = testing::KuhnGrid(8);
  plc::Plc plc;
  std::vector<ConstrainedFace> faces;
  Nested() {
    testing::AddBox(&plc, {1, 1, 1}, {7, 7, 7}, 1);
    testing::AddBox(&plc, {2, 2, 2}, {6, 6, 6}, 2);
    testing::AddBox(&plc, {3, 3, 3}, {5, 5, 5}, 3);
    faces = testing::FacesOnConvexFacets(grid.positions, grid.tets,
                                         testing::ConvexFacetsOf(plc, CoordinateMap{}));
  }
  LabelInput Input(std::span<const plc::RegionSeed> seeds, std::span<const Vec3> holes,
                   bool keep = false) const {
    LabelInput in;
    in.positions = grid.positions;
    in.tets = grid.tets;
    in.constrained_faces = faces;
    in.region_seeds = seeds;
    in.hole_seeds = holes;
    in.keep_bounding_box = keep;
    return in;
  }
};

// The plane marker of a face of the nested boxes, from its coordinates.
int32_t ExpectedMarker(const Grid& g, const std::array<uint32_t, 3>& v) {
  for (int axis = 0; axis < 3; ++axis) {
    const double c = g.positions[v[0]][axis];
    if (g.positions[v[1]][axis] != c || g.positions[v[2]][axis] != c) continue;
    if (c == 1 || c == 7) return 1;
    if (c == 2 || c == 6) return 2;
    if (c == 3 || c == 5) return 3;
  }
  return -1;
}

// crease_pair_0.1deg (session 40): finding each constrained face's slot by
// scanning the face bucket of its lowest-id vertex once per face cost
// |bucket| × its faces, quadratic in the degree of an input vertex; now each
// bucket is read once and its records looked up among the keys. This checks
// that lookup where it matters, at a vertex in all 60,000 tets and every
// cone face: every face is found in its one tet, a face that is not in the
// mesh is named. (The old way took ~5 s here, too little for a timeout to
// tell; Sliver.ConstraintsAtAVertexOfHighDegreeAreFoundInOnePass does.)
TEST(LabellingTest, ConstrainedFacesAtAVertexOfHighDegreeAreFoundInOnePass) {
  std::vector<std::array<uint32_t, 3>> cone;
  const Grid fan = testing::ApexFan(60000, &cone);
  std::vector<ConstrainedFace> faces;
  for (const auto& f : cone) faces.push_back({{f[2], f[0], f[1]}, 7, 0});
  LabelInput in;
  in.positions = fan.positions;
  in.tets = fan.tets;
  in.constrained_faces = faces;
  in.keep_bounding_box = true;
  absl::StatusOr<Labelling> l = LabelRegions(in);
  ASSERT_TRUE(l.ok()) << l.status();
  ASSERT_EQ(l->faces.size(), faces.size());
  for (size_t i = 0; i < faces.size(); ++i) {
    ASSERT_EQ(l->faces[i].tets[0], i) << "cone face " << i;
  }
  EXPECT_EQ(l->components.size(), fan.tets.size());  // the tets share edges, no faces
  EXPECT_EQ(l->num_kept_tets, fan.tets.size());
  faces.push_back({{0, 1, 3}, 7, 0});
  in.constrained_faces = faces;
  absl::StatusOr<Labelling> bad = LabelRegions(in);
  EXPECT_EQ(bad.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(bad.status().message().find("(0, 1, 3)"), std::string::npos) << bad.status();
}

TEST(LabellingTest, NestedBoxesTwoRegionsAndAHole) {
  Nested nb;
  EXPECT_EQ(nb.faces.size(), 6u * (36 + 16 + 4) * 2);
  const std::vector<plc::RegionSeed> seeds = {{{1.5, 1.5, 1.5}, 10, 0}, {{2.5, 2.6, 2.7}, 20, 0.5}};
  const std::vector<Vec3> holes = {{4.1, 4.2, 4.3}};
  auto l = LabelRegions(nb.Input(seeds, holes));
  ASSERT_TRUE(l.ok()) << l.status();
  EXPECT_TRUE(l->issues.empty()) << l->issues[0].message;
  EXPECT_EQ(l->components.size(), 4u);
  uint32_t kept = 0;
  for (size_t t = 0; t < nb.grid.tets.size(); ++t) {
    const Vec3 c = Centroid(nb.grid, nb.grid.tets[t]);
    const Component& comp = l->components[l->tet_component[t]];
    if (Inside(c, 3, 5) || !Inside(c, 1, 7)) {
      EXPECT_FALSE(comp.kept) << "tet " << t;
      continue;
    }
    ++kept;
    ASSERT_TRUE(comp.kept) << "tet " << t;
    if (Inside(c, 2, 6)) {
      EXPECT_EQ(comp.attribute, 20);
      EXPECT_EQ(comp.max_volume, 0.5);
      EXPECT_EQ(comp.seed, 1);
    } else {
      EXPECT_EQ(comp.attribute, 10);
      EXPECT_EQ(comp.seed, 0);
    }
  }
  EXPECT_EQ(kept, (216u - 8u) * 6u);
  EXPECT_EQ(l->num_kept_tets, kept);
  // Every constrained face has a kept side here: outer (kept|exterior),
  // middle (kept|kept), inner (kept|hole).
  ASSERT_EQ(l->faces.size(), nb.faces.size());
  for (const LabelledFace& f : l->faces) {
    EXPECT_EQ(f.marker, ExpectedMarker(nb.grid, f.v));
    EXPECT_TRUE(l->Kept(f.tets[0]));
    const bool interface = f.marker == 2;
    ASSERT_NE(f.tets[1], kNoTet);  // Ω's interior: every face has two tets
    EXPECT_EQ(l->Kept(f.tets[1]), interface);
  }
  // Components are numbered by their smallest tet.
  for (size_t c = 0; c < l->components.size(); ++c) {
    EXPECT_EQ(l->tet_component[l->components[c].first_tet], c);
    for (size_t t = 0; t < l->components[c].first_tet; ++t) EXPECT_LT(l->tet_component[t], c);
  }
  EXPECT_TRUE(l->components[0].touches_box);  // tet 0 is at the grid corner
}

// The caller's adjacency (LabelInput::neighbor_slots_of and find_face, as the
// refiner's size rounds pass them from Delaunay3) gives the labelling the
// face table gives, field for field — the faces' first tet included, though
// find_face here answers with the larger of a face's two slots.
TEST(LabellingTest, GivenAdjacencyGivesTheSameLabelling) {
  Nested nb;
  const std::vector<plc::RegionSeed> seeds = {{{1.5, 1.5, 1.5}, 10, 0}, {{2.5, 2.6, 2.7}, 20, 0.5}};
  const std::vector<Vec3> holes = {{4.1, 4.2, 4.3}};
  std::map<std::array<uint32_t, 3>, std::vector<uint32_t>> slots_of;
  for (uint32_t t = 0; t < nb.grid.tets.size(); ++t) {
    for (uint32_t f = 0; f < 4; ++f) {
      std::array<uint32_t, 3> k;
      for (uint32_t j = 0, m = 0; j < 4; ++j) {
        if (j != f) k[m++] = nb.grid.tets[t][j];
      }
      std::sort(k.begin(), k.end());
      slots_of[k].push_back(4 * t + f);
    }
  }
  std::vector<uint32_t> nbr(4 * nb.grid.tets.size(), kNoTet);
  for (const auto& [k, sl] : slots_of) {
    ASSERT_LE(sl.size(), 2u);
    if (sl.size() == 2) {
      nbr[sl[0]] = sl[1];
      nbr[sl[1]] = sl[0];
    }
  }
  LabelInput in = nb.Input(seeds, holes);
  in.neighbor_slots_of = [&](uint32_t t) {
    return std::array<uint32_t, 4>{nbr[4 * t], nbr[4 * t + 1], nbr[4 * t + 2], nbr[4 * t + 3]};
  };
  in.find_face = [&](uint32_t a, uint32_t b, uint32_t c) -> uint32_t {
    std::array<uint32_t, 3> k{a, b, c};
    std::sort(k.begin(), k.end());
    auto it = slots_of.find(k);
    return it == slots_of.end() ? kNoTet : it->second.back();
  };
  auto table = LabelRegions(nb.Input(seeds, holes));
  ASSERT_TRUE(table.ok()) << table.status();
  // The tets as an array, and read through tet_vertices_of (the refiner's
  // M_Ω in place): the same labelling both ways.
  LabelInput in_place = in;
  in_place.tets = {};
  in_place.tet_vertices_of = [&](uint32_t t) { return nb.grid.tets[t]; };
  in_place.num_tets = nb.grid.tets.size();
  // The adjacency as an array of neighbour tets (the sliver pass's form):
  // no function is read, the constrained faces are found in vertex stars.
  std::vector<std::array<uint32_t, 4>> nbr_tets(nb.grid.tets.size());
  for (uint32_t t = 0; t < nb.grid.tets.size(); ++t) {
    for (int f = 0; f < 4; ++f) nbr_tets[t][f] = nbr[4 * t + f] == kNoTet ? kNoTet : nbr[4 * t + f] / 4;
  }
  LabelInput by_tets = nb.Input(seeds, holes);
  by_tets.neighbor_tets = nbr_tets;
  for (const LabelInput* input : {&in, &in_place, &by_tets}) {
    SCOPED_TRACE(input == &in ? "array" : input == &in_place ? "in place" : "neighbour tets");
    auto given = LabelRegions(*input);
    ASSERT_TRUE(given.ok()) << given.status();
    EXPECT_EQ(given->tet_component, table->tet_component);
    ASSERT_EQ(given->components.size(), table->components.size());
    for (size_t c = 0; c < table->components.size(); ++c) {
      EXPECT_EQ(given->components[c].first_tet, table->components[c].first_tet);
      EXPECT_EQ(given->components[c].num_tets, table->components[c].num_tets);
      EXPECT_EQ(given->components[c].kept, table->components[c].kept);
      EXPECT_EQ(given->components[c].touches_box, table->components[c].touches_box);
      EXPECT_EQ(given->components[c].seed, table->components[c].seed);
    }
    EXPECT_EQ(given->seed_tet, table->seed_tet);
    EXPECT_EQ(given->hole_tet, table->hole_tet);
    EXPECT_EQ(given->num_kept_tets, table->num_kept_tets);
    ASSERT_EQ(given->faces.size(), table->faces.size());
    for (size_t i = 0; i < table->faces.size(); ++i) {
      EXPECT_EQ(given->faces[i].tets, table->faces[i].tets) << i;
      EXPECT_EQ(given->faces[i].constrained_face, table->faces[i].constrained_face) << i;
    }
  }
  // tet_vertices_of reads no face table of its own: without the adjacency
  // it is refused.
  LabelInput no_adjacency = in_place;
  no_adjacency.neighbor_slots_of = nullptr;
  EXPECT_EQ(LabelRegions(no_adjacency).status().code(), absl::StatusCode::kInvalidArgument);
  // Neighbour tets: with tet_vertices_of, with a row count that is not the
  // tets', with an id out of range, or not naming a constrained face's tet
  // back, refused.
  LabelInput tets_in_place = in_place;
  tets_in_place.neighbor_tets = nbr_tets;
  EXPECT_EQ(LabelRegions(tets_in_place).status().code(), absl::StatusCode::kInvalidArgument);
  std::vector<std::array<uint32_t, 4>> short_rows(nbr_tets.begin(), nbr_tets.end() - 1);
  LabelInput bad_rows = by_tets;
  bad_rows.neighbor_tets = short_rows;
  EXPECT_EQ(LabelRegions(bad_rows).status().code(), absl::StatusCode::kInvalidArgument);
  std::vector<std::array<uint32_t, 4>> out_of_range = nbr_tets;
  out_of_range[0][0] = static_cast<uint32_t>(nbr_tets.size());
  bad_rows.neighbor_tets = out_of_range;
  EXPECT_EQ(LabelRegions(bad_rows).status().code(), absl::StatusCode::kInvalidArgument);
  {
    // The far side of constrained face 0 forgets it.
    std::array<uint32_t, 3> k = nb.faces[0].v;
    std::sort(k.begin(), k.end());
    const std::vector<uint32_t>& sl = slots_of.at(k);
    ASSERT_EQ(sl.size(), 2u);
    std::vector<std::array<uint32_t, 4>> one_sided = nbr_tets;
    one_sided[sl[1] / 4][sl[1] % 4] = kNoTet;
    one_sided[sl[0] / 4][sl[0] % 4] = sl[1] / 4;
    bad_rows.neighbor_tets = one_sided;
    EXPECT_EQ(LabelRegions(bad_rows).status().code(), absl::StatusCode::kInvalidArgument);
  }
  // A constrained face that is no face of the tets is still an error.
  std::vector<ConstrainedFace> bad = nb.faces;
  bad.push_back({{0, 1, nb.grid.Id(8, 8, 8)}, 9, 0});
  in.constrained_faces = bad;
  EXPECT_FALSE(LabelRegions(in).ok());
  by_tets.constrained_faces = bad;
  EXPECT_FALSE(LabelRegions(by_tets).ok());
}

TEST(LabellingTest, KeepBoundingBoxKeepsEverything) {
  Nested nb;
  const std::vector<plc::RegionSeed> seeds = {{{2.5, 2.6, 2.7}, 20, 0}};
  const std::vector<Vec3> holes = {{4.1, 4.2, 4.3}};
  auto l = LabelRegions(nb.Input(seeds, holes, /*keep=*/true));
  ASSERT_TRUE(l.ok()) << l.status();
  EXPECT_EQ(l->num_kept_tets, nb.grid.tets.size());
  EXPECT_TRUE(HasIssue(*l, LabelIssueKind::kHoleSeedsIgnored));
  EXPECT_EQ(l->faces.size(), nb.faces.size());
  for (size_t t = 0; t < nb.grid.tets.size(); ++t) {
    const Vec3 c = Centroid(nb.grid, nb.grid.tets[t]);
    const bool middle = Inside(c, 2, 6) && !Inside(c, 3, 5);
    EXPECT_EQ(l->components[l->tet_component[t]].attribute, middle ? 20 : 0);
  }
}

TEST(LabellingTest, UnseededCubeInBoundingCubeHasAttributeZero) {
  const Grid g = testing::KuhnGrid(6);
  plc::Plc plc;
  testing::AddBox(&plc, {2, 2, 2}, {4, 4, 4}, 5);
  const auto faces = testing::FacesOnConvexFacets(g.positions, g.tets,
                                                  testing::ConvexFacetsOf(plc, CoordinateMap{}));
  LabelInput in;
  in.positions = g.positions;
  in.tets = g.tets;
  in.constrained_faces = faces;
  auto l = LabelRegions(in);
  ASSERT_TRUE(l.ok()) << l.status();
  EXPECT_EQ(l->components.size(), 2u);
  EXPECT_EQ(l->num_kept_tets, 8u * 6u);
  for (size_t t = 0; t < g.tets.size(); ++t) {
    const bool inside = Inside(Centroid(g, g.tets[t]), 2, 4);
    EXPECT_EQ(l->Kept(static_cast<uint32_t>(t)), inside);
    if (inside) {
      EXPECT_EQ(l->components[l->tet_component[t]].attribute, 0);
    }
  }
  EXPECT_EQ(l->faces.size(), 6u * 4u * 2u);
  for (const auto& f : l->faces) {
    EXPECT_EQ(f.marker, 5);
    EXPECT_FALSE(l->Kept(f.tets[1]));
  }
}

TEST(LabellingTest, SeedWarningsFirstSeedWins) {
  Nested nb;
  const std::vector<plc::RegionSeed> seeds = {
      {{1.5, 1.5, 1.5}, 10, 0},      // 0: outer shell
      {{100, 100, 100}, 11, 0},      // 1: outside the mesh
      {{0.5, 0.5, 0.5}, 12, 0},      // 2: exterior (dropped)
      {{6.5, 6.5, 6.5}, 13, 0},      // 3: outer shell again, other attribute: conflict
      {{6.5, 1.5, 6.5}, 10, 0},      // 4: outer shell, same attribute: fine
      {{4.5, 4.5, 4.5}, 14, 0},      // 5: in the hole
  };
  const std::vector<Vec3> holes = {{4.1, 4.2, 4.3}, {-5, 0, 0}};
  auto l = LabelRegions(nb.Input(seeds, holes));
  ASSERT_TRUE(l.ok()) << l.status();
  std::vector<std::pair<LabelIssueKind, int64_t>> got;
  for (const auto& i : l->issues) got.push_back({i.kind, i.ids[0]});
  const std::vector<std::pair<LabelIssueKind, int64_t>> want = {
      {LabelIssueKind::kHoleSeedOutsideMesh, 1}, {LabelIssueKind::kSeedOutsideMesh, 1},
      {LabelIssueKind::kSeedConflict, 3},        {LabelIssueKind::kSeedDropped, 2},
      {LabelIssueKind::kSeedDropped, 5}};
  // Order: hole seeds, region seeds, then drops in component order.
  ASSERT_EQ(got.size(), want.size());
  for (const auto& w : want) EXPECT_NE(std::find(got.begin(), got.end(), w), got.end()) << int(w.first) << " " << w.second;
  EXPECT_EQ(l->seed_tet[1], kNoTet);
  EXPECT_EQ(l->hole_tet[1], kNoTet);
  const Component& outer = l->components[l->tet_component[l->seed_tet[0]]];
  EXPECT_EQ(outer.attribute, 10);
  EXPECT_EQ(outer.seed, 0);
  EXPECT_EQ(l->tet_component[l->seed_tet[3]], l->tet_component[l->seed_tet[0]]);
  // The unseeded middle shell keeps attribute 0.
  for (size_t t = 0; t < nb.grid.tets.size(); ++t) {
    const Vec3 c = Centroid(nb.grid, nb.grid.tets[t]);
    if (Inside(c, 2, 6) && !Inside(c, 3, 5)) {
      const Component& m = l->components[l->tet_component[t]];
      EXPECT_TRUE(m.kept);
      EXPECT_EQ(m.seed, -1);
      EXPECT_EQ(m.attribute, 0);
    }
  }
}

// A seed exactly on the middle box's face x = 2 touches tets of both shells;
// the tet with the lexicographically smallest sorted vertex ids wins, whatever
// the order of the tet list.
TEST(LabellingTest, SeedOnFacetTieRuleIsOrderIndependent) {
  Nested nb;
  const std::vector<plc::RegionSeed> seeds = {{{2, 2.5, 3.25}, 7, 0}};
  auto l = LabelRegions(nb.Input(seeds, {}));
  ASSERT_TRUE(l.ok()) << l.status();
  ASSERT_TRUE(HasIssue(*l, LabelIssueKind::kSeedOnFacet));
  // Brute force: the containing tets and the smallest key.
  std::array<uint32_t, 4> best{~0u, ~0u, ~0u, ~0u};
  for (const auto& t : nb.grid.tets) {
    const auto& P = nb.grid.positions;
    const Vec3 q = seeds[0].point;
    if (geom::Orient3d(q, P[t[1]], P[t[2]], P[t[3]]) < 0 || geom::Orient3d(P[t[0]], q, P[t[2]], P[t[3]]) < 0 ||
        geom::Orient3d(P[t[0]], P[t[1]], q, P[t[3]]) < 0 || geom::Orient3d(P[t[0]], P[t[1]], P[t[2]], q) < 0) {
      continue;
    }
    auto k = t;
    std::sort(k.begin(), k.end());
    best = std::min(best, k);
  }
  auto chosen = nb.grid.tets[l->seed_tet[0]];
  std::sort(chosen.begin(), chosen.end());
  EXPECT_EQ(chosen, best);
  const bool in_middle = Inside(Centroid(nb.grid, nb.grid.tets[l->seed_tet[0]]), 2, 6);

  // Reverse the tet list: the same tet (by vertex set) is chosen.
  Nested rev;
  std::reverse(rev.grid.tets.begin(), rev.grid.tets.end());
  auto l2 = LabelRegions(rev.Input(seeds, {}));
  ASSERT_TRUE(l2.ok());
  auto chosen2 = rev.grid.tets[l2->seed_tet[0]];
  std::sort(chosen2.begin(), chosen2.end());
  EXPECT_EQ(chosen2, best);
  for (size_t t = 0; t < rev.grid.tets.size(); ++t) {
    const Vec3 c = Centroid(rev.grid, rev.grid.tets[t]);
    const bool middle = Inside(c, 2, 6) && !Inside(c, 3, 5);
    const bool outer = Inside(c, 1, 7) && !Inside(c, 2, 6);
    if (middle || outer) {
      EXPECT_EQ(l2->components[l2->tet_component[t]].attribute, (middle == in_middle) ? 7 : 0);
    }
  }
}

TEST(LabellingTest, DuplicateConstrainedFaceFirstMarkerWins) {
  const Grid g = testing::KuhnGrid(2);
  plc::Plc plc;
  testing::AddBox(&plc, {0, 0, 0}, {2, 2, 2}, 4);
  auto faces = testing::FacesOnConvexFacets(g.positions, g.tets,
                                            testing::ConvexFacetsOf(plc, CoordinateMap{}));
  ASSERT_EQ(faces.size(), 6u * 4u * 2u);  // the hull: every face constrained
  ConstrainedFace dup = faces[3];
  dup.marker = 99;
  std::swap(dup.v[0], dup.v[2]);
  faces.push_back(dup);
  LabelInput in;
  in.positions = g.positions;
  in.tets = g.tets;
  in.constrained_faces = faces;
  auto l = LabelRegions(in);
  ASSERT_TRUE(l.ok()) << l.status();
  ASSERT_EQ(l->issues.size(), 1u);
  EXPECT_EQ(l->issues[0].kind, LabelIssueKind::kDuplicateConstrainedFace);
  EXPECT_EQ(l->issues[0].ids, (std::vector<int64_t>{48, 3}));
  // The hull is all constrained: nothing touches ∂Ω, all 48 tets kept.
  EXPECT_EQ(l->num_kept_tets, g.tets.size());
  EXPECT_EQ(l->faces.size(), 48u);
  for (const auto& f : l->faces) {
    EXPECT_EQ(f.marker, 4);
    EXPECT_EQ(f.tets[1], kNoTet);
  }
}

TEST(LabellingTest, Errors) {
  const Grid g = testing::KuhnGrid(2);
  LabelInput in;
  in.positions = g.positions;
  in.tets = g.tets;
  // No facets at all: everything touches ∂Ω and is dropped.
  auto l = LabelRegions(in);
  EXPECT_EQ(l.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(l.status().message().find("no tetrahedron is left"), std::string::npos);
  // ... unless the box is kept.
  in.keep_bounding_box = true;
  EXPECT_TRUE(LabelRegions(in).ok());
  // A constrained face that is not a face of the mesh (a diagonal of the grid
  // cube not used by the Kuhn split).
  const std::vector<ConstrainedFace> bad = {{{g.Id(1, 0, 0), g.Id(0, 1, 0), g.Id(0, 0, 1)}, 1, 0}};
  in.constrained_faces = bad;
  l = LabelRegions(in);
  EXPECT_EQ(l.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(l.status().message().find("not a face"), std::string::npos) << l.status();
  in.constrained_faces = {};
  // A face in three tets.
  std::vector<std::array<uint32_t, 4>> tets = g.tets;
  tets.push_back(tets[0]);
  in.tets = tets;
  l = LabelRegions(in);
  EXPECT_EQ(l.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(l.status().message().find("tets"), std::string::npos);
  // The message names the smallest such face (sorted ids) and its three
  // smallest tets, as a sort of all (face, slot) records finds them; here
  // with the copy of the tet in front, so the copy has the smaller ids.
  tets = g.tets;
  tets.insert(tets.begin(), g.tets[3]);
  in.tets = tets;
  {
    std::vector<std::array<uint32_t, 4>> recs;  // a, b, c, slot
    for (uint32_t t = 0; t < tets.size(); ++t) {
      for (uint32_t f = 0; f < 4; ++f) {
        std::array<uint32_t, 3> k;
        for (uint32_t i = 0, j = 0; i < 4; ++i) {
          if (i != f) k[j++] = tets[t][i];
        }
        std::sort(k.begin(), k.end());
        recs.push_back({k[0], k[1], k[2], 4 * t + f});
      }
    }
    std::sort(recs.begin(), recs.end());
    size_t i = 0;
    while (!(recs[i][0] == recs[i + 2][0] && recs[i][1] == recs[i + 2][1] && recs[i][2] == recs[i + 2][2])) ++i;
    size_t n = 3;
    while (i + n < recs.size() && recs[i + n][0] == recs[i][0] && recs[i + n][1] == recs[i][1] &&
           recs[i + n][2] == recs[i][2]) {
      ++n;
    }
    const std::string want = absl::StrCat("face (", recs[i][0], ", ", recs[i][1], ", ", recs[i][2], ") is in ", n,
                                          " tets (", recs[i][3] / 4, ", ", recs[i + 1][3] / 4, ", ",
                                          recs[i + 2][3] / 4, ", ...): not a tetrahedralization");
    l = LabelRegions(in);
    EXPECT_EQ(l.status().message(), want);
  }
  // A vertex id out of range.
  tets = g.tets;
  tets[5][2] = 1000;
  in.tets = tets;
  EXPECT_EQ(LabelRegions(in).status().code(), absl::StatusCode::kInvalidArgument);
}

// Seeds are located by a walk through the tets (the scan takes the points it
// cannot settle: on a face, edge or vertex, or outside): on a Kuhn grid with
// its tets in a scrambled order (tet 0 anywhere), every seed's tet is the one
// the tie rule gives by brute force — the tet strictly containing it, else
// the lexicographically smallest sorted vertex ids among those whose closure
// holds it; a seed outside the grid has none.
TEST(LabellingTest, WalkedSeedsGetTheTieRulesTet) {
  testing::Grid g = testing::KuhnGrid(6);
  std::mt19937 rng(31);
  std::shuffle(g.tets.begin(), g.tets.end(), rng);
  std::uniform_real_distribution<double> u(-0.5, 6.5);
  std::vector<plc::RegionSeed> seeds;
  for (int i = 0; i < 200; ++i) seeds.push_back({{u(rng), u(rng), u(rng)}, static_cast<double>(i), 0});
  for (int i = 0; i < 40; ++i) {  // on grid faces, edges and vertices
    const double x = std::floor(u(rng)), y = std::floor(u(rng)) + 0.5 * (i % 2), z = u(rng);
    seeds.push_back({{std::clamp(x, 0.0, 6.0), std::clamp(y, 0.0, 6.0), i % 3 == 0 ? std::round(z) : z}, static_cast<double>(200 + i), 0});
  }
  LabelInput in;
  in.positions = g.positions;
  in.tets = g.tets;
  in.region_seeds = seeds;
  in.keep_bounding_box = true;
  auto l = LabelRegions(in);
  ASSERT_TRUE(l.ok()) << l.status();
  ASSERT_EQ(l->seed_tet.size(), seeds.size());
  int strict = 0;
  for (size_t i = 0; i < seeds.size(); ++i) {
    const Vec3 q = seeds[i].point;
    uint32_t want = kNoTet;
    bool want_strict = false;
    std::array<uint32_t, 4> want_key{};
    for (uint32_t t = 0; t < g.tets.size(); ++t) {
      const auto& v = g.tets[t];
      const Vec3 a = g.positions[v[0]], b = g.positions[v[1]], c = g.positions[v[2]], d = g.positions[v[3]];
      const int s[4] = {geom::Orient3d(q, b, c, d), geom::Orient3d(a, q, c, d), geom::Orient3d(a, b, q, d),
                        geom::Orient3d(a, b, c, q)};
      if (s[0] < 0 || s[1] < 0 || s[2] < 0 || s[3] < 0) continue;
      const bool st = s[0] > 0 && s[1] > 0 && s[2] > 0 && s[3] > 0;
      std::array<uint32_t, 4> key = v;
      std::sort(key.begin(), key.end());
      if (want == kNoTet || (st && !want_strict) || (st == want_strict && key < want_key)) {
        want = t;
        want_strict = st;
        want_key = key;
      }
    }
    strict += want_strict;
    EXPECT_EQ(l->seed_tet[i], want) << "seed " << i << " (" << q.x << ", " << q.y << ", " << q.z << ")";
  }
  EXPECT_GT(strict, 100);  // most seeds were walked to
}

}  // namespace
}  // namespace svrc::refine
