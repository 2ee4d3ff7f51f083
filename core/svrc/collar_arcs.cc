#include "core/svrc/collar_arcs.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <utility>

#include "absl/container/flat_hash_map.h"
#include "core/geometry/predicates.h"

namespace svrc::refine {

using delaunay::Delaunay2;
using VertexId2 = Delaunay2::VertexId;
using TriId2 = Delaunay2::TriId;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kTwoPi = 2 * std::numbers::pi;
constexpr double kU = 1.1102230246251565e-16;  // 2^-53
// Arc ends of ClipCircleByBalls are snapped to a (2,1) point within this angle.
constexpr double kEndMatch = 1e-6;

Vec3 Lift(Vec2 p) { return Vec3(p.x, p.y, 0); }
CollarBall LiftDisk(const PlaneCircle& c) { return CollarBall{Lift(c.center), c.radius}; }

// Angle in (−π, π] of d, wrapped.
double Wrap(double a) {
  a = std::fmod(a, kTwoPi);
  if (a > kPi) a -= kTwoPi;
  if (a <= -kPi) a += kTwoPi;
  return a;
}
// Angle in [0, 2π).
double Mod2Pi(double a) {
  a = std::fmod(a, kTwoPi);
  if (a < 0) a += kTwoPi;
  if (a >= kTwoPi) a -= kTwoPi;
  return a;
}

double Cross2(Vec2 a, Vec2 b) { return a.x * b.y - a.y * b.x; }
double Len(Vec2 a) { return std::hypot(a.x, a.y); }

// Exact "p strictly inside the disk of circle c" (InBall on the lifted disk).
bool InDisk(Vec2 p, const PlaneCircle& c) {
  return geom::InBall(Lift(p), Lift(c.center), c.radius) > 0;
}

// Rounding floor for "on the circle": a constructed point is off by a few ulps
// of its coordinates.
// Distance below which two points computed on circle c are one point up to
// the rounding of its centre and radius.
double RoundingTolerance(const PlaneCircle& c) {
  const double scale = std::max(std::fabs(c.center.x), std::fabs(c.center.y)) + c.radius;
  return 64 * kU * scale;
}

double OnCircleTolerance(const PlaneCircle& c, double snap) {
  return std::max(snap * c.radius, RoundingTolerance(c));
}

// p is (2,1) point k up to rounding. A point computed elsewhere as a
// crossing of a circle, e.g. an earlier round's arc repair on the bisector of
// two crease vertices that both carry a collar ball by now, can miss the
// (2,1) point's own rounding by 1e-17; two such vertices next to each other
// were refined down to the resolution of doubles (wedge-1.smesh).
bool At21(const FacetCollarSystem& sys, uint32_t k, Vec2 p) {
  const Point21& q = sys.points21[k];
  if (q.x == p) return true;
  return Len(q.x - p) <= RoundingTolerance(sys.circles[q.circle_a]);
}

// Arc parameter of a point p on (or near) the circle of arc `a`, clamped to
// the nearer end when its angle is outside the arc; exact ends map to 0 and
// length.
double ArcParam(const FacetCollarSystem& sys, uint32_t a, Vec2 p) {
  const CollarArc& arc = sys.arcs[a];
  if (!arc.full) {
    if (arc.end[0] != kNoArcIndex && At21(sys, arc.end[0], p)) return 0;
    if (arc.end[1] != kNoArcIndex && At21(sys, arc.end[1], p)) return arc.length;
  }
  const PlaneCircle& c = sys.circles[arc.circle];
  const double phi = std::atan2(p.y - c.center.y, p.x - c.center.x);
  double s = Mod2Pi(phi - arc.t0);
  if (arc.full || s <= arc.length) return s;
  return (s - arc.length < kTwoPi - s) ? arc.length : 0.0;
}

bool VertexAt(const Delaunay2& dt, Vec2 p, VertexId2* v, bool* outside) {
  *outside = false;
  const TriId2 t = dt.Locate(p);
  if (!t.valid()) {
    *outside = true;
    return false;
  }
  *v = dt.NearestVertex(p, t);
  return dt.Point(*v) == p;
}

bool Adjacent(const Delaunay2& dt, VertexId2 v, VertexId2 w, std::vector<VertexId2>* scratch) {
  dt.Neighbors(v, scratch);
  return std::find(scratch->begin(), scratch->end(), w) != scratch->end();
}

}  // namespace

