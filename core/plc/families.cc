#include "core/plc/families.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <numbers>
#include <random>
#include <tuple>
#include <utility>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"

namespace svrc::plc::families {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180;

// Builds a Plc with exact-coordinate vertex sharing: a vertex given twice
// with identical coordinates gets one id, so split walls and internal facets
// share their corners (std::map keyed by the coordinates: deterministic ids
// in first-use order).
class Builder {
 public:
  explicit Builder(std::string name) { plc_.source_name = std::move(name); }

  uint32_t V(double x, double y, double z) {
    auto [it, inserted] = ids_.try_emplace(std::make_tuple(x, y, z),
                                           static_cast<uint32_t>(plc_.vertices.size()));
    if (inserted) plc_.vertices.push_back({x, y, z});
    return it->second;
  }
  uint32_t V(const Vec3& p) { return V(p.x, p.y, p.z); }
  // A vertex that is always new (isolated points, line points).
  uint32_t NewV(const Vec3& p) {
    const uint32_t id = static_cast<uint32_t>(plc_.vertices.size());
    ids_.try_emplace(std::make_tuple(p.x, p.y, p.z), id);
    plc_.vertices.push_back(p);
    return id;
  }

  Facet& Face(std::vector<uint32_t> loop, int32_t marker) {
    Facet f;
    f.polygons.push_back(Polygon{std::move(loop)});
    f.marker = marker;
    plc_.facets.push_back(std::move(f));
    return plc_.facets.back();
  }
  // Quad through four points given in cyclic order.
  Facet& Quad(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, int32_t marker) {
    return Face({V(a), V(b), V(c), V(d)}, marker);
  }
  // The six faces of the axis-aligned box [lo, hi], each one quad.
  void Box(const Vec3& lo, const Vec3& hi, int32_t marker) {
    const double x0 = lo.x, y0 = lo.y, z0 = lo.z, x1 = hi.x, y1 = hi.y, z1 = hi.z;
    Quad({x0, y0, z0}, {x0, y1, z0}, {x1, y1, z0}, {x1, y0, z0}, marker);  // bottom
    Quad({x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1}, marker);  // top
    Quad({x0, y0, z0}, {x1, y0, z0}, {x1, y0, z1}, {x0, y0, z1}, marker);  // front y0
    Quad({x0, y1, z0}, {x0, y1, z1}, {x1, y1, z1}, {x1, y1, z0}, marker);  // back y1
    Quad({x0, y0, z0}, {x0, y0, z1}, {x0, y1, z1}, {x0, y1, z0}, marker);  // left x0
    Quad({x1, y0, z0}, {x1, y1, z0}, {x1, y1, z1}, {x1, y0, z1}, marker);  // right x1
  }
  void Segment(uint32_t a, uint32_t b, int32_t marker = 0) {
    plc_.segments.push_back(plc::Segment{a, b, marker});
  }
  void Region(const Vec3& p, double attribute, double max_volume = 0) {
    plc_.regions.push_back(RegionSeed{p, attribute, max_volume});
  }
  void Hole(const Vec3& p) { plc_.holes.push_back(p); }

  Plc& plc() { return plc_; }
  Plc Take() { return std::move(plc_); }

