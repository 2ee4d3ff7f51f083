// Creases (thesis Definitions 4-5; guide §5 items 5-7) and the spread Δ
// (Definition 3). Angles are measurements, not topological decisions, so they
// are computed in floating point; the threshold has a 1e-9 rad margin so that
// exact right angles (a cube) are never creases. See docs/plc.md.
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <string>

#include "absl/strings/str_cat.h"

#include "core/plc/features_internal.h"
#include "core/plc/grid.h"
#include "core/plc/intersect.h"

namespace svrc::plc::internal {
namespace {

using geom::Box3;
using geom::Cross;
using geom::Dot;
using geom::Norm;

constexpr double kPi = std::numbers::pi;

double Angle(const Vec3& a, const Vec3& b) { return std::atan2(Norm(Cross(a, b)), Dot(a, b)); }

Vec3 Unit(const Vec3& v) {
  const double n = Norm(v);
  return n > 0 ? v / n : v;
}

// The part of a facet around a point: a convex corner of one of its
// triangles (rays w1, w2) or, for a point inside the facet, the whole plane.
struct Wedge {
  Vec3 n, w1, w2;
  bool full = false;
};

// Is the direction d (in the wedge's plane) inside the closed convex wedge?
bool InWedge(const Vec3& d, const Wedge& w) {
  if (w.full) return true;
  const Vec3 c = Cross(w.w1, w.w2);
  return Dot(Cross(w.w1, d), c) >= 0 && Dot(Cross(d, w.w2), c) >= 0;
}

// Smallest angle between the unit ray d and the rays of the wedge.
double RayWedge(const Vec3& d, const Wedge& w) {
  const double dn = Dot(d, w.n);
  const Vec3 proj = d - dn * w.n;
  const double pl = Norm(proj);
  if (pl <= 1e-300) return kPi / 2;  // orthogonal to the plane
  if (InWedge(proj / pl, w)) return std::atan2(std::fabs(dn), pl);
  return std::min(Angle(d, w.w1), Angle(d, w.w2));
}

// Smallest angle between rays of two wedges at the same point. The minimum is
// at a boundary ray of one wedge, or 0 along the planes' common line.
double WedgeWedge(const Wedge& a, const Wedge& b) {
  double m = kPi;
  if (!a.full) m = std::min({m, RayWedge(a.w1, b), RayWedge(a.w2, b)});
  if (!b.full) m = std::min({m, RayWedge(b.w1, a), RayWedge(b.w2, a)});
  const Vec3 l = Cross(a.n, b.n);
  const double ln = Norm(l);
  if (ln > 1e-12) {
    for (double s : {1.0, -1.0}) {
      const Vec3 d = (s / ln) * l;
      if (InWedge(d, a) && InWedge(d, b)) return 0;
    }
  } else if (a.full || b.full) {
    m = 0;  // parallel planes through one point: the same plane
  }
  return m;
}

}  // namespace

void ComputeCreases(FeatureComplex* fc, double crease_angle_deg) {
  const double threshold = crease_angle_deg * kPi / 180 - 1e-9;
  const size_t np = fc->points.size();
  auto P = [&](PointId p) -> const Vec3& { return fc->points[p].p; };

  // Wedges of every facet at every point, and segments at every point.
  std::vector<std::vector<std::pair<FacetId, Wedge>>> wedges(np);
  for (FacetId f = 0; f < fc->facets.size(); ++f) {
    const FeatureFacet& ff = fc->facets[f];
    const Vec3 n = ff.frame.normal;
    std::vector<bool> has_corner;
    for (const auto& t : ff.triangles) {
      for (int k = 0; k < 3; ++k) {
        Wedge w;
        w.n = n;
        w.w1 = Unit(P(t[(k + 1) % 3]) - P(t[k]));
        w.w2 = Unit(P(t[(k + 2) % 3]) - P(t[k]));
        wedges[t[k]].push_back({f, w});
      }
    }
    // Points of the facet that are no triangle corner (interior points, ends
    // of in-facet segments, vertices of in-facet polygons): the whole plane.
    std::vector<PointId> pts(ff.interior_points);
    for (const auto& loop : ff.loops) pts.insert(pts.end(), loop.begin(), loop.end());
    for (SegmentId s : ff.segments) {
      pts.push_back(fc->segments[s].a);
      pts.push_back(fc->segments[s].b);
    }
    std::sort(pts.begin(), pts.end());
    pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
    for (PointId p : pts) {
      bool found = false;
      for (const auto& [g, w] : wedges[p]) found |= g == f;
      if (!found) {
        Wedge w;
        w.n = n;
        w.full = true;
        wedges[p].push_back({f, w});
      }
    }
  }
  std::vector<std::vector<SegmentId>> segs_at(np);
  for (SegmentId s = 0; s < fc->segments.size(); ++s) {
    segs_at[fc->segments[s].a].push_back(s);
    segs_at[fc->segments[s].b].push_back(s);
  }
  auto dir = [&](SegmentId s, PointId p) {
    const FeatureSegment& seg = fc->segments[s];
    return Unit(P(seg.a == p ? seg.b : seg.a) - P(p));
  };
  auto contains = [&](SegmentId s, FacetId f) {
    const auto& fs = fc->segments[s].facets;
    return std::binary_search(fs.begin(), fs.end(), f);
  };

  // Points: segment-segment, segment-facet, facet-facet (no common segment at p).
  for (PointId p = 0; p < np; ++p) {
    const auto& ss = segs_at[p];
    const auto& ws = wedges[p];
    double m = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < ss.size(); ++i) {
      const Vec3 di = dir(ss[i], p);
      for (size_t j = i + 1; j < ss.size(); ++j) m = std::min(m, Angle(di, dir(ss[j], p)));
      for (const auto& [f, w] : ws) {
        if (!contains(ss[i], f)) m = std::min(m, RayWedge(di, w));
      }
    }
    for (size_t i = 0; i < ws.size(); ++i) {
      for (size_t j = i + 1; j < ws.size(); ++j) {
        const FacetId f = ws[i].first, g = ws[j].first;
        if (f == g) continue;
        bool share = false;
        for (SegmentId s : ss) share |= contains(s, f) && contains(s, g);
        if (!share) m = std::min(m, WedgeWedge(ws[i].second, ws[j].second));
      }
    }
    fc->points[p].min_angle = m;
    if (m < threshold) fc->points[p].crease = true;
  }