Vec2 FacetCollarSystem::ArcPoint(uint32_t a, double s) const {
  const CollarArc& arc = arcs[a];
  if (!arc.full) {
    if (s == 0 && arc.end[0] != kNoArcIndex) return points21[arc.end[0]].x;
    if (s == arc.length && arc.end[1] != kNoArcIndex) return points21[arc.end[1]].x;
  }
  const PlaneCircle& c = circles[arc.circle];
  const double t = arc.t0 + s;
  return Vec2(c.center.x + c.radius * std::cos(t), c.center.y + c.radius * std::sin(t));
}

FacetCollarSystem FacetCollars(const plc::FacetFrame& frame, std::span<const CollarBall> balls) {
  FacetCollarSystem sys;
  const Vec3 n = geom::Cross(frame.u, frame.v);
  for (uint32_t i = 0; i < balls.size(); ++i) {
    Circle3 c3;
    if (!PlaneSphereCircle(frame.origin, n, balls[i], &c3)) continue;
    sys.circles.push_back(PlaneCircle{i, frame.ToPlane(c3.center), c3.radius});
  }
  const uint32_t nc = static_cast<uint32_t>(sys.circles.size());
  std::vector<CollarBall> disks;
  for (const PlaneCircle& c : sys.circles) disks.push_back(LiftDisk(c));

  // (2,1) points: pairwise circle crossings (the same factored radical-line
  // form as SphereSphereCircle), kept iff no third disk contains them strictly.
  std::vector<std::vector<uint32_t>> points_of_circle(nc);
  for (uint32_t i = 0; i < nc; ++i) {
    for (uint32_t j = i + 1; j < nc; ++j) {
      const PlaneCircle& ci = sys.circles[i];
      const PlaneCircle& cj = sys.circles[j];
      const Vec2 dv = cj.center - ci.center;
      const double d2 = geom::Norm2(dv);
      if (d2 == 0) continue;
      const double d = std::sqrt(d2);
      if (d >= ci.radius + cj.radius || d <= std::fabs(ci.radius - cj.radius)) continue;
      const double h = (d2 + (ci.radius - cj.radius) * (ci.radius + cj.radius)) / (2 * d);
      const double k2 = (ci.radius - h) * (ci.radius + h);
      if (!(k2 > 0)) continue;
      const double k = std::sqrt(k2);
      const Vec2 e(dv.x / d, dv.y / d);
      const Vec2 perp(-e.y, e.x);
      const Vec2 base = ci.center + h * e;
      for (double sign : {1.0, -1.0}) {
        const Vec2 x = base + (sign * k) * perp;
        bool covered = false;
        for (uint32_t m = 0; m < nc && !covered; ++m) {
          if (m != i && m != j) covered = InDisk(x, sys.circles[m]);
        }
        if (covered) continue;
        const uint32_t id = static_cast<uint32_t>(sys.points21.size());
        sys.points21.push_back(Point21{x, ci.ball, cj.ball, i, j});
        points_of_circle[i].push_back(id);
        points_of_circle[j].push_back(id);
      }
    }
  }

  // Arcs: ClipCircleByBalls on the lifted circle (normal +z) against the other
  // lifted disks; its angle t is measured in CircleFrame (u', w'), which for
  // normal +z is a counter-clockwise frame of the plane, so θ = t + angle(u').
  for (uint32_t i = 0; i < nc; ++i) {
    const PlaneCircle& c = sys.circles[i];
    const Circle3 lifted{Lift(c.center), Vec3(0, 0, 1), c.radius};
    Vec3 fu, fw;
    CircleFrame(lifted, &fu, &fw);
    const double offset = std::atan2(fu.y, fu.x);
    std::vector<CollarBall> others;
    for (uint32_t m = 0; m < nc; ++m) {
      if (m != i) others.push_back(disks[m]);
    }
    std::vector<Arc> raw = ClipCircleByBalls(lifted, others);
    if (raw.empty()) continue;
    std::vector<std::pair<double, double>> pieces;  // (t0, length) in θ
    if (raw.size() == 1 && raw[0].t0 == 0 && raw[0].t1 == kTwoPi) {
      CollarArc arc;
      arc.circle = i;
      arc.ball = c.ball;
      arc.t0 = -kPi;
      arc.length = kTwoPi;
      arc.full = true;
      sys.arcs.push_back(arc);
      continue;
    }
    // ClipCircleByBalls splits an arc through t = 0: join it back.
    if (raw.size() >= 2 && raw.front().t0 == 0 && raw.back().t1 == kTwoPi) {
      raw.back().t1 = raw.front().t1 + kTwoPi;
      raw.erase(raw.begin());
    }
    std::vector<CollarArc> arcs_here;
    for (const Arc& r : raw) {
      CollarArc arc;
      arc.circle = i;
      arc.ball = c.ball;
      double t0 = r.t0 + offset;
      double length = r.t1 - r.t0;
      // Snap both ends to the (2,1) points of this circle.
      for (int end = 0; end < 2; ++end) {
        const double theta = end == 0 ? t0 : t0 + length;
        uint32_t best = kNoArcIndex;
        double best_d = kEndMatch;
        double best_phi = 0;
        for (uint32_t p : points_of_circle[i]) {
          const Vec2 x = sys.points21[p].x;
          const double phi = std::atan2(x.y - c.center.y, x.x - c.center.x);
          const double dphi = std::fabs(Wrap(phi - theta));
          if (dphi <= best_d) {
            best_d = dphi;
            best = p;
            best_phi = phi;
          }
        }
        if (best == kNoArcIndex) {
          ++sys.unmatched_ends;
          continue;
        }
        arc.end[end] = best;
        const double delta = Wrap(best_phi - theta);
        if (end == 0) {
          t0 += delta;
          length -= delta;
        } else {
          length += delta;
        }
      }
      // Store t0 as the exact atan2 of the start point (ArcParam(start) = 0).
      if (arc.end[0] != kNoArcIndex) {
        const Vec2 x = sys.points21[arc.end[0]].x;
        t0 = std::atan2(x.y - c.center.y, x.x - c.center.x);
      } else {
        t0 = Wrap(t0);
      }
      arc.t0 = t0;
      arc.length = std::clamp(length, 0.0, kTwoPi);
      if (arc.length > 0) arcs_here.push_back(arc);
    }
    std::sort(arcs_here.begin(), arcs_here.end(),
              [](const CollarArc& a, const CollarArc& b) { return a.t0 < b.t0; });
    sys.arcs.insert(sys.arcs.end(), arcs_here.begin(), arcs_here.end());
  }
  return sys;
}

