// Validation and construction of the feature complex (validate.h, features.h).
// Steps: (1) indices and finiteness, (2) exact duplicate points, (3) facet
// loops, zero-area / non-planar checks and frames, (4) segments split at the
// points lying on them, (5) loop nesting, holes and facet triangulations,
// (6) isolated points inside facets, (7) closedness, (8) intersections
// (exact predicates, BoxGrid), then creases and spread (creases.cc).
#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <set>
#include <string>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/plc/exact.h"
#include "core/plc/features_internal.h"
#include "core/plc/grid.h"
#include "core/plc/intersect.h"
#include "core/plc/polygon2d.h"
#include "core/plc/read_util.h"
#include "core/plc/validate.h"

namespace svrc::plc {

using geom::Box3;
using internal::Cat;

absl::Status ValidationReport::ToStatus() const {
  if (errors.empty()) return absl::OkStatus();
  std::string msg;
  for (const Problem& p : errors) {
    if (!msg.empty()) msg += "\n";
    msg += p.message;
  }
  return absl::InvalidArgumentError(msg);
}

const Problem* ValidationReport::Find(ProblemKind kind) const {
  for (const Problem& p : errors) {
    if (p.kind == kind) return &p;
  }
  return nullptr;
}

size_t FeatureComplex::NumCreasePoints() const {
  size_t n = 0;
  for (const FeaturePoint& p : points) n += p.crease;
  return n;
}

std::string FeatureComplex::PointName(PointId p) const {
  const Vec3& x = points[p].p;
  return absl::StrCat("point ", p, " (", x.x, ", ", x.y, ", ", x.z, ")");
}

std::string FeatureComplex::SegmentName(SegmentId s) const {
  return absl::StrCat("segment (", segments[s].a, ", ", segments[s].b, ")");
}

double FeatureComplex::SharpestAngleDeg(std::string* where) const {
  // Segments first: on a tie the dihedral names the feature better than the
  // angle its end point sees.
  double best = std::numeric_limits<double>::infinity();
  SegmentId seg = kNoId;
  PointId point = kNoId;
  for (SegmentId s = 0; s < segments.size(); ++s) {
    if (segments[s].min_angle < best) {
      best = segments[s].min_angle;
      seg = s;
    }
  }
  for (PointId i = 0; i < points.size(); ++i) {
    if (points[i].min_angle < best) {
      best = points[i].min_angle;
      point = i;
    }
  }
  *where = point != kNoId ? PointName(point) : seg != kNoId ? SegmentName(seg) : std::string();
  return best * 180 / M_PI;
}

size_t FeatureComplex::NumCreaseSegments() const {
  size_t n = 0;
  for (const FeatureSegment& s : segments) n += s.crease;
  return n;
}

SegmentId FeatureComplex::FindSegment(PointId a, PointId b) const {
  if (a > b) std::swap(a, b);
  auto it = std::lower_bound(segments.begin(), segments.end(), std::make_pair(a, b),
                             [](const FeatureSegment& s, const std::pair<PointId, PointId>& k) {
                               return std::make_pair(s.a, s.b) < k;
                             });
  if (it != segments.end() && it->a == a && it->b == b) return static_cast<SegmentId>(it - segments.begin());
  return kNoId;
}

namespace {

uint64_t Bits(double d) {
  if (d == 0) d = 0;
  return std::bit_cast<uint64_t>(d);
}

// "a, b, c" in the file's numbering, at most `max` items then "... (N in all)".
std::string List(const std::vector<uint32_t>& ids, uint32_t base, size_t max) {
  std::string s;
  for (size_t i = 0; i < ids.size() && i < max; ++i) {
    if (i) s += ", ";
    s += std::to_string(uint64_t{ids[i]} + base);
  }
  if (ids.size() > max) s += Cat(", ... (", ids.size(), " in all)");
  return s;
}

struct Owner {
  uint32_t facet = kNoId;   // kNoId: a free segment
  int32_t loop = -1;        // loop index in the facet, -1 for an in-facet 2-gon
  uint32_t free_id = kNoId;
};

struct FacetWork {
  bool ok = true;                        // usable for triangulation / intersections
  int drop = 2;
  std::vector<std::vector<PointId>> raw_loops;   // before splitting
  std::vector<std::array<PointId, 2>> two_gons;
  std::vector<int> parent;               // loop nesting
  std::vector<bool> hole, two_sided;
};

class Preparer {
 public:
  Preparer(const Plc& plc, const ValidationOptions& vo, ValidationReport* rep)
      : plc_(plc), vo_(vo), rep_(*rep), base_(plc.index_base) {}

  // Returns false when errors make the later steps meaningless.
  bool Run() {
    if (!CheckIndices()) return false;
    MergePoints();
    BuildLoops();
    BuildSegments();
    ClassifyAndTriangulate();
    FindInteriorPoints();
    CheckClosed();
    if (vo_.check_intersections) CheckIntersections();
    return rep_.ok();
  }

  FeatureComplex TakeComplex() { return std::move(fc_); }

 private:
  void Error(ProblemKind k, std::string msg, std::vector<uint32_t> ids, uint32_t line = 0) {
    rep_.errors.push_back({k, Cat(plc_.source_name.empty() ? "<memory>" : plc_.source_name, ": ", msg),
                           std::move(ids), line});
  }
  void Warning(ProblemKind k, std::string msg, std::vector<uint32_t> ids, uint32_t line = 0) {
    rep_.warnings.push_back({k, Cat(plc_.source_name.empty() ? "<memory>" : plc_.source_name, ": ", msg),
                             std::move(ids), line});
  }
  // kUntriangulable naming the facets (0-based ids) and their lines.
  void UntriangulableError(const std::vector<uint32_t>& facets, const char* why) {
    std::vector<uint32_t> lines;
    for (uint32_t f : facets) lines.push_back(FacetLine(f));
    Error(ProblemKind::kUntriangulable,
          Cat(facets.size() == 1 ? "facet " : "facets ", List(facets, base_, vo_.max_listed), why, Lines(lines)), facets,
          lines[0]);
  }
  uint32_t VertexLine(uint32_t v) const { return v < plc_.vertex_lines.size() ? plc_.vertex_lines[v] : 0; }
  uint32_t FacetLine(uint32_t f) const { return f < plc_.facet_lines.size() ? plc_.facet_lines[f] : 0; }
  std::string Lines(const std::vector<uint32_t>& lines) const {
    std::vector<uint32_t> l;
    for (uint32_t x : lines) if (x) l.push_back(x);
    if (l.empty()) return "";
    return Cat(" (line", l.size() > 1 ? "s " : " ", List(l, 0, vo_.max_listed), ")");
  }
  // Input vertex number of a point (its first vertex), in the file's numbering.
  uint64_t VNum(PointId p) const { return uint64_t{first_vertex_[p]} + base_; }
  std::string FacetName(uint32_t f) const {
    std::string s = Cat("facet ", uint64_t{f} + base_);
    const auto& in = plc_.facets[f].input_faces;
    if (!in.empty() && (in.size() > 1 || in[0] != f)) {
      s += Cat(" (input face", in.size() > 1 ? "s " : " ", List(in, base_, 4), ")");
    }
    return s;
  }

