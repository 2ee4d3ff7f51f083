#include "core/codec/quantize.h"

#include <cmath>
#include <cstdlib>

#include "absl/strings/str_cat.h"
#include "core/geometry/predicates.h"

namespace svrc::codec {
namespace {

constexpr int64_t kTwo53 = int64_t{1} << 53;
constexpr int kMinExponent = -1074;  // spacing of the smallest subnormal
constexpr int kMaxExponent = 1023;

}  // namespace

absl::Status Lattice::Validate() const {
  if (bits < 1 || bits > kMaxQuantizationBits) {
    return absl::InvalidArgumentError(absl::StrCat("container: quantization bits ", bits));
  }
  if (exponent < kMinExponent || exponent > kMaxExponent) {
    return absl::InvalidArgumentError(absl::StrCat("container: lattice exponent ", exponent));
  }
  const int64_t top = (int64_t{1} << bits) - 1;
  for (int a = 0; a < 3; ++a) {
    // origin + q stays below 2^53 in magnitude: an exact double.
    if (origin[a] < -(kTwo53 - 1) || origin[a] > kTwo53 - 1 - top) {
      return absl::InvalidArgumentError(absl::StrCat("container: lattice origin ", origin[a]));
    }
  }
  return absl::OkStatus();
}

double Lattice::Dequantize(int axis, uint32_t q) const {
  // Exact: |origin + q| < 2^53 and exponent >= -1074 make the product a
  // representable double (or an overflow, which Validate rules out).
  return std::ldexp(static_cast<double>(origin[axis] + static_cast<int64_t>(q)), exponent);
}

absl::StatusOr<QuantizedPositions> Quantize(const std::vector<mesh::Vec3>& positions, int bits) {
  QuantizedPositions out;
  out.lattice.bits = bits;
  if (bits < 1 || bits > kMaxQuantizationBits) {
    return absl::InvalidArgumentError(absl::StrCat("container: quantization bits ", bits));
  }
  if (positions.empty()) return out;
  geom::Box3 box;
  for (size_t i = 0; i < positions.size(); ++i) {
    if (!geom::IsFinite(positions[i])) {
      return absl::InvalidArgumentError(absl::StrCat(
          "container: vertex ", i, " is not finite; only lossless positions can carry it"));
    }
    box.Add(positions[i]);
  }
  const int64_t top = (int64_t{1} << bits) - 1;
  // The finest spacing 2^k whose lattice spans the box in 2^bits points per
  // axis with an exactly representable origin. Monotone in k; at most ~2100
  // cheap tries.
  auto fits = [&](int k, Lattice* lat) {
    lat->exponent = k;
    for (int a = 0; a < 3; ++a) {
      const double lo = std::floor(std::ldexp(box.lo[a], -k));
      const double hi = std::ceil(std::ldexp(box.hi[a], -k));
      if (!std::isfinite(lo) || !std::isfinite(hi)) return false;
      if (std::fabs(lo) >= static_cast<double>(kTwo53 - top) ||
          std::fabs(hi) >= static_cast<double>(kTwo53)) {
        return false;
      }
      if (static_cast<int64_t>(hi) - static_cast<int64_t>(lo) > top) return false;
      lat->origin[a] = static_cast<int64_t>(lo);
      // The extreme vertices (rounding is monotone) must decode finite; lattice
      // points no vertex uses may overflow.
      for (double x : {box.lo[a], box.hi[a]}) {
        const double q = static_cast<double>(std::llround(std::ldexp(x, -k)));
        if (!std::isfinite(std::ldexp(q, k))) return false;
      }
    }
    return lat->Validate().ok();
  };
  bool found = false;
  for (int k = kMinExponent; k <= kMaxExponent && !found; ++k) found = fits(k, &out.lattice);
  if (!found) {
    return absl::InvalidArgumentError(absl::StrCat(
        "container: the bounding box cannot be quantized to ", bits, " bits; use lossless"));
  }
  const Lattice& lat = out.lattice;
  out.q.resize(positions.size());
  for (size_t i = 0; i < positions.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      const int64_t v = std::llround(std::ldexp(positions[i][a], -lat.exponent));
      out.q[i][a] = static_cast<uint32_t>(v - lat.origin[a]);  // in [0, top] by construction
    }
  }
  return out;
}

QuantizationReport MeasureQuantization(const mesh::TetMesh& mesh, const QuantizedPositions& qp) {
  QuantizationReport r;
  if (qp.q.empty()) return r;
  r.position_error_bound = std::ldexp(1.0, qp.lattice.exponent - 1);
  std::vector<mesh::Vec3> decoded(qp.q.size());
  for (size_t i = 0; i < qp.q.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      decoded[i][a] = qp.lattice.Dequantize(a, qp.q[i][a]);
      const double err = std::fabs(decoded[i][a] - mesh.positions[i][a]);
      if (err > r.max_position_error) r.max_position_error = err;
    }
  }
  const std::vector<mesh::Vec3>& p = mesh.positions;
  for (const auto& t : mesh.tets) {
    const int before = geom::Orient3d(p[t[0]], p[t[1]], p[t[2]], p[t[3]]);
    if (before == 0) continue;
    const int after = geom::Orient3d(decoded[t[0]], decoded[t[1]], decoded[t[2]], decoded[t[3]]);
    if (after == 0) {
      ++r.collapsed_tets;
    } else if (after != before) {
      ++r.inverted_tets;
    }
  }
  return r;
}

}  // namespace svrc::codec
