#include "core/mesh/conformity.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>
#include <set>
#include <tuple>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/geometry/predicates.h"
#include "core/plc/polygon2d.h"

namespace svrc::mesh {
namespace {

using geom::Box3;
using geom::Cross;
using geom::Dot;
using geom::Norm;

constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();
constexpr double kEps52 = 0x1p-52;

// Local face k of a tet is the one opposite vertex k. Faces are matched as
// sorted triples; sides are decided by Orient3d, not by the listing order.
constexpr int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

// ----------------------------------------------------------------- report

void Add(ConformityReport* r, const ConformityOptions& o, ViolationKind k,
         std::vector<int64_t> ids, std::string msg) {
  size_t& c = r->counts[static_cast<int>(k)];
  if (c < o.max_listed_per_kind) r->violations.push_back({k, std::move(ids), std::move(msg)});
  ++c;
}

// ------------------------------------------------------------ spatial grid

// A uniform grid over a box; items (tets, facets) are registered in every
// cell their bounding box overlaps (CSR storage). Queries may return an item
// more than once; callers deduplicate with a stamp.
class BoxGrid {
 public:
  template <typename BoxOf>
  BoxGrid(const Box3& domain, size_t num_items, size_t items_per_cell, int max_res,
          BoxOf box_of)
      : domain_(domain) {
    const double cells = std::max<double>(1.0, static_cast<double>(num_items) / items_per_cell);
    const int r = std::clamp(static_cast<int>(std::cbrt(cells)), 1, max_res);
    for (int a = 0; a < 3; ++a) {
      res_[a] = r;
      const double ext = domain.hi[a] - domain.lo[a];
      inv_[a] = ext > 0 ? r / ext : 0.0;
    }
    start_.assign(static_cast<size_t>(r) * r * r + 1, 0);
    for (int pass = 0; pass < 2; ++pass) {
      for (size_t i = 0; i < num_items; ++i) {
        const Box3 b = box_of(i);
        if (b.Empty()) continue;
        ForCells(b, [&](size_t c) {
          if (pass == 0) {
            ++start_[c + 1];
          } else {
            items_[fill_[c]++] = static_cast<uint32_t>(i);
          }
        });
      }
      if (pass == 0) {
        std::partial_sum(start_.begin(), start_.end(), start_.begin());
        items_.resize(start_.back());
        fill_.assign(start_.begin(), start_.end() - 1);
      }
    }
  }

  template <typename F>
  void Query(const Box3& b, F&& f) const {
    ForCells(b, [&](size_t c) {
      for (uint32_t k = start_[c]; k < start_[c + 1]; ++k) f(items_[k]);
    });
  }

 private:
  int CellOf(double v, int a) const {
    const double t = std::floor((v - domain_.lo[a]) * inv_[a]);
    if (!(t > 0)) return 0;
    return t >= res_[a] - 1 ? res_[a] - 1 : static_cast<int>(t);
  }
  template <typename F>
  void ForCells(const Box3& b, F&& f) const {
    int lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (int a = 0; a < 3; ++a) {
      lo[a] = CellOf(b.lo[a], a);
      hi[a] = CellOf(b.hi[a], a);
    }
    for (int z = lo[2]; z <= hi[2]; ++z) {
      for (int y = lo[1]; y <= hi[1]; ++y) {
        for (int x = lo[0]; x <= hi[0]; ++x) {
          f((static_cast<size_t>(z) * res_[1] + y) * res_[0] + x);
        }
      }
    }
  }

  Box3 domain_;
  int res_[3];
  double inv_[3];
  std::vector<uint32_t> start_, fill_, items_;
};

Box3 Expand(Box3 b, double d) {
  b.lo = b.lo - Vec3(d, d, d);
  b.hi = b.hi + Vec3(d, d, d);
  return b;
}

// ------------------------------------------------------- duplicate vertices

// first[v] = the smallest input id with exactly v's coordinates (== on each
// coordinate, so -0 and +0 are equal). The PLC readers/validator merge exact
// duplicates into their first occurrence (docs/plc.md), so segments and
// facets through a copy are checked as through the first occurrence. Ids
// with a NaN coordinate map to themselves.
std::vector<uint32_t> FirstOccurrences(const std::vector<Vec3>& pts) {
  std::vector<uint32_t> first(pts.size());
  std::iota(first.begin(), first.end(), 0u);
  std::vector<uint32_t> order;
  order.reserve(pts.size());
  for (uint32_t i = 0; i < pts.size(); ++i) {
    const Vec3& p = pts[i];
    if (!std::isnan(p.x) && !std::isnan(p.y) && !std::isnan(p.z)) order.push_back(i);
  }
  auto less = [&](uint32_t i, uint32_t j) {
    const Vec3 &a = pts[i], &b = pts[j];
    if (a.x != b.x) return a.x < b.x;
    if (a.y != b.y) return a.y < b.y;
    if (a.z != b.z) return a.z < b.z;
    return i < j;
  };
  std::sort(order.begin(), order.end(), less);
  for (size_t k = 1; k < order.size(); ++k) {
    if (pts[order[k]] == pts[order[k - 1]]) first[order[k]] = first[order[k - 1]];
  }
  return first;
}

// ------------------------------------------------------------- facet model

// A facet whose vertices are farther than this fraction of its diameter from
// the plane through three of them is not planar. Validation allows 1e-8 of the
// diameter from its Newell plane (plc::ValidationOptions::planarity_tolerance);
// the plane through three vertices can be twice as far from the others.
constexpr double kFacetFlatnessRel = 2e-8;

struct Plane {
  Vec3 a, b, c;  // three input points, not collinear
  Vec3 n;        // unit normal (floating point, for tolerances and areas)
  int axis = 2;  // dominant axis of n: the projection drops it
};

struct Loop {
  std::vector<Vec3> pts;
  std::vector<uint32_t> ids;
  bool outer = false;
  bool hole = false;
  double area = 0;  // 3D area (unsigned)
};

struct FacetGeom {
  bool valid = false;
  Plane plane;
  std::vector<Loop> loops;
  std::vector<std::vector<uint8_t>> inside;  // inside[i][j]: loop i lies inside loop j
  double area = 0;
  double perimeter = 0;  // of all its loops
  Box3 box;
  // Distance within which a point counts as on the facet: the checker's
  // on-feature tolerance, or 4x the facet's own flatness (its vertices'
  // largest distance from `plane`) when that is larger. Validation accepts
  // facets planar to 1e-8 of their diameter (docs/plc.md); a mesher puts a
  // facet's Steiner points on some plane through it, within flatness of the
  // vertices at both ends: up to ~4x the flatness from `plane` (docs/conformity.md).
  double tol = 0;
  int32_t marker = 0;
};

// Side of p with respect to the plane: the exact sign, except that points
// within `tol` of the plane count as on it (docs/conformity.md).
int SideOf(const Plane& pl, const Vec3& p, double tol) {
  // "On" is: exact Orient3d == 0 or distance <= tol. Deciding the distance
  // first gives the same answer and spares the exact stage of Orient3d for
  // points on slanted planes (where its filter cannot certify 0): most of
  // the checker's time on surface inputs such as bunny.off.
  if (tol > 0 && std::fabs(Dot(pl.n, p - pl.a)) <= tol) return 0;
  return geom::Orient3d(pl.a, pl.b, pl.c, p);
}

// Projected 2D coordinates (the axes after `axis`, cyclically), as in
// geom::Orient2dProjected.
inline double U(const Vec3& p, int axis) { return p[(axis + 1) % 3]; }
inline double V(const Vec3& p, int axis) { return p[(axis + 2) % 3]; }

// +1 strictly inside the closed polygon, 0 on its boundary, -1 outside; q is
// assumed to lie on the polygon's plane. Exact crossing-number test on the
// projection.
int PointInLoop(const std::vector<Vec3>& loop, const Vec3& q, int axis) {
  bool inside = false;
  const double qu = U(q, axis), qv = V(q, axis);
  for (size_t i = 0, n = loop.size(); i < n; ++i) {
    const Vec3& p = loop[i];
    const Vec3& r = loop[(i + 1) % n];
    const int o = geom::Orient2dProjected(p, r, q, axis);
    if (o == 0 && qu >= std::min(U(p, axis), U(r, axis)) && qu <= std::max(U(p, axis), U(r, axis)) &&
        qv >= std::min(V(p, axis), V(r, axis)) && qv <= std::max(V(p, axis), V(r, axis))) {
      return 0;
    }
    const bool p_above = V(p, axis) > qv, r_above = V(r, axis) > qv;
    if (p_above != r_above) {
      // The edge crosses the line v = qv; count it when the crossing is on
      // the +u side of q, i.e. q is left of the upward-directed edge.
      const bool up = r_above;
      if (up ? o > 0 : o < 0) inside = !inside;
    }
  }
  return inside ? 1 : -1;
}

bool InFacetRegion(const FacetGeom& f, const Vec3& q) {
  bool in_outer = false;
  for (const Loop& l : f.loops) {
    if (l.outer && !l.hole && PointInLoop(l.pts, q, f.plane.axis) >= 0) {
      in_outer = true;
      break;
    }
  }
  if (!in_outer) return false;
  for (const Loop& l : f.loops) {
    if (l.hole && PointInLoop(l.pts, q, f.plane.axis) > 0) return false;
  }
  return true;
}

// Vector area of a closed polygon, relative to its first point.
Vec3 VectorArea(const std::vector<Vec3>& pts) {
  Vec3 s;
  for (size_t i = 1; i + 1 < pts.size(); ++i) s += Cross(pts[i] - pts[0], pts[i + 1] - pts[0]);
  return 0.5 * s;
}

// Adds sign × (solid angle of the polygon fan pts[0], pts[i], pts[i+1] seen
// from p) to *total, term by term. Van Oosterom & Strackee (1983):
// tan(Ω/2) = det / denominator.
void AddTriangleSolidAngle(const Vec3& pa, const Vec3& pb, const Vec3& pc, const Vec3& p,
                           int sign, double* total) {
  const Vec3 a = pa - p, b = pb - p, c = pc - p;
  const double la = Norm(a), lb = Norm(b), lc = Norm(c);
  const double num = Dot(a, Cross(b, c));
  const double den = la * lb * lc + Dot(a, b) * lc + Dot(a, c) * lb + Dot(b, c) * la;
  *total += sign * 2 * std::atan2(num, den);
}

void AddFanSolidAngle(const std::vector<Vec3>& pts, const Vec3& p, int sign, double* total) {
  for (size_t i = 1; i + 1 < pts.size(); ++i) {
    AddTriangleSolidAngle(pts[0], pts[i], pts[i + 1], p, sign, total);
  }
}

// `first`: FirstOccurrences(plc.vertices); loop ids are stored mapped.
FacetGeom BuildFacet(const plc::Plc& plc, const plc::Facet& facet,
                     const std::vector<uint32_t>& first, double tol) {
  FacetGeom f;
  f.marker = facet.marker;
  std::vector<uint32_t> all;
  for (const auto& poly : facet.polygons) {
    for (uint32_t v : poly.vertices) {
      if (v >= plc.vertices.size()) return f;  // dangling index: invalid input
      all.push_back(v);
      f.box.Add(plc.vertices[v]);
    }
  }
  if (all.size() < 3) return f;
  // Plane through three input points: a, the farthest point from a, and the
  // point farthest from that line (the best-conditioned triple cheaply).
  const Vec3 a = plc.vertices[all[0]];
  Vec3 b = a, c = a;
  double best = 0;
  for (uint32_t v : all) {
    const double d = geom::Dist2(a, plc.vertices[v]);
    if (d > best) best = d, b = plc.vertices[v];
  }
  best = 0;
  for (uint32_t v : all) {
    const double d = geom::Norm2(Cross(b - a, plc.vertices[v] - a));
    if (d > best) best = d, c = plc.vertices[v];
  }
  if (best == 0) return f;  // collinear: zero-area facet
  f.plane.a = a;
  f.plane.b = b;
  f.plane.c = c;
  const Vec3 n = Cross(b - a, c - a);
  f.plane.n = n / Norm(n);
  f.plane.axis = geom::DominantAxis(n);
  double flat = 0;
  for (uint32_t v : all) flat = std::max(flat, std::fabs(Dot(f.plane.n, plc.vertices[v] - a)));
  const double diameter = Norm(f.box.hi - f.box.lo);
  if (flat > tol && flat > kFacetFlatnessRel * diameter) return f;  // not planar
  f.tol = std::max(tol, 4 * flat);
  for (const auto& poly : facet.polygons) {
    if (poly.vertices.size() < 3) continue;
    Loop l;
    for (uint32_t v : poly.vertices) {
      l.ids.push_back(first[v]);
      l.pts.push_back(plc.vertices[v]);
    }
    l.area = Norm(VectorArea(l.pts));
    for (size_t i = 0; i < l.pts.size(); ++i) f.perimeter += Norm(l.pts[(i + 1) % l.pts.size()] - l.pts[i]);
    f.loops.push_back(std::move(l));
  }
  if (f.loops.empty()) return f;
  const int axis = f.plane.axis;
  // Outer loops: not contained in another loop (all vertices inside or on it,
  // one strictly inside).
  const size_t nl = f.loops.size();
  std::vector<std::vector<uint8_t>>& inside = f.inside;
  inside.assign(nl, std::vector<uint8_t>(nl, 0));
  for (size_t i = 0; i < nl; ++i) {
    for (size_t j = 0; j < nl; ++j) {
      if (i == j) continue;
      bool all_in = true, one_strict = false;
      for (const Vec3& p : f.loops[i].pts) {
        const int s = PointInLoop(f.loops[j].pts, p, axis);
        all_in = all_in && s >= 0;
        one_strict = one_strict || s > 0;
      }
      inside[i][j] = all_in && one_strict;
    }
  }
  for (size_t i = 0; i < nl; ++i) {
    f.loops[i].outer = true;
    for (size_t j = 0; j < nl; ++j) f.loops[i].outer = f.loops[i].outer && !inside[i][j];
  }
  // A facet hole seed removes the innermost loop strictly containing it.
  for (const Vec3& h : facet.holes) {
    size_t best_loop = nl;
    for (size_t i = 0; i < nl; ++i) {
      if (PointInLoop(f.loops[i].pts, h, axis) <= 0) continue;
      if (best_loop == nl || inside[i][best_loop]) best_loop = i;
    }
    if (best_loop < nl) f.loops[best_loop].hole = true;
  }
  for (const Loop& l : f.loops) {
    if (l.hole) {
      f.area -= l.outer ? 0 : l.area;
    } else if (l.outer) {
      f.area += l.area;
    }
  }
  f.valid = true;
  return f;
}

// Triangulates the facet's region: every outer polygon (not itself a hole)
// minus the outermost hole polygons inside it, by plc::TriangulatePolygon
// (exact ear clipping with hole bridges in the projection that drops
// plane.axis). Ids index `verts` (the PLC's vertices). False when some
// polygon cannot be triangulated (self-intersecting loops).
bool TriangulateRegion(const std::vector<Vec3>& verts, const FacetGeom& f,
                       std::vector<std::array<uint32_t, 3>>* out) {
  const size_t nl = f.loops.size();
  auto is_hole = [&](size_t j) { return f.loops[j].hole && !f.loops[j].outer; };
  for (size_t i = 0; i < nl; ++i) {
    if (!f.loops[i].outer || f.loops[i].hole) continue;
    std::vector<std::vector<uint32_t>> holes;
    for (size_t j = 0; j < nl; ++j) {
      if (!is_hole(j) || !f.inside[j][i]) continue;
      bool outermost = true;
      for (size_t k = 0; k < nl && outermost; ++k) {
        outermost = k == j || !is_hole(k) || !f.inside[j][k];
      }
      if (outermost) holes.push_back(f.loops[j].ids);
    }
    if (!plc::TriangulatePolygon(verts, f.loops[i].ids, holes, f.plane.axis, out)) return false;
  }
  return true;
}

// --------------------------------------------------- 2D clipping for crossing

using P2 = std::array<double, 2>;

double SignedArea2(const std::vector<P2>& p) {
  double s = 0;
  for (size_t i = 0, n = p.size(); i < n; ++i) {
    const P2& a = p[i];
    const P2& b = p[(i + 1) % n];
    s += a[0] * b[1] - a[1] * b[0];
  }
  return 0.5 * s;
}

// Sutherland–Hodgman: subject (any simple polygon) clipped by a convex
// counter-clockwise polygon. The area of the result is the area of the
// intersection even for a non-convex subject.
std::vector<P2> ClipConvex(std::vector<P2> subject, const std::vector<P2>& clip) {
  for (size_t e = 0, m = clip.size(); e < m && !subject.empty(); ++e) {
    const P2 c0 = clip[e], c1 = clip[(e + 1) % m];
    auto side = [&](const P2& x) {
      return (c1[0] - c0[0]) * (x[1] - c0[1]) - (c1[1] - c0[1]) * (x[0] - c0[0]);
    };
    std::vector<P2> out;
    for (size_t i = 0, n = subject.size(); i < n; ++i) {
      const P2 cur = subject[i], prev = subject[(i + n - 1) % n];
      const double sc = side(cur), sp = side(prev);
      if ((sc >= 0) != (sp >= 0)) {
        const double t = sp / (sp - sc);
        out.push_back({prev[0] + t * (cur[0] - prev[0]), prev[1] + t * (cur[1] - prev[1])});
      }
      if (sc >= 0) out.push_back(cur);
    }
    subject = std::move(out);
  }
  return subject;
}

// ------------------------------------------------------------- the checker

class Checker {
 public:
  Checker(const plc::Plc* plc, const TetMesh& mesh, const ConformityOptions& opt,
          ConformityReport* rep)
      : plc_(plc), mesh_(mesh), opt_(opt), rep_(rep) {}

