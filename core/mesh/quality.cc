#include "core/mesh/quality.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace svrc::mesh {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

// Edge k joins kEdge[k][0] and kEdge[k][1]; the two other vertices are the
// opposite edge kEdge[5 - k].
constexpr int kEdge[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};

double TriangleArea(const Vec3& a, const Vec3& b, const Vec3& c) {
  return 0.5 * geom::Norm(geom::Cross(b - a, c - a));
}

}  // namespace

TetQuality ComputeTetQuality(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const Vec3 p[4] = {a, b, c, d};
  TetQuality q;
  double shortest2 = kInf, longest2 = 0;
  for (const auto& e : kEdge) {
    const double l2 = geom::Dist2(p[e[0]], p[e[1]]);
    shortest2 = std::min(shortest2, l2);
    longest2 = std::max(longest2, l2);
  }
  // Circumcentre relative to a:
  //   (|u|²(v×w) + |v|²(w×u) + |w|²(u×v)) / (2 u·(v×w)),  u,v,w = b-a, c-a, d-a.
  const Vec3 u = b - a, v = c - a, w = d - a;
  const double det = geom::Dot(u, geom::Cross(v, w));
  q.volume = det / 6;
  if (det != 0 && shortest2 > 0) {
    const Vec3 num = geom::Norm2(u) * geom::Cross(v, w) + geom::Norm2(v) * geom::Cross(w, u) +
                     geom::Norm2(w) * geom::Cross(u, v);
    q.radius_edge = geom::Norm(num) / (2 * std::fabs(det)) / std::sqrt(shortest2);
    const double faces = TriangleArea(b, c, d) + TriangleArea(a, c, d) + TriangleArea(a, b, d) +
                         TriangleArea(a, b, c);
    const double inradius = 3 * std::fabs(q.volume) / faces;
    q.aspect = std::sqrt(longest2) / (2 * std::sqrt(6.0) * inradius);
  } else {
    q.radius_edge = kInf;
    q.aspect = kInf;
  }
  q.min_dihedral_deg = kInf;
  q.max_dihedral_deg = 0;
  for (int k = 0; k < 6; ++k) {
    const Vec3& pi = p[kEdge[k][0]];
    const Vec3 e = p[kEdge[k][1]] - pi;
    // The normals of the two faces at the edge, both perpendicular to e: the
    // angle between them is the dihedral angle.
    const Vec3 n1 = geom::Cross(e, p[kEdge[5 - k][0]] - pi);
    const Vec3 n2 = geom::Cross(e, p[kEdge[5 - k][1]] - pi);
    const double angle = std::atan2(geom::Norm(geom::Cross(n1, n2)), geom::Dot(n1, n2)) * kRadToDeg;
    q.dihedral_deg[k] = angle;
    q.min_dihedral_deg = std::min(q.min_dihedral_deg, angle);
    q.max_dihedral_deg = std::max(q.max_dihedral_deg, angle);
  }
  return q;
}

Distribution Distribution::Of(std::vector<double> values) {
  Distribution d;
  d.count = values.size();
  if (values.empty()) return d;
  // Nearest rank: the smallest value with at least pct% of values <= it, the
  // element of index ceil(pct/100·n) − 1 of the sorted values. Selected with
  // nth_element over a shrinking range, rank by rank, instead of a full sort:
  // the same values (an order statistic does not depend on how it is found),
  // and linear time (the sort was 9% of a `svrc mesh --stats` run on cube
  // --max-volume 1e-5, six dihedral angles per tet).
  auto index = [&](double pct) {
    const double r = std::ceil(pct / 100.0 * static_cast<double>(values.size()));
    const size_t i = r < 1 ? 0 : static_cast<size_t>(r) - 1;
    return std::min(i, values.size() - 1);
  };
  const std::array<double, 5> pcts{1, 5, 50, 95, 99};
  std::array<double*, 5> out{&d.p1, &d.p5, &d.p50, &d.p95, &d.p99};
  auto first = values.begin();
  for (size_t k = 0; k < pcts.size(); ++k) {
    // The ranks ascend, so nth >= first: everything before first is <= it.
    const auto nth = values.begin() + static_cast<std::ptrdiff_t>(index(pcts[k]));
    std::nth_element(first, nth, values.end());
    first = nth;
    *out[k] = *nth;
  }
  const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
  d.min = *lo;
  d.max = *hi;
  return d;
}

