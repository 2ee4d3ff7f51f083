// Containment dimension (thesis Definition 36) with its collar refinement
// (Definition 37), and the feature table SVRC refines: Ω, the PLC's points,
// segments and facets, each with its superfeatures (§3.2.3 "superfeatures").
//
// CD orders everything in SVRC: Destroy warps to the lowest-CD unresolved point
// and yields to lower-CD balls (Figure 3.4). A created point's CD is the
// dimension of the feature it was created on (its parent feature, Def 36): a
// point made by M_F lies in Ω_F and, generically, in no lower feature domain.
#pragma once

#include <compare>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/plc/features.h"
#include "core/svrc/ids.h"

namespace svrc::refine {

// ⟨CD, collar dimension⟩ ordered lexicographically (Definition 37). Collar
// dimension: 1 on a collar circle, 2 on a partial sphere, 3 off the collar
// surface. The nine possible values, lowest first: (0,3) input vertices,
// (1,2), (1,3), (2,1), (2,2), (2,3), (3,1), (3,2), (3,3).
struct Cd {
  uint8_t dim = 3;
  uint8_t collar = 3;
  friend constexpr auto operator<=>(Cd, Cd) = default;
  friend constexpr bool operator==(Cd, Cd) = default;
};

inline constexpr Cd kCdInputVertex{0, 3};
inline constexpr Cd kCdSegment{1, 3};
inline constexpr Cd kCdFacet{2, 3};
inline constexpr Cd kCdSpace{3, 3};

// CD of a point created on (or being) a feature of dimension `feature_dim`,
// off the collar surface.
constexpr Cd CdOfFeatureDim(int feature_dim) { return Cd{static_cast<uint8_t>(feature_dim), 3}; }

// True iff `cd` is one of the nine values Definition 37 lists ((0,1), (0,2),
// (1,1) cannot occur: collars never meet input vertices, circles never meet
// segments).
bool IsPossibleCd(Cd cd);

std::string CdToString(Cd cd);

// The features SVRC meshes, with uniform ids: Ω is feature 0, then one feature
// per complex point (dim 0), per segment (dim 1), per facet (dim 2).
class FeatureTable {
 public:
  // Builds the table and the superfeature lists from the complex.
  static FeatureTable Build(const plc::FeatureComplex& complex);
  // Ω and `num_points` isolated points (a point set).
  static FeatureTable ForPointSet(uint32_t num_points);

  static constexpr FeatureId Omega() { return FeatureId(0); }
  FeatureId OfPoint(uint32_t point) const { return FeatureId(1 + point); }
  FeatureId OfSegment(uint32_t segment) const { return FeatureId(1 + num_points_ + segment); }
  FeatureId OfFacet(uint32_t facet) const {
    return FeatureId(1 + num_points_ + num_segments_ + facet);
  }

  uint32_t size() const { return static_cast<uint32_t>(dim_.size()); }
  int Dim(FeatureId f) const { return dim_[f.value()]; }
  // Index of the feature inside its own list of the complex (point, segment or
  // facet index; 0 for Ω).
  uint32_t Index(FeatureId f) const { return index_[f.value()]; }
  // The features strictly containing f, lowest dimension first, ids ascending
  // inside a dimension; Ω last. Empty for Ω.
  std::span<const FeatureId> Superfeatures(FeatureId f) const {
    return {super_.data() + super_begin_[f.value()],
            super_.data() + super_begin_[f.value() + 1]};
  }
  bool Contains(FeatureId outer, FeatureId inner) const;

 private:
  uint32_t num_points_ = 0, num_segments_ = 0, num_facets_ = 0;
  std::vector<uint8_t> dim_;
  std::vector<uint32_t> index_;
  std::vector<uint32_t> super_begin_;
  std::vector<FeatureId> super_;
};

}  // namespace svrc::refine