  void Run() {
    CheckIdsAndTags();
    CheckTets();
    CheckFaces();
    CheckTriangles();
    rep_->mesh_volume = MeshVolume();
    if (plc_ == nullptr) return;
    PrepareFacets();
    CheckOpenFaces();
    CheckVolume();
    CheckInputVertices();
    CheckSegments();
    CheckCrossings();
    CheckFacetCoverage();
  }

 private:
  const Vec3& P(uint32_t v) const { return mesh_.positions[v]; }

  void CheckIdsAndTags() {
    const size_t nv = mesh_.positions.size();
    tet_ok_.assign(mesh_.tets.size(), 1);
    for (size_t t = 0; t < mesh_.tets.size(); ++t) {
      for (uint32_t v : mesh_.tets[t]) {
        if (v >= nv) {
          tet_ok_[t] = 0;
          Add(rep_, opt_, ViolationKind::kIdOutOfRange, {static_cast<int64_t>(t), v},
              absl::StrCat("tet ", t, " has vertex id ", v, " >= ", nv));
          break;
        }
      }
    }
    tri_ok_.assign(mesh_.triangles.size(), 1);
    for (size_t t = 0; t < mesh_.triangles.size(); ++t) {
      for (uint32_t v : mesh_.triangles[t]) {
        if (v >= nv) {
          tri_ok_[t] = 0;
          Add(rep_, opt_, ViolationKind::kIdOutOfRange, {static_cast<int64_t>(t), v},
              absl::StrCat("triangle ", t, " has vertex id ", v, " >= ", nv));
          break;
        }
      }
    }
    if (mesh_.tet_region.size() != mesh_.tets.size()) {
      Add(rep_, opt_, ViolationKind::kTagCountMismatch, {},
          absl::StrCat(mesh_.tet_region.size(), " tet regions for ", mesh_.tets.size(), " tets"));
    } else if (!mesh_.regions.empty()) {
      for (size_t t = 0; t < mesh_.tets.size(); ++t) {
        const int32_t r = mesh_.tet_region[t];
        if (r < 0 || static_cast<size_t>(r) >= mesh_.regions.size()) {
          Add(rep_, opt_, ViolationKind::kTagCountMismatch, {static_cast<int64_t>(t), r},
              absl::StrCat("tet ", t, " has region id ", r, " of ", mesh_.regions.size()));
        }
      }
    }
    if (mesh_.triangle_marker.size() != mesh_.triangles.size()) {
      Add(rep_, opt_, ViolationKind::kTagCountMismatch, {},
          absl::StrCat(mesh_.triangle_marker.size(), " triangle markers for ",
                       mesh_.triangles.size(), " triangles"));
    }
  }