bool OnArc(Vec2 p, const FacetCollarSystem& system, uint32_t a, const ArcOptions& opts) {
  const CollarArc& arc = system.arcs[a];
  if (!arc.full) {
    for (uint32_t e : arc.end) {
      if (e != kNoArcIndex && At21(system, e, p)) return true;
    }
  }
  const PlaneCircle& c = system.circles[arc.circle];
  const double tol = OnCircleTolerance(c, opts.snap);
  const Vec2 d = p - c.center;
  if (std::fabs(Len(d) - c.radius) > tol) return false;
  if (arc.full) return true;
  const double s = Mod2Pi(std::atan2(d.y, d.x) - arc.t0);
  const double atol = tol / c.radius;
  return s <= arc.length + atol || s >= kTwoPi - atol;
}

std::vector<ArcEdge> RestrictedArcEdges(const Delaunay2& dt, const FacetCollarSystem& system, bool index_circles) {
  std::vector<ArcEdge> out;
  const uint32_t nc = static_cast<uint32_t>(system.circles.size());
  if (system.arcs.empty()) return out;
  std::vector<std::vector<uint32_t>> arcs_of_circle(nc);
  for (uint32_t a = 0; a < system.arcs.size(); ++a) {
    arcs_of_circle[system.arcs[a].circle].push_back(a);
  }
  // Circumcentres by triangle slot, in a buffer kept by the thread: a fresh
  // array per call (the facet's whole slot range, every COLLAR round, for
  // every facet with new points) was zeroed pages from the kernel (measured
  // on an armadillo.off round: clear_page 13.6% of its samples, this
  // function 8.4%). Every live slot is written below before it is read.
  thread_local std::vector<Vec2> cc_buf;
  if (cc_buf.size() < dt.TriCapacity()) cc_buf.resize(dt.TriCapacity() + dt.TriCapacity() / 4);
  Vec2* const cc = cc_buf.data();
  const std::vector<TriId2> tris = dt.Triangles();
  for (TriId2 t : tris) cc[t.value()] = dt.Circumcenter(t);

  // The circles with arcs in a uniform grid of their bounding boxes (cell =
  // the median diameter), so that a Voronoi edge is tested against the
  // circles whose boxes its box meets instead of all of them (measured on
  // wedge-1.smesh: the all-circles loop was 13% of the run). The hits, and
  // so the sorted output, are those of the all-circles loop: a circle whose
  // box misses the edge's box was skipped by the same box test there.
  std::vector<uint32_t> with_arcs;
  for (uint32_t k = 0; k < nc; ++k) {
    if (!arcs_of_circle[k].empty()) with_arcs.push_back(k);
  }
  double cell = 0;
  {
    std::vector<double> d;
    for (uint32_t k : with_arcs) d.push_back(2 * system.circles[k].radius);
    std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
    cell = d[d.size() / 2];
  }
  Vec2 glo(HUGE_VAL, HUGE_VAL);
  for (uint32_t k : with_arcs) {
    const PlaneCircle& c = system.circles[k];
    glo = Vec2(std::min(glo.x, c.center.x - c.radius), std::min(glo.y, c.center.y - c.radius));
  }
  // Cell coordinates clamped to a sane range: far boxes land in the edge
  // cells, which only adds candidates.
  auto cell_of = [&](double v, double lo) {
    const double q = std::floor((v - lo) / cell);
    return static_cast<int64_t>(std::clamp(q, -1.0, 1e6));
  };
  absl::flat_hash_map<std::pair<int64_t, int64_t>, std::vector<uint32_t>> grid;
  bool use_grid = index_circles && cell > 0 && std::isfinite(cell);
  for (uint32_t k : with_arcs) {
    if (!use_grid) break;
    const PlaneCircle& c = system.circles[k];
    const int64_t x0 = cell_of(c.center.x - c.radius, glo.x), x1 = cell_of(c.center.x + c.radius, glo.x);
    const int64_t y0 = cell_of(c.center.y - c.radius, glo.y), y1 = cell_of(c.center.y + c.radius, glo.y);
    if ((x1 - x0 + 1) * (y1 - y0 + 1) > 4096) {
      use_grid = false;  // a circle far bigger than the median: scan them all
      break;
    }
    for (int64_t x = x0; x <= x1; ++x) {
      for (int64_t y = y0; y <= y1; ++y) grid[{x, y}].push_back(k);
    }
  }
  std::vector<uint32_t> near;
  std::vector<uint8_t> mark(nc, 0);
  // The circles to test for the segment p–q (ascending), or all with arcs.
  auto circles_near = [&](const Vec2& p, const Vec2& q) -> const std::vector<uint32_t>& {
    if (!use_grid || !std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(q.x) || !std::isfinite(q.y)) {
      return with_arcs;
    }
    const int64_t x0 = cell_of(std::min(p.x, q.x), glo.x), x1 = cell_of(std::max(p.x, q.x), glo.x);
    const int64_t y0 = cell_of(std::min(p.y, q.y), glo.y), y1 = cell_of(std::max(p.y, q.y), glo.y);
    if ((x1 - x0 + 1) * (y1 - y0 + 1) > static_cast<int64_t>(grid.size())) return with_arcs;
    near.clear();
    for (int64_t x = x0; x <= x1; ++x) {
      for (int64_t y = y0; y <= y1; ++y) {
        const auto it = grid.find({x, y});
        if (it == grid.end()) continue;
        for (uint32_t k : it->second) {
          if (!mark[k]) {
            mark[k] = 1;
            near.push_back(k);
          }
        }
      }
    }
    for (uint32_t k : near) mark[k] = 0;
    std::sort(near.begin(), near.end());
    return near;
  };

  struct Hit {
    uint32_t arc;
    Vec2 x;
    double s;
  };
  std::vector<Hit> hits;
  for (TriId2 t : tris) {
    for (int e = 0; e < 3; ++e) {
      const TriId2 nb = dt.Neighbor(t, e);
      if (nb.valid() && nb.value() < t.value()) continue;  // each edge once
      const VertexId2 va = dt.TriVertex(t, (e + 1) % 3);
      const VertexId2 vb = dt.TriVertex(t, (e + 2) % 3);
      const Vec2 pa = dt.Point(va), pb = dt.Point(vb);
      const Vec2 p = cc[t.value()];
      // Hull edge: the Voronoi edge is the ray from the circumcentre away from
      // the triangle (to the right of the counter-clockwise edge a → b).
      Vec2 dir(0, 0);
      if (!nb.valid()) {
        const Vec2 ab = pb - pa;
        const double l = Len(ab);
        dir = Vec2(ab.y / l, -ab.x / l);
      }
      hits.clear();
      // A hull edge's ray depends on the circle: all circles.
      const std::vector<uint32_t>& ks = nb.valid() ? circles_near(p, cc[nb.value()]) : with_arcs;
      for (uint32_t k : ks) {
        const PlaneCircle& c = system.circles[k];
        Vec2 q;
        if (nb.valid()) {
          q = cc[nb.value()];
        } else {
          // Long enough to leave the disk from p.
          q = p + (2 * (Len(p - c.center) + c.radius)) * dir;
        }
        // Quick reject on bounding boxes.
        if (std::max(p.x, q.x) < c.center.x - c.radius ||
            std::min(p.x, q.x) > c.center.x + c.radius ||
            std::max(p.y, q.y) < c.center.y - c.radius ||
            std::min(p.y, q.y) > c.center.y + c.radius) {
          continue;
        }
        double roots[2];
        const int nr = SegmentSphere(Lift(p), Lift(q), LiftDisk(c), roots);
        for (int r = 0; r < nr; ++r) {
          const Vec2 y = p + roots[r] * (q - p);
          const Vec2 dy = y - c.center;
          const double ly = Len(dy);
          if (!(ly > 0)) continue;
          // Radial projection: on the circle to the rounding of c and r, however
          // long the Voronoi edge.
          const Vec2 x(c.center.x + c.radius * dy.x / ly, c.center.y + c.radius * dy.y / ly);
          bool covered = false;
          for (uint32_t m = 0; m < nc && !covered; ++m) {
            if (m != k) covered = InDisk(x, system.circles[m]);
          }
          if (covered) continue;
          // The arc of circle k holding x (nearest at rounding-level ends).
          uint32_t best = kNoArcIndex;
          double best_out = HUGE_VAL, best_s = 0;
          const double phi = std::atan2(dy.y, dy.x);
          for (uint32_t a : arcs_of_circle[k]) {
            const CollarArc& arc = system.arcs[a];
            const double s = Mod2Pi(phi - arc.t0);
            double outside = 0, sc = s;
            if (!arc.full && s > arc.length) {
              const double past = s - arc.length, before = kTwoPi - s;
              outside = std::min(past, before);
              sc = past < before ? arc.length : 0.0;
            }
            if (outside < best_out) {
              best_out = outside;
              best = a;
              best_s = sc;
            }
          }
          hits.push_back(Hit{best, x, best_s});
        }
      }
      for (const Hit& h : hits) {
        ArcEdge edge;
        edge.a = va.value() < vb.value() ? va : vb;
        edge.b = va.value() < vb.value() ? vb : va;
        edge.arc = h.arc;
        edge.x = h.x;
        edge.s = h.s;
        const Vec2 xa = h.x - pa;
        edge.rep_radius = Len(xa);
        // Definition 34 in 2D: the Voronoi edge (⟂ ab) against the circle's
        // normal x − centre.
        const Vec2 ab = pb - pa;
        const Vec2 vdir(-ab.y, ab.x);
        const Vec2 nrm = h.x - system.circles[system.arcs[h.arc].circle].center;
        edge.angle = std::atan2(std::fabs(Cross2(vdir, nrm)), std::fabs(geom::Dot(vdir, nrm)));
        edge.crossings = static_cast<uint32_t>(hits.size());
        out.push_back(edge);
      }
    }
  }
  std::sort(out.begin(), out.end(), [](const ArcEdge& l, const ArcEdge& r) {
    if (l.arc != r.arc) return l.arc < r.arc;
    if (l.s != r.s) return l.s < r.s;
    if (l.a != r.a) return l.a < r.a;
    return l.b < r.b;
  });
  return out;
}

