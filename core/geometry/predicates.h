// Robust geometric predicates: the ONLY place in svrc where the sign of a
// floating-point expression is decided (thesis §3.1 primitives; implementer's
// guide §3 "Primitives"). Every predicate is exact for double inputs.
//
// Scheme (Shewchuk 1997, "Adaptive Precision Floating-Point Arithmetic and Fast
// Robust Geometric Predicates"; Meyer & Pion 2008, "FPG: A code generator for
// fast and certified geometric predicates"):
//   1. an inline semi-static filter: the determinant in doubles, and an error
//      bound C·u·Π(max |coordinate difference| per axis) derived from
//      Shewchuk's stage-A bounds (derivation next to each constant below);
//   2. when |det| is not above the bound, an out-of-line exact evaluation with
//      expansion arithmetic (core/geometry/expansion.h), inputs first rescaled
//      by a power of two so that no intermediate product over/underflows. If
//      the coordinates' binary exponents span too wide a range for that (about
//      2000/degree orders of two, e.g. 1e120 next to a denormal), GMP rationals
//      evaluate the same polynomial instead. Before either, a fast exact path
//      for "nice" inputs (grids): when all coordinate differences are exact
//      and are small integers times one power of two, the double formula is
//      itself exact (predicates.cc, SmallDyadicDiffs). Exact for all finite
//      inputs;
//   3. for the *SoS variants, when the exact value is 0, simulation of
//      simplicity by caller-supplied global ids (see the SoS section below).
//
// Sign conventions (all return -1, 0 or +1):
//   Orient1d(a, b)          = sign(b − a)               (>0: a before b)
//   Orient2d(a, b, c)       = sign det[b−a, c−a]        (>0: a,b,c counter-clockwise)
//   Orient3d(a, b, c, d)    = sign det[b−a, c−a, d−a]   (>0: tet abcd positively
//       oriented; right-handed: d is on the side of plane abc towards which
//       (b−a)×(c−a) points). TetMesh and the Delaunay kernels require every tet
//       (p0,p1,p2,p3) to satisfy Orient3d(p0,p1,p2,p3) > 0.
//       NOTE: this is the opposite of Shewchuk's orient3d sign.
//   InCircle(a, b, c, d)    > 0 iff d is strictly inside the circle through a,b,c
//       when Orient2d(a,b,c) > 0 (the sign flips with the orientation of abc).
//   InSphere(a, b, c, d, e) > 0 iff e is strictly inside the sphere through
//       a,b,c,d when Orient3d(a,b,c,d) > 0 (flips with the orientation).
//   Equivalently, with the lifting p ↦ (p, |p|²):
//     InCircle = −sign det4[[1, p, |p|²]]_{p=a,b,c,d}
//     InSphere = −sign det5[[1, p, |p|²]]_{p=a,b,c,d,e}.
//
// Extra exact predicates SVRC needs (>0 always means "strictly inside"/"first"):
//   InDiametralSphere(a, b, p)          = −sign((a−p)·(b−p)): >0 iff p is strictly
//       inside the ball with diameter ab (segment encroachment, guide §3).
//   InTriangleCircumball3d(a, b, c, p)  >0 iff p is strictly inside the smallest
//       ball through the 3D points a,b,c (centred at the circumcentre of abc in
//       its plane, the triangle's diametral ball). 0 if a,b,c are collinear.
//   CompareDistance(p, a, b)            = sign(|p−a|² − |p−b|²) (>0: a is farther).
//   DotSign(a, b, c, d)                 = sign((b−a)·(d−c)).
//   Orient2dProjected(a, b, c, axis)    = Orient2d of a,b,c projected along
//       coordinate `axis` onto the plane of coordinates (axis+1, axis+2) mod 3
//       (cyclic, so it equals sign(((b−a)×(c−a))[axis])): orientation of coplanar
//       3D points seen from the +axis side. Use DominantAxis(normal) for axis and
//       multiply by sign(normal[axis]) to orient relative to a facet normal.
//
// Statistics: every call bumps a thread_local counter; filter failures and
// SoS decisions are counted separately (PredicateStats), so a meshing job can
// report them per phase (STYLE.md: as Triangle does).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/geometry/vec3.h"