  // ---- (1) indices, finiteness
  bool CheckIndices() {
    const size_t n = plc_.vertices.size();
    if (n == 0) {
      Error(ProblemKind::kEmpty, "the PLC has no vertices", {});
      return false;
    }
    std::vector<uint32_t> bad, lines;
    for (uint32_t v = 0; v < n; ++v) {
      if (!geom::IsFinite(plc_.vertices[v])) {
        bad.push_back(v);
        lines.push_back(VertexLine(v));
      }
    }
    if (!bad.empty()) {
      Error(ProblemKind::kNonFinite,
            Cat(bad.size() == 1 ? "vertex " : "vertices ", List(bad, base_, vo_.max_listed),
                bad.size() == 1 ? " has" : " have", " a non-finite coordinate (NaN or Inf)", Lines(lines)),
            bad, lines.empty() ? 0 : lines[0]);
    }
    std::vector<uint32_t> dangling;
    std::string what;
    size_t count = 0;
    for (uint32_t f = 0; f < plc_.facets.size(); ++f) {
      const Facet& facet = plc_.facets[f];
      for (uint32_t k = 0; k < facet.polygons.size(); ++k) {
        for (uint32_t v : facet.polygons[k].vertices) {
          if (v >= n) {
            if (dangling.empty() || dangling.back() != f) dangling.push_back(f);
            if (count++ < vo_.max_listed) {
              what += Cat(what.empty() ? "" : "; ", "facet ", uint64_t{f} + base_, " polygon ",
                          uint64_t{k} + base_, " references vertex ", uint64_t{v} + base_);
            }
          }
        }
        if (facet.polygons[k].vertices.empty()) {
          if (dangling.empty() || dangling.back() != f) dangling.push_back(f);
          if (count++ < vo_.max_listed) what += Cat(what.empty() ? "" : "; ", "facet ", uint64_t{f} + base_, " polygon ", uint64_t{k} + base_, " is empty");
        }
      }
      if (facet.polygons.empty()) {
        dangling.push_back(f);
        if (count++ < vo_.max_listed) what += Cat(what.empty() ? "" : "; ", "facet ", uint64_t{f} + base_, " has no polygon");
      }
    }
    if (!dangling.empty()) {
      Error(ProblemKind::kDanglingIndex,
            Cat("dangling indices (there are ", n, " vertices, numbered ", base_, "..",
                uint64_t{base_} + n - 1, "): ", what, count > vo_.max_listed ? Cat(" ... (", count, " in all)") : ""),
            dangling, FacetLine(dangling[0]));
    }
    std::vector<uint32_t> bad_seg;
    for (uint32_t s = 0; s < plc_.segments.size(); ++s) {
      if (plc_.segments[s].a >= n || plc_.segments[s].b >= n) bad_seg.push_back(s);
    }
    if (!bad_seg.empty()) {
      Error(ProblemKind::kDanglingIndex,
            Cat("segments ", List(bad_seg, base_, vo_.max_listed), " reference missing vertices"), bad_seg);
    }
    std::vector<uint32_t> bad_seeds;
    for (uint32_t f = 0; f < plc_.facets.size(); ++f)
      for (const Vec3& h : plc_.facets[f].holes)
        if (!geom::IsFinite(h)) bad_seeds.push_back(f);
    for (const Vec3& h : plc_.holes)
      if (!geom::IsFinite(h)) bad_seeds.push_back(kNoId);
    for (const RegionSeed& r : plc_.regions)
      if (!geom::IsFinite(r.point) || !std::isfinite(r.attribute) || std::isnan(r.max_volume))
        bad_seeds.push_back(kNoId);
    if (!bad_seeds.empty()) {
      Error(ProblemKind::kSeed, Cat(bad_seeds.size(), " hole or region seeds have non-finite values"), {});
    }
    return rep_.ok();
  }

  // ---- (2) exact duplicates
  void MergePoints() {
    const size_t n = plc_.vertices.size();
    std::vector<uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    auto key = [&](uint32_t i) {
      const Vec3& p = plc_.vertices[i];
      return std::array<uint64_t, 3>{Bits(p.x), Bits(p.y), Bits(p.z)};
    };
    std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return key(a) < key(b); });
    std::vector<uint32_t> rep(n);
    for (size_t k = 0; k < n;) {
      size_t e = k;
      while (e < n && key(order[e]) == key(order[k])) ++e;
      for (size_t q = k; q < e; ++q) rep[order[q]] = order[k];
      k = e;
    }
    fc_.point_of_vertex.assign(n, kNoId);
    std::vector<uint32_t> dups;
    std::string pairs;
    for (uint32_t v = 0; v < n; ++v) {
      if (rep[v] == v) {
        fc_.point_of_vertex[v] = static_cast<PointId>(fc_.points.size());
        FeaturePoint fp;
        fp.p = plc_.vertices[v];
        if (v < plc_.vertex_markers.size()) fp.marker = plc_.vertex_markers[v];
        fc_.points.push_back(fp);
        first_vertex_.push_back(v);
      } else {
        fc_.point_of_vertex[v] = fc_.point_of_vertex[rep[v]];
        if (dups.size() < vo_.max_listed) {
          pairs += Cat(pairs.empty() ? "" : ", ", uint64_t{v} + base_, " = ", uint64_t{rep[v]} + base_);
        }
        dups.push_back(v);
      }
    }
    if (!dups.empty()) {
      Warning(ProblemKind::kDuplicateVertex,
              Cat(dups.size(), " exact duplicate vertices merged (duplicate = kept): ", pairs,
                  dups.size() > vo_.max_listed ? ", ..." : ""),
              dups, VertexLine(dups[0]));
    }
    P_.reserve(fc_.points.size());
    for (const FeaturePoint& p : fc_.points) P_.push_back(p.p);
  }