 private:
  Plc plc_;
  std::map<std::tuple<double, double, double>, uint32_t> ids_;
};

// %.17g: every double round-trips through the text.
std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// Unit box walls except the front (y=0) and back (y=1) walls, which the crease
// families build themselves with in-facet segments.
void UnitBoxSidesAndCaps(Builder& b) {
  b.Quad({0, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}, kWallMarker);  // bottom
  b.Quad({0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}, kWallMarker);  // top
  b.Quad({0, 0, 0}, {0, 0, 1}, {0, 1, 1}, {0, 1, 0}, kWallMarker);  // left
  b.Quad({1, 0, 0}, {1, 1, 0}, {1, 1, 1}, {1, 0, 1}, kWallMarker);  // right
}

// Quads extruded in y over [0, 1] from the hinge (hx, hz) in the given unit
// directions (in the xz-plane), length `len`. The quads' edges on y = 0 and
// y = 1 are in-facet segments of the front and back walls. A y-extrusion is
// a parallelogram, so each quad is exactly planar.
void HingeQuads(Builder& b, double hx, double hz, const std::vector<Vec3>& dirs, double len) {
  UnitBoxSidesAndCaps(b);
  for (double y : {0.0, 1.0}) {
    Facet wall;
    wall.marker = kWallMarker;
    wall.polygons.push_back(
        Polygon{{b.V(0, y, 0), b.V(1, y, 0), b.V(1, y, 1), b.V(0, y, 1)}});
    const uint32_t h = b.V(hx, y, hz);
    for (const Vec3& d : dirs) {
      wall.polygons.push_back(Polygon{{h, b.V(hx + len * d.x, y, hz + len * d.z)}});
    }
    b.plc().facets.push_back(std::move(wall));
  }
  for (const Vec3& d : dirs) {
    const double tx = hx + len * d.x, tz = hz + len * d.z;
    b.Face({b.V(hx, 0, hz), b.V(tx, 0, tz), b.V(tx, 1, tz), b.V(hx, 1, hz)}, kCreaseMarker);
  }
}

}  // namespace

Plc BoxWithInternalFacets(int k) {
  if (k < 1) k = 1;
  Builder b(absl::StrCat("box_internal_facets(k=", k, ")"));
  std::vector<double> xs;
  for (int i = 0; i <= k + 1; ++i) xs.push_back(double(i) / double(k + 1));
  xs.back() = 1;
  b.Quad({0, 0, 0}, {0, 0, 1}, {0, 1, 1}, {0, 1, 0}, kWallMarker);  // left
  b.Quad({1, 0, 0}, {1, 1, 0}, {1, 1, 1}, {1, 0, 1}, kWallMarker);  // right
  for (int j = 0; j <= k; ++j) {
    const double x0 = xs[j], x1 = xs[j + 1];
    b.Quad({x0, 0, 0}, {x0, 1, 0}, {x1, 1, 0}, {x1, 0, 0}, kWallMarker);  // bottom
    b.Quad({x0, 0, 1}, {x1, 0, 1}, {x1, 1, 1}, {x0, 1, 1}, kWallMarker);  // top
    b.Quad({x0, 0, 0}, {x1, 0, 0}, {x1, 0, 1}, {x0, 0, 1}, kWallMarker);  // front
    b.Quad({x0, 1, 0}, {x0, 1, 1}, {x1, 1, 1}, {x1, 1, 0}, kWallMarker);  // back
    b.Region({(x0 + x1) / 2, 0.5, 0.5}, j + 1);
  }
  for (int i = 1; i <= k; ++i) {
    const double x = xs[i];
    b.Quad({x, 0, 0}, {x, 0, 1}, {x, 1, 1}, {x, 1, 0}, kInternalMarker);
  }
  return b.Take();
}

Plc BoxWithCubicalHole(double side) {
  Builder b(absl::StrCat("box_cubical_hole(side=", side, ")"));
  b.Box({0, 0, 0}, {1, 1, 1}, kWallMarker);
  const double lo = 0.5 - side / 2, hi = 0.5 + side / 2;
  b.Box({lo, lo, lo}, {hi, hi, hi}, kInternalMarker);
  b.Hole({0.5, 0.5, 0.5});
  return b.Take();
}

Plc BoxWithCavity(double side) {
  Builder b(absl::StrCat("box_cavity(side=", side, ")"));
  b.Box({0, 0, 0}, {1, 1, 1}, kWallMarker);
  const double lo = 0.5 - side / 2, hi = 0.5 + side / 2;
  b.Box({lo, lo, lo}, {hi, hi, hi}, kInternalMarker);
  b.Region({lo / 2, 0.5, 0.5}, 1);
  b.Region({0.5, 0.5, 0.5}, 2);
  return b.Take();
}