  // The first vertex of q within `tol` of its opposite face's plane (the
  // on-plane rule of facets, docs/conformity.md), or -1. A positively
  // oriented tet with such a vertex is flat at the checker's resolution: all
  // its faces can lie on one facet, which then counts twice over the tet
  // (armadillo.off's flat star, session 34), and its shape is meaningless.
  int FlatVertex(const std::array<uint32_t, 4>& q, double tol) const {
    static constexpr int kOpp[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
    for (int k = 0; k < 4; ++k) {
      const Vec3& a = P(q[kOpp[k][0]]);
      const Vec3 n = Cross(P(q[kOpp[k][1]]) - a, P(q[kOpp[k][2]]) - a);
      const double len = std::sqrt(Dot(n, n));
      if (!(len > 0) || std::fabs(Dot(n, P(q[k]) - a)) <= tol * len) return k;
    }
    return -1;
  }

  void CheckTets() {
    // The on-plane tolerance from the mesh's own coordinates (the PLC's are
    // not known to CheckValidity; the mesh holds them).
    const double flat_tol = OnFeatureTolerance(mesh_.positions, opt_.tolerance_ulps);
    // (sorted vertex ids packed in two words, tet): integer comparisons only.
    std::vector<std::tuple<uint64_t, uint64_t, uint32_t>> sorted;
    sorted.reserve(mesh_.tets.size());
    for (size_t t = 0; t < mesh_.tets.size(); ++t) {
      if (!tet_ok_[t]) continue;
      const auto& q = mesh_.tets[t];
      const int s = geom::Orient3d(P(q[0]), P(q[1]), P(q[2]), P(q[3]));
      if (s < 0) {
        Add(rep_, opt_, ViolationKind::kFlippedTet, {static_cast<int64_t>(t)},
            absl::StrCat("tet ", t, " (", q[0], " ", q[1], " ", q[2], " ", q[3],
                         ") is negatively oriented"));
      } else if (s == 0) {
        Add(rep_, opt_, ViolationKind::kDegenerateTet, {static_cast<int64_t>(t)},
            absl::StrCat("tet ", t, " (", q[0], " ", q[1], " ", q[2], " ", q[3], ") is flat"));
      } else if (const int k = FlatVertex(q, flat_tol); k >= 0) {
        Add(rep_, opt_, ViolationKind::kFlatTet, {static_cast<int64_t>(t), q[k]},
            absl::StrCat("tet ", t, " (", q[0], " ", q[1], " ", q[2], " ", q[3], ") is flat within the tolerance ",
                         flat_tol, ": vertex ", q[k], " is on the plane of its opposite face"));
      }
      auto key = q;
      std::sort(key.begin(), key.end());
      sorted.emplace_back(uint64_t{key[0]} << 32 | key[1], uint64_t{key[2]} << 32 | key[3],
                          static_cast<uint32_t>(t));
    }
    std::sort(sorted.begin(), sorted.end());
    for (size_t i = 1; i < sorted.size(); ++i) {
      const auto& [a0, a1, ta] = sorted[i - 1];
      const auto& [b0, b1, tb] = sorted[i];
      if (a0 == b0 && a1 == b1) {
        Add(rep_, opt_, ViolationKind::kDuplicateTet, {ta, tb},
            absl::StrCat("tets ", ta, " and ", tb, " have the same vertices"));
      }
    }
  }

  struct FaceRec {
    std::array<uint32_t, 3> key;
    uint32_t tet;
    uint8_t local;
    // Field by field: std::array's operators go through memcmp calls, which
    // dominated the sort of ~4M faces.
    bool operator<(const FaceRec& o) const {
      if (key[0] != o.key[0]) return key[0] < o.key[0];
      if (key[1] != o.key[1]) return key[1] < o.key[1];
      if (key[2] != o.key[2]) return key[2] < o.key[2];
      return tet != o.tet ? tet < o.tet : local < o.local;
    }
    bool SameKey(const FaceRec& o) const {
      return key[0] == o.key[0] && key[1] == o.key[1] && key[2] == o.key[2];
    }
  };

  void CheckFaces() {
    faces_.reserve(4 * mesh_.tets.size());
    for (size_t t = 0; t < mesh_.tets.size(); ++t) {
      if (!tet_ok_[t]) continue;
      for (int k = 0; k < 4; ++k) {
        std::array<uint32_t, 3> key = {mesh_.tets[t][kFace[k][0]], mesh_.tets[t][kFace[k][1]],
                                       mesh_.tets[t][kFace[k][2]]};
        std::sort(key.begin(), key.end());
        faces_.push_back({key, static_cast<uint32_t>(t), static_cast<uint8_t>(k)});
      }
    }
    std::sort(faces_.begin(), faces_.end());
    for (size_t i = 0; i < faces_.size();) {
      size_t j = i;
      while (j < faces_.size() && faces_[j].SameKey(faces_[i])) ++j;
      const auto& key = faces_[i].key;
      if (j - i == 1) {
        open_faces_.push_back(i);
      } else if (j - i == 2) {
        const uint32_t t1 = faces_[i].tet, t2 = faces_[i + 1].tet;
        const uint32_t d1 = mesh_.tets[t1][faces_[i].local];
        const uint32_t d2 = mesh_.tets[t2][faces_[i + 1].local];
        const int s1 = geom::Orient3d(P(key[0]), P(key[1]), P(key[2]), P(d1));
        const int s2 = geom::Orient3d(P(key[0]), P(key[1]), P(key[2]), P(d2));
        if (s1 != 0 && s2 != 0 && s1 == s2) {
          Add(rep_, opt_, ViolationKind::kNeighborsSameSide, {t1, t2},
              absl::StrCat("tets ", t1, " and ", t2, " share face (", key[0], " ", key[1], " ",
                           key[2], ") and lie on the same side of it"));
        }
      } else {
        std::vector<int64_t> ids = {key[0], key[1], key[2]};
        for (size_t k = i; k < j; ++k) ids.push_back(faces_[k].tet);
        Add(rep_, opt_, ViolationKind::kFaceInMoreThanTwoTets, ids,
            absl::StrCat("face (", key[0], " ", key[1], " ", key[2], ") is in ", j - i, " tets"));
      }
      i = j;
    }
  }

  void CheckTriangles() {
    std::vector<std::pair<std::array<uint32_t, 3>, uint32_t>> sorted;
    for (size_t t = 0; t < mesh_.triangles.size(); ++t) {
      if (!tri_ok_[t]) continue;
      auto key = mesh_.triangles[t];
      std::sort(key.begin(), key.end());
      sorted.push_back({key, static_cast<uint32_t>(t)});
      const FaceRec probe{key, 0, 0};
      auto it = std::lower_bound(faces_.begin(), faces_.end(), probe);
      if (it == faces_.end() || it->key != key) {
        Add(rep_, opt_, ViolationKind::kTriangleNotAFace, {static_cast<int64_t>(t)},
            absl::StrCat("triangle ", t, " (", key[0], " ", key[1], " ", key[2],
                         ") is not a face of any tet"));
      }
    }
    std::sort(sorted.begin(), sorted.end());
    for (size_t i = 1; i < sorted.size(); ++i) {
      if (sorted[i].first == sorted[i - 1].first) {
        tri_ok_[sorted[i].second] = 0;  // count its area once
        Add(rep_, opt_, ViolationKind::kDuplicateTriangle,
            {sorted[i - 1].second, sorted[i].second},
            absl::StrCat("triangles ", sorted[i - 1].second, " and ", sorted[i].second,
                         " have the same vertices"));
      }
    }
  }

  double MeshVolume() {
    Box3 box;
    for (const Vec3& p : mesh_.positions) box.Add(p);
    mesh_box_ = box;
    const Vec3 o = box.Empty() ? Vec3() : box.Center();
    double v = 0;
    for (size_t t = 0; t < mesh_.tets.size(); ++t) {
      if (!tet_ok_[t]) continue;
      const auto& q = mesh_.tets[t];
      const Vec3 a = P(q[0]) - o;
      v += Dot((P(q[1]) - o) - a, Cross((P(q[2]) - o) - a, (P(q[3]) - o) - a)) / 6.0;
    }
    return v;
  }

  // ------------------------------------------------------------ with a PLC

  void PrepareFacets() {
    tol_ = OnFeatureTolerance(plc_->vertices, opt_.tolerance_ulps);
    first_ = FirstOccurrences(plc_->vertices);
    facets_.reserve(plc_->facets.size());
    for (const auto& f : plc_->facets) facets_.push_back(BuildFacet(*plc_, f, first_, tol_));
    for (const FacetGeom& f : facets_) rep_->num_facets_checked += f.valid ? 1 : 0;
    Box3 all;
    for (const FacetGeom& f : facets_) {
      if (f.valid) {
        all.Add(f.box.lo);
        all.Add(f.box.hi);
      }
    }
    all = Expand(all, tol_);
    facet_grid_ = std::make_unique<BoxGrid>(all, facets_.size(), 1, 64, [&](size_t i) {
      return facets_[i].valid ? Expand(facets_[i].box, facets_[i].tol) : Box3();
    });
    facet_stamp_.assign(facets_.size(), kNone);
    region_.resize(facets_.size());
  }

  // Calls f(facet index) for every valid facet containing the triangle abc
  // (vertices on its plane, centroid in its region), each once.
  template <typename F>
  void ForFacetsContaining(const Vec3& a, const Vec3& b, const Vec3& c, F&& f) {
    const Vec3 g = (a + b + c) / 3.0;
    Box3 q;
    q.Add(g);
    ++query_;
    facet_grid_->Query(q, [&](uint32_t i) {
      if (facet_stamp_[i] == query_) return;
      facet_stamp_[i] = query_;
      const FacetGeom& fg = facets_[i];
      if (SideOf(fg.plane, a, fg.tol) != 0 || SideOf(fg.plane, b, fg.tol) != 0 ||
          SideOf(fg.plane, c, fg.tol) != 0) {
        return;
      }
      // The centroid is rounded; project it onto the plane's coordinates by
      // using it only in the 2D tests (which ignore the dropped axis).
      if (!InFacetRegion(fg, g)) return;
      f(i);
    });
  }

  bool OnBoxBoundary(const Vec3& a, const Vec3& b, const Vec3& c) const {
    for (int ax = 0; ax < 3; ++ax) {
      for (double w : {mesh_box_.lo[ax], mesh_box_.hi[ax]}) {
        if (a[ax] == w && b[ax] == w && c[ax] == w) return true;
      }
    }
    return false;
  }

  void CheckOpenFaces() {
    for (size_t i : open_faces_) {
      const auto& k = faces_[i].key;
      if (opt_.keep_bounding_box && OnBoxBoundary(P(k[0]), P(k[1]), P(k[2]))) continue;
      bool on_facet = false;
      ForFacetsContaining(P(k[0]), P(k[1]), P(k[2]), [&](uint32_t) { on_facet = true; });
      if (!on_facet) {
        Add(rep_, opt_, ViolationKind::kOpenFace, {faces_[i].tet, faces_[i].local},
            absl::StrCat("face (", k[0], " ", k[1], " ", k[2], ") of tet ", faces_[i].tet,
                         " is in no other tet and on no input facet",
                         opt_.keep_bounding_box ? " or the bounding box" : ""));
      }
    }
  }

  // The volume by which a mesh whose facet triangles are within each facet's
  // tolerance of it may differ from the volumes the facets enclose: the sum
  // of area x tolerance. Negligible for planar facets (8 ulps); a facet
  // planar to 1e-9 of its size moves Steiner points that far (a unit cube
  // with one vertex 9e-9 off its face's plane: cell volume 1.2e-9 over).
  double FlatnessVolume() const {
    double v = 0;
    for (const FacetGeom& fg : facets_) {
      if (fg.valid) v += fg.area * fg.tol;
    }
    return v;
  }

  // Enclosed volume by the divergence theorem, when the valid facets form
  // closed, consistently orientable 2-manifold surfaces (no internal facets);
  // nested surfaces and volume holes are resolved by winding numbers
  // (docs/conformity.md).
  void CheckVolume() {
    if (opt_.keep_bounding_box) {
      if (!mesh_box_.Empty()) {
        const Vec3 e = mesh_box_.hi - mesh_box_.lo;
        rep_->enclosed_volume = e.x * e.y * e.z;
        rep_->enclosed_volume_known = true;
      }
    } else {
      BuildCells();
      if (!cells_known_) ComputeEnclosedVolume();
    }
    rep_->cells_known = cells_known_;
    rep_->num_cells = cells_known_ ? static_cast<size_t>(num_bounded_cells_) : 0;
    if (!cells_known_) rep_->cells_unknown_reason = cells_reason_;
    if (!rep_->enclosed_volume_known) return;
    // Cell by cell subsumes the total (the cells' volumes add up to it); the
    // total is the fallback when a component could not be located.
    if (cells_known_ && CheckCellCoverage()) return;
    const double ve = rep_->enclosed_volume, vm = rep_->mesh_volume;
    if (std::fabs(vm - ve) > std::max(opt_.volume_rel_tol * std::fabs(ve), FlatnessVolume())) {
      Add(rep_, opt_, ViolationKind::kVolumeMismatch, {},
          absl::StrFormat("total tet volume %.17g != enclosed volume %.17g (relative %.3g)", vm,
                          ve, std::fabs(vm - ve) / std::max(std::fabs(ve), 1e-300)));
    }
  }

  void ComputeEnclosedVolume() {
    if (facets_.empty()) return;
    // Directed boundary edges: (facet, loop direction sign, u, v).
    struct Edge {
      std::array<uint32_t, 2> key;
      uint32_t facet;
      int dir;  // +1 when the facet's orientation traverses key[0] -> key[1]
    };
    std::vector<Edge> edges;
    std::vector<Vec3> normal(facets_.size());
    for (size_t f = 0; f < facets_.size(); ++f) {
      const FacetGeom& fg = facets_[f];
      if (!fg.valid) return;  // invalid facet: unknown
      const Loop* ref = nullptr;
      for (const Loop& l : fg.loops) {
        if (l.outer && !l.hole) {
          ref = &l;
          break;
        }
      }
      if (ref == nullptr) continue;
      normal[f] = VectorArea(ref->pts);
      for (const Loop& l : fg.loops) {
        if (!l.outer && !l.hole) continue;  // a subdivision inside the facet
        if (l.outer && l.hole) continue;
        const double d = Dot(VectorArea(l.pts), normal[f]);
        const int sign = (d > 0 ? 1 : -1) * (l.hole ? -1 : 1);
        for (size_t i = 0, n = l.ids.size(); i < n; ++i) {
          uint32_t u = l.ids[i], v = l.ids[(i + 1) % n];
          if (u == v) continue;
          const int dir = u < v ? sign : -sign;
          edges.push_back({{std::min(u, v), std::max(u, v)}, static_cast<uint32_t>(f), dir});
        }
      }
    }
    std::sort(edges.begin(), edges.end(), [](const Edge& a, const Edge& b) {
      return a.key != b.key ? a.key < b.key : a.facet < b.facet;
    });
    // Every edge in exactly two facets; union-find free BFS over facets.
    std::vector<std::vector<std::pair<uint32_t, int>>> adj(facets_.size());
    for (size_t i = 0; i < edges.size();) {
      size_t j = i;
      while (j < edges.size() && edges[j].key == edges[i].key) ++j;
      if (j - i != 2 || edges[i].facet == edges[i + 1].facet) return;  // not a closed 2-manifold
      // Consistent orientation: the two facets traverse the edge in opposite
      // directions, i.e. relative sign = -dir_i * dir_j.
      const int rel = -edges[i].dir * edges[i + 1].dir;
      adj[edges[i].facet].push_back({edges[i + 1].facet, rel});
      adj[edges[i + 1].facet].push_back({edges[i].facet, rel});
      i = j;
    }
    std::vector<int> orient(facets_.size(), 0);
    Box3 plc_box;
    for (const Vec3& p : plc_->vertices) plc_box.Add(p);
    const Vec3 o = plc_box.Center();
    struct Shell {
      std::vector<uint32_t> facets;
      double volume = 0;  // |signed volume|
    };
    std::vector<Shell> shells;
    for (size_t s = 0; s < facets_.size(); ++s) {
      if (orient[s] != 0 || facets_[s].area == 0) continue;
      orient[s] = 1;
      std::vector<uint32_t> stack = {static_cast<uint32_t>(s)};
      Shell shell;
      double vol = 0;
      while (!stack.empty()) {
        const uint32_t f = stack.back();
        stack.pop_back();
        shell.facets.push_back(f);
        const FacetGeom& fg = facets_[f];
        const Vec3 n = normal[f] / Norm(normal[f]);
        vol += orient[f] * fg.area * Dot(n, fg.plane.a - o) / 3.0;
        for (auto [g, rel] : adj[f]) {
          const int want = orient[f] * rel;
          if (orient[g] == 0) {
            orient[g] = want;
            stack.push_back(g);
          } else if (orient[g] != want) {
            return;  // not orientable
          }
        }
      }
      shell.volume = std::fabs(vol);
      shells.push_back(std::move(shell));
    }
    // Nesting by generalized winding numbers (Jacobson et al. 2013: the sum
    // of signed solid angles / 4π is an integer off a closed surface, so
    // rounding decides robustly). inside[c][d]: shell c lies inside shell d.
    constexpr size_t kMaxShells = 256;
    if (shells.size() > kMaxShells) return;
    const size_t ns = shells.size();
    auto winding = [&](const Shell& sh, const Vec3& p) {
      double total = 0;
      for (uint32_t f : sh.facets) {
        for (const Loop& l : facets_[f].loops) {
          if (l.outer == l.hole) continue;  // subdivision, or removed outer loop
          const int sign = (Dot(VectorArea(l.pts), normal[f]) > 0 ? 1 : -1) *
                           (l.hole ? -1 : 1) * orient[f];
          AddFanSolidAngle(l.pts, p, sign, &total);
        }
      }
      return total / (4 * 3.14159265358979323846);
    };
    // Rounded |winding number| of p w.r.t. shell d, or -1 when p is (nearly)
    // on the surface.
    auto inside_of = [&](size_t d, const Vec3& p) {
      const double w = winding(shells[d], p);
      const double r = std::round(w);
      return std::fabs(w - r) < 0.25 ? static_cast<int>(std::fabs(r)) : -1;
    };
    std::vector<std::vector<bool>> inside(ns, std::vector<bool>(ns, false));
    for (size_t c = 0; c < ns; ++c) {
      for (size_t d = 0; d < ns; ++d) {
        if (c == d) continue;
        // Try the vertices of c until one is clearly off d's surface.
        int in = -1;
        for (uint32_t f : shells[c].facets) {
          for (const Loop& l : facets_[f].loops) {
            for (const Vec3& p : l.pts) {
              in = inside_of(d, p);
              if (in >= 0) break;
            }
            if (in >= 0) break;
          }
          if (in >= 0) break;
        }
        if (in < 0 || in > 1) return;  // touching or self-overlapping shells: unknown
        inside[c][d] = in == 1;
      }
    }
    std::vector<int> depth(ns, 0);
    for (size_t c = 0; c < ns; ++c) {
      for (size_t d = 0; d < ns; ++d) depth[c] += inside[c][d] ? 1 : 0;
    }
    double total = 0;
    for (size_t c = 0; c < ns; ++c) total += depth[c] == 0 ? shells[c].volume : 0;
    // A volume hole removes the cell that contains its seed: the innermost
    // shell around the seed minus the shells directly inside that one.
    std::vector<bool> removed(ns, false);
    for (const Vec3& h : plc_->holes) {
      size_t cell = ns;
      for (size_t d = 0; d < ns; ++d) {
        const int in = inside_of(d, h);
        if (in < 0) return;  // seed on a facet: unknown
        if (in == 1 && (cell == ns || depth[d] > depth[cell])) cell = d;
      }
      if (cell == ns || removed[cell]) continue;  // in the exterior, or already removed
      removed[cell] = true;
      double hole = shells[cell].volume;
      for (size_t d = 0; d < ns; ++d) {
        if (inside[d][cell] && depth[d] == depth[cell] + 1) hole -= shells[d].volume;
      }
      total -= hole;
    }
    rep_->enclosed_volume = total;
    rep_->enclosed_volume_known = true;
  }

  // ------------------------------------------------ cells of the facet arrangement
  //
  // docs/conformity.md "Cells of the facet arrangement". The region of each
  // valid facet is triangulated (TriangulateRegion) with every edge of the
  // complex that lies inside it inserted as a constraint, and split into
  // *pieces*: the components of its triangles across edges that are not
  // constraints. Each piece has two sides (nodes 2p: Orient3d(a,b,c,x) > 0
  // of its facet's plane, 2p+1: < 0), and each side lies in one cell. Around
  // every edge bounding a piece the pieces' half-planes ("wings") are sorted
  // by angle with exact Orient3d; consecutive wings bound one wedge, so the
  // facing sides belong to the same cell: union them. Components are shells;
  // a shell with positive outward volume is the outer boundary of one bounded
  // cell, a negative one bounds a cell from inside (the unbounded cell or a
  // cavity) and belongs to the innermost positive shell containing a point
  // of it.

  struct Piece {
    uint32_t facet = 0;
    std::vector<std::array<uint32_t, 3>> tris;  // PLC vertex ids
    std::vector<int8_t> up;                     // Orient3d(tri, a + n·L) (normal vs n)
    double area = 0;
  };

  static int Sgn(double x) { return x > 0 ? 1 : (x < 0 ? -1 : 0); }

  // A point well off facet fg's plane on the side its unit normal n points to.
  Vec3 AbovePlane(const FacetGeom& fg) const { return fg.plane.a + fg.plane.n * cell_len_; }

  // Orient3d(a,b,c,x) > 0 lies along sigma_[f] * n.
  int PlaneSigma(const FacetGeom& fg) const {
    return geom::Orient3d(fg.plane.a, fg.plane.b, fg.plane.c, AbovePlane(fg));
  }

  uint32_t Find(std::vector<uint32_t>& uf, uint32_t x) const {
    while (uf[x] != x) x = uf[x] = uf[uf[x]];
    return x;
  }

  const Vec3& PV(uint32_t v) const { return plc_->vertices[v]; }

  // A point strictly inside piece pc (strictly inside one of its triangles,
  // exact), or false.
  bool PieceInteriorPoint(const Piece& pc, Vec3* out) const {
    const int axis = facets_[pc.facet].plane.axis;
    for (const auto& t : pc.tris) {
      const Vec3 g = (PV(t[0]) + PV(t[1]) + PV(t[2])) / 3.0;
      const int o = geom::Orient2dProjected(PV(t[0]), PV(t[1]), PV(t[2]), axis);
      bool in = o != 0;
      for (int k = 0; k < 3 && in; ++k) {
        in = geom::Orient2dProjected(PV(t[k]), PV(t[(k + 1) % 3]), g, axis) == o;
      }
      if (in) {
        *out = g;
        return true;
      }
    }
    return false;
  }

  // Winding number of p with respect to shell s, oriented outward.
  double ShellWinding(size_t s, const Vec3& p) const {
    double total = 0;
    for (uint32_t node : shell_nodes_[s]) {
      const Piece& pc = pieces_[node / 2];
      const int side = node % 2 == 0 ? 1 : -1;
      // The outward normal is -side * sigma * n; a triangle's normal has the
      // direction up * n.
      const int out = -side * facet_sigma_[pc.facet];
      for (size_t k = 0; k < pc.tris.size(); ++k) {
        const auto& t = pc.tris[k];
        AddTriangleSolidAngle(PV(t[0]), PV(t[1]), PV(t[2]), p, pc.up[k] * out, &total);
      }
    }
    return total / (4 * 3.14159265358979323846);
  }

  // Rounded winding number of p w.r.t. shell s; -1 when p is (nearly) on it.
  int ShellInside(size_t s, const Vec3& p) const {
    const double w = ShellWinding(s, p);
    const double r = std::round(w);
    if (std::fabs(w - r) >= 0.25) return -1;
    return static_cast<int>(std::fabs(r));
  }

  // The cell containing p (a point on no facet): the positive shell of least
  // volume whose winding number at p is 1, or the unbounded cell. -1 when p
  // is (nearly) on a facet. `skip_piece`: shells holding a side of this piece
  // are not asked (p lies on it).
  int32_t LocateCell(const Vec3& p, uint32_t skip_piece = kNone) const {
    int32_t best = num_bounded_cells_;
    for (size_t s = 0; s < shell_nodes_.size(); ++s) {
      const int32_t c = shell_cell_of_positive_[s];
      if (c < 0) continue;
      if (skip_piece != kNone && (node_shell_[2 * skip_piece] == s ||
                                  node_shell_[2 * skip_piece + 1] == s)) {
        continue;
      }
      const int in = ShellInside(s, p);
      if (in < 0 || in > 1) return -1;
      if (in == 1 && (best == num_bounded_cells_ || shell_volume_[s] < cell_outer_volume_[best])) {
        best = c;
      }
    }
    return best;
  }

  static uint64_t EdgeKey(uint32_t a, uint32_t b) {
    return uint64_t{std::min(a, b)} << 32 | std::max(a, b);
  }

  // Splits every facet's triangulated region into pieces (pieces_,
  // facet_pieces_) and collects the wings of the pieces' boundary edges.
  // False (with cells_reason_) when the arrangement is outside what this
  // handles.
  struct Wing {
    uint64_t key;
    uint32_t piece;
    uint32_t q;  // vertex of the piece's triangle on the edge: its interior side
  };
  bool BuildPieces(const std::vector<uint8_t>& present, std::vector<Wing>* wings) {
    const size_t nf = facets_.size();
    const std::vector<Vec3>& pv = plc_->vertices;
    Box3 vbox;
    for (const Vec3& p : pv) vbox.Add(p);
    const BoxGrid vgrid(vbox, pv.size(), 2, 64, [&](size_t i) {
      Box3 b;
      if (first_[i] == i) b.Add(pv[i]);
      return b;
    });
    // Every polygon edge of every facet, split at the vertices lying exactly
    // inside it (as the PLC validator does: T-junctions are legal), gives the
    // elementary edges. Per facet: the elementary edges of its outer/hole
    // polygons (bnd) and the vertices inside them (bnd_pts).
    std::vector<uint64_t> elem;
    std::vector<std::vector<uint64_t>> bnd(nf);
    std::vector<std::vector<uint32_t>> bnd_pts(nf);
    std::vector<uint32_t> inner;
    auto split = [&](uint32_t a, uint32_t b, std::vector<uint64_t>* out, std::vector<uint32_t>* pts) {
      const Vec3 &pa = pv[a], &pb = pv[b];
      const Vec3 d = pb - pa;
      const int ax = geom::DominantAxis(d);
      const double lo = std::min(pa[ax], pb[ax]), hi = std::max(pa[ax], pb[ax]);
      Box3 q;
      q.Add(pa);
      q.Add(pb);
      inner.clear();
      vgrid.Query(q, [&](uint32_t m) {
        if (m == a || m == b || !(pv[m][ax] > lo && pv[m][ax] < hi)) return;
        for (int k = 0; k < 3; ++k) {
          if (geom::Orient2dProjected(pa, pb, pv[m], k) != 0) return;
        }
        inner.push_back(m);
      });
      std::sort(inner.begin(), inner.end(), [&](uint32_t x, uint32_t y) {
        return pa[ax] < pb[ax] ? pv[x][ax] < pv[y][ax] : pv[x][ax] > pv[y][ax];
      });
      inner.erase(std::unique(inner.begin(), inner.end()), inner.end());
      uint32_t prev = a;
      for (uint32_t m : inner) {
        out->push_back(EdgeKey(prev, m));
        if (pts != nullptr) pts->push_back(m);
        prev = m;
      }
      out->push_back(EdgeKey(prev, b));
    };
    for (size_t f = 0; f < nf; ++f) {
      const FacetGeom& fg = facets_[f];
      for (const Loop& l : fg.loops) {
        const bool boundary = l.outer != l.hole;
        for (size_t i = 0, n = l.ids.size(); i < n; ++i) {
          const uint32_t u = l.ids[i], v = l.ids[(i + 1) % n];
          if (u == v) continue;
          if (boundary && present[f]) {
            split(u, v, &bnd[f], &bnd_pts[f]);
          } else {
            split(u, v, &elem, nullptr);
          }
        }
      }
      for (const auto& poly : plc_->facets[f].polygons) {
        if (poly.vertices.size() != 2 || poly.vertices[0] >= pv.size() ||
            poly.vertices[1] >= pv.size()) {
          continue;
        }
        const uint32_t u = first_[poly.vertices[0]], v = first_[poly.vertices[1]];
        if (u != v) split(u, v, &elem, nullptr);
      }
      std::sort(bnd[f].begin(), bnd[f].end());
      bnd[f].erase(std::unique(bnd[f].begin(), bnd[f].end()), bnd[f].end());
      elem.insert(elem.end(), bnd[f].begin(), bnd[f].end());
    }
    std::sort(elem.begin(), elem.end());
    elem.erase(std::unique(elem.begin(), elem.end()), elem.end());
    // Elementary edges lying in a facet's region (not on its boundary): they
    // split it. In a valid PLC such an edge lies in the facet's closed region
    // (its endpoints on the plane) and its open part is interior or on the
    // boundary; the midpoint decides.
    std::vector<std::vector<uint64_t>> cuts(nf);
    for (uint64_t e : elem) {
      const uint32_t a = static_cast<uint32_t>(e >> 32), b = static_cast<uint32_t>(e);
      const Vec3 mid = (pv[a] + pv[b]) / 2.0;
      Box3 q;
      q.Add(mid);
      ++query_;
      facet_grid_->Query(q, [&](uint32_t g) {
        if (facet_stamp_[g] == query_ || !present[g]) return;
        facet_stamp_[g] = query_;
        if (std::binary_search(bnd[g].begin(), bnd[g].end(), e)) return;
        const FacetGeom& gg = facets_[g];
        if (SideOf(gg.plane, pv[a], gg.tol) != 0 || SideOf(gg.plane, pv[b], gg.tol) != 0) return;
        if (!InFacetRegion(gg, mid) || !InFacetRegion(gg, pv[a]) || !InFacetRegion(gg, pv[b])) {
          return;
        }
        cuts[g].push_back(e);
      });
    }
    struct EdgeRec {
      uint64_t key;
      uint32_t tri;
      uint8_t local;  // edge local = (t[local], t[local+1]), opposite t[local+2]
      bool operator<(const EdgeRec& o) const {
        return key != o.key ? key < o.key : (tri != o.tri ? tri < o.tri : local < o.local);
      }
    };
    for (size_t f = 0; f < nf; ++f) {
      if (!present[f]) continue;
      const FacetGeom& fg = facets_[f];
      const RegionMesh& rm = Region(f);
      if (rm.state != 1) {
        cells_reason_ = absl::StrCat("facet ", f, "'s polygons cannot be triangulated");
        return false;
      }
      std::vector<std::array<uint32_t, 3>> tris = rm.tris;
      std::vector<uint64_t>& cut = cuts[f];
      std::sort(cut.begin(), cut.end());
      cut.erase(std::unique(cut.begin(), cut.end()), cut.end());
      if (!cut.empty() || !bnd_pts[f].empty()) {
        std::vector<uint32_t> pts = bnd_pts[f];
        std::vector<std::array<uint32_t, 2>> segs;
        for (uint64_t e : cut) {
          const uint32_t a = static_cast<uint32_t>(e >> 32), b = static_cast<uint32_t>(e);
          pts.push_back(a);
          pts.push_back(b);
          segs.push_back({a, b});
        }
        std::sort(pts.begin(), pts.end());
        pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
        if (!plc::InsertConstraints(pv, fg.plane.axis, pts, segs, &tris)) {
          cells_reason_ = absl::StrCat("facet ", f, ": the edges lying in it cannot be inserted");
          return false;
        }
      }
      // Triangle adjacency; pieces = components across non-constraint edges.
      std::vector<EdgeRec> er;
      er.reserve(3 * tris.size());
      for (uint32_t t = 0; t < tris.size(); ++t) {
        for (uint8_t k = 0; k < 3; ++k) er.push_back({EdgeKey(tris[t][k], tris[t][(k + 1) % 3]), t, k});
      }
      std::sort(er.begin(), er.end());
      std::vector<uint32_t> uf(tris.size());
      std::iota(uf.begin(), uf.end(), 0u);
      for (size_t i = 0; i < er.size();) {
        size_t j = i;
        while (j < er.size() && er[j].key == er[i].key) ++j;
        const bool is_cut = std::binary_search(cut.begin(), cut.end(), er[i].key);
        if (j - i > 2) {
          cells_reason_ = absl::StrCat("facet ", f, ": a triangulation edge in 3 triangles");
          return false;
        }
        if (j - i == 1 && !std::binary_search(bnd[f].begin(), bnd[f].end(), er[i].key)) {
          // The region's boundary must be made of its polygons' elementary
          // edges, or other facets would not find the same edge keys.
          cells_reason_ = absl::StrCat("facet ", f, "'s boundary does not match its polygon edges");
          return false;
        }
        if (j - i == 2 && !is_cut) uf[Find(uf, er[i].tri)] = Find(uf, er[i + 1].tri);
        i = j;
      }
      std::vector<uint32_t> piece_of(tris.size(), kNone);
      const Vec3 above = AbovePlane(fg);
      for (uint32_t t = 0; t < tris.size(); ++t) {
        const uint32_t r = Find(uf, t);
        if (piece_of[r] == kNone) {
          piece_of[r] = static_cast<uint32_t>(pieces_.size());
          facet_pieces_[f].push_back(piece_of[r]);
          pieces_.emplace_back();
          pieces_.back().facet = static_cast<uint32_t>(f);
        }
        piece_of[t] = piece_of[r];
        Piece& pc = pieces_[piece_of[t]];
        const auto& tr = tris[t];
        pc.tris.push_back(tr);
        pc.up.push_back(static_cast<int8_t>(geom::Orient3d(PV(tr[0]), PV(tr[1]), PV(tr[2]), above)));
        pc.area += 0.5 * Norm(Cross(PV(tr[1]) - PV(tr[0]), PV(tr[2]) - PV(tr[0])));
      }
      for (size_t i = 0; i < er.size();) {
        size_t j = i;
        while (j < er.size() && er[j].key == er[i].key) ++j;
        if (j - i == 1 || std::binary_search(cut.begin(), cut.end(), er[i].key)) {
          for (size_t k = i; k < j; ++k) {
            const auto& tr = tris[er[k].tri];
            wings->push_back({er[k].key, piece_of[er[k].tri], tr[(er[k].local + 2) % 3]});
          }
        }
        i = j;
      }
    }
    return true;
  }

  // Builds the cells; leaves cells_known_ false (with a reason) when the
  // arrangement is outside what this handles (docs/conformity.md).
  void BuildCells() {
    const size_t nf = facets_.size();
    if (nf == 0) return;
    Box3 plc_box;
    for (const Vec3& p : plc_->vertices) plc_box.Add(p);
    cell_origin_ = plc_box.Center();
    cell_len_ = std::max(1.0, Norm(plc_box.hi - plc_box.lo));
    facet_sigma_.assign(nf, 0);
    facet_pieces_.assign(nf, {});
    std::vector<uint8_t> present(nf, 0);
    for (size_t f = 0; f < nf; ++f) {
      const FacetGeom& fg = facets_[f];
      if (!fg.valid) return cells_reason_ = "an invalid facet", void();
      int outers = 0;
      for (const Loop& l : fg.loops) outers += l.outer && !l.hole ? 1 : 0;
      if (outers == 0) continue;  // nothing left of the facet
      present[f] = 1;
      facet_sigma_[f] = PlaneSigma(fg);
      if (facet_sigma_[f] == 0) return cells_reason_ = "a degenerate facet plane", void();
    }
    std::vector<Wing> wings;
    if (!BuildPieces(present, &wings)) return;
    std::sort(wings.begin(), wings.end(), [](const Wing& a, const Wing& b) {
      return a.key != b.key ? a.key < b.key : (a.piece != b.piece ? a.piece < b.piece : a.q < b.q);
    });
    const size_t np = pieces_.size();
    std::vector<uint32_t> uf(2 * np);
    std::iota(uf.begin(), uf.end(), 0u);
    auto unite = [&](uint32_t a, uint32_t b) { uf[Find(uf, a)] = Find(uf, b); };
    auto node = [](uint32_t p, int side) { return 2 * p + (side > 0 ? 0 : 1); };
    for (size_t i = 0; i < wings.size();) {
      size_t j = i;
      while (j < wings.size() && wings[j].key == wings[i].key) ++j;
      const Vec3 u = PV(static_cast<uint32_t>(wings[i].key >> 32));
      const Vec3 v = PV(static_cast<uint32_t>(wings[i].key));
      std::vector<const Wing*> w;
      for (size_t k = i; k < j; ++k) w.push_back(&wings[k]);
      i = j;
      if (w.size() == 1) {  // a free facet edge: both sides meet around it
        unite(node(w[0]->piece, 1), node(w[0]->piece, -1));
        continue;
      }
      // Angular order around u->v from the first wing r0 (exact): class 0 = r0,
      // 1 = (0, π), 2 = π, 3 = (π, 2π); within 1 and 3, q after p iff
      // Orient3d(u, v, p, q) > 0.
      const Vec3 r0 = PV(w[0]->q);
      const int axis0 = geom::DominantAxis(Cross(v - u, r0 - u));
      const int ref2d = geom::Orient2dProjected(u, v, r0, axis0);
      bool tie = false;
      auto cls = [&](const Vec3& p) {
        const int s = geom::Orient3d(u, v, r0, p);
        if (s > 0) return 1;
        if (s < 0) return 3;
        return geom::Orient2dProjected(u, v, p, axis0) == ref2d ? 0 : 2;
      };
      std::vector<int> cl(w.size());
      for (size_t k = 0; k < w.size(); ++k) cl[k] = cls(PV(w[k]->q));
      std::vector<size_t> order(w.size());
      std::iota(order.begin(), order.end(), size_t{0});
      std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
        if (cl[a] != cl[b]) return cl[a] < cl[b];
        if (a == b) return false;
        const int s = geom::Orient3d(u, v, PV(w[a]->q), PV(w[b]->q));
        if (s == 0) tie = true;
        return s > 0 ? true : (s < 0 ? false : a < b);
      });
      for (size_t k = 1; k < order.size(); ++k) {
        if (cl[order[k]] == cl[order[k - 1]] && (cl[order[k]] == 0 || cl[order[k]] == 2)) tie = true;
      }
      if (tie) return cells_reason_ = "overlapping facets around an edge", void();
      // The wedge from wing a to the next wing b (increasing angle) lies on
      // the side Orient3d(u, v, q_a, .) > 0 of a and < 0 of b.
      auto facing = [&](const Wing& x, int toward) {
        const uint32_t f = pieces_[x.piece].facet;
        return toward * facet_sigma_[f] * geom::Orient3d(u, v, PV(x.q), AbovePlane(facets_[f]));
      };
      for (size_t k = 0; k < order.size(); ++k) {
        const Wing& a = *w[order[k]];
        const Wing& b = *w[order[(k + 1) % order.size()]];
        const int sa = facing(a, 1), sb = facing(b, -1);
        if (sa == 0 || sb == 0) return cells_reason_ = "a degenerate wing", void();
        unite(node(a.piece, sa), node(b.piece, sb));
      }
    }
    // Shells.
    node_shell_.assign(2 * np, kNone);
    for (uint32_t p = 0; p < np; ++p) {
      for (uint32_t nd : {node(p, 1), node(p, -1)}) {
        const uint32_t root = Find(uf, nd);
        if (node_shell_[root] == kNone) {
          node_shell_[root] = static_cast<uint32_t>(shell_nodes_.size());
          shell_nodes_.emplace_back();
        }
        node_shell_[nd] = node_shell_[root];
        shell_nodes_[node_shell_[nd]].push_back(nd);
      }
    }
    constexpr size_t kMaxShells = 256;
    if (shell_nodes_.size() > kMaxShells) return cells_reason_ = "more than 256 shells", void();
    const size_t ns = shell_nodes_.size();
    shell_volume_.assign(ns, 0);
    shell_cell_of_positive_.assign(ns, -1);
    for (size_t s = 0; s < ns; ++s) {
      bool fin_only = true;
      double vol = 0;
      for (uint32_t nd : shell_nodes_[s]) {
        const Piece& pc = pieces_[nd / 2];
        const int side = nd % 2 == 0 ? 1 : -1;
        fin_only = fin_only && node_shell_[nd ^ 1u] == s;
        const FacetGeom& fg = facets_[pc.facet];
        const Vec3 out = -(side * facet_sigma_[pc.facet]) * fg.plane.n;
        vol += pc.area * Dot(out, fg.plane.a - cell_origin_) / 3.0;
      }
      shell_volume_[s] = fin_only ? 0 : vol;
      if (!fin_only && vol > 0) {
        shell_cell_of_positive_[s] = num_bounded_cells_++;
        cell_outer_volume_.push_back(vol);
      }
    }
    cell_volume_ = cell_outer_volume_;
    cell_volume_.push_back(0);  // the unbounded cell, id num_bounded_cells_
    node_cell_.assign(2 * np, -1);
    for (size_t s = 0; s < ns; ++s) {
      int32_t cell = shell_cell_of_positive_[s];
      if (cell < 0) {
        // An inner shell: the cell on its side of one of its pieces.
        const uint32_t nd = shell_nodes_[s][0];
        Vec3 x;
        if (!PieceInteriorPoint(pieces_[nd / 2], &x)) {
          return cells_reason_ = "a facet piece without an interior point", void();
        }
        cell = LocateCell(x, nd / 2);
        if (cell < 0) return cells_reason_ = "an inner shell touching another shell", void();
        if (cell < num_bounded_cells_) cell_volume_[cell] += shell_volume_[s];
      }
      for (uint32_t nd : shell_nodes_[s]) node_cell_[nd] = cell;
    }
    for (int32_t c = 0; c < num_bounded_cells_; ++c) {
      if (!(cell_volume_[c] > 0)) return cells_reason_ = "a cell of non-positive volume", void();
    }
    cell_hole_.assign(num_bounded_cells_ + 1, 0);
    cell_hole_[num_bounded_cells_] = 1;  // the unbounded cell is never meshed
    for (const Vec3& h : plc_->holes) {
      const int32_t c = LocateCell(h);
      if (c < 0) return cells_reason_ = "a hole seed on a facet", void();
      cell_hole_[c] = 1;
    }
    double total = 0;
    for (int32_t c = 0; c < num_bounded_cells_; ++c) total += cell_hole_[c] ? 0 : cell_volume_[c];
    rep_->enclosed_volume = total;
    rep_->enclosed_volume_known = true;
    cells_known_ = true;
  }