  // ---- (3) loops, zero area, planarity, frames
  void BuildLoops() {
    const size_t nf = plc_.facets.size();
    work_.resize(nf);
    fc_.facets.resize(nf);
    std::vector<uint32_t> degenerate, zero, nonplanar;
    std::string degenerate_msg, nonplanar_msg;
    for (uint32_t f = 0; f < nf; ++f) {
      const Facet& in = plc_.facets[f];
      FacetWork& w = work_[f];
      FeatureFacet& ff = fc_.facets[f];
      ff.marker = in.marker;
      ff.holes = in.holes;
      ff.input_facet = f;
      std::vector<PointId> all;
      for (uint32_t k = 0; k < in.polygons.size(); ++k) {
        std::vector<PointId> loop;
        for (uint32_t v : in.polygons[k].vertices) {
          const PointId p = fc_.point_of_vertex[v];
          if (loop.empty() || loop.back() != p) loop.push_back(p);
        }
        while (loop.size() > 1 && loop.front() == loop.back()) loop.pop_back();
        all.insert(all.end(), loop.begin(), loop.end());
        std::string why;
        if (in.polygons[k].vertices.size() == 2) {
          if (loop.size() == 2) {
            w.two_gons.push_back({loop[0], loop[1]});
            continue;
          }
          why = "is a segment of length 0";
        } else if (loop.size() < 3) {
          why = "has fewer than 3 distinct vertices";
        } else {
          std::vector<PointId> s = loop;
          std::sort(s.begin(), s.end());
          if (std::adjacent_find(s.begin(), s.end()) != s.end()) why = "is not simple (a vertex repeats)";
        }
        if (!why.empty()) {
          w.ok = false;
          if (degenerate.empty() || degenerate.back() != f) degenerate.push_back(f);
          if (degenerate.size() <= vo_.max_listed) {
            degenerate_msg += Cat(degenerate_msg.empty() ? "" : "; ", "polygon ", uint64_t{k} + base_, " of ", FacetName(f), " ", why);
          }
          continue;
        }
        w.raw_loops.push_back(std::move(loop));
      }
      if (w.raw_loops.empty()) {
        if (w.ok) {
          w.ok = false;
          degenerate.push_back(f);
          degenerate_msg += Cat(degenerate_msg.empty() ? "" : "; ", FacetName(f), " has no polygon with 3 or more vertices");
        }
        continue;
      }
      // Zero area: every point collinear with the first two distinct ones.
      bool collinear = true;
      for (size_t i = 2; i < all.size() && collinear; ++i) {
        collinear = Collinear(P_[all[0]], P_[all[1]], P_[all[i]]);
      }
      if (collinear) {
        w.ok = false;
        zero.push_back(f);
        continue;
      }
      for (size_t l = 0; l < w.raw_loops.size(); ++l) {
        const auto& loop = w.raw_loops[l];
        bool col = true;
        for (size_t i = 2; i < loop.size() && col; ++i) col = Collinear(P_[loop[0]], P_[loop[1]], P_[loop[i]]);
        if (col) {
          w.ok = false;
          if (degenerate.empty() || degenerate.back() != f) degenerate.push_back(f);
          if (degenerate.size() <= vo_.max_listed) {
            degenerate_msg += Cat(degenerate_msg.empty() ? "" : "; ", "a polygon of ", FacetName(f), " has zero area (collinear vertices)");
          }
        }
      }
      // Frame from the loop of largest area.
      size_t best = 0;
      double best_n = -1;
      Vec3 normal;
      for (size_t l = 0; l < w.raw_loops.size(); ++l) {
        const Vec3 n = NewellNormal(P_, w.raw_loops[l]);
        if (geom::Norm(n) > best_n) {
          best_n = geom::Norm(n);
          best = l;
          normal = n;
        }
      }
      FacetFrame& fr = ff.frame;
      fr.origin = P_[w.raw_loops[best][0]];
      fr.normal = best_n > 0 ? normal / best_n : Vec3(0, 0, 1);
      double far = -1;
      Vec3 dir(1, 0, 0);
      for (PointId p : w.raw_loops[best]) {
        const Vec3 d = P_[p] - fr.origin;
        const Vec3 t = d - geom::Dot(d, fr.normal) * fr.normal;
        if (geom::Norm2(t) > far) {
          far = geom::Norm2(t);
          dir = t;
        }
      }
      fr.u = far > 0 ? dir / std::sqrt(far) : Vec3(1, 0, 0);
      fr.v = geom::Cross(fr.normal, fr.u);
      w.drop = DropAxis(fr.normal);
      // Planarity: distance from the best-fit plane, i.e. the Newell normal
      // through the centroid of the facet's points (relative to the origin).
      Box3 box;
      Vec3 centroid;
      for (PointId p : all) centroid += P_[p] - fr.origin;
      centroid = fr.origin + centroid / static_cast<double>(all.size());
      double dmax = 0;
      PointId worst = all[0];
      for (PointId p : all) {
        box.Add(P_[p]);
        const double d = std::fabs(geom::Dot(P_[p] - centroid, fr.normal));
        if (d > dmax) {
          dmax = d;
          worst = p;
        }
      }
      const double diam = box.Diagonal();
      if (!(dmax <= vo_.planarity_tolerance * diam)) {
        w.ok = false;
        nonplanar.push_back(f);
        if (nonplanar.size() <= vo_.max_listed) {
          char buf[160];
          std::snprintf(buf, sizeof buf, " is not planar: vertex %llu is %.3g from its plane (%.3g x the facet diameter %.3g; tolerance %.3g)",
                        static_cast<unsigned long long>(VNum(worst)), dmax, dmax / diam, diam, vo_.planarity_tolerance);
          nonplanar_msg += Cat(nonplanar_msg.empty() ? "" : "; ", FacetName(f), buf);
        }
      }
    }
    auto lines_of = [&](const std::vector<uint32_t>& fs) {
      std::vector<uint32_t> l;
      for (uint32_t f : fs) l.push_back(FacetLine(f));
      return l;
    };
    if (!degenerate.empty()) {
      Error(ProblemKind::kDegeneratePolygon, Cat("degenerate polygons: ", degenerate_msg, Lines(lines_of(degenerate))), degenerate, FacetLine(degenerate[0]));
    }
    if (!zero.empty()) {
      Error(ProblemKind::kZeroAreaFacet,
            Cat(zero.size() == 1 ? "facet " : "facets ", List(zero, base_, vo_.max_listed),
                zero.size() == 1 ? " has" : " have", " zero area (all vertices collinear)", Lines(lines_of(zero))),
            zero, FacetLine(zero[0]));
    }
    if (!nonplanar.empty()) {
      Error(ProblemKind::kNonPlanarFacet, Cat("non-planar facets: ", nonplanar_msg, Lines(lines_of(nonplanar))), nonplanar, FacetLine(nonplanar[0]));
    }
  }