namespace svrc::geom {

// ---------------------------------------------------------------- statistics

enum class Pred : int {
  kOrient1d = 0,
  kOrient2d,
  kOrient3d,
  kInCircle,
  kInSphere,
  kInDiametralSphere,
  kInTriangleCircumball3d,
  kCompareDistance,
  kDotSign,
  kOrient2dProjected,
  kInBall,
  kCount
};
inline constexpr int kNumPredicates = static_cast<int>(Pred::kCount);
const char* PredicateName(Pred p);

struct PredicateStats {
  uint64_t calls[kNumPredicates] = {};  // every call (SoS variants count once)
  uint64_t exact[kNumPredicates] = {};  // filter failed: exact arithmetic ran
  uint64_t sos[kNumPredicates] = {};    // exact value was 0: perturbation decided
  uint64_t TotalCalls() const;
  uint64_t TotalExact() const;
  uint64_t TotalSos() const;
};

namespace internal {
// An inline variable (one definition, emitted where used) of a trivial type
// with constant initialisation: every access is a plain TLS load, with no
// cross-TU TLS wrapper call.
inline thread_local constinit PredicateStats tls_predicate_stats;
inline void CountCall(Pred p) { ++tls_predicate_stats.calls[static_cast<int>(p)]; }
}  // namespace internal

// This thread's counters since the last reset.
inline const PredicateStats& GetPredicateStats() { return internal::tls_predicate_stats; }
inline void ResetPredicateStats() { internal::tls_predicate_stats = PredicateStats{}; }

// ---------------------------------------------------------- exact fallbacks
// Out-of-line exact evaluations (predicates.cc). Callers use the filtered
// functions below; these are public for tests and benchmarks.
namespace internal {
int Orient2dExact(Vec2 a, Vec2 b, Vec2 c);
int Orient3dExact(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);
int InCircleExact(Vec2 a, Vec2 b, Vec2 c, Vec2 d);
int InSphereExact(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const Vec3& e);

// SoS tie-breaks, called only when the exact value is 0.
int Orient2dSoSTail(Vec2 a, Vec2 b, Vec2 c, uint32_t ia, uint32_t ib, uint32_t ic);
int Orient3dSoSTail(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, uint32_t ia,
                    uint32_t ib, uint32_t ic, uint32_t id);
int InCircleSoSTail(Vec2 a, Vec2 b, Vec2 c, Vec2 d, uint32_t ia, uint32_t ib, uint32_t ic,
                    uint32_t id);
int InSphereSoSTail(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const Vec3& e,
                    uint32_t ia, uint32_t ib, uint32_t ic, uint32_t id, uint32_t ie);

// Filter constants, u = 2^-53 (unit roundoff). Shewchuk's stage-A bound for
// each determinant is K·u·P with P the permanent (the same expression with
// absolute values) of the rounded coordinate differences; K(1+O(u)) =
// 3 (orient2d), 7 (orient3d), 10 (incircle), 16 (insphere). Bounding P by the
// per-axis maxima mx, my, mz of |differences|:
//   orient2d  P ≤ 2·mx·my                 → 6u   → use  8u
//   orient3d  P ≤ 3·mz·2·mx·my            → 42u  → use 48u
//   incircle  P ≤ 3·(mx²+my²)·2·mx·my     → 60u  → use 64u
//   insphere  P ≤ 4·(mx²+my²+mz²)·6·mx·my·mz → 384u → use 400u
// The slack covers the rounding in computing the bound itself. Bounds hold
// only without underflow/overflow, hence the range checks on the maxima
// (degree d: product of d maxima stays within [2^-970, 2^970]).
inline constexpr double kU = 1.1102230246251565e-16;  // 2^-53
inline constexpr double kOrient2dBound = 8 * kU;
inline constexpr double kOrient3dBound = 48 * kU;
inline constexpr double kInCircleBound = 64 * kU;
inline constexpr double kInSphereBound = 400 * kU;

inline int SignOf(double x) { return (x > 0) - (x < 0); }
}  // namespace internal

// ------------------------------------------------------- filtered predicates

inline int Orient1d(double a, double b) {
  internal::CountCall(Pred::kOrient1d);
  return (b > a) - (b < a);
}

namespace internal {
// The filtered predicates without the call counter (used inside other
// predicates' exact/SoS stages so those are not counted twice).
inline int Orient2dUncounted(Vec2 a, Vec2 b, Vec2 c) {
  const double bax = b.x - a.x, bay = b.y - a.y;
  const double cax = c.x - a.x, cay = c.y - a.y;
  const double det = bax * cay - bay * cax;
  const double mx = std::max(std::fabs(bax), std::fabs(cax));
  const double my = std::max(std::fabs(bay), std::fabs(cay));
  const double lo = std::min(mx, my), hi = std::max(mx, my);
  if (lo == 0) return 0;  // a zero column: the determinant is exactly 0
  if (lo > 1e-146 && hi < 1e146) {
    const double eps = kOrient2dBound * mx * my;
    if (det > eps) return 1;
    if (det < -eps) return -1;
  }
  // Two equal points: the determinant is exactly 0 (a facet mesh's
  // triangles tested against the segments whose endpoints they share; every
  // such call reached the expansion arithmetic).
  if (c == a || c == b || a == b) return 0;
  return internal::Orient2dExact(a, b, c);
}
}  // namespace internal

inline int Orient2d(Vec2 a, Vec2 b, Vec2 c) {
  internal::CountCall(Pred::kOrient2d);
  return internal::Orient2dUncounted(a, b, c);
}

namespace internal {
inline int Orient3dUncounted(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const double bax = b.x - a.x, bay = b.y - a.y, baz = b.z - a.z;
  const double cax = c.x - a.x, cay = c.y - a.y, caz = c.z - a.z;
  const double dax = d.x - a.x, day = d.y - a.y, daz = d.z - a.z;
  const double det = bax * (cay * daz - caz * day) + bay * (caz * dax - cax * daz) +
                     baz * (cax * day - cay * dax);
  const double mx = std::max(std::max(std::fabs(bax), std::fabs(cax)), std::fabs(dax));
  const double my = std::max(std::max(std::fabs(bay), std::fabs(cay)), std::fabs(day));
  const double mz = std::max(std::max(std::fabs(baz), std::fabs(caz)), std::fabs(daz));
  const double lo = std::min(std::min(mx, my), mz);
  const double hi = std::max(std::max(mx, my), mz);
  if (lo == 0) return 0;
  if (lo > 1e-97 && hi < 1e97) {
    const double eps = kOrient3dBound * mx * my * mz;
    if (det > eps) return 1;
    if (det < -eps) return -1;
  }
  if (d == a || d == b || d == c || a == b || a == c || b == c) return 0;  // two equal points: exactly 0
  return internal::Orient3dExact(a, b, c, d);
}
}  // namespace internal

inline int Orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  internal::CountCall(Pred::kOrient3d);
  return internal::Orient3dUncounted(a, b, c, d);
}

