#include "core/svrc/rip_stitch.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <tuple>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "core/geometry/predicates.h"
#include "core/svrc/ball_grid.h"

namespace svrc::refine {

using delaunay::Delaunay3;
using delaunay::TetId;
using delaunay::VertexId;
using Kind = StitchFailure::Kind;

const char* StitchFailureKindName(Kind kind) {
  switch (kind) {
    case Kind::kUnlistedCircle: return "unlisted_circle";
    case Kind::kCreaseVertexOnSurface: return "crease_vertex_on_surface";
    case Kind::kNoCrossing: return "no_crossing";
    case Kind::kMultipleCrossings: return "multiple_crossings";
    case Kind::kLargeAngle: return "large_angle";
    case Kind::kCoarseSample: return "coarse_sample";
    case Kind::kStarInverted: return "star_inverted";
    case Kind::kStarFlat: return "star_flat";
    case Kind::kNonManifoldEdge: return "non_manifold_edge";
    case Kind::kCircleCrossing: return "circle_crossing";
    case Kind::kBookDegenerate: return "book_degenerate";
    case Kind::kBookFlat: return "book_flat";
    case Kind::kFaceMismatch: return "face_mismatch";
    case Kind::kBookFold: return "book_fold";
    case Kind::kVertexOutsideCollars: return "vertex_outside_collars";
    case Kind::kCreaseVertexUnused: return "crease_vertex_unused";
    case Kind::kCreaseEdgeMissing: return "crease_edge_missing";
  }
  return "?";
}

namespace {

constexpr double kRadToDeg = 180 / std::numbers::pi;
constexpr uint32_t kNone = 0xFFFFFFFFu;

Vec3 Unit(const Vec3& v) {
  const double n = geom::Norm(v);
  return n > 0 ? v / n : v;
}

Vec3 Min3(const Vec3& a, const Vec3& b) {
  return Vec3(std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z));
}
Vec3 Max3(const Vec3& a, const Vec3& b) {
  return Vec3(std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z));
}

double PlaneAngle(const Vec3& a, const Vec3& b, const Vec3& c) { return AngleBetween(b - a, c - a); }

// Side of the apex (position k of a positively oriented tet) relative to the
// face's vertices in ascending order: Orient3d(sorted face, apex). For a
// positive tet the apex at k is on the positive side of the other three in tet
// order iff k is odd; sorting them multiplies by the permutation's sign.
struct SortedFace {
  std::array<uint32_t, 3> key;
  int8_t side;
};
SortedFace FaceOf(const std::array<uint32_t, 4>& tet, int k) {
  std::array<uint32_t, 3> f;
  for (int i = 0, m = 0; i < 4; ++i) {
    if (i != k) f[m++] = tet[i];
  }
  int parity = 0;
  for (int i = 0; i < 3; ++i) {
    for (int j = i + 1; j < 3; ++j) parity ^= (f[i] > f[j]) ? 1 : 0;
  }
  std::sort(f.begin(), f.end());
  const int side = ((k & 1) ? 1 : -1) * (parity ? -1 : 1);
  return {f, static_cast<int8_t>(side)};
}

std::string Fmt(const Vec3& p) {
  char buf[96];
  std::snprintf(buf, sizeof(buf), "(%.9g, %.9g, %.9g)", p.x, p.y, p.z);
  return buf;
}

// A hole-boundary face: inside tet `tin`, face `f` (opposite its vertex f).
struct BoundaryFace {
  TetId tin;
  int f = 0;
  std::array<uint32_t, 4> tet;  // tin's vertices; tet[f] is the apex
  uint32_t ball = kNone;        // partial sphere carrying the representation point
  Vec3 x;                       // representation point
};

struct CreasePair {
  uint32_t i = 0, j = 0;  // i < j
  bool crosses = false;
  Circle3 circle;
  uint32_t books = 0;
};

}  // namespace

double StitchedTetFlatness(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  // Altitude over face k = 3V / area_k = |det| / (2 area_k); the smallest is
  // over the largest face.
  const double det = std::fabs(geom::Dot(b - a, geom::Cross(c - a, d - a)));
  const double twice_area = std::max({geom::Norm(geom::Cross(b - a, c - a)), geom::Norm(geom::Cross(b - a, d - a)),
                                      geom::Norm(geom::Cross(c - a, d - a)), geom::Norm(geom::Cross(c - b, d - b))});
  const double longest = std::sqrt(std::max({geom::Dist2(a, b), geom::Dist2(a, c), geom::Dist2(a, d),
                                             geom::Dist2(b, c), geom::Dist2(b, d), geom::Dist2(c, d)}));
  if (!(twice_area > 0) || !(longest > 0)) return 0;
  return det / twice_area / longest;
}