  // Region by region (cell by cell): the tets in each cell must fill it
  // exactly once (meshed cells) or not at all (holes, the unbounded cell).
  // Tets are grouped into components by flooding across faces shared by two
  // tets and lying on no facet; a component lies in one cell (no tet crosses
  // a facet), located by the centroid of one of its tets.
  // False when some component could not be located (nothing reported).
  bool CheckCellCoverage() {
    const size_t nt = mesh_.tets.size();
    std::vector<uint32_t> uf(nt);
    std::iota(uf.begin(), uf.end(), 0u);
    // Vertices on some facet plane (within a facet's box): only faces with
    // three such vertices can lie on a facet.
    std::vector<uint8_t> on_plane(mesh_.positions.size(), 0);
    for (size_t v = 0; v < mesh_.positions.size(); ++v) {
      Box3 q;
      q.Add(P(static_cast<uint32_t>(v)));
      facet_grid_->Query(q, [&](uint32_t f) {
        if (!on_plane[v] && facets_[f].valid &&
            SideOf(facets_[f].plane, P(static_cast<uint32_t>(v)), facets_[f].tol) == 0) {
          on_plane[v] = 1;
        }
      });
    }
    for (size_t i = 0; i + 1 < faces_.size();) {
      size_t j = i;
      while (j < faces_.size() && faces_[j].SameKey(faces_[i])) ++j;
      if (j - i == 2) {
        const auto& k = faces_[i].key;
        bool on_facet = false;
        if (on_plane[k[0]] && on_plane[k[1]] && on_plane[k[2]]) {
          ForFacetsContaining(P(k[0]), P(k[1]), P(k[2]), [&](uint32_t) { on_facet = true; });
        }
        if (!on_facet) uf[Find(uf, faces_[i].tet)] = Find(uf, faces_[i + 1].tet);
      }
      i = j;
    }
    std::vector<int32_t> comp_cell(nt, -1);  // by root
    std::vector<uint8_t> tries(nt, 0);
    for (size_t t = 0; t < nt; ++t) {
      if (!tet_ok_[t]) continue;
      const uint32_t r = Find(uf, static_cast<uint32_t>(t));
      const auto& q = mesh_.tets[t];
      if (comp_cell[r] < 0 && tries[r] < 8) {
        ++tries[r];
        comp_cell[r] = LocateCell((P(q[0]) + P(q[1]) + P(q[2]) + P(q[3])) / 4.0);
      }
    }
    std::vector<double> cell_mesh(num_bounded_cells_ + 1, 0);
    const Vec3 o = mesh_box_.Center();
    size_t unlocated = 0;
    for (size_t t = 0; t < nt; ++t) {
      if (!tet_ok_[t]) continue;
      const auto& q = mesh_.tets[t];
      const int32_t c = comp_cell[Find(uf, static_cast<uint32_t>(t))];
      const Vec3 a = P(q[0]) - o;
      const double vol = Dot((P(q[1]) - o) - a, Cross((P(q[2]) - o) - a, (P(q[3]) - o) - a)) / 6.0;
      if (c < 0) {
        ++unlocated;
        continue;
      }
      cell_mesh[c] += vol;
    }
    if (unlocated > 0) {
      // Only near-degenerate components (every tried centroid within rounding
      // of a facet) get here; the global volume check still applies.
      rep_->cells_unknown_reason =
          absl::StrCat(unlocated, " tets in components that could not be located");
      return false;
    }
    const double scale = std::max(rep_->enclosed_volume, 1e-300);
    const double flatness_volume = FlatnessVolume();
    for (int32_t c = 0; c <= num_bounded_cells_; ++c) {
      const bool meshed = !cell_hole_[c];
      const double want = meshed ? cell_volume_[c] : 0;
      if (std::fabs(cell_mesh[c] - want) <= std::max(opt_.volume_rel_tol * std::max(want, scale), flatness_volume)) {
        continue;
      }
      std::string seeds;
      for (size_t r = 0; r < plc_->regions.size(); ++r) {
        if (LocateCell(plc_->regions[r].point) == c) absl::StrAppend(&seeds, " ", r);
      }
      const std::string what =
          c == num_bounded_cells_ ? std::string("the unbounded cell")
                                  : absl::StrCat("cell ", c, cell_hole_[c] ? " (a volume hole)" : "",
                                                 seeds.empty() ? "" : " with region seed(s)" + seeds);
      Add(rep_, opt_, ViolationKind::kVolumeMismatch, {c},
          absl::StrFormat("%s: tets in it have volume %.17g, expected %.17g (%s)", what,
                          cell_mesh[c], want,
                          cell_mesh[c] > want ? "covered more than once or outside the domain"
                                              : "not filled"));
    }
    return true;
  }

