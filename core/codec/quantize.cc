#include "core/codec/quantize.h"

#include <cmath>
#include <cstdlib>

#include "absl/strings/str_cat.h"

namespace svrc::codec {
namespace {

constexpr int64_t kTwo53 = int64_t{1} << 53;
constexpr int kMinExponent = -1074;  // spacing of the smallest subnormal
constexpr int kMaxExponent = 1023;

// Sign of det[a-d, b-d, c-d] of input positions.
// TEMPORARY until core/geometry/predicates.h (Orient3d) lands: the double
// determinant with a static forward error bound (Shewchuk 1997, orient3d
// errboundA) and, when the sign is in doubt, a long double re-evaluation —
// not exact for nearly flat tets.
int InputOrientSign(const mesh::Vec3& a, const mesh::Vec3& b, const mesh::Vec3& c,
                    const mesh::Vec3& d) {
  const double adx = a.x - d.x, bdx = b.x - d.x, cdx = c.x - d.x;
  const double ady = a.y - d.y, bdy = b.y - d.y, cdy = c.y - d.y;
  const double adz = a.z - d.z, bdz = b.z - d.z, cdz = c.z - d.z;
  const double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy;
  const double cdxady = cdx * ady, adxcdy = adx * cdy;
  const double adxbdy = adx * bdy, bdxady = bdx * ady;
  const double det = adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady);
  const double permanent = (std::fabs(bdxcdy) + std::fabs(cdxbdy)) * std::fabs(adz) +
                           (std::fabs(cdxady) + std::fabs(adxcdy)) * std::fabs(bdz) +
                           (std::fabs(adxbdy) + std::fabs(bdxady)) * std::fabs(cdz);
  const double eps = 0x1p-53;
  const double bound = (7.0 + 56.0 * eps) * eps * permanent;
  if (det > bound) return 1;
  if (-det > bound) return -1;
  using L = long double;
  const L ldet = L(adz) * (L(bdx) * cdy - L(cdx) * bdy) + L(bdz) * (L(cdx) * ady - L(adx) * cdy) +
                 L(cdz) * (L(adx) * bdy - L(bdx) * ady);
  return ldet > 0 ? 1 : (ldet < 0 ? -1 : 0);
}

// Exact sign of the same determinant on lattice indices: differences are
// below 2^24 in magnitude, so every product fits comfortably in 128 bits.
int LatticeOrientSign(const std::array<uint32_t, 3>& a, const std::array<uint32_t, 3>& b,
                      const std::array<uint32_t, 3>& c, const std::array<uint32_t, 3>& d) {
  using I = __int128;
  auto diff = [&](const std::array<uint32_t, 3>& p, int k) {
    return static_cast<I>(static_cast<int64_t>(p[k]) - static_cast<int64_t>(d[k]));
  };
  const I adx = diff(a, 0), bdx = diff(b, 0), cdx = diff(c, 0);
  const I ady = diff(a, 1), bdy = diff(b, 1), cdy = diff(c, 1);
  const I adz = diff(a, 2), bdz = diff(b, 2), cdz = diff(c, 2);
  const I det = adz * (bdx * cdy - cdx * bdy) + bdz * (cdx * ady - adx * cdy) +
                cdz * (adx * bdy - bdx * ady);
  return det > 0 ? 1 : (det < 0 ? -1 : 0);
}

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
  for (size_t i = 0; i < qp.q.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      const double err = std::fabs(qp.lattice.Dequantize(a, qp.q[i][a]) - mesh.positions[i][a]);
      if (err > r.max_position_error) r.max_position_error = err;
    }
  }
  for (const auto& t : mesh.tets) {
    const int before = InputOrientSign(mesh.positions[t[0]], mesh.positions[t[1]],
                                       mesh.positions[t[2]], mesh.positions[t[3]]);
    if (before == 0) continue;
    const int after = LatticeOrientSign(qp.q[t[0]], qp.q[t[1]], qp.q[t[2]], qp.q[t[3]]);
    if (after == 0) {
      ++r.collapsed_tets;
    } else if (after != before) {
      ++r.inverted_tets;
    }
  }
  return r;
}

}  // namespace svrc::codec