namespace {

// The most (degrees) that rounding the vertices of abcd to doubles can have
// moved its dihedral angles: 8·u/h radians (MaxDihedralLessRounding).
double RoundingSlackDeg(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const TetQuality& q) {
  double scale = 0;
  for (const Vec3* p : {&a, &b, &c, &d}) {
    scale = std::max({scale, std::fabs(p->x), std::fabs(p->y), std::fabs(p->z)});
  }
  const double max_face =
      std::max({TriangleArea(b, c, d), TriangleArea(a, c, d), TriangleArea(a, b, d), TriangleArea(a, b, c)});
  const double h = max_face > 0 ? 3 * std::fabs(q.volume) / max_face : 0;
  return h > 0 ? 8 * std::ldexp(scale, -52) / h * (180 / M_PI) : 180;
}

bool Touches(const std::array<uint32_t, 4>& t, const std::vector<uint8_t>& flagged_vertex) {
  bool touches = false;
  for (uint32_t v : t) touches = touches || flagged_vertex[v] != 0;
  return touches;
}

}  // namespace

double MaxDihedralLessRounding(const TetMesh& mesh, const std::vector<uint8_t>& flagged_vertex) {
  if (flagged_vertex.size() != mesh.positions.size()) return 0;
  double worst = 0;
  for (const auto& t : mesh.tets) {
    if (!Touches(t, flagged_vertex)) continue;
    const Vec3 &a = mesh.positions[t[0]], &b = mesh.positions[t[1]], &c = mesh.positions[t[2]],
               &d = mesh.positions[t[3]];
    const TetQuality q = ComputeTetQuality(a, b, c, d);
    worst = std::max(worst, q.max_dihedral_deg - RoundingSlackDeg(a, b, c, d, q));
  }
  return worst;
}

MinDihedralShortfall BelowMinDihedral(const TetMesh& mesh, const std::vector<uint8_t>& crease_vertex,
                                      double min_deg) {
  const bool has_creases = crease_vertex.size() == mesh.positions.size();
  MinDihedralShortfall r;
  for (const auto& t : mesh.tets) {
    if (has_creases && Touches(t, crease_vertex)) continue;
    const Vec3 &a = mesh.positions[t[0]], &b = mesh.positions[t[1]], &c = mesh.positions[t[2]],
               &d = mesh.positions[t[3]];
    const TetQuality q = ComputeTetQuality(a, b, c, d);
    r.smallest_deg = std::min(r.smallest_deg, q.min_dihedral_deg);
    if (q.min_dihedral_deg + RoundingSlackDeg(a, b, c, d, q) < min_deg) ++r.num_below;
  }
  return r;
}

QualityReport ComputeQuality(const TetMesh& mesh, const std::vector<uint8_t>& crease_vertex) {
  struct Acc {
    std::vector<double> re, dih, min_dih, aspect;
    double max_volume = -HUGE_VAL;
    QualityGroup Finish() {
      QualityGroup g;
      g.num_tets = re.size();
      g.max_volume = re.empty() ? 0 : max_volume;
      g.radius_edge = Distribution::Of(std::move(re));
      g.dihedral_deg = Distribution::Of(std::move(dih));
      g.min_dihedral_deg = Distribution::Of(std::move(min_dih));
      g.aspect = Distribution::Of(std::move(aspect));
      return g;
    }
  } crease, other, all;
  const bool has_creases = crease_vertex.size() == mesh.positions.size();
  for (const auto& t : mesh.tets) {
    const TetQuality q = ComputeTetQuality(mesh.positions[t[0]], mesh.positions[t[1]],
                                           mesh.positions[t[2]], mesh.positions[t[3]]);
    bool touches = false;
    if (has_creases) {
      for (uint32_t v : t) touches = touches || crease_vertex[v] != 0;
    }
    for (Acc* acc : {touches ? &crease : &other, &all}) {
      acc->re.push_back(q.radius_edge);
      acc->dih.insert(acc->dih.end(), q.dihedral_deg.begin(), q.dihedral_deg.end());
      acc->min_dih.push_back(q.min_dihedral_deg);
      acc->aspect.push_back(q.aspect);
      acc->max_volume = std::max(acc->max_volume, q.volume);
    }
  }
  QualityReport r;
  r.crease = crease.Finish();
  r.other = other.Finish();
  r.all = all.Finish();
  return r;
}

std::string FormatQualityReport(const QualityReport& report) {
  std::string out;
  auto row = [&](const char* name, const Distribution& d) {
    absl::StrAppendFormat(&out,
                          "  %-18s min %-9.4g p1 %-9.4g p5 %-9.4g p50 %-9.4g p95 %-9.4g "
                          "p99 %-9.4g max %.4g\n",
                          name, d.min, d.p1, d.p5, d.p50, d.p95, d.p99, d.max);
  };
  auto group = [&](const char* title, const QualityGroup& g) {
    absl::StrAppendFormat(&out, "%s: %d tets\n", title, g.num_tets);
    if (g.num_tets == 0) return;
    row("radius-edge", g.radius_edge);
    row("dihedral (deg)", g.dihedral_deg);
    row("min dihedral (deg)", g.min_dihedral_deg);
    row("aspect", g.aspect);
  };
  group("all tets", report.all);
  if (report.crease.num_tets > 0) {
    group("away from creases", report.other);
    group("touching a crease", report.crease);
  }
  return out;
}

}  // namespace svrc::mesh