  // Segments: dihedral angles between every pair of facets containing them.
  std::vector<std::vector<std::pair<FacetId, double>>> sides(fc->segments.size());
  for (FacetId f = 0; f < fc->facets.size(); ++f) {
    for (const auto& t : fc->facets[f].triangles) {
      for (int k = 0; k < 3; ++k) {
        const PointId a = t[k], b = t[(k + 1) % 3], c = t[(k + 2) % 3];
        const SegmentId s = fc->FindSegment(a, b);
        if (s == kNoId) continue;
        const FeatureSegment& seg = fc->segments[s];
        const Vec3 w = Cross(fc->facets[f].frame.normal, P(seg.b) - P(seg.a));
        sides[s].push_back({f, Dot(P(c) - P(seg.a), w) >= 0 ? 1.0 : -1.0});
      }
    }
  }
  for (SegmentId s = 0; s < fc->segments.size(); ++s) {
    FeatureSegment& seg = fc->segments[s];
    if (seg.facets.size() < 2) continue;
    const Vec3 t = P(seg.b) - P(seg.a);
    std::vector<std::pair<FacetId, Vec3>> rays;  // directions into each facet, orthogonal to s
    for (FacetId f : seg.facets) {
      const Vec3 w = Unit(Cross(fc->facets[f].frame.normal, t));
      bool pos = false, neg = false;
      for (const auto& [g, side] : sides[s]) {
        if (g != f) continue;
        (side > 0 ? pos : neg) = true;
      }
      if (!pos && !neg) pos = neg = true;  // an in-facet segment: both sides
      if (pos) rays.push_back({f, w});
      if (neg) rays.push_back({f, -1.0 * w});
    }
    double m = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < rays.size(); ++i) {
      for (size_t j = i + 1; j < rays.size(); ++j) {
        if (rays[i].first != rays[j].first) m = std::min(m, Angle(rays[i].second, rays[j].second));
      }
    }
    seg.min_angle = m;
    if (m < threshold) {
      seg.crease = true;
      fc->points[seg.a].crease = true;
      fc->points[seg.b].crease = true;
    }
  }
}