  void CheckInputVertices() {
    const size_t nv = mesh_.positions.size();
    std::vector<uint32_t> order(nv);
    std::iota(order.begin(), order.end(), 0u);
    auto less = [](const Vec3& a, const Vec3& b) {
      return a.x != b.x ? a.x < b.x : (a.y != b.y ? a.y < b.y : a.z < b.z);
    };
    std::sort(order.begin(), order.end(), [&](uint32_t i, uint32_t j) {
      return less(P(i), P(j)) || (P(i) == P(j) && i < j);
    });
    std::vector<uint8_t> used(nv, 0);
    for (size_t t = 0; t < mesh_.tets.size(); ++t) {
      if (!tet_ok_[t]) continue;
      for (uint32_t v : mesh_.tets[t]) used[v] = 1;
    }
    input_map_.assign(plc_->vertices.size(), kNone);
    for (size_t i = 0; i < plc_->vertices.size(); ++i) {
      const Vec3& p = plc_->vertices[i];
      if (opt_.input_vertices_first && i < nv && P(static_cast<uint32_t>(i)) == p) {
        input_map_[i] = static_cast<uint32_t>(i);
        continue;
      }
      auto it = std::lower_bound(order.begin(), order.end(), p,
                                 [&](uint32_t v, const Vec3& q) { return less(P(v), q); });
      // Several mesh vertices at p (e.g. a duplicated input vertex kept at
      // both ids): the segment walk needs the one the tets use.
      for (auto jt = it; jt != order.end() && P(*jt) == p; ++jt) {
        if (used[*jt]) {
          it = jt;
          break;
        }
      }
      if (it == order.end() || !(P(*it) == p)) {
        Add(rep_, opt_, ViolationKind::kMissingInputVertex, {static_cast<int64_t>(i)},
            absl::StrFormat("input vertex %d (%.17g, %.17g, %.17g) is not a mesh vertex", i, p.x,
                            p.y, p.z));
        continue;
      }
      input_map_[i] = *it;
      if (opt_.input_vertices_first) {
        Add(rep_, opt_, ViolationKind::kInputVertexIndex, {static_cast<int64_t>(i), *it},
            absl::StrCat("input vertex ", i, " is mesh vertex ", *it, ", expected ", i));
      }
    }
  }