inline int InCircle(Vec2 a, Vec2 b, Vec2 c, Vec2 d) {
  internal::CountCall(Pred::kInCircle);
  const double adx = a.x - d.x, ady = a.y - d.y;
  const double bdx = b.x - d.x, bdy = b.y - d.y;
  const double cdx = c.x - d.x, cdy = c.y - d.y;
  const double alift = adx * adx + ady * ady;
  const double blift = bdx * bdx + bdy * bdy;
  const double clift = cdx * cdx + cdy * cdy;
  // det3[[a−d, |a−d|²], [b−d, …], [c−d, …]], > 0 iff d inside CCW abc.
  const double det = alift * (bdx * cdy - cdx * bdy) + blift * (cdx * ady - adx * cdy) +
                     clift * (adx * bdy - bdx * ady);
  const double mx = std::max(std::max(std::fabs(adx), std::fabs(bdx)), std::fabs(cdx));
  const double my = std::max(std::max(std::fabs(ady), std::fabs(bdy)), std::fabs(cdy));
  const double lo = std::min(mx, my), hi = std::max(mx, my);
  if (lo == 0) return 0;
  if (lo > 1e-73 && hi < 1e73) {
    const double eps = internal::kInCircleBound * mx * my * (mx * mx + my * my);
    if (det > eps) return 1;
    if (det < -eps) return -1;
  }
  return internal::InCircleExact(a, b, c, d);
}