const char* ArcRepairReasonName(ArcRepairReason r) {
  switch (r) {
    case ArcRepairReason::kMissingPoint21: return "missing_point21";
    case ArcRepairReason::kMultipleCrossings: return "multiple_crossings";
    case ArcRepairReason::kBrokenPath: return "broken_path";
    case ArcRepairReason::kEmptyArc: return "empty_arc";
    case ArcRepairReason::kOffArcVertex: return "off_arc_vertex";
    case ArcRepairReason::kAngle: return "angle";
    case ArcRepairReason::kSize: return "size";
  }
  return "?";
}

std::vector<ArcRepair> ArcRepairs(const Delaunay2& dt, const FacetCollarSystem& system,
                                  double sigma, ArcReport* report, const ArcOptions& opts) {
  ArcReport rep;
  std::vector<ArcRepair> out;
  const std::vector<ArcEdge> edges = RestrictedArcEdges(dt, system);
  rep.restricted_edges = static_cast<int>(edges.size());

  auto emit = [&](ArcRepair r) {
    VertexId2 v;
    bool outside = false;
    if (VertexAt(dt, r.x, &v, &outside) || outside) {
      ++rep.skipped;
      return;
    }
    out.push_back(r);
  };

  // (2,1) points: radius-0 RepBalls; they must be vertices.
  std::vector<VertexId2> p21_vertex(system.points21.size());
  std::vector<bool> p21_present(system.points21.size(), false);
  for (uint32_t k = 0; k < system.points21.size(); ++k) {
    const Point21& p = system.points21[k];
    VertexId2 v;
    bool outside = false;
    if (VertexAt(dt, p.x, &v, &outside) || (!outside && At21(system, k, dt.Point(v)))) {
      p21_vertex[k] = v;
      p21_present[k] = true;
      continue;
    }
    ++rep.missing_points21;
    ArcRepair r;
    r.x = p.x;
    r.ball = std::min(p.a, p.b);
    r.other_ball = std::max(p.a, p.b);
    r.point21 = k;
    r.collar_dim = 1;
    r.radius = 0;
    r.reason = ArcRepairReason::kMissingPoint21;
    emit(r);
  }

  // Per restricted edge: the most urgent reason (enum order), or none.
  constexpr int kNoReason = 255;
  std::vector<int> reason(edges.size(), kNoReason);
  auto flag = [&](size_t i, ArcRepairReason r) {
    reason[i] = std::min(reason[i], static_cast<int>(r));
  };

  // (a) Voronoi edges with ≥ 2 crossings: repair the crossing with the largest
  // RepBall (one per Delaunay edge).
  std::map<std::pair<uint32_t, uint32_t>, size_t> multi;
  for (size_t i = 0; i < edges.size(); ++i) {
    if (edges[i].crossings <= 1) continue;
    const auto key = std::make_pair(edges[i].a.value(), edges[i].b.value());
    auto it = multi.find(key);
    if (it == multi.end()) {
      multi.emplace(key, i);
    } else if (edges[i].rep_radius > edges[it->second].rep_radius) {
      it->second = i;
    }
  }
  rep.multi_crossings = static_cast<int>(multi.size());
  for (const auto& [key, i] : multi) flag(i, ArcRepairReason::kMultipleCrossings);

  // Per arc: path/cycle, degree, off-arc vertices, angles, emptiness.
  std::vector<ArcRepair> empty_repairs;
  size_t begin = 0;
  for (uint32_t a = 0; a < system.arcs.size(); ++a) {
    const CollarArc& arc = system.arcs[a];
    size_t end = begin;
    while (end < edges.size() && edges[end].arc == a) ++end;
    const size_t k = end - begin;
    const bool ends_known = arc.full || (arc.end[0] != kNoArcIndex && arc.end[1] != kNoArcIndex);
    const bool ends_present =
        arc.full || (ends_known && p21_present[arc.end[0]] && p21_present[arc.end[1]]);

    if (k == 0) {
      if (ends_present) {
        // The arc lies in one cell: insert its point farthest from that cell's
        // vertex (the largest gap).
        ++rep.empty_arcs;
        const PlaneCircle& c = system.circles[arc.circle];
        const Vec2 probe = system.ArcPoint(a, 0.5 * arc.length);
        VertexId2 v;
        bool outside = false;
        VertexAt(dt, probe, &v, &outside);
        if (outside) {
          ++rep.skipped;
        } else {
          const Vec2 pv = dt.Point(v);
          double s;
          if (arc.full) {
            const Vec2 d = c.center - pv;
            const double phi = Len(d) > 0 ? std::atan2(d.y, d.x) : 0.0;
            s = Mod2Pi(phi - arc.t0);
          } else {
            s = 0.5 * arc.length;
          }
          ArcRepair r;
          r.x = system.ArcPoint(a, s);
          r.ball = arc.ball;
          r.arc = a;
          r.radius = Len(r.x - pv);
          r.reason = ArcRepairReason::kEmptyArc;
          empty_repairs.push_back(r);
        }
      }
      begin = end;
      continue;
    }

    // Degree per vertex on this arc (c).
    std::map<uint32_t, std::pair<int, size_t>> degree;  // vertex → (count, largest edge)
    for (size_t i = begin; i < end; ++i) {
      for (VertexId2 v : {edges[i].a, edges[i].b}) {
        auto& [count, best] = degree.try_emplace(v.value(), 0, i).first->second;
        ++count;
        if (edges[i].rep_radius > edges[best].rep_radius) best = i;
      }
    }
    for (const auto& [v, cb] : degree) {
      if (cb.first > 2) {
        ++rep.high_degree;
        flag(cb.second, ArcRepairReason::kBrokenPath);
      }
    }

    // (b) One simple walk through the cells along the arc, in arc order.
    if (ends_present) {
      bool broken = false;
      size_t bad = begin;
      uint32_t start;
      if (arc.full) {
        const ArcEdge& first = edges[begin];
        const ArcEdge& last = edges[end - 1];
        if (first.a == last.a || first.a == last.b) {
          start = first.a.value();
        } else if (first.b == last.a || first.b == last.b) {
          start = first.b.value();
        } else {
          start = kNoArcIndex;
          broken = true;
          bad = edges[begin].rep_radius >= edges[end - 1].rep_radius ? begin : end - 1;
        }
        if (k < 3) broken = true;
      } else {
        start = p21_vertex[arc.end[0]].value();
      }
      std::vector<uint32_t> visited;
      uint32_t cur = start;
      double last_s = -1;  // arc parameter of the last on-arc vertex of the walk
      int descents = 0;
      if (!broken) {
        visited.push_back(cur);
        for (size_t i = begin; i < end && !broken; ++i) {
          uint32_t next;
          if (edges[i].a.value() == cur) {
            next = edges[i].b.value();
          } else if (edges[i].b.value() == cur) {
            next = edges[i].a.value();
          } else {
            broken = true;
            bad = (i > begin && edges[i - 1].rep_radius > edges[i].rep_radius) ? i - 1 : i;
            break;
          }
          const bool closing = arc.full && i + 1 == end && next == start;
          if (!closing && std::find(visited.begin(), visited.end(), next) != visited.end()) {
            broken = true;
            bad = i;
            break;
          }
          // Arc order of the vertices lying on the arc.
          const Vec2 pn = dt.Point(VertexId2(next));
          if (!closing && OnArc(pn, system, a, opts)) {
            const double s = ArcParam(system, a, pn);
            if (s < last_s) {
              ++descents;
              if (!arc.full || descents > 1) {
                broken = true;
                bad = i;
                break;
              }
            }
            last_s = s;
          }
          visited.push_back(next);
          cur = next;
        }
        if (!broken) {
          const uint32_t goal = arc.full ? start : p21_vertex[arc.end[1]].value();
          if (cur != goal) {
            broken = true;
            bad = end - 1;
          }
        }
      }
      if (broken) {
        ++rep.broken_arcs;
        flag(bad, ArcRepairReason::kBrokenPath);
      }
    }

    // Vertices off the arc, and the angle bound σ.
    for (size_t i = begin; i < end; ++i) {
      const ArcEdge& e = edges[i];
      rep.max_angle = std::max(rep.max_angle, e.angle);
      if (!OnArc(dt.Point(e.a), system, a, opts) || !OnArc(dt.Point(e.b), system, a, opts)) {
        ++rep.off_arc_edges;
        if (opts.require_on_arc) flag(i, ArcRepairReason::kOffArcVertex);
      }
      if (e.angle > sigma) {
        ++rep.bad_angles;
        flag(i, ArcRepairReason::kAngle);
      }
      if (opts.eps > 0 && e.rep_radius > opts.eps * system.circles[arc.circle].radius) {
        ++rep.too_large;
        flag(i, ArcRepairReason::kSize);
      }
    }
    begin = end;
  }

  for (ArcRepair& r : empty_repairs) emit(r);
  for (size_t i = 0; i < edges.size(); ++i) {
    if (reason[i] == kNoReason) continue;
    const ArcEdge& e = edges[i];
    ArcRepair r;
    r.x = e.x;
    r.ball = system.arcs[e.arc].ball;
    r.arc = e.arc;
    r.collar_dim = 2;
    r.radius = e.rep_radius;
    r.reason = static_cast<ArcRepairReason>(reason[i]);
    // A crossing at an end of its arc, up to rounding, is that end's (2,1)
    // point. Two collar balls of one radius on neighbouring crease vertices
    // meet on their bisector, which is the Voronoi edge of the two centres,
    // so this is the rule, not the exception. Inserted as a (2,2) point
    // 1e-17 beside the (2,1) point, it left two vertices a rounding error
    // apart and the next facet refinement split them down to the resolution
    // of doubles (measured on wedge-1.smesh: 19 such pairs on one facet).
    const CollarArc& arc = system.arcs[e.arc];
    uint32_t at_end = kNoArcIndex;
    for (int k = 0; k < 2 && !arc.full; ++k) {
      if (arc.end[k] != kNoArcIndex && At21(system, arc.end[k], r.x)) at_end = arc.end[k];
    }
    if (at_end != kNoArcIndex) {
      if (p21_present[at_end]) continue;  // already a vertex: nothing to insert
      const Point21& p = system.points21[at_end];
      r.x = p.x;
      r.ball = std::min(p.a, p.b);
      r.other_ball = std::max(p.a, p.b);
      r.arc = kNoArcIndex;
      r.point21 = at_end;
      r.collar_dim = 1;
      r.radius = 0;
    }
    emit(r);
  }
  if (report != nullptr) *report = rep;
  return out;
}

