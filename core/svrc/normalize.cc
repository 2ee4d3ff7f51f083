// Exact input normalisation (see normalize.h, docs/svrc-design.md §1).
#include "core/svrc/normalize.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"

namespace svrc::refine {

using geom::Vec3;

Vec3 Normalization::Forward(const Vec3& x) const {
  // x − t is exact by the choice of t (Sterbenz); ldexp is exact in range.
  return {std::ldexp(x.x - translation.x, -exponent), std::ldexp(x.y - translation.y, -exponent),
          std::ldexp(x.z - translation.z, -exponent)};
}

Vec3 Normalization::Backward(const Vec3& y) const {
  return {std::ldexp(y.x, exponent) + translation.x, std::ldexp(y.y, exponent) + translation.y,
          std::ldexp(y.z, exponent) + translation.z};
}

double Normalization::ToInputLength(double normalised) const { return std::ldexp(normalised, exponent); }

namespace {

// Per axis: t = lo if 0 < lo and hi ≤ 2·lo (then lo/2 ≤ lo ≤ x ≤ hi ≤ 2·lo, so
// x − lo is exact by Sterbenz' lemma); the mirror for negative boxes; else 0.
double AxisTranslation(double lo, double hi) {
  if (lo > 0 && hi <= 2 * lo) return lo;
  if (hi < 0 && lo >= 2 * hi) return hi;
  return 0;
}

}  // namespace

absl::StatusOr<Normalization> ChooseNormalization(std::span<const Vec3> points) {
  if (points.empty()) return absl::InvalidArgumentError("normalisation: no points");
  geom::Box3 box;
  for (size_t i = 0; i < points.size(); ++i) {
    if (!geom::IsFinite(points[i])) {
      return absl::InvalidArgumentError(absl::StrCat("normalisation: point ", i, " is not finite"));
    }
    box.Add(points[i]);
  }
  Normalization n;
  n.translation = {AxisTranslation(box.lo.x, box.hi.x), AxisTranslation(box.lo.y, box.hi.y),
                   AxisTranslation(box.lo.z, box.hi.z)};
  double extent = 0;  // largest |x − t| over the box
  for (int a = 0; a < 3; ++a) {
    extent = std::max({extent, std::fabs(box.lo[a] - n.translation[a]),
                       std::fabs(box.hi[a] - n.translation[a])});
  }
  if (extent == 0) {
    n.exponent = 0;  // a single point: nothing to scale
    return n;
  }
  // extent·2^−e in [0.5, 1): e = ilogb(extent) + 1.
  n.exponent = std::ilogb(extent) + 1;
  // The smallest nonzero |x − t| must stay a normal double after scaling;
  // coordinates are >= 2^−1074 apart, so require 2^(e) not to push them
  // below 2^−1022: reject tiny extents outright (documented bound).
  if (n.exponent < -900) {
    return absl::InvalidArgumentError("normalisation: input extent below 2^-900");
  }
  // Guarantee the round trip rather than argue it: a coordinate so tiny that
  // scaling makes it subnormal would lose bits. Then fall back to the identity
  // (exact, just less well scaled).
  for (const Vec3& p : points) {
    if (!(n.Backward(n.Forward(p)) == p)) return Normalization{};
  }
  return n;
}

}  // namespace svrc::refine