  // ---- (4) segments, split at points lying on them
  void BuildSegments() {
    // Candidate segments with their owners.
    std::map<std::pair<PointId, PointId>, std::vector<Owner>> cand;
    auto add = [&](PointId a, PointId b, Owner o) { cand[{std::min(a, b), std::max(a, b)}].push_back(o); };
    for (uint32_t f = 0; f < work_.size(); ++f) {
      const FacetWork& w = work_[f];
      for (size_t l = 0; l < w.raw_loops.size(); ++l) {
        const auto& loop = w.raw_loops[l];
        for (size_t i = 0; i < loop.size(); ++i) add(loop[i], loop[(i + 1) % loop.size()], {f, static_cast<int32_t>(l), kNoId});
      }
      for (const auto& g : w.two_gons) add(g[0], g[1], {f, -1, kNoId});
    }
    fc_.pieces_of_free_segment.resize(plc_.segments.size());
    std::vector<uint32_t> zero_len;
    for (uint32_t s = 0; s < plc_.segments.size(); ++s) {
      const PointId a = fc_.point_of_vertex[plc_.segments[s].a], b = fc_.point_of_vertex[plc_.segments[s].b];
      if (a == b) {
        zero_len.push_back(s);
        continue;
      }
      add(a, b, {kNoId, -1, s});
    }
    if (!zero_len.empty()) {
      Error(ProblemKind::kDegeneratePolygon, Cat("free segments ", List(zero_len, base_, vo_.max_listed), " have length 0"), zero_len);
    }
    // Points lying exactly inside candidate segments (grid over the points).
    Box3 bounds;
    for (const Vec3& p : P_) bounds.Add(p);
    bounds_ = bounds;
    BoxGrid grid(bounds, P_.size());
    for (const Vec3& p : P_) grid.Insert(Box3{p, p});
    std::vector<uint32_t> hits;
    std::map<std::pair<PointId, PointId>, std::vector<PointId>> chains;  // a..b inclusive, a < b
    for (const auto& [ab, owners] : cand) {
      const auto [a, b] = ab;
      Box3 box;
      box.Add(P_[a]);
      box.Add(P_[b]);
      grid.Query(box, &hits);
      std::vector<PointId> on;
      for (uint32_t p : hits) {
        if (p != a && p != b && StrictlyInsideSegment(P_[p], P_[a], P_[b])) on.push_back(p);
      }
      const Vec3 e = P_[b] - P_[a];
      const int k = std::fabs(e.x) >= std::fabs(e.y) && std::fabs(e.x) >= std::fabs(e.z) ? 0 : (std::fabs(e.y) >= std::fabs(e.z) ? 1 : 2);
      const bool up = P_[b][k] > P_[a][k];
      std::sort(on.begin(), on.end(), [&](PointId x, PointId y) { return up ? P_[x][k] < P_[y][k] : P_[x][k] > P_[y][k]; });
      std::vector<PointId> chain{a};
      chain.insert(chain.end(), on.begin(), on.end());
      chain.push_back(b);
      chains[ab] = std::move(chain);
    }
    // Pieces, sorted by (a, b).
    std::set<std::pair<PointId, PointId>> pieces;
    for (const auto& [ab, chain] : chains) {
      for (size_t i = 0; i + 1 < chain.size(); ++i) pieces.insert({std::min(chain[i], chain[i + 1]), std::max(chain[i], chain[i + 1])});
    }
    for (const auto& [a, b] : pieces) {
      FeatureSegment s;
      s.a = a;
      s.b = b;
      fc_.segments.push_back(s);
    }
    piece_owners_.resize(fc_.segments.size());
    auto chain_of = [&](PointId u, PointId v) {
      std::vector<PointId> c = chains.at({std::min(u, v), std::max(u, v)});
      if (u > v) std::reverse(c.begin(), c.end());
      return c;
    };
    for (const auto& [ab, owners] : cand) {
      const std::vector<PointId>& chain = chains[ab];
      for (size_t i = 0; i + 1 < chain.size(); ++i) {
        const SegmentId sid = fc_.FindSegment(chain[i], chain[i + 1]);
        for (const Owner& o : owners) {
          piece_owners_[sid].push_back(o);
          FeatureSegment& s = fc_.segments[sid];
          if (o.facet != kNoId) {
            s.facets.push_back(o.facet);
          } else {
            s.is_free = true;
            s.marker = plc_.segments[o.free_id].marker;
          }
        }
      }
    }
    for (FeatureSegment& s : fc_.segments) {
      std::sort(s.facets.begin(), s.facets.end());
      s.facets.erase(std::unique(s.facets.begin(), s.facets.end()), s.facets.end());
    }
    for (uint32_t s = 0; s < plc_.segments.size(); ++s) {
      const PointId a = fc_.point_of_vertex[plc_.segments[s].a], b = fc_.point_of_vertex[plc_.segments[s].b];
      if (a == b) continue;
      const std::vector<PointId> c = chain_of(a, b);
      for (size_t i = 0; i + 1 < c.size(); ++i) fc_.pieces_of_free_segment[s].push_back(fc_.FindSegment(c[i], c[i + 1]));
    }
    // Split loops and facet segment lists.
    for (uint32_t f = 0; f < work_.size(); ++f) {
      FeatureFacet& ff = fc_.facets[f];
      for (const auto& loop : work_[f].raw_loops) {
        std::vector<PointId> split;
        for (size_t i = 0; i < loop.size(); ++i) {
          const std::vector<PointId> c = chain_of(loop[i], loop[(i + 1) % loop.size()]);
          split.insert(split.end(), c.begin(), c.end() - 1);
        }
        ff.loops.push_back(std::move(split));
      }
    }
    for (SegmentId sid = 0; sid < fc_.segments.size(); ++sid) {
      for (FacetId f : fc_.segments[sid].facets) fc_.facets[f].segments.push_back(sid);
    }
  }

