// Facet meshes M_F (thesis §3.1, Definition 35; guide §5 item 4).
#include "core/svrc/facet_mesh.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "core/geometry/predicates.h"
#include "core/util/grow.h"

namespace svrc::refine {

using geom::Vec2;
using Delaunay2 = delaunay::Delaunay2;

namespace {

// Ω_F's corners: centre of the uv box ± 1.5·diam (side 3·diam(F)).
std::pair<Vec2, Vec2> SquareOf(const FacetRegion& r) {
  const Vec2 c = 0.5 * (r.lo + r.hi);
  const Vec2 d = r.hi - r.lo;
  double half = 1.5 * std::sqrt(geom::Norm2(d));
  if (!(half > 0)) half = 1.0;  // a degenerate facet cannot pass validation; stay finite
  return {Vec2{c.x - half, c.y - half}, Vec2{c.x + half, c.y + half}};
}

double Dist2(Vec2 a, Vec2 b) { return geom::Norm2(a - b); }

}  // namespace

void FacetRegion::AddLoop(std::vector<Vec2> uv, std::vector<PointId> points, bool is_hole) {
  Loop l;
  double area = 0;
  const size_t n = uv.size();
  for (size_t i = 0; i < n; ++i) {
    const Vec2 a = uv[i], b = uv[(i + 1) % n];
    area += a.x * b.y - a.y * b.x;
    if (loops.empty() && i == 0 && lo.x == 0 && hi.x == 0 && lo.y == 0 && hi.y == 0) {
      lo = hi = a;
    }
    lo = {std::fmin(lo.x, a.x), std::fmin(lo.y, a.y)};
    hi = {std::fmax(hi.x, a.x), std::fmax(hi.y, a.y)};
  }
  l.uv = std::move(uv);
  l.points = std::move(points);
  l.is_hole = is_hole;
  l.abs_area = 0.5 * std::fabs(area);
  loops.push_back(std::move(l));
}

void FacetRegion::CollectPoints() {
  std::vector<std::pair<uint32_t, Vec2>> pts;
  for (const Loop& l : loops) {
    for (size_t i = 0; i < l.uv.size(); ++i) pts.push_back({l.points[i].value(), l.uv[i]});
  }
  for (size_t i = 0; i < segments.size(); ++i) {
    for (int k = 0; k < 2; ++k) pts.push_back({segment_points[i][k].value(), segments[i][k]});
  }
  for (size_t i = 0; i < interior_uv.size(); ++i) {
    pts.push_back({interior_points[i].value(), interior_uv[i]});
  }
  std::sort(pts.begin(), pts.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  all_uv.clear();
  all_points.clear();
  for (size_t i = 0; i < pts.size(); ++i) {
    if (i > 0 && pts[i].first == pts[i - 1].first) continue;
    all_points.push_back(PointId(pts[i].first));
    all_uv.push_back(pts[i].second);
  }
}

FacetRegion::Where FacetRegion::Locate(Vec2 p) const {
  // Crossing number along the ray from p towards +x, half-open in y; each
  // "edge right of p" decision is an exact Orient2d sign.
  const Loop* innermost = nullptr;
  for (const Loop& l : loops) {
    const size_t n = l.uv.size();
    bool inside = false;
    for (size_t i = 0; i < n; ++i) {
      const Vec2 a = l.uv[i], b = l.uv[(i + 1) % n];
      const int o = geom::Orient2d(a, b, p);
      if (o == 0 && std::fmin(a.x, b.x) <= p.x && p.x <= std::fmax(a.x, b.x) &&
          std::fmin(a.y, b.y) <= p.y && p.y <= std::fmax(a.y, b.y)) {
        return Where::kOnBoundary;
      }
      if ((a.y > p.y) != (b.y > p.y)) {
        // Upward edge (b above): crosses the ray iff p is left of a→b.
        if (b.y > a.y ? o > 0 : o < 0) inside = !inside;
      }
    }
    if (inside && (innermost == nullptr || l.abs_area < innermost->abs_area)) innermost = &l;
  }
  if (innermost == nullptr || innermost->is_hole) return Where::kOutside;
  return Where::kInside;
}

namespace internal {
bool TriangleMeetsSegmentBySides(Vec2 a, Vec2 b, Vec2 c, Vec2 s0, Vec2 s1) {
  const std::array<Vec2, 3> t = {a, b, c};
  // Triangle edge lines (abc counter-clockwise: interior is left, > 0).
  for (int e = 0; e < 3; ++e) {
    const Vec2 u = t[e], w = t[(e + 1) % 3];
    if (geom::Orient2d(u, w, s0) <= 0 && geom::Orient2d(u, w, s1) <= 0) return false;
  }
  // The segment's line: the open triangle is on one side iff all three
  // vertices are on one closed side (not all zero: abc is not degenerate).
  int pos = 0, neg = 0;
  for (const Vec2& x : t) {
    const int o = geom::Orient2d(s0, s1, x);
    pos += o > 0;
    neg += o < 0;
  }
  return pos != 0 && neg != 0;
}
}  // namespace internal

bool TriangleMeetsSegment(Vec2 a, Vec2 b, Vec2 c, Vec2 s0, Vec2 s1) {
  // Disjoint bounding boxes: the closed triangle and segment are disjoint,
  // and then a line through an edge of one of them separates them (convex
  // polygons), so the side tests return false too. Without predicates: on
  // cube --max-volume 1e-4 most triangles outside F are far from most of its
  // segments.
  if (std::max({a.x, b.x, c.x}) < std::min(s0.x, s1.x) || std::min({a.x, b.x, c.x}) > std::max(s0.x, s1.x) ||
      std::max({a.y, b.y, c.y}) < std::min(s0.y, s1.y) || std::min({a.y, b.y, c.y}) > std::max(s0.y, s1.y)) {
    return false;
  }
  return internal::TriangleMeetsSegmentBySides(a, b, c, s0, s1);
}

bool FacetRegion::CrossesSegment(Vec2 a, Vec2 b, Vec2 c) const {
  for (const auto& s : segments) {
    if (TriangleMeetsSegment(a, b, c, s[0], s[1])) return true;
  }
  return false;
}

bool FacetRegion::TriangleInFacet(Vec2 a, Vec2 b, Vec2 c) const {
  const Vec2 centroid{(a.x + b.x + c.x) / 3.0, (a.y + b.y + c.y) / 3.0};
  if (Locate(centroid) == Where::kInside) return true;
  return CrossesSegment(a, b, c);
}

FacetRegion BuildFacetRegion(const plc::FeatureComplex& complex, uint32_t facet,
                             const Normalization& norm, std::span<const PointId> point_ids,
                             plc::FacetFrame* normalised_frame) {
  const plc::FeatureFacet& f = complex.facets[facet];
  plc::FacetFrame frame = f.frame;
  frame.origin = norm.Forward(f.frame.origin);
  // The same point always gets the same uv (projected once per facet).
  auto uv_of = [&](plc::PointId p) { return frame.ToPlane(norm.Forward(complex.points[p].p)); };
  FacetRegion r;
  for (size_t i = 0; i < f.loops.size(); ++i) {
    std::vector<Vec2> uv;
    std::vector<PointId> ids;
    for (plc::PointId p : f.loops[i]) {
      uv.push_back(uv_of(p));
      ids.push_back(point_ids[p]);
    }
    r.AddLoop(std::move(uv), std::move(ids), f.loop_is_hole[i]);
  }
  for (plc::SegmentId s : f.segments) {
    const plc::FeatureSegment& seg = complex.segments[s];
    r.segments.push_back({uv_of(seg.a), uv_of(seg.b)});
    r.segment_points.push_back({point_ids[seg.a], point_ids[seg.b]});
    r.segment_ids.push_back(s);
  }
  for (plc::PointId p : f.interior_points) {
    r.interior_uv.push_back(uv_of(p));
    r.interior_points.push_back(point_ids[p]);
  }
  r.CollectPoints();
  if (normalised_frame != nullptr) *normalised_frame = frame;
  return r;
}

FacetMesh::FacetMesh(FacetRegion region, const std::array<PointId, 4>& corner_ids)
    : region_(std::move(region)),
      square_lo_(SquareOf(region_).first),
      square_hi_(SquareOf(region_).second),
      dt_(Delaunay2::Square(square_lo_ - (square_hi_ - square_lo_), square_hi_ + (square_hi_ - square_lo_),
                            {corner_ids[0].value(), corner_ids[1].value(), corner_ids[2].value(),
                             corner_ids[3].value()})) {
  for (uint32_t i = 0; i < 4; ++i) Register(Delaunay2::VertexId(i), corner_ids[i]);
}

Vec2 FacetMesh::Corner(int i) const {
  switch (i & 3) {
    case 0: return square_lo_;
    case 1: return {square_hi_.x, square_lo_.y};
    case 2: return square_hi_;
    default: return {square_lo_.x, square_hi_.y};
  }
}

void FacetMesh::Register(VertexId2 v, PointId p) {
  if (point_of_.size() <= v.value()) {
    // 1.25x growth, not resize's doubling: six facet meshes growing in step
    // held up to half their capacity unused (cube 1e-4, session 45).
    const size_t extra = v.value() + 1 - point_of_.size();
    util::ReserveForAppend(point_of_, extra);
    util::ReserveForAppend(cell_gen_, extra);
    util::ReserveForAppend(skinny_event_, extra);
    util::ReserveForAppend(unresolved_event_, extra);
    point_of_.resize(v.value() + 1);
    cell_gen_.resize(v.value() + 1, 0);
    skinny_event_.resize(v.value() + 1);
    unresolved_event_.resize(v.value() + 1);
  }
  point_of_[v.value()] = p;
  ++cell_gen_[v.value()];
}

Delaunay2::InsertResult FacetMesh::Insert(Vec2 uv, PointId id, TriId2 hint) {
  Delaunay2::InsertResult r = dt_.Insert(uv, id.value(), hint);
  if (r.outcome == Delaunay2::InsertOutcome::kInserted) {
    Register(r.vertex, id);
    for (VertexId2 u : r.cavity_vertices) BumpCell(u);
  }
  return r;
}

void FacetMesh::SetOnSegment(VertexId2 v, int32_t k) {
  if (on_segment_.size() <= v.value()) on_segment_.resize(v.value() + 1, -1);
  on_segment_[v.value()] = k;
}

bool FacetMesh::OnSegment(VertexId2 v, size_t k) const {
  if (v.value() < on_segment_.size() && on_segment_[v.value()] == static_cast<int32_t>(k)) return true;
  const PointId p = PointOf(v);
  return p == region_.segment_points[k][0] || p == region_.segment_points[k][1];
}

bool FacetMesh::InFacet(TriId2 t) const {
  const std::array<Vec2, 3> x = {dt_.Point(dt_.TriVertex(t, 0)), dt_.Point(dt_.TriVertex(t, 1)),
                                 dt_.Point(dt_.TriVertex(t, 2))};
  const Vec2 centroid{(x[0].x + x[1].x + x[2].x) / 3.0, (x[0].y + x[1].y + x[2].y) / 3.0};
  if (region_.Locate(centroid) == FacetRegion::Where::kInside) return true;
  // Straddling a segment of F (guide §5 item 4), decided with the points
  // known to lie on it: a segment's Steiner points are rounded off its line
  // (design §2), so the exact test against the input segment would call a
  // triangle with an edge on the segment "crossing" it by a rounding hair.
  // Two vertices on s: its side is its line, no crossing. One vertex on s:
  // crossing iff the other two are strictly on opposite sides.
  for (size_t k = 0; k < region_.segments.size(); ++k) {
    if (MeetsSegmentPart(t, k, region_.segments[k][0], region_.segments[k][1])) return true;
  }
  return false;
}

bool FacetMesh::MeetsSegmentPart(TriId2 t, size_t k, Vec2 a, Vec2 b) const {
  const std::array<Vec2, 3> x = {dt_.Point(dt_.TriVertex(t, 0)), dt_.Point(dt_.TriVertex(t, 1)),
                                 dt_.Point(dt_.TriVertex(t, 2))};
  const Vec2 s0 = region_.segments[k][0], s1 = region_.segments[k][1];
  int on = 0;
  std::array<int, 3> off{};
  int n_off = 0;
  for (int i = 0; i < 3; ++i) {
    if (OnSegment(dt_.TriVertex(t, i), k)) {
      ++on;
    } else {
      off[n_off++] = i;
    }
  }
  if (on >= 2) return false;
  if (!TriangleMeetsSegment(x[0], x[1], x[2], a, b)) return false;
  if (on == 1 && geom::Orient2d(s0, s1, x[off[0]]) * geom::Orient2d(s0, s1, x[off[1]]) >= 0) return false;
  return true;
}

int32_t FacetMesh::RegionSegment(uint32_t seg) const {
  const auto& ids = region_.segment_ids;
  for (size_t k = 0; k < ids.size(); ++k) {
    if (ids[k] == seg) return static_cast<int32_t>(k);
  }
  return -1;
}

std::vector<std::array<PointId, 3>> FacetMesh::InFacetTriangles() const {
  std::vector<std::array<PointId, 3>> out;
  for (TriId2 t : dt_.Triangles()) {
    // SyncTriangleBalls / CreateAllTriangleBalls recorded InFacet for every
    // live triangle (it depends only on the triangle's vertices): on
    // nested_boxes_3 the tests here were 5% of the run (session 41).
    const uint8_t known = t.value() < in_facet_.size() ? in_facet_[t.value()] : kInFacetUnknown;
    if (known == kInFacetNo || (known == kInFacetUnknown && !InFacet(t))) continue;
    out.push_back({PointOf(dt_.TriVertex(t, 0)), PointOf(dt_.TriVertex(t, 1)),
                   PointOf(dt_.TriVertex(t, 2))});
  }
  return out;
}

void FacetMesh::TriangleBall(TriId2 t, const plc::FacetFrame& frame, geom::Vec3* center,
                             double* radius) const {
  *center = frame.ToSpace(dt_.Circumcenter(t));
  *radius = dt_.Circumradius(t);
}

void FacetMesh::SyncTriangleBalls(const Delaunay2::InsertResult& r, const plc::FacetFrame& frame,
                                  FeatureId feature, MeshId mesh, BallStore* balls,
                                  std::vector<BallId>* added, std::vector<BallId>* killed) {
  if (r.outcome != Delaunay2::InsertOutcome::kInserted) return;
  // Destroyed first: slots are reused, so a slot can be in both lists.
  for (TriId2 t : r.destroyed) {
    if (t.value() < tri_ball_.size() && tri_ball_[t.value()].valid()) {
      balls->Kill(tri_ball_[t.value()]);
      if (killed != nullptr) killed->push_back(tri_ball_[t.value()]);
      tri_ball_[t.value()] = kNoneBall;
    }
    if (t.value() < in_facet_.size()) in_facet_[t.value()] = kInFacetUnknown;
  }
  if (tri_ball_.size() < dt_.TriCapacity()) tri_ball_.resize(dt_.TriCapacity(), kNoneBall);
  if (in_facet_.size() < dt_.TriCapacity()) in_facet_.resize(dt_.TriCapacity(), kInFacetUnknown);
  for (TriId2 t : r.created) {
    const bool in = InFacet(t);
    in_facet_[t.value()] = in ? kInFacetYes : kInFacetNo;
    if (!in) continue;
    geom::Vec3 c;
    double rad;
    TriangleBall(t, frame, &c, &rad);
    const BallId b = balls->AddTriangleBall(PointOf(dt_.TriVertex(t, 0)), PointOf(dt_.TriVertex(t, 1)),
                                            PointOf(dt_.TriVertex(t, 2)), c, rad, feature, mesh);
    tri_ball_[t.value()] = b;
    if (added != nullptr) added->push_back(b);
  }
}

void FacetMesh::CreateAllTriangleBalls(const plc::FacetFrame& frame, FeatureId feature,
                                       MeshId mesh, BallStore* balls, std::vector<BallId>* added) {
  if (tri_ball_.size() < dt_.TriCapacity()) tri_ball_.resize(dt_.TriCapacity(), kNoneBall);
  if (in_facet_.size() < dt_.TriCapacity()) in_facet_.resize(dt_.TriCapacity(), kInFacetUnknown);
  for (TriId2 t : dt_.Triangles()) {
    if (tri_ball_[t.value()].valid()) {
      in_facet_[t.value()] = kInFacetYes;
      continue;
    }
    const bool in = InFacet(t);
    in_facet_[t.value()] = in ? kInFacetYes : kInFacetNo;
    if (!in) continue;
    geom::Vec3 c;
    double rad;
    TriangleBall(t, frame, &c, &rad);
    const BallId b = balls->AddTriangleBall(PointOf(dt_.TriVertex(t, 0)), PointOf(dt_.TriVertex(t, 1)),
                                            PointOf(dt_.TriVertex(t, 2)), c, rad, feature, mesh);
    tri_ball_[t.value()] = b;
    if (added != nullptr) added->push_back(b);
  }
}

CellSize2 FacetMesh::Size(VertexId2 v) const {
  CellSize2 out;
  const Vec2 pv = dt_.Point(v);
  dt_.Star(v, &star_);
  // r_v = Delaunay2::InRadius(v), from the star's vertices (v's neighbours,
  // each seen once or twice) instead of a second walk around v: the same
  // minimum of the same squared distances.
  double shortest2 = std::numeric_limits<double>::infinity();
  for (TriId2 t : star_) {
    for (int i = 0; i < 3; ++i) {
      const VertexId2 u = dt_.TriVertex(t, i);
      if (u != v) shortest2 = std::min(shortest2, geom::Norm2(dt_.Point(u) - pv));
    }
  }
  out.inradius = 0.5 * std::sqrt(shortest2);
  poly_.clear();
  bool outside = dt_.IsCorner(v);  // a corner's cell is unbounded
  if (!outside) {
    for (TriId2 t : star_) {
      const Vec2 c = dt_.Circumcenter(t);
      outside = outside || c.x < square_lo_.x || c.y < square_lo_.y || c.x > square_hi_.x ||
                c.y > square_hi_.y;
      poly_.push_back(c);
    }
  }
  if (outside) {
    // V(v) ∩ Ω_F directly: the square clipped by the bisector half-plane of
    // every Delaunay neighbour (the Delaunay neighbours' bisectors bound V(v)).
    // Robust for unbounded cells and circumcentres beyond a side alike.
    poly_.assign({square_lo_, Vec2{square_hi_.x, square_lo_.y}, square_hi_,
                  Vec2{square_lo_.x, square_hi_.y}});
    std::vector<VertexId2>& nbrs = nbrs_;
    dt_.Neighbors(v, &nbrs);
    for (VertexId2 u : nbrs) {
      if (poly_.empty()) break;
      const Vec2 pu = dt_.Point(u);
      const Vec2 m = 0.5 * (pv + pu), d = pu - pv;
      auto f = [&](Vec2 x) { return geom::Dot(x - m, d); };  // ≤ 0: closer to v
      scratch_.clear();
      const size_t n = poly_.size();
      for (size_t i = 0; i < n; ++i) {
        const Vec2 a = poly_[i], b = poly_[(i + 1) % n];
        const double fa = f(a), fb = f(b);
        if (fa <= 0) scratch_.push_back(a);
        if ((fa <= 0) != (fb <= 0)) scratch_.push_back(a + (fa / (fa - fb)) * (b - a));
      }
      poly_.swap(scratch_);
    }
    out.clipped = true;
  }
  double best = -1;
  for (const Vec2& c : poly_) {
    const double d2 = Dist2(c, pv);
    if (d2 > best) {
      best = d2;
      out.corner = c;
    }
  }
  // A clipped corner is a rounded intersection with a side of Ω_F; keep it
  // on the square (it may come out an ulp beyond), where it is inserted.
  out.corner.x = std::clamp(out.corner.x, square_lo_.x, square_hi_.x);
  out.corner.y = std::clamp(out.corner.y, square_lo_.y, square_hi_.y);
  out.outradius = best > 0 ? std::sqrt(best) : 0;
  out.hint = star_.front();
  return out;
}

}  // namespace svrc::refine
