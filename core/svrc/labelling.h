// Region labelling of the final tetrahedralization (DESIGN.md pipeline step 5;
// implementer's guide §5 item 10; thesis §3.3 "output" after RipStitchCollar):
// flood-fill tets across non-constrained faces, seed regions, drop holes and ∂Ω.
// A pure function over explicit inputs; decisions in docs/svrc-output.md.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/geometry/vec3.h"
#include "core/plc/plc.h"

namespace svrc::refine {

inline constexpr uint32_t kNoTet = 0xFFFFFFFFu;
inline constexpr uint32_t kNoFacet = 0xFFFFFFFFu;

// A face of the tetrahedralization lying on an input facet (guide §5 item 10:
// the in-facet triangles of every M_F plus the stitched faces in collars).
struct ConstrainedFace {
  std::array<uint32_t, 3> v{};  // vertex ids into LabelInput::positions, any order
  int32_t marker = 0;           // the facet's marker
  uint32_t facet = kNoFacet;    // index of the facet in Plc::facets (for messages)
};

struct LabelInput {
  // Vertex positions in the mesher's coordinates (the same the tets are
  // positively oriented in, e.g. normalised ones) and the tets over them:
  // positively oriented (Orient3d(p0, p1, p2, p3) > 0), each face in at most
  // two tets. A face in one tet only lies on the boundary of the
  // tetrahedralized domain (∂Ω, or a constrained face).
  std::span<const geom::Vec3> positions;
  std::span<const std::array<uint32_t, 4>> tets;
  // Or, with neighbor_slots_of and find_face below, `num_tets` tets whose
  // vertices this function gives (tets then empty): the refiner's M_Ω is
  // read in place instead of copied (16 bytes per tet, the peak of a small
  // run's labelling; docs/svrc-design.md §8 item 79).
  std::function<std::array<uint32_t, 4>(uint32_t)> tet_vertices_of;
  size_t num_tets = 0;
  std::span<const ConstrainedFace> constrained_faces;
  // Seeds, in the same coordinates as `positions` (map them with the mesher's
  // normalisation first), in PLC order.
  std::span<const plc::RegionSeed> region_seeds;
  std::span<const geom::Vec3> hole_seeds;
  // Keep every tet (the whole Ω mesh, DESIGN.md "keep_bounding_box"): neither
  // the exterior nor hole components are dropped.
  bool keep_bounding_box = false;
  // Optional, from a caller that already has the adjacency (the refiner's
  // Delaunay3): a function giving, for tet t and each f, the slot 4u + g of
  // the face opposite local vertex f (slot 4t + f) in the other tet u, or
  // kNoTet; and one giving some slot of the face with vertices {a, b, c}, or
  // kNoTet. With both, the face table (TetFaces: 64 bytes per tet, the peak
  // of a small run's size round, docs/svrc-design.md §8 item 43) is not built
  // and the tets are trusted to form a tetrahedralization. The labelling is
  // the same. (Functions, not arrays: the refiner's array of neighbour slots,
  // 16 bytes per tet, was a fifth of the labelling's peak; session 29.)
  std::function<std::array<uint32_t, 4>(uint32_t)> neighbor_slots_of;
  std::function<uint32_t(uint32_t, uint32_t, uint32_t)> find_face;
  // Or, instead of both functions, the adjacency as an array (with `tets`,
  // not tet_vertices_of): per tet t, the tet across face f (opposite local
  // vertex f), kNoTet on the boundary — the sliver pass's final adjacency
  // (SliverResult::neighbors). The constrained faces are found in the stars
  // of their smallest vertices, and their far sides by the tet across
  // naming t back (else INVALID_ARGUMENT); ids are range-checked and the
  // rest trusted. The same labelling (docs/svrc-design.md §8 item 82).
  std::span<const std::array<uint32_t, 4>> neighbor_tets;
};

enum class LabelIssueKind {
  kSeedOutsideMesh,          // ids: region seed (in no tet)
  kSeedDropped,              // ids: region seed, component (exterior or hole): seed ignored
  kSeedConflict,             // ids: region seed, winning seed, component (first seed wins)
  kSeedOnFacet,              // ids: seed (region: >= 0, hole: -1-index), tet chosen, other tet
  kHoleSeedOutsideMesh,      // ids: hole seed
  kHoleSeedsIgnored,         // keep_bounding_box with hole seeds
  kDuplicateConstrainedFace, // ids: face, first face with the same vertices
};

// Warnings: the labelling is still complete and deterministic.
struct LabelIssue {
  LabelIssueKind kind;
  std::vector<int64_t> ids;
  std::string message;
};

// A connected set of tets (adjacent across non-constrained faces).
struct Component {
  uint32_t first_tet = kNoTet;  // its smallest tet index (components are numbered by it)
  uint32_t num_tets = 0;
  int32_t seed = -1;            // index of the region seed that labels it, -1: unseeded
  int32_t hole_seed = -1;       // first hole seed inside it, -1: none
  bool touches_box = false;     // has a face in one tet that is not constrained (∂Ω)
  bool kept = false;
  double attribute = 0;         // the seed's attribute, 0 when unseeded
  double max_volume = 0;        // the seed's max_volume, 0 when unseeded
};

// A constrained face with at least one kept tet next to it: a boundary or
// interface triangle of the output, or an internal facet inside one region.
struct LabelledFace {
  std::array<uint32_t, 3> v{};     // as given in ConstrainedFace
  std::array<uint32_t, 2> tets{};  // tets[0] kept; tets[1] the other side (kNoTet: none)
  int32_t marker = 0;
  uint32_t facet = kNoFacet;
  uint32_t constrained_face = 0;   // index into LabelInput::constrained_faces
};

struct Labelling {
  std::vector<uint32_t> tet_component;  // per tet
  std::vector<Component> components;    // numbered by smallest tet index
  std::vector<uint32_t> seed_tet;       // per region seed: its tet, or kNoTet
  std::vector<uint32_t> hole_tet;       // per hole seed: its tet, or kNoTet
  std::vector<LabelledFace> faces;      // in constrained-face order
  std::vector<LabelIssue> issues;
  uint32_t num_kept_tets = 0;

  bool Kept(uint32_t tet) const { return components[tet_component[tet]].kept; }
};

// Labels the tets. Errors (INVALID_ARGUMENT, naming ids): a vertex id out of
// range, a face in more than two tets, a constrained face that is not a face
// of any tet, or no tet left after dropping the exterior and holes (e.g. an
// open surface). Seed problems are warnings in Labelling::issues.
absl::StatusOr<Labelling> LabelRegions(const LabelInput& input);

std::string_view LabelIssueKindName(LabelIssueKind kind);

}  // namespace svrc::refine