  // ---- (5) nesting, holes, triangulation
  void ClassifyAndTriangulate() {
    std::vector<uint32_t> failed;
    for (uint32_t f = 0; f < work_.size(); ++f) {
      FacetWork& w = work_[f];
      FeatureFacet& ff = fc_.facets[f];
      const size_t nl = ff.loops.size();
      w.parent.assign(nl, -1);
      w.hole.assign(nl, false);
      w.two_sided.assign(nl, false);
      ff.loop_is_hole.assign(nl, false);
      if (!w.ok) continue;
      std::vector<double> area(nl);
      for (size_t l = 0; l < nl; ++l) area[l] = geom::Norm(NewellNormal(P_, ff.loops[l]));
      for (size_t i = 0; i < nl; ++i) {
        for (size_t j = 0; j < nl; ++j) {
          if (i == j || area[j] <= area[i]) continue;
          // A vertex of loop i that is not on loop j decides.
          const std::vector<PointId>& lj = ff.loops[j];
          for (PointId p : ff.loops[i]) {
            if (std::find(lj.begin(), lj.end(), p) != lj.end()) continue;
            if (PointInLoop(P_, lj, P_[p], w.drop) &&
                (w.parent[i] < 0 || area[j] < area[w.parent[i]])) {
              w.parent[i] = static_cast<int>(j);
            }
            break;
          }
        }
      }
      for (const Vec3& seed : ff.holes) {
        int inner = -1;
        for (size_t l = 0; l < nl; ++l) {
          if (PointInLoop(P_, ff.loops[l], seed, w.drop) && (inner < 0 || area[l] < area[inner])) inner = static_cast<int>(l);
        }
        if (inner >= 0) w.hole[inner] = true;
      }
      for (size_t l = 0; l < nl; ++l) {
        ff.loop_is_hole[l] = w.hole[l];
        w.two_sided[l] = !w.hole[l] && w.parent[l] >= 0 && !w.hole[w.parent[l]];
      }
      bool ok = true;
      for (size_t l = 0; l < nl && ok; ++l) {
        if (w.hole[l] || w.two_sided[l]) continue;  // not a piece
        std::vector<std::vector<uint32_t>> holes;
        for (size_t h = 0; h < nl; ++h) {
          if (w.hole[h] && w.parent[h] == static_cast<int>(l)) holes.push_back(ff.loops[h]);
        }
        ok = TriangulatePolygon(P_, ff.loops[l], holes, w.drop, &ff.triangles);
      }
      // In-facet segments and edges of in-facet polygons become triangle edges.
      if (ok) {
        std::vector<std::array<uint32_t, 2>> cons;
        for (SegmentId sid : ff.segments) {
          for (const Owner& o : piece_owners_[sid]) {
            if (o.facet == f && (o.loop < 0 || w.two_sided[o.loop])) {
              cons.push_back({fc_.segments[sid].a, fc_.segments[sid].b});
              ff.interior_segments.push_back(sid);
              break;
            }
          }
        }
        if (!cons.empty()) ok = InsertConstraints(P_, w.drop, {}, cons, &ff.triangles);
      }
      if (!ok) {
        w.ok = false;
        ff.triangles.clear();
        failed.push_back(f);
      }
    }
    if (!failed.empty()) UntriangulableError(failed, ": polygons are not simple or cross each other (cannot triangulate)");
  }

  // ---- (6) isolated points and free segment ends inside facets
  void FindInteriorPoints() {
    std::vector<bool> on_loop(P_.size(), false), on_free(P_.size(), false);
    for (const FeatureFacet& ff : fc_.facets)
      for (const auto& loop : ff.loops)
        for (PointId p : loop) on_loop[p] = true;
    for (const FeatureSegment& s : fc_.segments) {
      if (!s.facets.empty()) {
        on_loop[s.a] = on_loop[s.b] = true;  // in-facet 2-gons count as facet points
      } else {
        on_free[s.a] = on_free[s.b] = true;
      }
    }
    std::vector<PointId> cands;
    for (PointId p = 0; p < P_.size(); ++p) {
      if (!on_loop[p]) cands.push_back(p);
    }
    if (!cands.empty()) {
      BoxGrid grid(bounds_, TriangleCount() + 1);
      std::vector<std::pair<uint32_t, uint32_t>> tri_ref;
      for (uint32_t f = 0; f < fc_.facets.size(); ++f) {
        for (uint32_t t = 0; t < fc_.facets[f].triangles.size(); ++t) {
          grid.Insert(TriBox(f, t));
          tri_ref.push_back({f, t});
        }
      }
      std::vector<uint32_t> hits;
      for (PointId p : cands) {
        grid.Query(Box3{P_[p], P_[p]}, &hits);
        for (uint32_t h : hits) {
          const auto [f, t] = tri_ref[h];
          const auto& tr = fc_.facets[f].triangles[t];
          if (!PointInTriangle(P_[p], P_[tr[0]], P_[tr[1]], P_[tr[2]])) continue;
          auto& io = fc_.points[p].interior_of;
          if (std::find(io.begin(), io.end(), f) == io.end()) {
            io.push_back(f);
            fc_.facets[f].interior_points.push_back(p);
          }
        }
      }
    }
    for (uint32_t f = 0; f < fc_.facets.size(); ++f) {
      FeatureFacet& ff = fc_.facets[f];
      if (ff.interior_points.empty()) continue;
      std::sort(ff.interior_points.begin(), ff.interior_points.end());
      if (!InsertConstraints(P_, work_[f].drop, ff.interior_points, {}, &ff.triangles)) {
        Error(ProblemKind::kUntriangulable, Cat(FacetName(f), ": cannot insert its interior points"), {f}, FacetLine(f));
        work_[f].ok = false;
      }
    }
    for (PointId p = 0; p < P_.size(); ++p) {
      fc_.points[p].isolated = !on_loop[p] && !on_free[p] && fc_.points[p].interior_of.empty();
      std::sort(fc_.points[p].interior_of.begin(), fc_.points[p].interior_of.end());
    }
    for (FeatureFacet& ff : fc_.facets) std::sort(ff.interior_points.begin(), ff.interior_points.end());
  }