Plc BoxWithTunnel(double side) {
  Builder b(absl::StrCat("box_tunnel(side=", side, ")"));
  const double lo = 0.5 - side / 2, hi = 0.5 + side / 2;
  for (double z : {0.0, 1.0}) {
    Polygon hole{{b.V(lo, lo, z), b.V(hi, lo, z), b.V(hi, hi, z), b.V(lo, hi, z)}};
    Facet& f = b.Face({b.V(0, 0, z), b.V(1, 0, z), b.V(1, 1, z), b.V(0, 1, z)}, kWallMarker);
    f.polygons.push_back(std::move(hole));
    f.holes.push_back({0.5, 0.5, z});
  }
  b.Quad({0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}, kWallMarker);  // front
  b.Quad({0, 1, 0}, {0, 1, 1}, {1, 1, 1}, {1, 1, 0}, kWallMarker);  // back
  b.Quad({0, 0, 0}, {0, 0, 1}, {0, 1, 1}, {0, 1, 0}, kWallMarker);  // left
  b.Quad({1, 0, 0}, {1, 1, 0}, {1, 1, 1}, {1, 0, 1}, kWallMarker);  // right
  // Tunnel lining.
  b.Quad({lo, lo, 0}, {hi, lo, 0}, {hi, lo, 1}, {lo, lo, 1}, kInternalMarker);
  b.Quad({hi, lo, 0}, {hi, hi, 0}, {hi, hi, 1}, {hi, lo, 1}, kInternalMarker);
  b.Quad({hi, hi, 0}, {lo, hi, 0}, {lo, hi, 1}, {hi, hi, 1}, kInternalMarker);
  b.Quad({lo, hi, 0}, {lo, lo, 0}, {lo, lo, 1}, {lo, hi, 1}, kInternalMarker);
  return b.Take();
}

Plc InternalFacetWithHole(int hole_sides, double hole_radius) {
  if (hole_sides < 3) hole_sides = 3;
  Builder b(absl::StrCat("internal_facet_with_hole(sides=", hole_sides,
                         ", radius=", hole_radius, ")"));
  const double m = 0.5;
  b.Quad({0, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}, kWallMarker);  // bottom
  b.Quad({0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}, kWallMarker);  // top
  for (const auto& [z0, z1] : {std::pair{0.0, m}, std::pair{m, 1.0}}) {
    b.Quad({0, 0, z0}, {1, 0, z0}, {1, 0, z1}, {0, 0, z1}, kWallMarker);  // front
    b.Quad({0, 1, z0}, {0, 1, z1}, {1, 1, z1}, {1, 1, z0}, kWallMarker);  // back
    b.Quad({0, 0, z0}, {0, 0, z1}, {0, 1, z1}, {0, 1, z0}, kWallMarker);  // left
    b.Quad({1, 0, z0}, {1, 1, z0}, {1, 1, z1}, {1, 0, z1}, kWallMarker);  // right
  }
  Polygon hole;
  for (int i = 0; i < hole_sides; ++i) {
    const double a = 2 * kPi * i / hole_sides;
    hole.vertices.push_back(b.NewV({m + hole_radius * std::cos(a), m + hole_radius * std::sin(a), m}));
  }
  Facet& f = b.Face({b.V(0, 0, m), b.V(1, 0, m), b.V(1, 1, m), b.V(0, 1, m)}, kInternalMarker);
  f.polygons.push_back(std::move(hole));
  f.holes.push_back({m, m, m});
  return b.Take();
}

Plc FreeSegmentsAndPoints(int num_segments, int num_points, uint64_t seed) {
  Builder b(absl::StrCat("free_segments_points(segments=", num_segments,
                         ", points=", num_points, ", seed=", seed, ")"));
  b.Box({0, 0, 0}, {1, 1, 1}, kWallMarker);
  for (int i = 0; i < num_segments; ++i) {
    const double z = double(i + 1) / double(num_segments + 1);
    const double a = kPi * i / std::max(num_segments, 1);
    const double dx = 0.35 * std::cos(a), dy = 0.35 * std::sin(a);
    const uint32_t p = b.NewV({0.5 - dx, 0.5 - dy, z});
    const uint32_t q = b.NewV({0.5 + dx, 0.5 + dy, z});
    b.Segment(p, q, 10 + i);
  }
  // std::mt19937_64's output sequence is fixed by the standard; the
  // distributions are not, so the mantissa is taken from the raw bits.
  std::mt19937_64 rng(seed);
  auto unit = [&] { return 0.1 + 0.8 * (double(rng() >> 11) * 0x1p-53); };
  for (int i = 0; i < num_points; ++i) {
    const double x = unit(), y = unit(), z = unit();
    b.NewV({x, y, z});
  }
  return b.Take();
}