std::vector<ArcChain> ArcChains(const Delaunay2& dt, const FacetCollarSystem& system,
                                const ArcOptions& opts) {
  std::vector<ArcChain> chains;
  std::vector<VertexId2> scratch;
  for (uint32_t a = 0; a < system.arcs.size(); ++a) {
    const CollarArc& arc = system.arcs[a];
    const PlaneCircle& c = system.circles[arc.circle];
    const double reach = c.radius + OnCircleTolerance(c, opts.snap);
    std::vector<std::pair<double, uint32_t>> on;
    for (uint32_t v = 0; v < dt.NumVertices(); ++v) {
      const Vec2 p = dt.Point(VertexId2(v));
      if (std::fabs(p.x - c.center.x) > reach || std::fabs(p.y - c.center.y) > reach) continue;
      if (!OnArc(p, system, a, opts)) continue;
      on.emplace_back(ArcParam(system, a, p), v);
    }
    std::sort(on.begin(), on.end());
    ArcChain chain;
    chain.arc = a;
    chain.closed = arc.full;
    for (const auto& [s, v] : on) chain.vertices.push_back(VertexId2(v));
    bool ok;
    const size_t n = chain.vertices.size();
    if (arc.full) {
      ok = n >= 3;
    } else {
      ok = n >= 2 && arc.end[0] != kNoArcIndex && arc.end[1] != kNoArcIndex &&
           At21(system, arc.end[0], dt.Point(chain.vertices.front())) &&
           At21(system, arc.end[1], dt.Point(chain.vertices.back()));
    }
    for (size_t i = 0; ok && i + 1 < n; ++i) {
      ok = Adjacent(dt, chain.vertices[i], chain.vertices[i + 1], &scratch);
    }
    if (ok && arc.full) ok = Adjacent(dt, chain.vertices[n - 1], chain.vertices[0], &scratch);
    chain.complete = ok;
    chains.push_back(std::move(chain));
  }
  return chains;
}

bool ArcChordsPresent(const Delaunay2& dt, const FacetCollarSystem& system,
                      const ArcOptions& opts) {
  for (const ArcChain& c : ArcChains(dt, system, opts)) {
    if (!c.complete) return false;
  }
  return true;
}

std::vector<ArcChain3> ArcChainsToSpace(const plc::FacetFrame& frame, const Delaunay2& dt,
                                        const FacetCollarSystem& system,
                                        std::span<const ArcChain> chains) {
  std::vector<ArcChain3> out;
  for (const ArcChain& c : chains) {
    ArcChain3 c3;
    c3.arc = c.arc;
    c3.ball = system.arcs[c.arc].ball;
    c3.closed = c.closed;
    for (VertexId2 v : c.vertices) c3.points.push_back(frame.ToSpace(dt.Point(v)));
    out.push_back(std::move(c3));
  }
  return out;
}

Vec3 RepairToSpace(const plc::FacetFrame& frame, const ArcRepair& repair) {
  return frame.ToSpace(repair.x);
}

}  // namespace svrc::refine
