// Containment dimension and the feature table (thesis Definitions 36–37).
#include "core/svrc/containment.h"

#include <algorithm>

#include "absl/strings/str_cat.h"

namespace svrc::refine {

bool IsPossibleCd(Cd cd) {
  if (cd.dim > 3 || cd.collar < 1 || cd.collar > 3) return false;
  if (cd.dim == 0) return cd.collar == 3;
  if (cd.dim == 1) return cd.collar >= 2;
  return true;
}

std::string CdToString(Cd cd) { return absl::StrCat("(", cd.dim, ",", cd.collar, ")"); }

FeatureTable FeatureTable::ForPointSet(uint32_t num_points) {
  plc::FeatureComplex complex;
  complex.points.resize(num_points);
  return Build(complex);
}

FeatureTable FeatureTable::Build(const plc::FeatureComplex& complex) {
  FeatureTable t;
  t.num_points_ = static_cast<uint32_t>(complex.points.size());
  t.num_segments_ = static_cast<uint32_t>(complex.segments.size());
  t.num_facets_ = static_cast<uint32_t>(complex.facets.size());
  const uint32_t n = 1 + t.num_points_ + t.num_segments_ + t.num_facets_;
  t.dim_.resize(n);
  t.index_.resize(n);
  t.dim_[0] = 3;
  t.index_[0] = 0;
  for (uint32_t i = 0; i < t.num_points_; ++i) {
    t.dim_[t.OfPoint(i).value()] = 0;
    t.index_[t.OfPoint(i).value()] = i;
  }
  for (uint32_t i = 0; i < t.num_segments_; ++i) {
    t.dim_[t.OfSegment(i).value()] = 1;
    t.index_[t.OfSegment(i).value()] = i;
  }
  for (uint32_t i = 0; i < t.num_facets_; ++i) {
    t.dim_[t.OfFacet(i).value()] = 2;
    t.index_[t.OfFacet(i).value()] = i;
  }

  // Superfeatures: point ⊂ its segments and the facets containing it (through
  // a segment, as an interior point); segment ⊂ its facets; everything ⊂ Ω.
  std::vector<std::vector<FeatureId>> super(n);
  for (uint32_t s = 0; s < t.num_segments_; ++s) {
    const plc::FeatureSegment& seg = complex.segments[s];
    const FeatureId fs = t.OfSegment(s);
    for (uint32_t p : {seg.a, seg.b}) {
      super[t.OfPoint(p).value()].push_back(fs);
      for (uint32_t f : seg.facets) super[t.OfPoint(p).value()].push_back(t.OfFacet(f));
    }
    for (uint32_t f : seg.facets) super[fs.value()].push_back(t.OfFacet(f));
  }
  for (uint32_t p = 0; p < t.num_points_; ++p) {
    for (uint32_t f : complex.points[p].interior_of) super[t.OfPoint(p).value()].push_back(t.OfFacet(f));
  }
  t.super_begin_.assign(n + 1, 0);
  for (uint32_t f = 0; f < n; ++f) {
    std::vector<FeatureId>& list = super[f];
    if (f != 0) list.push_back(Omega());
    // Lowest dimension first, then id; Ω (dim 3) therefore last.
    std::sort(list.begin(), list.end(), [&](FeatureId a, FeatureId b) {
      if (t.dim_[a.value()] != t.dim_[b.value()]) return t.dim_[a.value()] < t.dim_[b.value()];
      return a < b;
    });
    list.erase(std::unique(list.begin(), list.end()), list.end());
    t.super_begin_[f + 1] = t.super_begin_[f] + static_cast<uint32_t>(list.size());
    t.super_.insert(t.super_.end(), list.begin(), list.end());
  }
  return t;
}

bool FeatureTable::Contains(FeatureId outer, FeatureId inner) const {
  if (outer == inner) return true;
  for (FeatureId f : Superfeatures(inner)) {
    if (f == outer) return true;
  }
  return false;
}

}  // namespace svrc::refine