  size_t TriangleCount() const {
    size_t n = 0;
    for (const FeatureFacet& ff : fc_.facets) n += ff.triangles.size();
    return n;
  }
  Box3 TriBox(uint32_t f, uint32_t t) const {
    Box3 b;
    for (PointId p : fc_.facets[f].triangles[t]) b.Add(P_[p]);
    return b;
  }

  // Number of facet sides at each segment: a boundary loop edge counts 1, an
  // in-facet segment or an edge of an in-facet polygon counts 2.
  std::vector<int> SideCounts(const std::vector<bool>& alive) const {
    std::vector<int> sides(fc_.segments.size(), 0);
    for (SegmentId s = 0; s < fc_.segments.size(); ++s) {
      for (const Owner& o : piece_owners_[s]) {
        if (o.facet == kNoId || !alive[o.facet]) continue;
        const bool two = o.loop < 0 || work_[o.facet].two_sided[o.loop];
        sides[s] += two ? 2 : 1;
      }
    }
    return sides;
  }

  std::string EdgeList(const std::vector<uint32_t>& segs) const {
    std::string s;
    for (size_t i = 0; i < segs.size() && i < vo_.max_listed; ++i) {
      s += Cat(i ? ", " : "", VNum(fc_.segments[segs[i]].a), "-", VNum(fc_.segments[segs[i]].b));
    }
    if (segs.size() > vo_.max_listed) s += ", ...";
    return s;
  }

  // ---- (7) closedness
  void CheckClosed() {
    const size_t nf = fc_.facets.size();
    if (nf == 0) return;
    std::vector<bool> alive(nf, true);
    std::vector<int> sides = SideCounts(alive);
    std::vector<uint32_t> boundary, nonmanifold;
    for (SegmentId s = 0; s < sides.size(); ++s) {
      if (sides[s] == 1) boundary.push_back(s);
      if (sides[s] > 2) nonmanifold.push_back(s);
    }
    if (plc_.is_surface) {
      if (!boundary.empty()) {
        Error(ProblemKind::kOpenBoundary,
              Cat("open surface: ", boundary.size(), " boundary edges (on a single face), e.g. vertices ",
                  EdgeList(boundary), "; a surface input must be closed to enclose a volume"),
              boundary, FacetLine(fc_.segments[boundary[0]].facets[0]));
      }
      if (!nonmanifold.empty()) {
        Warning(ProblemKind::kNonManifoldEdge,
                Cat(nonmanifold.size(), " non-manifold edges (on more than two faces), e.g. vertices ", EdgeList(nonmanifold)),
                nonmanifold);
      }
      return;
    }
    // Peel facets with a free edge until none is left; what remains encloses volumes.
    std::vector<uint32_t> queue;
    auto has_free_edge = [&](uint32_t f) {
      for (SegmentId s : fc_.facets[f].segments) if (sides[s] == 1) return true;
      return false;
    };
    for (uint32_t f = 0; f < nf; ++f) if (has_free_edge(f)) queue.push_back(f);
    std::vector<uint32_t> peeled;
    while (!queue.empty()) {
      const uint32_t f = queue.back();
      queue.pop_back();
      if (!alive[f]) continue;
      alive[f] = false;
      peeled.push_back(f);
      for (SegmentId s : fc_.facets[f].segments) {
        for (const Owner& o : piece_owners_[s]) {
          if (o.facet == f) sides[s] -= (o.loop < 0 || work_[f].two_sided[o.loop]) ? 2 : 1;
        }
        if (sides[s] == 1) {
          for (FacetId g : fc_.segments[s].facets) if (alive[g]) queue.push_back(g);
        }
      }
    }
    std::sort(peeled.begin(), peeled.end());
    if (peeled.size() == nf) {
      Error(ProblemKind::kOpenBoundary,
            Cat("the facets enclose no volume: ", boundary.size(),
                " boundary edges lie on a single facet side, e.g. vertices ", EdgeList(boundary),
                boundary.empty() ? "" : Cat(" (facet ", uint64_t{fc_.segments[boundary[0]].facets[0]} + base_, ")")),
            boundary, boundary.empty() ? 0 : FacetLine(fc_.segments[boundary[0]].facets[0]));
    } else if (!peeled.empty()) {
      Warning(ProblemKind::kDanglingFacet,
              Cat("facets ", List(peeled, base_, vo_.max_listed),
                  " have free edges (they do not bound a closed region: internal fins or open parts)"),
              peeled);
    }
  }