inline int InSphere(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const Vec3& e) {
  internal::CountCall(Pred::kInSphere);
  const double aex = a.x - e.x, aey = a.y - e.y, aez = a.z - e.z;
  const double bex = b.x - e.x, bey = b.y - e.y, bez = b.z - e.z;
  const double cex = c.x - e.x, cey = c.y - e.y, cez = c.z - e.z;
  const double dex = d.x - e.x, dey = d.y - e.y, dez = d.z - e.z;
  // 2x2 minors of the (x, y) columns.
  const double ab = aex * bey - bex * aey;
  const double bc = bex * cey - cex * bey;
  const double cd = cex * dey - dex * cey;
  const double da = dex * aey - aex * dey;
  const double ac = aex * cey - cex * aey;
  const double bd = bex * dey - dex * bey;
  // 3x3 minors of the (x, y, z) columns.
  const double abc = aez * bc - bez * ac + cez * ab;
  const double bcd = bez * cd - cez * bd + dez * bc;
  const double cda = cez * da + dez * ac + aez * cd;
  const double dab = dez * ab + aez * bd + bez * da;
  const double alift = aex * aex + aey * aey + aez * aez;
  const double blift = bex * bex + bey * bey + bez * bez;
  const double clift = cex * cex + cey * cey + cez * cez;
  const double dlift = dex * dex + dey * dey + dez * dez;
  // det4[[a−e, |a−e|²], …] = (dlift·abc − clift·dab) + (blift·cda − alift·bcd);
  // InSphere = −sign of it (see the conventions above).
  const double det = (clift * dab - dlift * abc) + (alift * bcd - blift * cda);
  const double mx = std::max(std::max(std::fabs(aex), std::fabs(bex)),
                             std::max(std::fabs(cex), std::fabs(dex)));
  const double my = std::max(std::max(std::fabs(aey), std::fabs(bey)),
                             std::max(std::fabs(cey), std::fabs(dey)));
  const double mz = std::max(std::max(std::fabs(aez), std::fabs(bez)),
                             std::max(std::fabs(cez), std::fabs(dez)));
  const double lo = std::min(std::min(mx, my), mz);
  const double hi = std::max(std::max(mx, my), mz);
  if (lo == 0) return 0;
  if (lo > 1e-58 && hi < 1e58) {
    const double eps = internal::kInSphereBound * mx * my * mz * (mx * mx + my * my + mz * mz);
    if (det > eps) return 1;
    if (det < -eps) return -1;
  }
  return internal::InSphereExact(a, b, c, d, e);
}