Plc NestedBoxes(int levels, double outer_max_volume, double volume_ratio) {
  if (levels < 1) levels = 1;
  Builder b(absl::StrCat("nested_boxes(levels=", levels, ", outer_max_volume=",
                         outer_max_volume, ", ratio=", volume_ratio, ")"));
  std::vector<double> half;
  for (int i = 0; i < levels; ++i) half.push_back(std::ldexp(1.0, -(i + 1)));
  for (int i = 0; i < levels; ++i) {
    b.Box({0.5 - half[i], 0.5 - half[i], 0.5 - half[i]},
          {0.5 + half[i], 0.5 + half[i], 0.5 + half[i]}, i == 0 ? kWallMarker : kInternalMarker);
  }
  double vol = outer_max_volume;
  for (int i = 0; i < levels; ++i) {
    const double x = i + 1 < levels ? 0.5 - (half[i] + half[i + 1]) / 2 : 0.5;
    b.Region({x, 0.5, 0.5}, i + 1, outer_max_volume > 0 ? vol : 0);
    vol *= volume_ratio;
  }
  return b.Take();
}

Plc VolumeConstrainedCube(double side, double max_volume) {
  Builder b(absl::StrCat("volume_constrained_cube(side=", side,
                         ", max_volume=", max_volume, ")"));
  b.Box({0, 0, 0}, {side, side, side}, kWallMarker);
  b.Region({side / 2, side / 2, side / 2}, 1, max_volume);
  return b.Take();
}

Plc SkewLines(int n, const SkewLinesOptions& options) {
  if (n < 2) n = 2;
  Builder b(absl::StrCat("skew_lines(n=", n, options.segments ? ", segments" : "",
                         options.bounding_box ? ", box" : "", ")"));
  auto t = [&](int i) { return 0.125 + 0.75 * double(i) / double(n - 1); };
  for (int i = 0; i < n; ++i) b.NewV({t(i), 0.5, 0.25});
  for (int i = 0; i < n; ++i) b.NewV({0.5, t(i), 0.75});
  // Each line is a chain of n-1 segments between consecutive points (TetGen
  // 1.5 aborts on input vertices lying inside an input segment; our reader
  // would split one long segment into the same pieces).
  if (options.segments) {
    for (int i = 0; i + 1 < n; ++i) b.Segment(i, i + 1, 1);
    for (int i = 0; i + 1 < n; ++i) b.Segment(n + i, n + i + 1, 2);
  }
  if (options.bounding_box) b.Box({0, 0, 0}, {1, 1, 1}, kWallMarker);
  return b.Take();
}

Plc CreaseFacetPair(double angle_deg) {
  Builder b(absl::StrCat("crease_facet_pair(angle=", angle_deg, "deg)"));
  const double h = angle_deg * kDeg / 2;
  HingeQuads(b, 0.25, 0.5, {{std::cos(h), 0, std::sin(h)}, {std::cos(h), 0, -std::sin(h)}}, 0.5);
  return b.Take();
}

Plc SegmentFacetAngle(double angle_deg) {
  Builder b(absl::StrCat("segment_facet_angle(angle=", angle_deg, "deg)"));
  b.Box({0, 0, 0}, {1, 1, 1}, kWallMarker);
  const double a = angle_deg * kDeg;
  const uint32_t p = b.NewV({0.25, 0.5, 0});
  const uint32_t q = b.NewV({0.25 + 0.5 * std::cos(a), 0.5, 0.5 * std::sin(a)});
  // The foot is the end of an in-facet segment pointing away (-x) from the
  // free segment (angle 180° - angle: no second crease). TetGen 1.5 aborts
  // (fillregion assertion) on a free segment ending at a bare interior point
  // of a facet, and our reader has no 1-vertex polygons.
  const uint32_t back = b.NewV({0.125, 0.5, 0});
  b.plc().facets[0].polygons.push_back(Polygon{{p, back}});  // facets[0]: the floor
  b.Segment(p, q, 1);
  return b.Take();
}