  // ---- (8) intersections
  bool TriTriImproper(uint32_t f1, const std::array<PointId, 3>& t1, uint32_t f2,
                      const std::array<PointId, 3>& t2) const {
    int shared = 0;
    for (PointId a : t1) for (PointId b : t2) shared += a == b;
    const Vec3 &a0 = P_[t1[0]], &a1 = P_[t1[1]], &a2 = P_[t1[2]];
    const Vec3 &b0 = P_[t2[0]], &b1 = P_[t2[1]], &b2 = P_[t2[2]];
    if (shared >= 3) return true;
    if (shared == 0) {
      for (int i = 0; i < 3; ++i) {
        if (SegmentMeetsTriangle(P_[t1[i]], P_[t1[(i + 1) % 3]], b0, b1, b2)) return true;
        if (SegmentMeetsTriangle(P_[t2[i]], P_[t2[(i + 1) % 3]], a0, a1, a2)) return true;
      }
      return false;
    }
    if (shared == 2) {
      PointId u = kNoId, v = kNoId, a = kNoId, b = kNoId;
      for (PointId x : t1) {
        if (std::find(t2.begin(), t2.end(), x) != t2.end()) (u == kNoId ? u : v) = x;
        else a = x;
      }
      for (PointId x : t2) if (x != u && x != v) b = x;
      // The shared edge must be a segment of both facets (not a diagonal of
      // one facet's triangulation lying in its interior).
      const SegmentId sid = fc_.FindSegment(u, v);
      if (sid == kNoId) return true;
      const auto& fs = fc_.segments[sid].facets;
      if (!std::binary_search(fs.begin(), fs.end(), f1) || !std::binary_search(fs.begin(), fs.end(), f2)) return true;
      if (Orient3dSign(P_[u], P_[v], P_[a], P_[b]) != 0) return false;
      const int d = FaithfulDrop(P_[u], P_[v], P_[a]);
      return Orient2dSign(P_[u], P_[v], P_[a], d) == Orient2dSign(P_[u], P_[v], P_[b], d);
    }
    // One shared vertex v: an edge of one triangle meets the other elsewhere.
    PointId v = kNoId;
    for (PointId x : t1) if (std::find(t2.begin(), t2.end(), x) != t2.end()) v = x;
    auto check = [&](const std::array<PointId, 3>& s, const std::array<PointId, 3>& t) {
      std::array<PointId, 2> others;
      int k = 0;
      for (PointId x : s) if (x != v) others[k++] = x;
      std::array<PointId, 2> tothers;
      k = 0;
      for (PointId x : t) if (x != v) tothers[k++] = x;
      if (SegmentMeetsTriangle(P_[others[0]], P_[others[1]], P_[t[0]], P_[t[1]], P_[t[2]])) return true;
      for (PointId x : others) {
        if (SegmentFromCornerEntersTriangle(P_[v], P_[x], P_[tothers[0]], P_[tothers[1]])) return true;
      }
      return false;
    };
    return check(t1, t2) || check(t2, t1);
  }

  bool SegTriImproper(SegmentId sid, uint32_t f, const std::array<PointId, 3>& t) const {
    const FeatureSegment& s = fc_.segments[sid];
    const auto& ip = fc_.facets[f].interior_points;
    auto in_facet = [&](PointId p) {
      return std::find(t.begin(), t.end(), p) != t.end() || std::binary_search(ip.begin(), ip.end(), p);
    };
    const bool sa = in_facet(s.a), sb = in_facet(s.b);
    if (sa && sb) return true;  // the segment lies in the facet but is not one of its segments
    if (!sa && !sb) return SegmentMeetsTriangle(P_[s.a], P_[s.b], P_[t[0]], P_[t[1]], P_[t[2]]);
    const PointId v = sa ? s.a : s.b, x = sa ? s.b : s.a;
    const auto vit = std::find(t.begin(), t.end(), v);
    if (vit == t.end()) {  // v inside the facet: improper iff the segment lies in its plane
      return Orient3dSign(P_[t[0]], P_[t[1]], P_[t[2]], P_[x]) == 0;
    }
    std::array<PointId, 2> o;
    int k = 0;
    for (PointId y : t) if (y != v) o[k++] = y;
    if (SegmentFromCornerEntersTriangle(P_[v], P_[x], P_[o[0]], P_[o[1]])) return true;
    return false;
  }

  // Do segments i and j meet other than at a shared endpoint? Exactly in 3D
  // (drop < 0), or in the projection dropping axis `drop` for edges of one
  // facet: a slanted facet's points are coplanar only up to rounding, and
  // the 3D test needs exact coplanarity (random_plcs.py holed 85: a hole loop
  // crossing the outer loop of a slanted facet was VALID).
  bool SegSegImproper(SegmentId i, SegmentId j, int drop = -1) const {
    const FeatureSegment& s = fc_.segments[i];
    const FeatureSegment& t = fc_.segments[j];
    PointId v = kNoId, a = kNoId, b = kNoId;
    if (s.a == t.a || s.a == t.b) v = s.a, a = s.b, b = s.a == t.a ? t.b : t.a;
    else if (s.b == t.a || s.b == t.b) v = s.b, a = s.a, b = s.b == t.a ? t.b : t.a;
    if (v == kNoId) {
      return drop < 0 ? SegmentsMeet(P_[s.a], P_[s.b], P_[t.a], P_[t.b])
                      : SegmentsMeetProjected(P_[s.a], P_[s.b], P_[t.a], P_[t.b], drop);
    }
    if (drop < 0 ? !Collinear(P_[v], P_[a], P_[b]) : Orient2dSign(P_[v], P_[a], P_[b], drop) != 0) return false;
    // Collinear: they overlap iff a and b are on one side of v, along the
    // largest coordinate of a − v that is kept.
    const Vec3 e = P_[a] - P_[v];
    int k = -1;
    for (int c = 0; c < 3; ++c) {
      if (c != drop && (k < 0 || std::fabs(e[c]) > std::fabs(e[k]))) k = c;
    }
    return (P_[a][k] > P_[v][k]) == (P_[b][k] > P_[v][k]);
  }