  // Vertex -> neighbour lists of the mesh edges (CSR).
  void BuildEdges() {
    // Undirected edges packed as (min << 32 | max): integer sort, then CSR.
    std::vector<uint64_t> e;
    e.reserve(6 * mesh_.tets.size());
    for (size_t t = 0; t < mesh_.tets.size(); ++t) {
      if (!tet_ok_[t]) continue;
      const auto& q = mesh_.tets[t];
      for (int i = 0; i < 4; ++i) {
        for (int j = i + 1; j < 4; ++j) {
          const uint64_t a = std::min(q[i], q[j]), b = std::max(q[i], q[j]);
          e.push_back(a << 32 | b);
        }
      }
    }
    std::sort(e.begin(), e.end());
    e.erase(std::unique(e.begin(), e.end()), e.end());
    adj_start_.assign(mesh_.positions.size() + 1, 0);
    for (uint64_t x : e) {
      ++adj_start_[(x >> 32) + 1];
      ++adj_start_[(x & 0xffffffffu) + 1];
    }
    std::partial_sum(adj_start_.begin(), adj_start_.end(), adj_start_.begin());
    adj_.resize(2 * e.size());
    std::vector<uint32_t> fill(adj_start_.begin(), adj_start_.end() - 1);
    for (uint64_t x : e) {
      const uint32_t a = static_cast<uint32_t>(x >> 32), b = static_cast<uint32_t>(x);
      adj_[fill[a]++] = b;
      adj_[fill[b]++] = a;
    }
  }

  // p lies on the line ab: exactly (all three projections collinear) or within tol.
  bool OnLine(const Vec3& a, const Vec3& b, const Vec3& p) const {
    if (geom::Orient2dProjected(a, b, p, 0) == 0 && geom::Orient2dProjected(a, b, p, 1) == 0 &&
        geom::Orient2dProjected(a, b, p, 2) == 0) {
      return true;
    }
    const Vec3 d = b - a;
    const double dist = Norm(Cross(d, p - a)) / Norm(d);
    return dist <= tol_;
  }