Plc FacetFan(int k, double spacing_deg) {
  if (k < 2) k = 2;
  Builder b(absl::StrCat("facet_fan(k=", k, ", spacing=", spacing_deg, "deg)"));
  std::vector<Vec3> dirs;
  for (int i = 0; i < k; ++i) {
    const double a = i * spacing_deg * kDeg;
    dirs.push_back({std::cos(a), 0, std::sin(a)});
  }
  HingeQuads(b, 0.5, 0.5, dirs, 0.4);
  return b.Take();
}

Plc FlatTetrahedron() {
  Builder b("flat_tetrahedron");
  const uint32_t v[4] = {b.V(0, 0, 0), b.V(1, 0, 0), b.V(0.5, 0.9, 0), b.V(0.5, 0.3, 0.15)};
  for (const auto& t : {std::array<int, 3>{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}}) {
    b.Face({v[t[0]], v[t[1]], v[t[2]]}, 0);
  }
  return b.Take();
}

std::vector<GeneratedInput> StandardInputs() {
  std::vector<GeneratedInput> out;
  auto add = [&](std::string name, std::string description, Plc plc, double max_volume = 0,
                 double crease = 0) {
    plc.source_name = name;
    out.push_back(GeneratedInput{std::move(name), std::move(description), std::move(plc),
                                 max_volume, crease});
  };
  add("box_internal_facets_k1", "unit box, 1 internal facet x=1/2, 2 regions",
      BoxWithInternalFacets(1));
  add("box_internal_facets_k3", "unit box, 3 internal facets x=i/4, 4 regions",
      BoxWithInternalFacets(3));
  add("box_cubical_hole", "unit box, cubical void of side 0.4 (hole seed)",
      BoxWithCubicalHole(0.4));
  add("box_cavity", "unit box, closed cubical cavity of side 0.4 as region 2",
      BoxWithCavity(0.4));
  add("box_tunnel", "unit box pierced by a square tunnel of side 0.4 (facets with holes)",
      BoxWithTunnel(0.4));
  add("facet_hole_4gon", "internal facet z=1/2 with a square hole (circumradius 0.25)",
      InternalFacetWithHole(4, 0.25));
  add("facet_hole_7gon", "internal facet z=1/2 with a 7-gon hole (circumradius 0.3)",
      InternalFacetWithHole(7, 0.3));
  add("free_segments_points", "unit box, 4 free segments, 20 isolated points (seed 1)",
      FreeSegmentsAndPoints(4, 20, 1));
  add("nested_boxes_3", "3 nested cubes, attributes 1..3, region max volume 1e-2, 1.25e-3, 1.5625e-4",
      NestedBoxes(3, 1e-2, 0.125));
  add("cube_maxvol_1e-4", "unit cube, region max volume 1e-4", VolumeConstrainedCube(1, 1e-4));
  add("skew_lines_50", "2 orthogonal skew segments with 50 points each, in the unit box",
      SkewLines(50));
  add("skew_lines_200_vol1e-3", "2 skew segments with 200 points each, in the unit box, max volume 1e-3",
      SkewLines(200), 1e-3);
  add("skew_points_200", "point set: 200 points on each of 2 skew lines (quadratic Delaunay)",
      SkewLines(200, {.segments = false, .bounding_box = false}));
  for (double a : {30.0, 10.0, 5.0, 1.0, 0.1}) {
    add(absl::StrCat("crease_pair_", a, "deg"),
        absl::StrCat("two internal quads on a hinge at ", a, " deg in the unit box"),
        CreaseFacetPair(a), 0, a);
  }
  for (double a : {10.0, 1.0, 0.1}) {
    add(absl::StrCat("segment_facet_", a, "deg"),
        absl::StrCat("free segment leaving the floor at ", a, " deg"), SegmentFacetAngle(a), 0, a);
  }
  add("fan_6x60deg", "6 quads around one edge, 60 deg apart", FacetFan(6, 60), 0, 60);
  add("fan_8x5deg", "8 quads around one edge, 5 deg apart", FacetFan(8, 5), 0, 5);
  return out;
}