// ------------------------------------------------------- simulation of simplicity
//
// The *SoS variants equal the exact predicate whenever that is non-zero, and
// otherwise decide as if the input had been perturbed symbolically, the
// perturbation attached to each point through its global id (ids must be
// distinct among the arguments). Because the perturbation belongs to the
// point, permuting the arguments permutes the rows of the perturbed
// determinant: the result flips with the parity of the permutation, and all
// calls of a run agree with ONE perturbed point set (reproducible, independent
// of insertion order). Ranks: among the arguments, the point with the
// smallest id gets rank 1, the next rank 2, ...; rank 1 is the most
// significant (largest) perturbation.
//
// Orientation (Edelsbrunner & Mücke 1990, coordinates perturbed):
//   coordinate j (x=1, y=2[, z=3]) of the point of rank r moves by
//   ε^(2^(d·r − j)). The perturbed det[[1, p̃]] is a polynomial in ε whose
//   terms all have distinct exponents; its sign for ε → 0 is the sign of the
//   lowest-order non-zero coefficient. The coefficient of Π ε(r,j) over a set
//   S of (point, coordinate) pairs (at most one per point and per coordinate)
//   is the determinant with each chosen point's row replaced by the unit
//   vector e_j. Coefficients are visited in increasing exponent (= increasing
//   bitmask) order; once every coordinate column is covered the coefficient is
//   ±1, so the result is NEVER 0 (not even for coincident points).
//
// InCircle / InSphere (lifting perturbation, as in Edelsbrunner & Mücke §5.4
// and Devillers & Teillaud 2011): only the lifted coordinate is perturbed,
//   |p|² ↦ |p|² + ε^rank(p),
// i.e. the points get generic power weights −ε^rank, so the result is the
// sign test of a *regular* triangulation with infinitesimal weights — a
// genuine triangulation of the unperturbed points (no flat cells).
// Derivation: det5[[1, p, |p|² + δ_p]] is linear in each δ, so
//   D̃ = D + Σ_p δ_p·C_p,  C_p = cofactor of the lifted entry of row p
//     = (−1)^(row(p)+5) · Orient3d(the other four points, in argument order).
// With rows a,b,c,d,e = 1..5:
//   C_e = +Orient3d(a,b,c,d), C_d = −Orient3d(a,b,c,e), C_c = +Orient3d(a,b,d,e),
//   C_b = −Orient3d(a,c,d,e), C_a = +Orient3d(b,c,d,e).
// When D = 0, InSphereSoS = −sign(C_p) for the lowest-rank p with C_p ≠ 0
// (the δ's are ordered ε ≫ ε² ≫ ...). In 2D likewise with det4 and Orient2d:
//   C_d = +Orient2d(a,b,c), C_c = −Orient2d(a,b,d), C_b = +Orient2d(a,c,d),
//   C_a = −Orient2d(b,c,d).
// E.g. when e has the smallest id, e inside a tet's circumsphere under
// perturbation iff Orient3d(a,b,c,d) < 0: a cospherical e is *outside* every
// positively oriented tet. The lifting perturbation is 0 only if all C_p = 0,
// i.e. when all five (four) points are coplanar (collinear); never so when
// abcd (abc) is a proper tet (triangle), which is how the Delaunay kernels
// call it.

inline int Orient2dSoS(Vec2 a, Vec2 b, Vec2 c, uint32_t ia, uint32_t ib, uint32_t ic) {
  const int s = Orient2d(a, b, c);
  return s != 0 ? s : internal::Orient2dSoSTail(a, b, c, ia, ib, ic);
}

inline int Orient3dSoS(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, uint32_t ia,
                       uint32_t ib, uint32_t ic, uint32_t id) {
  const int s = Orient3d(a, b, c, d);
  return s != 0 ? s : internal::Orient3dSoSTail(a, b, c, d, ia, ib, ic, id);
}

inline int InCircleSoS(Vec2 a, Vec2 b, Vec2 c, Vec2 d, uint32_t ia, uint32_t ib, uint32_t ic,
                       uint32_t id) {
  const int s = InCircle(a, b, c, d);
  return s != 0 ? s : internal::InCircleSoSTail(a, b, c, d, ia, ib, ic, id);
}

inline int InSphereSoS(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const Vec3& e,
                       uint32_t ia, uint32_t ib, uint32_t ic, uint32_t id, uint32_t ie) {
  const int s = InSphere(a, b, c, d, e);
  return s != 0 ? s : internal::InSphereSoSTail(a, b, c, d, e, ia, ib, ic, id, ie);
}

// ------------------------------------------------------------ extra predicates
// Filtered by a running error bound (forward error analysis per operation),
// exact fallback through the same expression on expansions.

int InDiametralSphere(const Vec3& a, const Vec3& b, const Vec3& p);
int InDiametralCircle(Vec2 a, Vec2 b, Vec2 p);  // 2D version, same convention
int InTriangleCircumball3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p);
int CompareDistance(const Vec3& p, const Vec3& a, const Vec3& b);
int CompareDistance(Vec2 p, Vec2 a, Vec2 b);
int DotSign(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);
int Orient2dProjected(const Vec3& a, const Vec3& b, const Vec3& c, int axis);
// sign(r² − |p − c|²): >0 iff p is strictly inside the ball B(c, r) whose radius r
// is a given double (collar balls, thesis §2.4); 0 on its sphere.
int InBall(const Vec3& p, const Vec3& c, double r);

// Index (0, 1, 2) of the largest |component| of n (ties: the lowest index).
inline int DominantAxis(const Vec3& n) {
  const double ax = std::fabs(n.x), ay = std::fabs(n.y), az = std::fabs(n.z);
  if (ax >= ay && ax >= az) return 0;
  return ay >= az ? 1 : 2;
}

}  // namespace svrc::geom