  void CheckSegments() {
    const auto segs = ConformitySegments(*plc_);
    BuildEdges();
    rep_->num_segments_checked = segs.size();
    for (size_t s = 0; s < segs.size(); ++s) {
      if (segs[s][0] >= input_map_.size() || segs[s][1] >= input_map_.size()) continue;
      const uint32_t va = input_map_[segs[s][0]], vb = input_map_[segs[s][1]];
      if (va == kNone || vb == kNone) continue;  // already reported
      const Vec3 a = P(va), b = P(vb), d = b - a;
      const double len2 = Dot(d, d);
      uint32_t cur = va;
      double cur_t = 0;
      for (size_t steps = 0; cur != vb && steps <= mesh_.positions.size(); ++steps) {
        // The next chain vertex: the neighbour on the segment that advances
        // least beyond the current one (exactly one on a conforming mesh).
        uint32_t next = kNone;
        double next_t = 0;
        for (uint32_t k = adj_start_[cur]; k < adj_start_[cur + 1]; ++k) {
          const uint32_t w = adj_[k];
          const double t = Dot(P(w) - a, d) / len2;
          if (!(t > cur_t) || t > 1 + 1e-12) continue;
          if (w != vb && !OnLine(a, b, P(w))) continue;
          if (next == kNone || t < next_t) next = w, next_t = t;
        }
        if (next == kNone) break;
        cur = next;
        cur_t = next_t;
      }
      if (cur != vb) {
        Add(rep_, opt_, ViolationKind::kBrokenSegment, {static_cast<int64_t>(s), cur},
            absl::StrCat("segment ", s, " (input vertices ", segs[s][0], " ", segs[s][1],
                         ") is not a chain of mesh edges: the walk stops at mesh vertex ", cur));
      }
    }
  }

  void CheckFacetCoverage() {
    std::vector<double> covered(facets_.size(), 0);
    for (size_t t = 0; t < mesh_.triangles.size(); ++t) {
      if (!tri_ok_[t]) continue;
      const auto& k = mesh_.triangles[t];
      const Vec3 &a = P(k[0]), &b = P(k[1]), &c = P(k[2]);
      const double area = 0.5 * Norm(Cross(b - a, c - a));
      bool found = false, marker_ok = false;
      uint32_t first = kNone;
      const bool has_marker = mesh_.triangle_marker.size() == mesh_.triangles.size();
      ForFacetsContaining(a, b, c, [&](uint32_t f) {
        found = true;
        if (first == kNone) first = f;
        covered[f] += area;
        marker_ok = marker_ok || !has_marker || mesh_.triangle_marker[t] == facets_[f].marker;
      });
      if (!found) {
        Add(rep_, opt_, ViolationKind::kTriangleOffFacet, {static_cast<int64_t>(t)},
            absl::StrCat("triangle ", t, " (", k[0], " ", k[1], " ", k[2],
                         ") lies on no input facet"));
      } else if (opt_.check_markers && !marker_ok) {
        Add(rep_, opt_, ViolationKind::kWrongMarker, {static_cast<int64_t>(t), first},
            absl::StrCat("triangle ", t, " has marker ", mesh_.triangle_marker[t], ", facet ",
                         first, " has marker ", facets_[first].marker));
      }
    }
    for (size_t f = 0; f < facets_.size(); ++f) {
      if (!facets_[f].valid) continue;
      // Outside the domain: with cells, every piece with unmeshed cells on
      // both sides (e.g. between a volume hole and the exterior: TetGen and
      // we drop it); without, a facet no tet touches.
      double want = facets_[f].area;
      if (cells_known_ && !facet_pieces_[f].empty()) {
        double inside_area = 0;
        size_t out = 0;
        for (uint32_t p : facet_pieces_[f]) {
          if (cell_hole_[node_cell_[2 * p]] && cell_hole_[node_cell_[2 * p + 1]]) {
            ++out;
          } else {
            inside_area += pieces_[p].area;
          }
        }
        if (out == facet_pieces_[f].size()) {
          ++rep_->num_facets_outside;
          continue;
        }
        if (out > 0) {
          ++rep_->num_facets_partly_outside;
          want = inside_area;
        }
      } else if (!cells_known_ && covered[f] == 0 && !facet_crossed_[f] && !AnyTetFaceOn(f)) {
        ++rep_->num_facets_outside;
        continue;
      }
      // Mesh vertices on the facet's boundary are on it within its tolerance
      // (FacetGeom::tol), so the covered area may differ from the
      // facet's by up to its perimeter times that without a gap; far from
      // the origin that exceeds area_rel_tol (random_plcs.py hull+far 2: a
      // facet of area 2.2e-7 at coordinates ~1.2e4, 3.0e-16 short = 1.3e-9 of
      // it, with tol_ = 2.1e-11 and a perimeter of 2.6e-3).
      if (std::fabs(covered[f] - want) > std::max(opt_.area_rel_tol * want, facets_[f].perimeter * facets_[f].tol)) {
        Add(rep_, opt_, ViolationKind::kFacetNotCovered, {static_cast<int64_t>(f)},
            absl::StrFormat("facet %d: mesh triangles on it cover area %.17g, facet area %.17g", f,
                            covered[f], want));
      }
    }
  }

  const BoxGrid& TetGrid() {
    if (tet_grid_ == nullptr) {
      tet_grid_ = std::make_unique<BoxGrid>(mesh_box_, mesh_.tets.size(), 4, 128, [&](size_t t) {
        Box3 b;
        if (tet_ok_[t]) {
          for (uint32_t v : mesh_.tets[t]) b.Add(P(v));
        }
        return b;
      });
    }
    return *tet_grid_;
  }

  // True when some face of some tet lies on facet f (vertices on its plane,
  // centroid in its region).
  bool AnyTetFaceOn(size_t f) {
    if (mesh_box_.Empty() || mesh_.tets.empty()) return false;
    const FacetGeom& fg = facets_[f];
    bool found = false;
    TetGrid().Query(Expand(fg.box, fg.tol), [&](uint32_t t) {
      if (found || !tet_ok_[t]) return;
      const auto& q = mesh_.tets[t];
      int on = 0;
      for (int i = 0; i < 4; ++i) on += SideOf(fg.plane, P(q[i]), fg.tol) == 0 ? 1 : 0;
      if (on < 3) return;
      for (const auto& face : kFace) {
        const Vec3 &a = P(q[face[0]]), &b = P(q[face[1]]), &c = P(q[face[2]]);
        if (SideOf(fg.plane, a, fg.tol) == 0 && SideOf(fg.plane, b, fg.tol) == 0 &&
            SideOf(fg.plane, c, fg.tol) == 0 && InFacetRegion(fg, (a + b + c) / 3.0)) {
          found = true;
          return;
        }
      }
    });
    return found;
  }

  // ------------------------------------------------------------ crossings
  //
  // docs/conformity.md "Crossings". A tet crosses facet f when its interior
  // meets the relative interior of f's region. The region is triangulated
  // (TriangulateRegion); a tet with vertices strictly on both sides of f's
  // plane crosses f iff its interior meets the interior of one of those
  // triangles. Both are convex and the triangle lies in the plane, so they
  // are disjoint iff a separating axis exists among (a) the edge lines of the
  // triangle, tested on the tet's cross-section S with the plane, and (b) the
  // tet's face planes (whose traces are S's edges) — the separating axis
  // theorem for two convex polygons in the plane. Every sign is exact:
  //   * S's vertices are the tet vertices on the plane ("O", with the
  //     tolerance) and the crossing points x_ab of the tet edges ab whose
  //     ends are strictly on either side ("X"). x_ab is never constructed:
  //     its side of a line pq in the plane is the Plücker sign
  //     -Orient3d(p, q, a, b) * sign(N[axis]) (a on the positive side, N the
  //     plane's normal), exact when p, q lie on the plane.
  //   * an O vertex's side of pq is Orient2dProjected; a triangle vertex's
  //     side of a tet face plane is Orient3d.
  // The slanted-feature tolerance: an O vertex within tol of the line pq, or
  // a triangle vertex within tol of a face plane, counts as on it (both can
  // only be off by the rounding of Steiner points on slanted features).

  struct RegionMesh {
    int state = 0;  // 0: not built, 1: built, -1: not triangulable
    std::vector<std::array<uint32_t, 3>> tris;
    std::vector<int8_t> orient;  // Orient2dProjected of each triangle
    std::vector<Box3> boxes;     // expanded by tol
    std::unique_ptr<BoxGrid> grid;
    std::vector<uint32_t> stamp;
    uint32_t query = 0;
  };

  RegionMesh& Region(size_t f) {
    RegionMesh& rm = region_[f];
    if (rm.state != 0) return rm;
    const FacetGeom& fg = facets_[f];
    rm.state = -1;
    std::vector<std::array<uint32_t, 3>> tris;
    if (!TriangulateRegion(plc_->vertices, fg, &tris)) return rm;
    const std::vector<Vec3>& pv = plc_->vertices;
    for (const auto& t : tris) {
      const int o = geom::Orient2dProjected(pv[t[0]], pv[t[1]], pv[t[2]], fg.plane.axis);
      if (o == 0) continue;  // no interior
      Box3 b;
      for (uint32_t v : t) b.Add(pv[v]);
      rm.tris.push_back(t);
      rm.orient.push_back(static_cast<int8_t>(o));
      rm.boxes.push_back(Expand(b, fg.tol));
    }
    if (rm.tris.size() > 16) {
      rm.grid = std::make_unique<BoxGrid>(Expand(fg.box, fg.tol), rm.tris.size(), 2, 64,
                                          [&](size_t i) { return rm.boxes[i]; });
      rm.stamp.assign(rm.tris.size(), kNone);
    }
    rm.state = 1;
    return rm;
  }

  static double DistToLine(const Vec3& a, const Vec3& b, const Vec3& p) {
    const Vec3 d = b - a;
    return Norm(Cross(d, p - a)) / Norm(d);
  }
  static double DistToPlane(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p) {
    const Vec3 n = Cross(b - a, c - a);
    return std::fabs(Dot(n, p - a)) / Norm(n);
  }

  // A vertex of the cross-section: tet vertex i on the plane (j < 0), or the
  // crossing point of the tet edge from vertex i (positive side) to vertex j
  // (negative side).
  struct SectionPoint {
    int i, j;
  };

  // Side (+1 left, -1 right, 0 on) of section point s of tet q with respect
  // to the line p->r of facet plane pl, in the projection dropping pl.axis;
  // nsign = sign of the plane normal's axis component.
  int SectionSide(const std::array<uint32_t, 4>& q, const SectionPoint& s, const Vec3& p,
                  const Vec3& r, int axis, int nsign, double tol) const {
    if (s.j < 0) {
      const Vec3& o = P(q[s.i]);
      const int side = geom::Orient2dProjected(p, r, o, axis);
      if (side != 0 && tol > 0 && DistToLine(p, r, o) <= tol) return 0;
      return side;
    }
    return -geom::Orient3d(p, r, P(q[s.i]), P(q[s.j])) * nsign;
  }

  bool TetCrossesRegion(const FacetGeom& fg, RegionMesh& rm, const std::array<uint32_t, 4>& q,
                        const int side[4], int nsign) {
    const int st = geom::Orient3d(P(q[0]), P(q[1]), P(q[2]), P(q[3]));
    if (st == 0) return false;  // no interior (reported as degenerate)
    // Faces in kFace order have the opposite vertex on the side -st.
    const int inner = -st;
    SectionPoint sec[4];
    int ns = 0;
    for (int i = 0; i < 4; ++i) {
      if (side[i] == 0) sec[ns++] = {i, -1};
    }
    for (int i = 0; i < 4; ++i) {
      for (int j = 0; j < 4; ++j) {
        if (side[i] > 0 && side[j] < 0) sec[ns++] = {i, j};
      }
    }
    Box3 tb;
    for (uint32_t v : q) tb.Add(P(v));
    const std::vector<Vec3>& pv = plc_->vertices;
    const int axis = fg.plane.axis;
    auto separated = [&](size_t k) {
      const auto& t = rm.tris[k];
      // (a) an edge line of the triangle, S on its closed outer side.
      for (int e = 0; e < 3; ++e) {
        const Vec3 &a = pv[t[e]], &b = pv[t[(e + 1) % 3]];
        bool out = true;
        for (int m = 0; m < ns && out; ++m) {
          out = SectionSide(q, sec[m], a, b, axis, nsign, fg.tol) * rm.orient[k] <= 0;
        }
        if (out) return true;
      }
      // (b) a face plane of the tet, the triangle on its closed outer side.
      for (const auto& face : kFace) {
        const Vec3 &a = P(q[face[0]]), &b = P(q[face[1]]), &c = P(q[face[2]]);
        bool out = true;
        for (int m = 0; m < 3 && out; ++m) {
          const Vec3& x = pv[t[m]];
          const int o = geom::Orient3d(a, b, c, x);
          out = o != inner || (fg.tol > 0 && DistToPlane(a, b, c, x) <= fg.tol);
        }
        if (out) return true;
      }
      return false;
    };
    auto overlaps = [&](size_t k) {
      const Box3& b = rm.boxes[k];
      for (int a = 0; a < 3; ++a) {
        if (b.hi[a] < tb.lo[a] || tb.hi[a] < b.lo[a]) return false;
      }
      return true;
    };
    if (rm.grid == nullptr) {
      for (size_t k = 0; k < rm.tris.size(); ++k) {
        if (overlaps(k) && !separated(k)) return true;
      }
      return false;
    }
    bool crosses = false;
    ++rm.query;
    rm.grid->Query(tb, [&](uint32_t k) {
      if (crosses || rm.stamp[k] == rm.query) return;
      rm.stamp[k] = rm.query;
      if (overlaps(k) && !separated(k)) crosses = true;
    });
    return crosses;
  }