std::string PolyText(const Plc& plc) {
  std::string s = absl::StrCat("# ", plc.source_name.empty() ? "<memory>" : plc.source_name,
                               " (svrc core/plc/families.cc)\n");
  const bool markers = plc.vertex_markers.size() == plc.vertices.size() && !plc.vertices.empty();
  absl::StrAppend(&s, plc.vertices.size(), " 3 0 ", markers ? 1 : 0, "\n");
  for (size_t i = 0; i < plc.vertices.size(); ++i) {
    const Vec3& p = plc.vertices[i];
    absl::StrAppend(&s, i + 1, " ", Num(p.x), " ", Num(p.y), " ", Num(p.z));
    if (markers) absl::StrAppend(&s, " ", plc.vertex_markers[i]);
    s += '\n';
  }
  absl::StrAppend(&s, plc.facets.size() + plc.segments.size(), " 1\n");
  for (const Facet& f : plc.facets) {
    absl::StrAppend(&s, f.polygons.size(), " ", f.holes.size(), " ", f.marker, "\n");
    for (const Polygon& poly : f.polygons) {
      absl::StrAppend(&s, poly.vertices.size());
      for (uint32_t v : poly.vertices) absl::StrAppend(&s, " ", v + 1);
      s += '\n';
    }
    for (size_t h = 0; h < f.holes.size(); ++h) {
      absl::StrAppend(&s, h + 1, " ", Num(f.holes[h].x), " ", Num(f.holes[h].y), " ",
                      Num(f.holes[h].z), "\n");
    }
  }
  for (const plc::Segment& seg : plc.segments) {
    absl::StrAppend(&s, "1 0 ", seg.marker, "\n2 ", seg.a + 1, " ", seg.b + 1, "\n");
  }
  absl::StrAppend(&s, plc.holes.size(), "\n");
  for (size_t h = 0; h < plc.holes.size(); ++h) {
    absl::StrAppend(&s, h + 1, " ", Num(plc.holes[h].x), " ", Num(plc.holes[h].y), " ",
                    Num(plc.holes[h].z), "\n");
  }
  absl::StrAppend(&s, plc.regions.size(), "\n");
  for (size_t r = 0; r < plc.regions.size(); ++r) {
    const RegionSeed& seed = plc.regions[r];
    absl::StrAppend(&s, r + 1, " ", Num(seed.point.x), " ", Num(seed.point.y), " ",
                    Num(seed.point.z), " ", Num(seed.attribute), " ",
                    seed.max_volume > 0 ? Num(seed.max_volume) : std::string("-1"), "\n");
  }
  return s;
}

std::string NodeText(const Plc& plc) {
  std::string s = absl::StrCat("# ", plc.source_name.empty() ? "<memory>" : plc.source_name,
                               " (svrc core/plc/families.cc)\n");
  absl::StrAppend(&s, plc.vertices.size(), " 3 0 0\n");
  for (size_t i = 0; i < plc.vertices.size(); ++i) {
    const Vec3& p = plc.vertices[i];
    absl::StrAppend(&s, i + 1, " ", Num(p.x), " ", Num(p.y), " ", Num(p.z), "\n");
  }
  return s;
}

absl::Status WritePoly(const Plc& plc, const std::string& path) {
  const std::string text = absl::EndsWithIgnoreCase(path, ".node") ? NodeText(plc) : PolyText(plc);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) return absl::UnavailableError(absl::StrCat("cannot open ", path, " for writing"));
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  out.close();
  if (!out) return absl::UnavailableError(absl::StrCat("cannot write ", path));
  return absl::OkStatus();
}

}  // namespace svrc::plc::families
