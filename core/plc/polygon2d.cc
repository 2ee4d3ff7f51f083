#include "core/plc/polygon2d.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/plc/exact.h"

namespace svrc::plc {

using geom::Vec3;

Vec3 NewellNormal(const std::vector<Vec3>& pts, const std::vector<uint32_t>& loop) {
  Vec3 n;
  if (loop.empty()) return n;
  // Relative to the first vertex, for accuracy far from the origin.
  const Vec3 o = pts[loop[0]];
  for (size_t i = 0; i < loop.size(); ++i) {
    const Vec3 a = pts[loop[i]] - o, b = pts[loop[(i + 1) % loop.size()]] - o;
    n.x += (a.y - b.y) * (a.z + b.z);
    n.y += (a.z - b.z) * (a.x + b.x);
    n.z += (a.x - b.x) * (a.y + b.y);
  }
  return n;
}

int DropAxis(const Vec3& n) {
  const double ax = std::fabs(n.x), ay = std::fabs(n.y), az = std::fabs(n.z);
  if (az >= ax && az >= ay) return 2;
  if (ay >= ax) return 1;
  return 0;
}

namespace {

struct Proj {
  const std::vector<Vec3>& pts;
  int drop;
  int O(uint32_t a, uint32_t b, uint32_t c) const {
    return Orient2dSign(pts[a], pts[b], pts[c], drop);
  }
  double X(uint32_t a) const { return pts[a][(drop + 1) % 3]; }
  double Y(uint32_t a) const { return pts[a][(drop + 2) % 3]; }
  bool Less(uint32_t a, uint32_t b) const {
    return X(a) < X(b) || (X(a) == X(b) && Y(a) < Y(b));
  }
};

int Orientation(const Proj& pr, const std::vector<uint32_t>& loop) {
  const size_t n = loop.size();
  if (n < 3) return 0;
  size_t m = 0;
  for (size_t i = 1; i < n; ++i) {
    if (pr.Less(loop[i], loop[m])) m = i;
  }
  // Neighbours distinct from the minimum (skip repeated ids).
  size_t p = (m + n - 1) % n, q = (m + 1) % n;
  int o = pr.O(loop[p], loop[m], loop[q]);
  if (o != 0) return o;
  // Degenerate at the extreme vertex: fall back to the sign of the area, decided
  // exactly as the sum of fan orientations is not exact; use any non-zero turn.
  double area = 0;
  for (size_t i = 0; i < n; ++i) {
    const uint32_t a = loop[i], b = loop[(i + 1) % n];
    area += (pr.X(a) - pr.X(loop[0])) * (pr.Y(b) - pr.Y(loop[0])) -
            (pr.X(b) - pr.X(loop[0])) * (pr.Y(a) - pr.Y(loop[0]));
  }
  return area > 0 ? 1 : (area < 0 ? -1 : 0);
}

bool InClosedTriangle(const Proj& pr, uint32_t a, uint32_t b, uint32_t c, uint32_t p) {
  return pr.O(a, b, p) >= 0 && pr.O(b, c, p) >= 0 && pr.O(c, a, p) >= 0;
}

// Ear clipping of a counter-clockwise (in `pr`) polygon whose vertex ids may
// repeat (hole bridges). Returns false if it gets stuck on a non-degenerate rest.
bool EarClip(const Proj& pr, const std::vector<uint32_t>& poly,
             std::vector<std::array<uint32_t, 3>>* out) {
  const size_t n = poly.size();
  if (n < 3) return false;
  std::vector<size_t> prv(n), nxt(n);
  for (size_t i = 0; i < n; ++i) {
    prv[i] = (i + n - 1) % n;
    nxt[i] = (i + 1) % n;
  }
  std::vector<std::array<uint32_t, 3>> tris;
  size_t remaining = n, i = 0, since_clip = 0;
  while (remaining > 3) {
    const size_t a = prv[i], c = nxt[i];
    const uint32_t ia = poly[a], ib = poly[i], ic = poly[c];
    bool ear = pr.O(ia, ib, ic) > 0;
    if (ear) {
      for (size_t j = nxt[c]; j != a; j = nxt[j]) {
        const uint32_t ij = poly[j];
        if (ij == ia || ij == ib || ij == ic) continue;
        // Only non-convex vertices can lie in an ear; testing all is simpler and safe.
        if (InClosedTriangle(pr, ia, ib, ic, ij)) {
          ear = false;
          break;
        }
      }
    }
    if (ear) {
      tris.push_back({ia, ib, ic});
      nxt[a] = c;
      prv[c] = a;
      --remaining;
      i = a;
      since_clip = 0;
      continue;
    }
    // Remove a straight vertex whose neighbours continue the line (zero-area
    // spike or collinear run) only when nothing else works: see below.
    i = nxt[i];
    if (++since_clip > remaining) {
      // Stuck: succeed only if the rest has zero area (all collinear).
      for (size_t k = 0, j = i; k < remaining; ++k, j = nxt[j]) {
        if (pr.O(poly[prv[j]], poly[j], poly[nxt[j]]) != 0) return false;
      }
      out->insert(out->end(), tris.begin(), tris.end());
      return true;
    }
  }
  const size_t a = prv[i], c = nxt[i];
  if (pr.O(poly[a], poly[i], poly[c]) > 0) tris.push_back({poly[a], poly[i], poly[c]});
  else if (pr.O(poly[a], poly[i], poly[c]) < 0) return false;
  out->insert(out->end(), tris.begin(), tris.end());
  return true;
}

// Does the closed segment pq meet the closed segment rs (projection)?
bool SegmentsMeet(const Proj& pr, uint32_t p, uint32_t q, uint32_t r, uint32_t s) {
  const int o1 = pr.O(p, q, r), o2 = pr.O(p, q, s), o3 = pr.O(r, s, p), o4 = pr.O(r, s, q);
  if (o1 * o2 < 0 && o3 * o4 < 0) return true;
  auto on = [&](uint32_t a, uint32_t b, uint32_t x) {  // x collinear with ab: within the box?
    return std::min(pr.X(a), pr.X(b)) <= pr.X(x) && pr.X(x) <= std::max(pr.X(a), pr.X(b)) &&
           std::min(pr.Y(a), pr.Y(b)) <= pr.Y(x) && pr.Y(x) <= std::max(pr.Y(a), pr.Y(b));
  };
  if (o1 == 0 && on(p, q, r)) return true;
  if (o2 == 0 && on(p, q, s)) return true;
  if (o3 == 0 && on(r, s, p)) return true;
  if (o4 == 0 && on(r, s, q)) return true;
  return false;
}

}  // namespace

int LoopOrientation(const std::vector<Vec3>& pts, const std::vector<uint32_t>& loop, int drop) {
  return Orientation(Proj{pts, drop}, loop);
}

bool PointInLoop(const std::vector<Vec3>& pts, const std::vector<uint32_t>& loop, const Vec3& q,
                 int drop) {
  const int i = (drop + 1) % 3, j = (drop + 2) % 3;
  bool inside = false;
  for (size_t k = 0, n = loop.size(); k < n; ++k) {
    const Vec3& a = pts[loop[k]];
    const Vec3& b = pts[loop[(k + 1) % n]];
    if ((a[j] > q[j]) != (b[j] > q[j])) {
      const double x = a[i] + (q[j] - a[j]) * (b[i] - a[i]) / (b[j] - a[j]);
      if (q[i] < x) inside = !inside;
    }
  }
  return inside;
}

bool TriangulatePolygon(const std::vector<Vec3>& pts, const std::vector<uint32_t>& outer_in,
                        const std::vector<std::vector<uint32_t>>& holes_in, int drop,
                        std::vector<std::array<uint32_t, 3>>* triangles) {
  const Proj pr{pts, drop};
  const int so = Orientation(pr, outer_in);
  if (so == 0) return false;
  std::vector<uint32_t> poly = outer_in;
  if (so < 0) std::reverse(poly.begin(), poly.end());
  // Holes clockwise, bridged in order of decreasing max x (Eberly's ordering):
  // the bridge from a hole's rightmost vertex then never crosses a later hole.
  struct H {
    std::vector<uint32_t> loop;
    size_t right;  // index of the rightmost vertex
  };
  std::vector<H> holes;
  for (const auto& h : holes_in) {
    const int sh = Orientation(pr, h);
    if (sh == 0) return false;
    H hh{h, 0};
    if (sh > 0) std::reverse(hh.loop.begin(), hh.loop.end());
    for (size_t k = 1; k < hh.loop.size(); ++k) {
      if (pr.Less(hh.loop[hh.right], hh.loop[k])) hh.right = k;
    }
    holes.push_back(std::move(hh));
  }
  std::sort(holes.begin(), holes.end(), [&](const H& a, const H& b) {
    return pr.Less(b.loop[b.right], a.loop[a.right]);
  });
  for (size_t h = 0; h < holes.size(); ++h) {
    const uint32_t m = holes[h].loop[holes[h].right];
    // Candidate outer vertices by distance from m.
    std::vector<size_t> cand(poly.size());
    std::iota(cand.begin(), cand.end(), 0);
    auto d2 = [&](size_t k) {
      const double dx = pr.X(poly[k]) - pr.X(m), dy = pr.Y(poly[k]) - pr.Y(m);
      return dx * dx + dy * dy;
    };
    std::stable_sort(cand.begin(), cand.end(), [&](size_t a, size_t b) { return d2(a) < d2(b); });
    size_t chosen = poly.size();
    for (size_t k : cand) {
      const uint32_t p = poly[k];
      const uint32_t a = poly[(k + poly.size() - 1) % poly.size()], b = poly[(k + 1) % poly.size()];
      // m must lie in the interior cone at p (ccw polygon).
      const int turn = pr.O(a, p, b);
      const int l1 = pr.O(a, p, m), l2 = pr.O(p, b, m);
      const bool in_cone = turn > 0 ? (l1 > 0 && l2 > 0) : (turn < 0 ? (l1 > 0 || l2 > 0) : l1 > 0);
      if (!in_cone) continue;
      bool blocked = false;
      auto check_loop = [&](const std::vector<uint32_t>& loop) {
        for (size_t e = 0; e < loop.size() && !blocked; ++e) {
          const uint32_t r = loop[e], s = loop[(e + 1) % loop.size()];
          if (r == p || s == p || r == m || s == m) continue;
          if (SegmentsMeet(pr, p, m, r, s)) blocked = true;
        }
      };
      check_loop(poly);
      for (size_t g = h; g < holes.size() && !blocked; ++g) check_loop(holes[g].loop);
      if (!blocked) {
        chosen = k;
        break;
      }
    }
    if (chosen == poly.size()) return false;
    // poly[0..chosen], m, hole..., m, poly[chosen], poly[chosen+1..]
    std::vector<uint32_t> merged(poly.begin(), poly.begin() + chosen + 1);
    const auto& hl = holes[h].loop;
    for (size_t k = 0; k <= hl.size(); ++k) merged.push_back(hl[(holes[h].right + k) % hl.size()]);
    merged.insert(merged.end(), poly.begin() + chosen, poly.end());
    poly.swap(merged);
  }
  return EarClip(pr, poly, triangles);
}

namespace {

bool HasVertex(const std::array<uint32_t, 3>& t, uint32_t v) {
  return t[0] == v || t[1] == v || t[2] == v;
}

bool InsertPoint(const Proj& pr, uint32_t p, std::vector<std::array<uint32_t, 3>>& tris) {
  for (const auto& t : tris) {
    if (HasVertex(t, p)) return true;
  }
  for (size_t i = 0; i < tris.size(); ++i) {
    const auto t = tris[i];
    int o[3];
    for (int k = 0; k < 3; ++k) o[k] = pr.O(t[k], t[(k + 1) % 3], p);  // edge k = t[k] t[k+1]
    if (o[0] < 0 || o[1] < 0 || o[2] < 0) continue;
    int zero = -1, nz = 0;
    for (int k = 0; k < 3; ++k) {
      if (o[k] == 0) {
        zero = k;
        ++nz;
      }
    }
    if (nz > 1) return false;  // coincides with a vertex (excluded above): degenerate
    if (nz == 0) {
      tris[i] = {t[0], t[1], p};
      tris.push_back({t[1], t[2], p});
      tris.push_back({t[2], t[0], p});
      return true;
    }
    // On edge (a, b) = (t[zero], t[zero+1]); c opposite.
    const uint32_t a = t[zero], b = t[(zero + 1) % 3], c = t[(zero + 2) % 3];
    tris[i] = {a, p, c};
    tris.push_back({p, b, c});
    for (size_t j = 0; j < tris.size(); ++j) {
      const auto u = tris[j];
      for (int k = 0; k < 3; ++k) {
        if (u[k] == b && u[(k + 1) % 3] == a) {
          const uint32_t x = u[(k + 2) % 3];
          tris[j] = {b, p, x};
          tris.push_back({p, a, x});
          return true;
        }
      }
    }
    return true;  // a boundary edge
  }
  return false;
}

bool InsertSegment(const Proj& pr, uint32_t a, uint32_t b, std::vector<std::array<uint32_t, 3>>& tris) {
  for (const auto& t : tris) {
    if (HasVertex(t, a) && HasVertex(t, b)) return true;  // already an edge
  }
  // Cavity: triangles with an edge properly crossed by ab.
  auto crosses = [&](uint32_t u, uint32_t v) {
    if (u == a || u == b || v == a || v == b) return false;
    return pr.O(a, b, u) * pr.O(a, b, v) < 0 && pr.O(u, v, a) * pr.O(u, v, b) < 0;
  };
  std::vector<std::array<uint32_t, 3>> keep, cavity;
  for (const auto& t : tris) {
    bool c = false;
    for (int k = 0; k < 3 && !c; ++k) c = crosses(t[k], t[(k + 1) % 3]);
    (c ? cavity : keep).push_back(t);
  }
  if (cavity.empty()) return false;
  // Boundary edges of the cavity (counter-clockwise), chained from a.
  std::vector<std::pair<uint32_t, uint32_t>> bnd;
  for (const auto& t : cavity) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t u = t[k], v = t[(k + 1) % 3];
      bool inner = false;
      for (const auto& s : cavity) {
        for (int m = 0; m < 3; ++m) inner |= s[m] == v && s[(m + 1) % 3] == u;
      }
      if (!inner) bnd.push_back({u, v});
    }
  }
  std::vector<uint32_t> loop{a};
  for (size_t guard = 0; guard <= bnd.size(); ++guard) {
    uint32_t next = UINT32_MAX;
    int found = 0;
    for (const auto& [u, v] : bnd) {
      if (u == loop.back()) {
        next = v;
        ++found;
      }
    }
    if (found != 1) return false;
    if (next == a) break;
    loop.push_back(next);
  }
  if (loop.size() != bnd.size()) return false;
  const auto bpos = std::find(loop.begin(), loop.end(), b);
  if (bpos == loop.end()) return false;
  // Two polygons: a .. b (one side) and b .. a (the other), each closed by ab.
  std::vector<uint32_t> left(loop.begin(), bpos + 1);
  std::vector<uint32_t> right(bpos, loop.end());
  right.push_back(a);
  std::vector<std::array<uint32_t, 3>> out;
  for (auto* poly : {&left, &right}) {
    if (poly->size() < 3) return false;
    std::vector<std::array<uint32_t, 3>> part;
    if (!TriangulatePolygon(pr.pts, *poly, {}, pr.drop, &part)) return false;
    out.insert(out.end(), part.begin(), part.end());
  }
  keep.insert(keep.end(), out.begin(), out.end());
  tris.swap(keep);
  return true;
}

}  // namespace