void ComputeSpread(FeatureComplex* fc) {
  const size_t np = fc->points.size();
  auto P = [&](PointId p) -> const Vec3& { return fc->points[p].p; };
  Box3 bounds;
  for (const FeaturePoint& p : fc->points) bounds.Add(p.p);
  fc->diameter = bounds.Diagonal();
  fc->min_feature_distance = 0;
  fc->spread = 0;
  fc->closest_features.clear();
  if (np == 0) return;
  double d = std::numeric_limits<double>::infinity();
  // Which two features d is between (kind 0 point, 1 segment, 2 facet).
  struct Feature {
    int kind = 0;
    uint32_t id = 0;
  };
  Feature near_a, near_b;
  auto closer = [&](double dist, Feature a, Feature b) {
    if (!(dist < d)) return;
    d = dist;
    near_a = a;
    near_b = b;
  };
  // Closest pair of points: grid pairs within h, doubling h until one is found.
  if (np >= 2) {
    const Vec3 ext = bounds.hi - bounds.lo;
    double h = std::max({ext.x, ext.y, ext.z}) / std::max(1.0, std::cbrt(static_cast<double>(np)));
    if (!(h > 0)) h = 1;
    for (int iter = 0; iter < 80 && !std::isfinite(d); ++iter, h *= 2) {
      BoxGrid grid(bounds, np);
      for (PointId p = 0; p < np; ++p) {
        const Vec3 e(h / 2, h / 2, h / 2);
        grid.Insert(Box3{P(p) - e, P(p) + e});
      }
      grid.ForEachOverlappingPair([&](uint32_t i, uint32_t j) {
        closer(geom::Dist(P(i), P(j)), {0, std::min(i, j)}, {0, std::max(i, j)});
      });
    }
  }
  // Points vs segments and facet triangles, segments vs segments, within d.
  if (std::isfinite(d)) {
    std::vector<std::vector<PointId>> facet_points(fc->facets.size());
    for (FacetId f = 0; f < fc->facets.size(); ++f) {
      auto& fp = facet_points[f];
      const FeatureFacet& ff = fc->facets[f];
      fp = ff.interior_points;
      for (const auto& loop : ff.loops) fp.insert(fp.end(), loop.begin(), loop.end());
      for (SegmentId s : ff.segments) {
        fp.push_back(fc->segments[s].a);
        fp.push_back(fc->segments[s].b);
      }
      std::sort(fp.begin(), fp.end());
      fp.erase(std::unique(fp.begin(), fp.end()), fp.end());
    }
    struct Prim {
      int kind;  // 0 point, 1 segment, 2 triangle
      uint32_t a, b;
    };
    std::vector<Prim> prims;
    BoxGrid grid(bounds, np + fc->segments.size() + 1);
    const Vec3 e(d / 2, d / 2, d / 2);
    auto add = [&](Prim pr, Box3 box) {
      box.lo -= e;
      box.hi += e;
      grid.Insert(box);
      prims.push_back(pr);
    };
    for (PointId p = 0; p < np; ++p) add({0, p, 0}, Box3{P(p), P(p)});
    for (SegmentId s = 0; s < fc->segments.size(); ++s) {
      Box3 b;
      b.Add(P(fc->segments[s].a));
      b.Add(P(fc->segments[s].b));
      add({1, s, 0}, b);
    }
    for (FacetId f = 0; f < fc->facets.size(); ++f) {
      for (uint32_t t = 0; t < fc->facets[f].triangles.size(); ++t) {
        Box3 b;
        for (PointId q : fc->facets[f].triangles[t]) b.Add(P(q));
        add({2, f, t}, b);
      }
    }
    grid.ForEachOverlappingPair([&](uint32_t i, uint32_t j) {
      Prim x = prims[i], y = prims[j];
      if (x.kind > y.kind) std::swap(x, y);
      if (x.kind == 0 && y.kind == 1) {
        const FeatureSegment& s = fc->segments[y.a];
        if (x.a != s.a && x.a != s.b) closer(PointSegmentDistance(P(x.a), P(s.a), P(s.b)), {0, x.a}, {1, y.a});
      } else if (x.kind == 0 && y.kind == 2) {
        if (!std::binary_search(facet_points[y.a].begin(), facet_points[y.a].end(), x.a)) {
          const auto& t = fc->facets[y.a].triangles[y.b];
          closer(PointTriangleDistance(P(x.a), P(t[0]), P(t[1]), P(t[2])), {0, x.a}, {2, y.a});
        }
      } else if (x.kind == 1 && y.kind == 1) {
        const FeatureSegment& s = fc->segments[x.a];
        const FeatureSegment& t = fc->segments[y.a];
        if (s.a != t.a && s.a != t.b && s.b != t.a && s.b != t.b) {
          closer(SegmentSegmentDistance(P(s.a), P(s.b), P(t.a), P(t.b)), {1, std::min(x.a, y.a)},
                 {1, std::max(x.a, y.a)});
        }
      }
    });
  }
  if (std::isfinite(d) && d > 0) {
    fc->min_feature_distance = d;
    fc->spread = fc->diameter / d;
    auto name = [&](Feature f) -> std::string {
      if (f.kind == 0) return fc->PointName(f.id);
      if (f.kind == 1) return fc->SegmentName(f.id);
      const uint32_t input = fc->facets[f.id].input_facet;
      return absl::StrCat("facet ", input != kNoId ? input : f.id);
    };
    fc->closest_features = absl::StrCat(name(near_a), " and ", name(near_b));
  }
}

}  // namespace svrc::plc::internal