  // Fallback for a facet whose polygons cannot be triangulated (not a valid
  // PLC facet): the cross-section in floating point, clipped against every
  // outer/hole polygon; crossing when the overlap exceeds 1e-9 x the
  // section's area. Returns the overlap area (0 when not crossing).
  double CrossingAreaByClipping(const FacetGeom& fg, const std::vector<std::vector<P2>>& loops2,
                                const std::array<uint32_t, 4>& q, const int side[4]) const {
    const int axis = fg.plane.axis;
    std::vector<P2> sec;
    for (int i = 0; i < 4; ++i) {
      if (side[i] == 0) sec.push_back({U(P(q[i]), axis), V(P(q[i]), axis)});
    }
    for (int i = 0; i < 4; ++i) {
      for (int j = i + 1; j < 4; ++j) {
        if (side[i] * side[j] >= 0) continue;
        const Vec3 &pi = P(q[i]), &pj = P(q[j]);
        const double di = Dot(fg.plane.n, pi - fg.plane.a);
        const double dj = Dot(fg.plane.n, pj - fg.plane.a);
        const double s = di / (di - dj);
        const Vec3 x = pi + s * (pj - pi);
        sec.push_back({U(x, axis), V(x, axis)});
      }
    }
    if (sec.size() < 3) return 0;
    // Order counter-clockwise around the centroid (convex, <= 4 points).
    P2 c{0, 0};
    for (const P2& p : sec) c = {c[0] + p[0] / sec.size(), c[1] + p[1] / sec.size()};
    std::sort(sec.begin(), sec.end(), [&](const P2& x, const P2& y) {
      return std::atan2(x[1] - c[1], x[0] - c[0]) < std::atan2(y[1] - c[1], y[0] - c[0]);
    });
    const double sec_area = std::fabs(SignedArea2(sec));
    if (sec_area == 0) return 0;
    double overlap = 0;
    for (size_t l = 0; l < fg.loops.size(); ++l) {
      const Loop& lp = fg.loops[l];
      if (lp.hole == lp.outer) continue;  // subdivision, or an outer loop removed
      const double a = std::fabs(SignedArea2(ClipConvex(loops2[l], sec)));
      overlap += lp.outer ? a : -a;
    }
    return overlap > 1e-9 * sec_area ? overlap / std::fabs(fg.plane.n[axis]) : 0;
  }

  void CheckCrossings() {
    facet_crossed_.assign(facets_.size(), 0);
    if (mesh_box_.Empty() || mesh_.tets.empty()) return;
    const BoxGrid& tet_grid = TetGrid();
    std::vector<uint32_t> stamp(mesh_.tets.size(), kNone);
    for (size_t f = 0; f < facets_.size(); ++f) {
      const FacetGeom& fg = facets_[f];
      if (!fg.valid || fg.area == 0) continue;
      const int axis = fg.plane.axis;
      const int nsign = geom::Orient2dProjected(fg.plane.a, fg.plane.b, fg.plane.c, axis);
      RegionMesh* rm = nullptr;  // built on the first candidate tet
      std::vector<std::vector<P2>> loops2;  // for the fallback only
      tet_grid.Query(Expand(fg.box, fg.tol), [&](uint32_t t) {
        if (stamp[t] == f) return;
        stamp[t] = static_cast<uint32_t>(f);
        const auto& q = mesh_.tets[t];
        int side[4];
        bool pos = false, neg = false;
        for (int i = 0; i < 4; ++i) {
          side[i] = SideOf(fg.plane, P(q[i]), fg.tol);
          pos = pos || side[i] > 0;
          neg = neg || side[i] < 0;
        }
        if (!pos || !neg) return;
        if (rm == nullptr) rm = &Region(f);
        std::string how;
        if (rm->state == 1 && nsign != 0) {
          if (!TetCrossesRegion(fg, *rm, q, side, nsign)) return;
        } else {
          if (loops2.empty()) {
            loops2.resize(fg.loops.size());
            for (size_t l = 0; l < fg.loops.size(); ++l) {
              for (const Vec3& p : fg.loops[l].pts) loops2[l].push_back({U(p, axis), V(p, axis)});
            }
          }
          const double area = CrossingAreaByClipping(fg, loops2, q, side);
          if (area == 0) return;
          how = absl::StrFormat(" (facet not triangulable: floating-point overlap area %.3g)", area);
        }
        facet_crossed_[f] = 1;
        Add(rep_, opt_, ViolationKind::kTetCrossesFacet, {t, static_cast<int64_t>(f)},
            absl::StrCat("tet ", t, " (", q[0], " ", q[1], " ", q[2], " ", q[3],
                         ") crosses facet ", f, how));
      });
    }
  }

  const plc::Plc* plc_;
  const TetMesh& mesh_;
  const ConformityOptions& opt_;
  ConformityReport* rep_;

  std::vector<uint8_t> tet_ok_, tri_ok_;
  std::vector<FaceRec> faces_;
  std::vector<size_t> open_faces_;
  Box3 mesh_box_;
  double tol_ = 0;
  std::vector<FacetGeom> facets_;
  std::unique_ptr<BoxGrid> facet_grid_;
  std::unique_ptr<BoxGrid> tet_grid_;
  std::vector<uint8_t> facet_crossed_;
  std::vector<RegionMesh> region_;  // per facet, for the crossing test
  std::vector<uint32_t> facet_stamp_;
  uint32_t query_ = 0;
  std::vector<uint32_t> input_map_;
  std::vector<uint32_t> first_;  // FirstOccurrences(plc vertices)
  std::vector<uint32_t> adj_start_, adj_;
  // Cells of the facet arrangement (BuildCells).
  bool cells_known_ = false;
  std::string cells_reason_;
  Vec3 cell_origin_;
  double cell_len_ = 1;
  std::vector<int> facet_sigma_;
  std::vector<Piece> pieces_;
  std::vector<std::vector<uint32_t>> facet_pieces_;
  std::vector<uint32_t> node_shell_;
  std::vector<std::vector<uint32_t>> shell_nodes_;
  std::vector<double> shell_volume_;
  std::vector<int32_t> shell_cell_of_positive_;
  int32_t num_bounded_cells_ = 0;
  std::vector<double> cell_outer_volume_, cell_volume_;
  std::vector<int32_t> node_cell_;
  std::vector<uint8_t> cell_hole_;
};

}  // namespace

ConformityCategory CategoryOf(ViolationKind kind) {
  if (kind <= ViolationKind::kDuplicateTriangle) return ConformityCategory::kValidity;
  if (kind <= ViolationKind::kVolumeMismatch) return ConformityCategory::kCoverage;
  return ConformityCategory::kConformity;
}

std::string_view KindName(ViolationKind kind) {
  switch (kind) {
    case ViolationKind::kIdOutOfRange: return "id_out_of_range";
    case ViolationKind::kFlippedTet: return "flipped_tet";
    case ViolationKind::kDegenerateTet: return "degenerate_tet";
    case ViolationKind::kFlatTet: return "flat_tet";
    case ViolationKind::kDuplicateTet: return "duplicate_tet";
    case ViolationKind::kFaceInMoreThanTwoTets: return "face_in_more_than_two_tets";
    case ViolationKind::kNeighborsSameSide: return "neighbors_same_side";
    case ViolationKind::kTagCountMismatch: return "tag_count_mismatch";
    case ViolationKind::kTriangleNotAFace: return "triangle_not_a_face";
    case ViolationKind::kDuplicateTriangle: return "duplicate_triangle";
    case ViolationKind::kOpenFace: return "open_face";
    case ViolationKind::kVolumeMismatch: return "volume_mismatch";
    case ViolationKind::kMissingInputVertex: return "missing_input_vertex";
    case ViolationKind::kInputVertexIndex: return "input_vertex_index";
    case ViolationKind::kBrokenSegment: return "broken_segment";
    case ViolationKind::kFacetNotCovered: return "facet_not_covered";
    case ViolationKind::kTriangleOffFacet: return "triangle_off_facet";
    case ViolationKind::kWrongMarker: return "wrong_marker";
    case ViolationKind::kTetCrossesFacet: return "tet_crosses_facet";
  }
  return "unknown";
}

std::string_view CategoryName(ConformityCategory category) {
  switch (category) {
    case ConformityCategory::kValidity: return "validity";
    case ConformityCategory::kCoverage: return "coverage";
    case ConformityCategory::kConformity: return "conformity";
  }
  return "unknown";
}

bool ConformityReport::ok() const {
  for (size_t c : counts) {
    if (c != 0) return false;
  }
  return true;
}

size_t ConformityReport::Count(ConformityCategory category) const {
  size_t n = 0;
  for (int k = 0; k < kNumViolationKinds; ++k) {
    if (CategoryOf(static_cast<ViolationKind>(k)) == category) n += counts[k];
  }
  return n;
}

std::string ConformityReport::Summary() const {
  std::string out;
  absl::StrAppendFormat(&out, "mesh volume %.17g, enclosed volume %s\n", mesh_volume,
                        enclosed_volume_known ? absl::StrFormat("%.17g", enclosed_volume)
                                              : std::string("unknown"));
  if (ok()) {
    absl::StrAppend(&out, "no violations\n");
    return out;
  }
  for (int k = 0; k < kNumViolationKinds; ++k) {
    if (counts[k] == 0) continue;
    const auto kind = static_cast<ViolationKind>(k);
    out += std::string(CategoryName(CategoryOf(kind))) + "/" + std::string(KindName(kind)) + ": " +
           std::to_string(counts[k]) + "\n";
  }
  for (const Violation& v : violations) absl::StrAppend(&out, "  ", v.message, "\n");
  return out;
}

std::vector<std::array<uint32_t, 2>> ConformitySegments(const plc::Plc& plc) {
  std::vector<std::array<uint32_t, 2>> out;
  std::set<std::array<uint32_t, 2>> seen;
  const std::vector<uint32_t> first = FirstOccurrences(plc.vertices);
  auto add = [&](uint32_t a, uint32_t b) {
    if (a < first.size()) a = first[a];
    if (b < first.size()) b = first[b];
    if (a == b) return;
    if (seen.insert({std::min(a, b), std::max(a, b)}).second) out.push_back({a, b});
  };
  for (const auto& s : plc.segments) add(s.a, s.b);
  for (const auto& f : plc.facets) {
    for (const auto& p : f.polygons) {
      const size_t n = p.vertices.size();
      if (n == 2) {
        add(p.vertices[0], p.vertices[1]);
      } else if (n >= 3) {
        for (size_t i = 0; i < n; ++i) add(p.vertices[i], p.vertices[(i + 1) % n]);
      }
    }
  }
  return out;
}

double OnFeatureTolerance(std::span<const geom::Vec3> points, double tolerance_ulps) {
  double scale = 0;
  for (const geom::Vec3& p : points) scale = std::max({scale, std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
  return tolerance_ulps * kEps52 * scale;
}

ConformityReport CheckConformity(const plc::Plc& plc, const TetMesh& mesh,
                                 const ConformityOptions& options) {
  ConformityReport report;
  Checker(&plc, mesh, options, &report).Run();
  return report;
}

ConformityReport CheckValidity(const TetMesh& mesh, const ConformityOptions& options) {
  ConformityReport report;
  Checker(nullptr, mesh, options, &report).Run();
  return report;
}

}  // namespace svrc::mesh