bool InsertConstraints(const std::vector<Vec3>& pts, int drop, const std::vector<uint32_t>& points,
                       const std::vector<std::array<uint32_t, 2>>& segments,
                       std::vector<std::array<uint32_t, 3>>* triangles) {
  const Proj pr{pts, drop};
  for (uint32_t p : points) {
    if (!InsertPoint(pr, p, *triangles)) return false;
  }
  for (const auto& s : segments) {
    if (!InsertPoint(pr, s[0], *triangles) || !InsertPoint(pr, s[1], *triangles)) return false;
  }
  for (const auto& s : segments) {
    if (!InsertSegment(pr, s[0], s[1], *triangles)) return false;
  }
  return true;
}

bool PointInsideLoop(const std::vector<Vec3>& pts, const std::vector<uint32_t>& loop, int drop,
                     Vec3* out) {
  std::vector<std::array<uint32_t, 3>> tris;
  if (!TriangulatePolygon(pts, loop, {}, drop, &tris) || tris.empty()) return false;
  // The largest triangle (by projected area) keeps the point away from edges.
  const Proj pr{pts, drop};
  double best = -1;
  for (const auto& t : tris) {
    const double area = std::fabs((pr.X(t[1]) - pr.X(t[0])) * (pr.Y(t[2]) - pr.Y(t[0])) -
                                  (pr.X(t[2]) - pr.X(t[0])) * (pr.Y(t[1]) - pr.Y(t[0])));
    if (area > best) {
      best = area;
      *out = (pts[t[0]] + pts[t[1]] + pts[t[2]]) / 3.0;
    }
  }
  return true;
}

}  // namespace svrc::plc