std::vector<uint32_t> PruneHiddenChainBalls(std::span<const CollarBall> balls, std::vector<uint32_t>* chain) {
  std::vector<uint32_t> hidden;
  std::vector<uint32_t>& c = *chain;
  size_t k = 1;
  while (k + 1 < c.size()) {
    const CollarBall& b = balls[c[k]];
    Circle3 circle;
    bool hide = false;
    if (SphereSphereCircle(balls[c[k - 1]], balls[c[k + 1]], &circle)) {
      // Nearest point of the circle to b's centre: axial offset a, radial
      // offset q from the circle's axis; squared distance a² + (h − q)².
      const Vec3 v = b.center - circle.center;
      const double a = geom::Dot(v, circle.normal);
      const double q = geom::Norm(v - a * circle.normal);
      const double dmin = circle.radius - q;
      hide = a * a + dmin * dmin >= b.radius * b.radius;
    }
    if (!hide) {
      ++k;
      continue;
    }
    hidden.push_back(c[k]);
    c.erase(c.begin() + static_cast<std::ptrdiff_t>(k));
    if (k > 1) --k;
  }
  return hidden;
}

absl::StatusOr<StitchResult> RipStitchCollar(const StitchInput& in,
                                             std::vector<StitchFailure>* failures) {
  if (in.dt == nullptr) return absl::InvalidArgumentError("RipStitchCollar: null triangulation");
  const Delaunay3& dt = *in.dt;
  if (!dt.Is3d()) return absl::InvalidArgumentError("RipStitchCollar: triangulation is not 3D");
  const uint32_t nv = dt.NumVertices();
  const uint32_t nb = static_cast<uint32_t>(in.balls.size());
  std::vector<CollarBall> balls(nb);
  std::vector<uint32_t> ball_of_vertex(nv, kNone);  // crease vertex → its ball
  for (uint32_t i = 0; i < nb; ++i) {
    const StitchBall& sb = in.balls[i];
    if (!sb.centre.valid() || sb.centre.value() >= nv || !(sb.ball.radius > 0)) {
      return absl::InvalidArgumentError(absl::StrCat("RipStitchCollar: ball ", i, " has a bad centre or radius"));
    }
    if (!dt.VertexTet(sb.centre).valid()) {
      return absl::InvalidArgumentError(absl::StrCat("RipStitchCollar: ball ", i, "'s centre is not in the triangulation"));
    }
    if (ball_of_vertex[sb.centre.value()] != kNone) {
      return absl::InvalidArgumentError(absl::StrCat("RipStitchCollar: balls ", ball_of_vertex[sb.centre.value()], " and ", i, " share a centre vertex"));
    }
    if (geom::InBall(dt.Point(sb.centre), sb.ball.center, sb.ball.radius) <= 0) {
      return absl::InvalidArgumentError(absl::StrCat("RipStitchCollar: ball ", i, "'s centre vertex is not inside it"));
    }
    ball_of_vertex[sb.centre.value()] = i;
    balls[i] = sb.ball;
  }
  auto P = [&dt](uint32_t v) -> const Vec3& { return dt.Point(VertexId(v)); };

  std::vector<StitchFailure> fails;
  const BallGrid grid(balls);
  std::vector<uint32_t> cand;
  auto nearest_ball = [&](const Vec3& p) {
    uint32_t best = StitchFailure::kNoBall;
    double bd = std::numeric_limits<double>::infinity();
    for (uint32_t i = 0; i < nb; ++i) {
      const double d = geom::Dist(p, balls[i].center) - balls[i].radius;
      if (d < bd) {
        bd = d;
        best = i;
      }
    }
    return best;
  };
  auto fail = [&](Kind kind, const Vec3& where, uint32_t ball, std::string detail) {
    if (ball == StitchFailure::kNoBall) ball = nearest_ball(where);
    fails.push_back(StitchFailure{kind, where, ball, std::move(detail)});
  };
  // css(x) ≈ min_j max(ρ_j, |x c_j|) (guide: 1-Lipschitz minorant of rad, Def 32).
  auto css = [&](const Vec3& x, double upper) {
    double best = upper;
    std::vector<uint32_t> near;
    grid.Query(x - Vec3(upper, upper, upper), x + Vec3(upper, upper, upper), &near);
    for (uint32_t j : near) best = std::min(best, std::max(balls[j].radius, geom::Dist(x, balls[j].center)));
    return best;
  };

  // --- Crease pairs and their circles; unlisted crossing pairs (Lemma 13).
  std::vector<CreasePair> pairs;
  for (auto [a, b] : in.crease_edges) {
    if (a >= nb || b >= nb || a == b) {
      return absl::InvalidArgumentError(absl::StrCat("RipStitchCollar: bad crease edge (", a, ", ", b, ")"));
    }
    CreasePair cp;
    cp.i = std::min(a, b);
    cp.j = std::max(a, b);
    pairs.push_back(cp);
  }
  std::sort(pairs.begin(), pairs.end(), [](const CreasePair& p, const CreasePair& q) {
    return std::pair(p.i, p.j) < std::pair(q.i, q.j);
  });
  pairs.erase(std::unique(pairs.begin(), pairs.end(),
                          [](const CreasePair& p, const CreasePair& q) { return p.i == q.i && p.j == q.j; }),
              pairs.end());
  StitchResult res;
  std::vector<std::vector<uint32_t>> circles_of_ball(nb);
  for (uint32_t k = 0; k < pairs.size(); ++k) {
    CreasePair& cp = pairs[k];
    cp.crosses = SphereSphereCircle(balls[cp.i], balls[cp.j], &cp.circle);
    if (cp.crosses) {
      circles_of_ball[cp.i].push_back(k);
      circles_of_ball[cp.j].push_back(k);
    } else {
      ++res.crease_edges_without_circle;
    }
  }
  auto find_pair = [&pairs](uint32_t a, uint32_t b) -> uint32_t {
    const std::pair<uint32_t, uint32_t> key(std::min(a, b), std::max(a, b));
    auto it = std::lower_bound(pairs.begin(), pairs.end(), key,
                               [](const CreasePair& p, const std::pair<uint32_t, uint32_t>& k) {
                                 return std::pair(p.i, p.j) < k;
                               });
    return (it != pairs.end() && it->i == key.first && it->j == key.second)
               ? static_cast<uint32_t>(it - pairs.begin())
               : kNone;
  };
  for (uint32_t i = 0; i < nb; ++i) {
    const double r = balls[i].radius;
    grid.Query(balls[i].center - Vec3(r, r, r), balls[i].center + Vec3(r, r, r), &cand);
    for (uint32_t j : cand) {
      if (j <= i) continue;
      Circle3 c;
      if (!SphereSphereCircle(balls[i], balls[j], &c)) continue;
      const uint32_t k = find_pair(i, j);
      if (k == kNone) {
        // A circle covered by the other balls is not on S (Definition 26):
        // balls of non-consecutive points of one crease overlap inside the
        // ball between them, which is no circle of the collar description.
        std::vector<CollarBall> others;
        for (uint32_t o : cand) {
          if (o != i && o != j) others.push_back(balls[o]);
        }
        if (ClipCircleByBalls(c, others).empty()) continue;
        fail(Kind::kUnlistedCircle, CirclePoint(c, 0), i,
             absl::StrCat("spheres of balls ", i, " and ", j, " cross but are not a crease edge"));
      }
    }
  }

  // --- 1. Inside tets: circumcentre strictly inside the union of the balls.
  const uint32_t cap = dt.TetCapacity();
  std::vector<uint8_t> inside(cap, 0);
  for (uint32_t ti = 0; ti < cap; ++ti) {
    const TetId t(ti);
    if (!dt.IsAlive(t) || dt.IsGhost(t)) continue;
    if (grid.StrictlyInside(dt.Circumcenter(t))) {
      inside[ti] = 1;
      ++res.inside_tets;
    } else {
      ++res.outside_tets;
    }
  }

  // --- 2–3. T′ and stars.
  // Length of a hull face's Voronoi ray: enough to leave every ball.
  const Vec3 bb_mid = 0.5 * (grid.lo() + grid.hi());
  const double bb_half = 0.5 * geom::Dist(grid.lo(), grid.hi());
  std::vector<BoundaryFace> faces;
  std::vector<uint8_t> centre_face_failed(nb, 0);
  std::vector<std::pair<uint32_t, Vec3>> roots;
  double s[2];
  for (uint32_t ti = 0; ti < cap; ++ti) {
    if (!inside[ti]) continue;
    const TetId t(ti);
    const Vec3 cin = dt.Circumcenter(t);
    for (int f = 0; f < 4; ++f) {
      const TetId u = dt.Neighbor(t, f);
      const bool hull = dt.IsGhost(u);
      if (!hull && inside[u.value()]) continue;
      BoundaryFace bf;
      bf.tin = t;
      bf.f = f;
      for (int k = 0; k < 4; ++k) bf.tet[k] = dt.TetVertex(t, k).value();
      const uint32_t fa = bf.tet[(f + 1) & 3], fb = bf.tet[(f + 2) & 3], fc = bf.tet[(f + 3) & 3];
      const Vec3 centroid = (P(fa) + P(fb) + P(fc)) / 3.0;
      Vec3 end;
      if (hull) {
        Vec3 n = geom::Cross(P(fb) - P(fa), P(fc) - P(fa));
        if (geom::Dot(n, P(bf.tet[f]) - P(fa)) > 0) n = -1.0 * n;
        end = cin + (2 * (geom::Dist(cin, bb_mid) + bb_half) + 1) * Unit(n);
      } else {
        end = dt.Circumcenter(u);
      }
      grid.Query(Min3(cin, end), Max3(cin, end), &cand);
      roots.clear();
      for (uint32_t j : cand) {
        const int nr = SegmentSphere(cin, end, balls[j], s);
        for (int k = 0; k < nr; ++k) {
          const Vec3 x = cin + s[k] * (end - cin);
          if (!grid.StrictlyInside(x, j)) roots.push_back({j, x});
        }
      }
      const std::string face_name = absl::StrCat("face (", fa, ", ", fb, ", ", fc, ")");
      if (roots.empty()) {
        fail(Kind::kNoCrossing, centroid, StitchFailure::kNoBall,
             absl::StrCat("Voronoi edge of hole-boundary ", face_name, " does not meet S"));
        faces.push_back(bf);
        continue;
      }
      if (roots.size() > 1) {
        fail(Kind::kMultipleCrossings, roots[0].second, roots[0].first,
             absl::StrCat("Voronoi edge of ", face_name, " meets S ", roots.size(), " times"));
        faces.push_back(bf);
        continue;
      }
      bf.ball = roots[0].first;
      bf.x = roots[0].second;
      const CollarBall& b = balls[bf.ball];
      for (uint32_t v : {fa, fb, fc}) {
        const uint32_t cb = ball_of_vertex[v];
        if (cb != kNone) {
          centre_face_failed[cb] = 1;
          fail(Kind::kCreaseVertexOnSurface, bf.x, cb,
               absl::StrCat("crease vertex ", v, " (ball ", cb, ") is on hole-boundary ", face_name));
        }
      }
      const Vec3 nrm = geom::Cross(P(fb) - P(fa), P(fc) - P(fa));
      const double sigma = RepresentationAngle(nrm, bf.x, b.center);
      const double rep = geom::Dist(bf.x, P(fa));
      if (sigma > in.options.max_rep_angle) {
        fail(Kind::kLargeAngle, bf.x, bf.ball,
             absl::StrCat(face_name, ": representation angle ", sigma * kRadToDeg, " deg > ",
                          in.options.max_rep_angle * kRadToDeg));
      }
      const double cs = css(bf.x, b.radius);
      if (rep > in.options.max_rep_ratio * cs) {
        fail(Kind::kCoarseSample, bf.x, bf.ball,
             absl::StrCat(face_name, ": RepBall radius ", rep, " > ", in.options.max_rep_ratio,
                          " * css ", cs));
      }
      std::array<uint32_t, 4> star = bf.tet;
      star[f] = in.balls[bf.ball].centre.value();
      if (geom::Orient3d(P(star[0]), P(star[1]), P(star[2]), P(star[3])) <= 0) {
        fail(Kind::kStarInverted, bf.x, bf.ball,
             absl::StrCat("star of ball ", bf.ball, " over ", face_name, " is not positively oriented"));
      } else if (const double fl = StitchedTetFlatness(P(star[0]), P(star[1]), P(star[2]), P(star[3]));
                 fl < in.options.min_flatness) {
        fail(Kind::kStarFlat, bf.x, bf.ball,
             absl::StrCat("star of ball ", bf.ball, " over ", face_name, " is flat (altitude ", fl,
                          " of its longest edge)"));
      }
      faces.push_back(bf);
    }
  }
  res.boundary_faces = static_cast<uint32_t>(faces.size());

  // --- 4. Edges of T′ and books.
  struct EdgeRec {
    uint32_t a, b, face;
  };
  std::vector<EdgeRec> erec;
  erec.reserve(3 * faces.size());
  for (uint32_t fi = 0; fi < faces.size(); ++fi) {
    const BoundaryFace& bf = faces[fi];
    for (int k = 1; k <= 3; ++k) {
      uint32_t a = bf.tet[(bf.f + k) & 3], b = bf.tet[(bf.f + k % 3 + 1) & 3];
      if (a > b) std::swap(a, b);
      erec.push_back({a, b, fi});
    }
  }
  std::sort(erec.begin(), erec.end(), [](const EdgeRec& p, const EdgeRec& q) {
    return std::tie(p.a, p.b, p.face) < std::tie(q.a, q.b, q.face);
  });
  // Crossings of `circle` with the Voronoi facet of ab that are on S: x on the
  // bisector plane (constructed) and in V(a), i.e. no Delaunay neighbour of a
  // nearer than a (relative tie tolerance 1e-12, as RestrictedCircleEdges).
  auto facet_crossings = [&](uint32_t a, uint32_t b, const CreasePair& cp, Vec3 out[2]) {
    const Circle3& circle = cp.circle;
    Vec3 cu, cw;
    CircleFrame(circle, &cu, &cw);
    const Vec3 n = P(b) - P(a);
    const Vec3 mid = 0.5 * (P(a) + P(b));
    const double A = circle.radius * geom::Dot(n, cu);
    const double B = circle.radius * geom::Dot(n, cw);
    const double D = geom::Dot(n, mid - circle.center);
    const double amp = std::hypot(A, B);
    if (!(amp > std::fabs(D))) return 0;
    const double phi = std::atan2(B, A), half = std::acos(D / amp);
    int cnt = 0;
    for (double tt : {phi - half, phi + half}) {
      const Vec3 x = circle.center + circle.radius * (std::cos(tt) * cu + std::sin(tt) * cw);
      if (grid.StrictlyInside(x, cp.i, cp.j)) continue;
      const double da = geom::Dist(x, P(a));
      bool in_cell = true;
      for (VertexId w : dt.NeighborsView(VertexId(a))) {
        if (w.value() == b) continue;
        if (geom::Dist(x, dt.Point(w)) < da * (1 - 1e-12)) {
          in_cell = false;
          break;
        }
      }
      if (in_cell) out[cnt++] = x;
    }
    return cnt;
  };
  struct Book {
    std::array<uint32_t, 4> tet;
    uint32_t pair;
    Vec3 x;
  };
  std::vector<Book> books;
  Vec3 xs[2];
  for (size_t e0 = 0; e0 < erec.size();) {
    size_t e1 = e0;
    while (e1 < erec.size() && erec[e1].a == erec[e0].a && erec[e1].b == erec[e0].b) ++e1;
    const uint32_t a = erec[e0].a, b = erec[e0].b;
    const Vec3 mid = 0.5 * (P(a) + P(b));
    const std::string edge_name = absl::StrCat("T' edge (", a, ", ", b, ")");
    if (e1 - e0 != 2) {
      const BoundaryFace& f0 = faces[erec[e0].face];
      fail(Kind::kNonManifoldEdge, f0.ball != kNone ? f0.x : mid, f0.ball,
           absl::StrCat(edge_name, " is in ", e1 - e0, " hole-boundary faces"));
      e0 = e1;
      continue;
    }
    const BoundaryFace& f0 = faces[erec[e0].face];
    const BoundaryFace& f1 = faces[erec[e0 + 1].face];
    e0 = e1;
    if (f0.ball == kNone || f1.ball == kNone) continue;  // already reported
    if (f0.ball == f1.ball) {
      // No circle of this ball may cross the facet (its restricted curve would
      // leave the partial sphere and come back: not a topological ball).
      for (uint32_t k : circles_of_ball[f0.ball]) {
        const int c = facet_crossings(a, b, pairs[k], xs);
        if (c != 0) {
          fail(Kind::kCircleCrossing, xs[0], f0.ball,
               absl::StrCat("circle of balls ", pairs[k].i, ", ", pairs[k].j, " crosses the Voronoi facet of ",
                            edge_name, " ", c, " times, but both its faces are on ball ", f0.ball));
        }
      }
      continue;
    }
    const uint32_t k = find_pair(f0.ball, f1.ball);
    if (k == kNone || !pairs[k].crosses) {
      fail(Kind::kCircleCrossing, 0.5 * (f0.x + f1.x), f0.ball,
           absl::StrCat(edge_name, " joins faces on balls ", f0.ball, " and ", f1.ball,
                        ", which have no crease-edge circle"));
      continue;
    }
    CreasePair& cp = pairs[k];
    const int c = facet_crossings(a, b, cp, xs);
    if (c != 1) {
      // Report a point of S: the circle point nearest the edge's midpoint.
      // (A midpoint on the circle's axis is equally near every point of it:
      // angle 0 of its frame.)
      Vec3 where = xs[0];
      if (c == 0 && !NearestCirclePoint(cp.circle, mid, &where)) where = CirclePoint(cp.circle, 0);
      fail(Kind::kCircleCrossing, where, cp.i,
           absl::StrCat("circle of balls ", cp.i, ", ", cp.j, " crosses the Voronoi facet of ",
                        edge_name, " ", c, " times (expected once)"));
      continue;
    }
    const uint32_t v = in.balls[cp.i].centre.value(), w = in.balls[cp.j].centre.value();
    Book bk{{v, w, a, b}, k, xs[0]};
    const int o = geom::Orient3d(P(v), P(w), P(a), P(b));
    if (o == 0) {
      fail(Kind::kBookDegenerate, xs[0], cp.i, absl::StrCat("book (", v, ", ", w, ", ", a, ", ", b, ") is flat"));
      continue;
    }
    if (const double fl = StitchedTetFlatness(P(v), P(w), P(a), P(b)); fl < in.options.min_flatness) {
      fail(Kind::kBookFlat, xs[0], cp.i,
           absl::StrCat("book (", v, ", ", w, ", ", a, ", ", b, ") is flat (altitude ", fl, " of its longest edge)"));
      continue;
    }
    if (o < 0) std::swap(bk.tet[2], bk.tet[3]);
    const double sigma_e = CircleRepresentationAngle(P(a), P(b), cp.circle, xs[0]);
    const double rep = std::max(geom::Dist(xs[0], P(a)), geom::Dist(xs[0], P(b)));
    if (sigma_e > in.options.max_rep_angle) {
      fail(Kind::kLargeAngle, xs[0], cp.i,
           absl::StrCat(edge_name, ": circle representation angle ", sigma_e * kRadToDeg, " deg > ",
                        in.options.max_rep_angle * kRadToDeg));
    }
    const double cs = css(xs[0], std::min(balls[cp.i].radius, balls[cp.j].radius));
    if (rep > in.options.max_rep_ratio * cs) {
      fail(Kind::kCoarseSample, xs[0], cp.i,
           absl::StrCat(edge_name, ": circle RepBall radius ", rep, " > ", in.options.max_rep_ratio,
                        " * css ", cs));
    }
    ++cp.books;
    books.push_back(bk);
  }
  // Read by nothing below; at the output below it would sit beside the tets.
  std::vector<EdgeRec>().swap(erec);

  // --- Vertices: used by outside tets (hull vertices count: ghosts are outside).
  std::vector<uint8_t> outside_vertex(nv, 0);
  for (uint32_t ti = 0; ti < cap; ++ti) {
    const TetId t(ti);
    if (!dt.IsAlive(t) || inside[ti]) continue;
    for (int k = 0; k < 4; ++k) {
      const VertexId v = dt.TetVertex(t, k);
      if (v != delaunay::kInfiniteVertex) outside_vertex[v.value()] = 1;
    }
  }
  for (uint32_t i = 0; i < nb; ++i) {
    const uint32_t c = in.balls[i].centre.value();
    if (outside_vertex[c] && !centre_face_failed[i]) {
      fail(Kind::kCreaseVertexOnSurface, P(c), i,
           absl::StrCat("crease vertex ", c, " (ball ", i, ") is a vertex of a tet outside the collars"));
    }
  }
  for (uint32_t v = 0; v < nv; ++v) {
    if (outside_vertex[v] || ball_of_vertex[v] != kNone || !dt.VertexTet(VertexId(v)).valid()) continue;
    res.removed_vertices.push_back(v);
    // Its Voronoi corners are all inside; with a consistent sample so is v.
    if (!grid.StrictlyInside(P(v))) {
      fail(Kind::kVertexOutsideCollars, P(v), StitchFailure::kNoBall,
           absl::StrCat("vertex ", v, " is only on inside tets but not strictly inside a ball"));
    }
  }

  // --- 5. Exact verification of the assembled stitch (only if nothing failed).
  std::vector<std::array<uint32_t, 4>> stitched;
  if (fails.empty()) {
    stitched.reserve(faces.size() + books.size());
    for (const BoundaryFace& bf : faces) {
      std::array<uint32_t, 4> star = bf.tet;
      star[bf.f] = in.balls[bf.ball].centre.value();
      stitched.push_back(star);
    }
    for (const Book& bk : books) stitched.push_back(bk.tet);
    struct FaceRec {
      std::array<uint32_t, 3> key;
      int8_t side;
      uint32_t src;  // stitched index, or kTPrime | T′ index
    };
    constexpr uint32_t kTPrime = 0x80000000u;
    std::vector<FaceRec> recs;
    recs.reserve(4 * stitched.size() + faces.size());
    std::vector<uint8_t> removed(nv, 0);
    for (uint32_t v : res.removed_vertices) removed[v] = 1;
    std::vector<uint8_t> centre_used(nb, 0);
    for (uint32_t si = 0; si < stitched.size(); ++si) {
      const auto& t = stitched[si];
      const int o = geom::Orient3d(P(t[0]), P(t[1]), P(t[2]), P(t[3]));
      if (o <= 0) {
        fail(Kind::kFaceMismatch, (P(t[0]) + P(t[1]) + P(t[2]) + P(t[3])) / 4.0, StitchFailure::kNoBall,
             absl::StrCat("stitched tet (", t[0], ", ", t[1], ", ", t[2], ", ", t[3], ") has Orient3d ", o));
      }
      for (int k = 0; k < 4; ++k) {
        if (removed[t[k]]) {
          fail(Kind::kFaceMismatch, P(t[k]), StitchFailure::kNoBall,
               absl::StrCat("stitched tet uses removed vertex ", t[k]));
        }
        if (ball_of_vertex[t[k]] != kNone) centre_used[ball_of_vertex[t[k]]] = 1;
        const SortedFace sf = FaceOf(t, k);
        recs.push_back({sf.key, sf.side, si});
      }
    }
    for (uint32_t fi = 0; fi < faces.size(); ++fi) {
      // The inside tet's apex side: a stitched tet over this face must have its
      // apex on the same side (it replaces the inside tet there).
      const SortedFace sf = FaceOf(faces[fi].tet, faces[fi].f);
      recs.push_back({sf.key, sf.side, kTPrime | fi});
    }
    std::sort(recs.begin(), recs.end(), [](const FaceRec& p, const FaceRec& q) {
      return std::tie(p.key, p.side, p.src) < std::tie(q.key, q.side, q.src);
    });
    for (size_t r0 = 0; r0 < recs.size();) {
      size_t r1 = r0;
      while (r1 < recs.size() && recs[r1].key == recs[r0].key) ++r1;
      bool ok = false;
      if (r1 - r0 == 2) {
        const FaceRec& p = recs[r0];
        const FaceRec& q = recs[r0 + 1];
        const bool pt = p.src & kTPrime, qt = q.src & kTPrime;
        if (!pt && !qt) ok = p.side != q.side;           // interior face
        if (pt != qt) ok = p.side == q.side;             // T′ face matched once
      }
      // Two books of one crease edge vw over circle edges ab and ac on the
      // same side of their face (v, w, a): the restricted edges fold back
      // around the axis at a (hull seed 60 of session 36's sweep: circle
      // edges 8716-27209 and 27209-37289 of one ball pair). The circle's
      // point nearest a is a point of S that splits the fold.
      if (!ok && r1 - r0 == 2 && !(recs[r0].src & kTPrime) && !(recs[r0 + 1].src & kTPrime) &&
          recs[r0].src >= faces.size() && recs[r0 + 1].src >= faces.size() && recs[r0].side == recs[r0 + 1].side) {
        const Book& b0 = books[recs[r0].src - faces.size()];
        const Book& b1 = books[recs[r0 + 1].src - faces.size()];
        if (b0.pair == b1.pair) {
          const CreasePair& cp = pairs[b0.pair];
          uint32_t a = kNone;
          for (uint32_t v : recs[r0].key) {
            if (v != b0.tet[0] && v != b0.tet[1]) a = v;
          }
          Vec3 x;
          if (a != kNone && NearestCirclePoint(cp.circle, P(a), &x)) {
            fail(Kind::kBookFold, x, cp.i,
                 absl::StrCat("books (", b0.tet[0], ", ", b0.tet[1], ", ", b0.tet[2], ", ", b0.tet[3], ") and (",
                              b1.tet[0], ", ", b1.tet[1], ", ", b1.tet[2], ", ", b1.tet[3],
                              ") of one crease edge are on the same side of their shared face"));
            r0 = r1;
            continue;
          }
        }
      }
      if (!ok) {
        const auto& k = recs[r0].key;
        const Vec3 c = (P(k[0]) + P(k[1]) + P(k[2])) / 3.0;
        int nt = 0, ns = 0;
        for (size_t r = r0; r < r1; ++r) (recs[r].src & kTPrime) ? ++nt : ++ns;
        fail(Kind::kFaceMismatch, c, StitchFailure::kNoBall,
             absl::StrCat("face (", k[0], ", ", k[1], ", ", k[2], ") is in ", ns, " stitched tets and ", nt,
                          " T' faces with the wrong sides or count"));
      }
      r0 = r1;
    }
    for (uint32_t i = 0; i < nb; ++i) {
      if (!centre_used[i]) {
        fail(Kind::kCreaseVertexUnused, balls[i].center, i,
             absl::StrCat("crease vertex ", in.balls[i].centre.value(), " (ball ", i, ") is in no stitched tet"));
      }
    }
    for (const CreasePair& cp : pairs) {
      if (cp.crosses && cp.books == 0) {
        fail(Kind::kCreaseEdgeMissing, CirclePoint(cp.circle, 0), cp.i,
             absl::StrCat("crease edge of balls ", cp.i, ", ", cp.j, " has no book (circle not represented)"));
      }
    }
  }

  if (!fails.empty()) {
    const StitchFailure& f = fails[0];
    const std::string msg =
        absl::StrCat("RipStitchCollar: ", fails.size(), " failure(s); first: ", StitchFailureKindName(f.kind),
                     " at ", Fmt(f.where), " ball ", f.ball, ": ", f.detail);
    if (failures != nullptr) failures->insert(failures->end(), fails.begin(), fails.end());
    return absl::FailedPreconditionError(msg);
  }

  std::vector<std::array<uint32_t, 4>>().swap(stitched);  // verified; the output rebuilds them
  std::vector<uint8_t>().swap(outside_vertex);
  // --- Output and measurements. Reserved exactly: a vector doubling here
  // held two copies of M_Ω's outside tets at the run's heap peak (bunny.off:
  // 10 M tets in M_Ω at the stitch).
  res.tets.reserve(size_t{res.outside_tets} + faces.size() + books.size());
  for (uint32_t ti = 0; ti < cap; ++ti) {
    const TetId t(ti);
    if (!dt.IsAlive(t) || dt.IsGhost(t) || inside[ti]) continue;
    res.tets.push_back({dt.TetVertex(t, 0).value(), dt.TetVertex(t, 1).value(), dt.TetVertex(t, 2).value(),
                        dt.TetVertex(t, 3).value()});
  }
  res.stars = static_cast<uint32_t>(faces.size());
  res.books = static_cast<uint32_t>(books.size());
  double sig_max = 0, eps_max = 0, gam_max = 0, base_max = 0, rad_max = 0;
  for (const BoundaryFace& bf : faces) {
    const uint32_t fa = bf.tet[(bf.f + 1) & 3], fb = bf.tet[(bf.f + 2) & 3], fc = bf.tet[(bf.f + 3) & 3];
    const Vec3 &a = P(fa), &b = P(fb), &c = P(fc);
    const CollarBall& ball = balls[bf.ball];
    const double sig = RepresentationAngle(geom::Cross(b - a, c - a), bf.x, ball.center);
    const double eps = geom::Dist(bf.x, a) / ball.radius;
    const double gam = std::max({PlaneAngle(a, b, c), PlaneAngle(b, c, a), PlaneAngle(c, a, b)});
    sig_max = std::max(sig_max, sig);
    eps_max = std::max(eps_max, eps);
    gam_max = std::max(gam_max, gam);
    const StarDihedrals d = MeasureStar(ball.center, a, b, c);
    base_max = std::max(base_max, d.max_base);
    rad_max = std::max(rad_max, d.max_radial);
    const StarBound own = StarDihedralBound(sig, eps, gam);
    const double worst = std::max(d.max_base, d.max_radial) * kRadToDeg;
    if (own.valid) {
      ++res.shape.stars_bounded;
      if (d.max_base > own.base + 1e-9 || d.max_radial > own.radial + 1e-9) ++res.shape.star_violations;
      res.shape.max_bounded_dihedral_deg = std::max(res.shape.max_bounded_dihedral_deg, worst);
    } else {
      res.shape.max_unbounded_dihedral_deg = std::max(res.shape.max_unbounded_dihedral_deg, worst);
    }
  }
  res.shape.max_star_base_deg = base_max * kRadToDeg;
  res.shape.max_star_radial_deg = rad_max * kRadToDeg;
  res.shape.star_sigma_max_deg = sig_max * kRadToDeg;
  res.shape.star_eps_max = eps_max;
  res.shape.star_gamma_max_deg = gam_max * kRadToDeg;
  if (!faces.empty()) {
    const StarBound sb = StarDihedralBound(sig_max, eps_max, gam_max);
    res.shape.star_bound_valid = sb.valid;
    res.shape.star_bound_base_deg = sb.base * kRadToDeg;
    res.shape.star_bound_radial_deg = sb.radial * kRadToDeg;
  }
  double bs = 0, be = 0, ba = 0, mab = 0, mside = 0, maxis = 0;
  for (const Book& bk : books) {
    const CreasePair& cp = pairs[bk.pair];
    const Vec3 &v = P(bk.tet[0]), &w = P(bk.tet[1]), &a = P(bk.tet[2]), &b = P(bk.tet[3]);
    const double sig = CircleRepresentationAngle(a, b, cp.circle, bk.x);
    const double eps = std::max(geom::Dist(bk.x, a), geom::Dist(bk.x, b)) / cp.circle.radius;
    const Vec3 m = 0.5 * (a + b);
    const double alpha = AngleBetween(v - m, w - m);
    bs = std::max(bs, sig);
    be = std::max(be, eps);
    ba = std::max(ba, alpha);
    const BookDihedrals d = MeasureBook(v, w, a, b);
    mab = std::max(mab, d.at_ab);
    mside = std::max(mside, d.max_side);
    maxis = std::max(maxis, d.at_axis);
    const BookBound own = BookDihedralBound(sig, eps, alpha);
    const double worst = std::max({d.at_ab, d.max_side, d.at_axis}) * kRadToDeg;
    if (own.valid) {
      ++res.shape.books_bounded;
      if (d.at_ab > own.at_ab + 1e-9 || d.max_side > own.side + 1e-9 || d.at_axis > own.axis + 1e-9) {
        ++res.shape.book_violations;
      }
      res.shape.max_bounded_dihedral_deg = std::max(res.shape.max_bounded_dihedral_deg, worst);
    } else {
      res.shape.max_unbounded_dihedral_deg = std::max(res.shape.max_unbounded_dihedral_deg, worst);
    }
  }
  res.shape.max_book_ab_deg = mab * kRadToDeg;
  res.shape.max_book_side_deg = mside * kRadToDeg;
  res.shape.max_book_axis_deg = maxis * kRadToDeg;
  res.shape.book_sigma_max_deg = bs * kRadToDeg;
  res.shape.book_eps_max = be;
  res.shape.book_alpha_max_deg = ba * kRadToDeg;
  if (!books.empty()) {
    const BookBound bb = BookDihedralBound(bs, be, ba);
    res.shape.book_bound_valid = bb.valid;
    res.shape.book_bound_ab_deg = bb.at_ab * kRadToDeg;
    res.shape.book_bound_side_deg = bb.side * kRadToDeg;
    res.shape.book_bound_axis_deg = bb.axis * kRadToDeg;
  }
  for (const BoundaryFace& bf : faces) {
    std::array<uint32_t, 4> star = bf.tet;
    star[bf.f] = in.balls[bf.ball].centre.value();
    res.tets.push_back(star);
  }
  for (const Book& bk : books) res.tets.push_back(bk.tet);
  return res;
}

}  // namespace svrc::refine