  void CheckIntersections() {
    // Primitives: triangles of usable facets, free segments on no facet.
    // Segments of facets take part in the segment-segment test only: two
    // edges of one facet's polygons that cross (a hole loop crossing its
    // outer loop) are invisible to the triangle tests, which skip pairs of
    // one facet, and the facet's triangulation may even succeed by leaving
    // the crossing loop out of it (random_plcs.py holed 2).
    struct Prim {
      uint32_t facet;     // kNoId for a segment
      uint32_t index;     // triangle index or segment id
      bool facet_segment = false;
    };
    std::vector<Prim> prims;
    for (uint32_t f = 0; f < fc_.facets.size(); ++f) {
      if (!work_[f].ok) continue;
      for (uint32_t t = 0; t < fc_.facets[f].triangles.size(); ++t) prims.push_back({f, t});
    }
    // Only facets that triangulated with two or more loops can hide a
    // crossing (a lone loop that crosses itself fails to triangulate).
    auto several_loops = [&](FacetId f) { return work_[f].ok && fc_.facets[f].loops.size() >= 2; };
    for (SegmentId s = 0; s < fc_.segments.size(); ++s) {
      const std::vector<FacetId>& fs = fc_.segments[s].facets;
      if (fs.empty()) {
        prims.push_back({kNoId, s});
      } else if (std::any_of(fs.begin(), fs.end(), several_loops)) {
        prims.push_back({kNoId, s, true});
      }
    }
    if (prims.size() < 2) return;
    BoxGrid grid(bounds_, prims.size());
    for (const Prim& p : prims) {
      if (p.facet != kNoId) {
        grid.Insert(TriBox(p.facet, p.index));
      } else {
        Box3 b;
        b.Add(P_[fc_.segments[p.index].a]);
        b.Add(P_[fc_.segments[p.index].b]);
        grid.Insert(b);
      }
    }
    std::set<std::pair<uint32_t, uint32_t>> ff, sf, ss;
    std::set<uint32_t> crossed_facets;
    grid.ForEachOverlappingPair([&](uint32_t i, uint32_t j) {
      const Prim& a = prims[i];
      const Prim& b = prims[j];
      if (a.facet_segment || b.facet_segment) {
        if (a.facet != kNoId || b.facet != kNoId) return;  // a facet's segment and a triangle
        const std::vector<FacetId>& fa = fc_.segments[a.index].facets;
        const std::vector<FacetId>& fb = fc_.segments[b.index].facets;
        // Edges of two facets that cross make their triangles cross too
        // (reported below); edges of one facet are this test's own finding.
        for (FacetId f : fa) {
          if (several_loops(f) && std::find(fb.begin(), fb.end(), f) != fb.end() &&
              SegSegImproper(a.index, b.index, work_[f].drop)) {
            crossed_facets.insert(f);
          }
        }
        return;
      }
      if (a.facet != kNoId && b.facet != kNoId) {
        if (a.facet == b.facet) return;
        const auto key = std::make_pair(std::min(a.facet, b.facet), std::max(a.facet, b.facet));
        if (ff.count(key)) return;
        if (TriTriImproper(a.facet, fc_.facets[a.facet].triangles[a.index], b.facet, fc_.facets[b.facet].triangles[b.index])) ff.insert(key);
      } else if (a.facet == kNoId && b.facet == kNoId) {
        if (SegSegImproper(a.index, b.index)) ss.insert({a.index, b.index});
      } else {
        const Prim& s = a.facet == kNoId ? a : b;
        const Prim& t = a.facet == kNoId ? b : a;
        if (sf.count({s.index, t.facet})) return;
        if (SegTriImproper(s.index, t.facet, fc_.facets[t.facet].triangles[t.index])) sf.insert({s.index, t.facet});
      }
    });
    if (!crossed_facets.empty()) {
      UntriangulableError({crossed_facets.begin(), crossed_facets.end()}, ": edges of its polygons cross each other");
    }
    if (!ff.empty()) {
      std::vector<uint32_t> ids;
      std::string msg;
      size_t k = 0;
      for (const auto& [x, y] : ff) {
        ids.push_back(x);
        ids.push_back(y);
        if (k++ < vo_.max_listed) msg += Cat(msg.empty() ? "" : "; ", FacetName(x), " and ", FacetName(y));
      }
      Error(ProblemKind::kIntersection,
            Cat(ff.size(), " pairs of facets intersect other than along shared segments and points: ", msg,
                ff.size() > vo_.max_listed ? "; ..." : ""),
            ids, FacetLine(ids[0]));
    }
    if (!sf.empty()) {
      std::vector<uint32_t> ids;
      std::string msg;
      size_t k = 0;
      for (const auto& [s, f] : sf) {
        ids.push_back(s);
        ids.push_back(f);
        if (k++ < vo_.max_listed) msg += Cat(msg.empty() ? "" : "; ", "segment ", VNum(fc_.segments[s].a), "-", VNum(fc_.segments[s].b), " and ", FacetName(f));
      }
      Error(ProblemKind::kIntersection,
            Cat(sf.size(), " free segments meet facets other than at shared points: ", msg, sf.size() > vo_.max_listed ? "; ..." : ""), ids);
    }
    if (!ss.empty()) {
      std::vector<uint32_t> ids;
      std::string msg;
      size_t k = 0;
      for (const auto& [s, t] : ss) {
        ids.push_back(s);
        ids.push_back(t);
        if (k++ < vo_.max_listed) msg += Cat(msg.empty() ? "" : "; ", "segments ", VNum(fc_.segments[s].a), "-", VNum(fc_.segments[s].b), " and ", VNum(fc_.segments[t].a), "-", VNum(fc_.segments[t].b));
      }
      Error(ProblemKind::kIntersection,
            Cat(ss.size(), " pairs of free segments cross or overlap: ", msg, ss.size() > vo_.max_listed ? "; ..." : ""), ids);
    }
  }

  const Plc& plc_;
  const ValidationOptions& vo_;
  ValidationReport& rep_;
  const uint32_t base_;
  FeatureComplex fc_;
  std::vector<Vec3> P_;                    // point coordinates
  std::vector<uint32_t> first_vertex_;     // point -> first input vertex
  std::vector<FacetWork> work_;
  std::vector<std::vector<Owner>> piece_owners_;
  Box3 bounds_;
};

}  // namespace

ValidationReport ValidatePlc(const Plc& plc, const ValidationOptions& options) {
  ValidationReport report;
  Preparer(plc, options, &report).Run();
  return report;
}

absl::StatusOr<FeatureComplex> PreparePlc(const Plc& plc, const ValidationOptions& voptions,
                                          const FeatureOptions& foptions, ValidationReport* report) {
  ValidationReport local;
  ValidationReport& rep = report ? *report : local;
  rep = ValidationReport{};
  Preparer prep(plc, voptions, &rep);
  if (!prep.Run()) return rep.ToStatus();
  FeatureComplex fc = prep.TakeComplex();
  fc.holes = plc.holes;
  fc.regions = plc.regions;
  internal::ComputeCreases(&fc, foptions.crease_angle_deg);
  if (foptions.compute_spread) internal::ComputeSpread(&fc);
  return fc;
}

absl::StatusOr<FeatureComplex> BuildFeatureComplex(const Plc& plc, const FeatureOptions& options) {
  return PreparePlc(plc, ValidationOptions{}, options, nullptr);
}

}  // namespace svrc::plc
