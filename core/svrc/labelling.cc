// Region labelling: see labelling.h and docs/svrc-output.md.
#include "core/svrc/labelling.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/geometry/predicates.h"
#include "core/svrc/tet_faces.h"

namespace svrc::refine {
namespace {

using geom::Vec3;

std::array<uint32_t, 3> Sorted3(std::array<uint32_t, 3> v) {
  std::sort(v.begin(), v.end());
  return v;
}

std::array<uint32_t, 4> Sorted4(std::array<uint32_t, 4> v) {
  std::sort(v.begin(), v.end());
  return v;
}

std::string PointString(const Vec3& p) { return absl::StrFormat("(%.17g, %.17g, %.17g)", p.x, p.y, p.z); }

// Closed-tet containment by exact orientation (core/geometry/predicates.h):
// -1 outside, 0 on the boundary (a face, edge or vertex), +1 strictly inside.
// A positively oriented tet contains p iff p is on the non-negative side of
// each face (the face seen from the opposite vertex).
int InTet(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const int s0 = geom::Orient3d(p, b, c, d);
  if (s0 < 0) return -1;
  const int s1 = geom::Orient3d(a, p, c, d);
  if (s1 < 0) return -1;
  const int s2 = geom::Orient3d(a, b, p, d);
  if (s2 < 0) return -1;
  const int s3 = geom::Orient3d(a, b, c, p);
  if (s3 < 0) return -1;
  return (s0 > 0 && s1 > 0 && s2 > 0 && s3 > 0) ? 1 : 0;
}

// For every query point, the tets whose closure contains it and whether it is
// strictly inside each. A uniform grid over the vertices' bounding box bins
// the points; every tet visits the cells its bounding box overlaps. Cell
// indices come from a monotone map, so a point inside a tet's box lies in a
// cell of the tet's range.
struct Hit {
  uint32_t tet;
  bool strict;
};

// A walk through the tets towards q from tet 0, across a face whose plane
// has q strictly on its far side (InTet's orientations; the first such face
// from a rotating start, so that a walk in a mesh that is not Delaunay does
// not circle). The tet that strictly contains q, or kNoTet: q on a face,
// edge or vertex of the tet reached, a boundary face crossed, or more than
// `max_steps` steps. A point strictly inside a tet lies in no other tet's
// closure, so then that tet is its only hit (as the scan would find it).
template <typename Tets, typename Nbr4>
uint32_t WalkToStrictTet(std::span<const Vec3> pos, const Tets& tets, const Nbr4& nbr4, const Vec3& q,
                         size_t max_steps) {
  uint32_t t = 0;
  for (size_t step = 0; step < max_steps; ++step) {
    const std::array<uint32_t, 4> v = tets[t];
    Vec3 x[4] = {pos[v[0]], pos[v[1]], pos[v[2]], pos[v[3]]};
    int beyond = -1;
    bool strict = true;
    for (int i = 0; i < 4 && beyond < 0; ++i) {
      const int f = static_cast<int>((i + step) % 4);
      const Vec3 keep = x[f];
      x[f] = q;
      const int o = geom::Orient3d(x[0], x[1], x[2], x[3]);
      x[f] = keep;
      if (o < 0) beyond = f;
      if (o == 0) strict = false;
    }
    if (beyond < 0) return strict ? t : kNoTet;
    const uint32_t s = nbr4(t)[beyond];
    if (s == kNoTet) return kNoTet;
    t = s / 4;
  }
  return kNoTet;
}

template <typename Tets, typename Nbr4>
std::vector<std::vector<Hit>> LocatePoints(std::span<const Vec3> pos, const Tets& tets,
                                           std::span<const Vec3> queries, const Nbr4& nbr4) {
  std::vector<std::vector<Hit>> hits(queries.size());
  if (queries.empty() || tets.empty() || pos.empty()) return hits;
  // Walk first (region seeds lie inside their regions; on cube --max-volume
  // 1e-5 the scan below was 4% of the run's instructions); the scan takes
  // the points no walk settles.
  // A walked point has its one hit; the scan takes those with none.
  const size_t max_steps = 64 + 16 * static_cast<size_t>(std::cbrt(static_cast<double>(tets.size())));
  size_t left = 0;
  for (size_t i = 0; i < queries.size(); ++i) {
    const uint32_t t = geom::IsFinite(queries[i]) ? WalkToStrictTet(pos, tets, nbr4, queries[i], max_steps) : kNoTet;
    if (t != kNoTet) {
      hits[i].push_back({t, true});
    } else {
      ++left;
    }
  }
  if (left == 0) return hits;
  Vec3 lo = pos[0], hi = pos[0];
  for (const Vec3& p : pos) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  const int n = std::clamp(static_cast<int>(std::cbrt(static_cast<double>(tets.size()) / 4.0)), 1,
                           128);
  auto cell1 = [&](double x, double l, double h) {
    if (!(h > l)) return 0;
    const double f = (x - l) / (h - l) * n;
    if (!(f > 0)) return 0;
    return std::min(n - 1, static_cast<int>(f));
  };
  auto inside_box = [&](const Vec3& q) {
    return q.x >= lo.x && q.x <= hi.x && q.y >= lo.y && q.y <= hi.y && q.z >= lo.z && q.z <= hi.z;
  };
  // CSR: cell -> queries.
  const size_t num_cells = static_cast<size_t>(n) * n * n;
  std::vector<uint32_t> start(num_cells + 1, 0);
  std::vector<size_t> qcell(queries.size(), num_cells);
  for (size_t i = 0; i < queries.size(); ++i) {
    const Vec3& q = queries[i];
    if (!hits[i].empty() || !geom::IsFinite(q) || !inside_box(q)) continue;
    qcell[i] = (static_cast<size_t>(cell1(q.z, lo.z, hi.z)) * n + cell1(q.y, lo.y, hi.y)) * n +
               cell1(q.x, lo.x, hi.x);
    ++start[qcell[i] + 1];
  }
  for (size_t c = 0; c < num_cells; ++c) start[c + 1] += start[c];
  std::vector<uint32_t> fill(start.begin(), start.end() - 1);
  std::vector<uint32_t> items(start[num_cells]);
  for (size_t i = 0; i < queries.size(); ++i) {
    if (qcell[i] != num_cells) items[fill[qcell[i]]++] = static_cast<uint32_t>(i);
  }
  if (items.empty()) return hits;
  for (size_t t = 0; t < tets.size(); ++t) {
    const std::array<uint32_t, 4> tv = tets[t];
    const Vec3& a = pos[tv[0]];
    const Vec3& b = pos[tv[1]];
    const Vec3& c = pos[tv[2]];
    const Vec3& d = pos[tv[3]];
    const Vec3 tlo{std::min({a.x, b.x, c.x, d.x}), std::min({a.y, b.y, c.y, d.y}),
                   std::min({a.z, b.z, c.z, d.z})};
    const Vec3 thi{std::max({a.x, b.x, c.x, d.x}), std::max({a.y, b.y, c.y, d.y}),
                   std::max({a.z, b.z, c.z, d.z})};
    const int x0 = cell1(tlo.x, lo.x, hi.x), x1 = cell1(thi.x, lo.x, hi.x);
    const int y0 = cell1(tlo.y, lo.y, hi.y), y1 = cell1(thi.y, lo.y, hi.y);
    const int z0 = cell1(tlo.z, lo.z, hi.z), z1 = cell1(thi.z, lo.z, hi.z);
    for (int z = z0; z <= z1; ++z) {
      for (int y = y0; y <= y1; ++y) {
        for (int x = x0; x <= x1; ++x) {
          const size_t cell = (static_cast<size_t>(z) * n + y) * n + x;
          for (uint32_t k = start[cell]; k < start[cell + 1]; ++k) {
            const uint32_t qi = items[k];
            const Vec3& q = queries[qi];
            if (q.x < tlo.x || q.x > thi.x || q.y < tlo.y || q.y > thi.y || q.z < tlo.z ||
                q.z > thi.z) {
              continue;
            }
            const int s = InTet(q, a, b, c, d);
            if (s >= 0) hits[qi].push_back({static_cast<uint32_t>(t), s > 0});
          }
        }
      }
    }
  }
  return hits;
}

// The tie rule of docs/svrc-output.md: a tet strictly containing the point
// wins; otherwise (the point is on a face, edge or vertex of the mesh) the tet
// whose sorted vertex ids are lexicographically smallest. The rule depends on
// the tets' vertex sets only, not on the order of the tet list.
template <typename Tets>
uint32_t ChooseTet(const std::vector<Hit>& hits, const Tets& tets) {
  uint32_t best = kNoTet;
  bool best_strict = false;
  std::array<uint32_t, 4> best_key{};
  for (const Hit& h : hits) {
    const std::array<uint32_t, 4> key = Sorted4(tets[h.tet]);
    if (best == kNoTet || (h.strict && !best_strict) ||
        (h.strict == best_strict && key < best_key)) {
      best = h.tet;
      best_strict = h.strict;
      best_key = key;
    }
  }
  return best;
}

// LabelInput's tets, from its array or its tet_vertices_of function.
struct TetList {
  const LabelInput* in;
  size_t size() const { return in->tet_vertices_of ? in->num_tets : in->tets.size(); }
  bool empty() const { return size() == 0; }
  std::array<uint32_t, 4> operator[](size_t t) const {
    return in->tet_vertices_of ? in->tet_vertices_of(static_cast<uint32_t>(t)) : in->tets[t];
  }
};

}  // namespace

std::string_view LabelIssueKindName(LabelIssueKind kind) {
  switch (kind) {
    case LabelIssueKind::kSeedOutsideMesh: return "seed_outside_mesh";
    case LabelIssueKind::kSeedDropped: return "seed_dropped";
    case LabelIssueKind::kSeedConflict: return "seed_conflict";
    case LabelIssueKind::kSeedOnFacet: return "seed_on_facet";
    case LabelIssueKind::kHoleSeedOutsideMesh: return "hole_seed_outside_mesh";
    case LabelIssueKind::kHoleSeedsIgnored: return "hole_seeds_ignored";
    case LabelIssueKind::kDuplicateConstrainedFace: return "duplicate_constrained_face";
  }
  return "unknown";
}

absl::StatusOr<Labelling> LabelRegions(const LabelInput& in) {
  const size_t nv = in.positions.size();
  const TetList tets{&in};
  const size_t nt = tets.size();
  if (nt >= (size_t{1} << 30)) {
    return absl::InvalidArgumentError(absl::StrCat("too many tets for labelling: ", nt));
  }
  for (size_t t = 0; t < nt; ++t) {
    for (uint32_t v : tets[t]) {
      if (v >= nv) {
        return absl::InvalidArgumentError(
            absl::StrCat("tet ", t, " has vertex id ", v, " out of range (", nv, " vertices)"));
      }
    }
  }
  const size_t ncf = in.constrained_faces.size();
  for (size_t i = 0; i < ncf; ++i) {
    const auto& v = in.constrained_faces[i].v;
    for (uint32_t x : v) {
      if (x >= nv) {
        return absl::InvalidArgumentError(absl::StrCat("constrained face ", i, " has vertex id ",
                                                       x, " out of range (", nv, " vertices)"));
      }
    }
  }

  // --- Face adjacency: group the 4T faces by their vertex sets. -------------
  // Bucketed by smallest vertex and matched inside each bucket (tet_faces.h):
  // same pairs, same first (smallest-slot) record per face and same error as
  // sorting all 4T records by (a, b, c, slot), without the sort (it took ~60%
  // of the labelling). Two records: the tets are neighbours; more: not a
  // tetrahedralization (reported for the smallest (a, b, c), with its three
  // smallest slots).
  const bool slot_array = !in.neighbor_tets.empty();
  const bool given = slot_array || (in.neighbor_slots_of != nullptr && in.find_face != nullptr);
  if (in.tet_vertices_of != nullptr && (slot_array || !given)) {
    return absl::InvalidArgumentError("tet_vertices_of needs neighbor_slots_of and find_face");
  }
  if (slot_array) {
    if (in.neighbor_tets.size() != nt) {
      return absl::InvalidArgumentError(
          absl::StrCat(in.neighbor_tets.size(), " rows of neighbour tets for ", nt, " tets"));
    }
    for (size_t t = 0; t < nt; ++t) {
      for (int f = 0; f < 4; ++f) {
        const uint32_t u = in.neighbor_tets[t][f];
        if (u != kNoTet && (u >= nt || u == t)) {
          return absl::InvalidArgumentError(absl::StrCat("tet ", t, " face ", f, " has neighbour ", u));
        }
      }
    }
  }
  // With the array: the tets at each constrained face's smallest vertex,
  // whose faces there stand in for the table's buckets (StarBucket).
  VertexStars stars;
  if (slot_array) {
    std::vector<uint8_t> first(nv, 0);
    for (const ConstrainedFace& cf : in.constrained_faces) {
      first[std::min({cf.v[0], cf.v[1], cf.v[2]})] = 1;
    }
    stars = StarsOf(in.tets, nv, first);
  }
  std::optional<TetFaces> tet_faces;
  std::vector<uint32_t> own_nbr;
  if (!given) {
    tet_faces.emplace(in.tets, nv);
    own_nbr.assign(4 * nt, kNoTet);
  }
  // The four slots facing tet t's (one call per tet when given). From the
  // array of neighbour tets: 4u, a slot of the right tet, which is all the
  // flood and the walks read (slot / 4); nbr() below finds the exact one.
  auto nbr4 = [&](uint32_t t) -> std::array<uint32_t, 4> {
    if (slot_array) {
      const std::array<uint32_t, 4>& r = in.neighbor_tets[t];
      return {r[0] == kNoTet ? kNoTet : 4 * r[0], r[1] == kNoTet ? kNoTet : 4 * r[1],
              r[2] == kNoTet ? kNoTet : 4 * r[2], r[3] == kNoTet ? kNoTet : 4 * r[3]};
    }
    if (given) return in.neighbor_slots_of(t);
    return {own_nbr[4 * t], own_nbr[4 * t + 1], own_nbr[4 * t + 2], own_nbr[4 * t + 3]};
  };
  // The slot across slot s: with the array, the face of the tet across
  // that names s's tet back (kNoTet if none does: not an adjacency).
  bool asymmetric = false;
  auto nbr = [&](uint32_t s) -> uint32_t {
    if (!slot_array) return nbr4(s / 4)[s % 4];
    const uint32_t u = in.neighbor_tets[s / 4][s % 4];
    if (u == kNoTet) return kNoTet;
    for (uint32_t g = 0; g < 4; ++g) {
      if (in.neighbor_tets[u][g] == s / 4) return 4 * u + g;
    }
    asymmetric = true;
    return kNoTet;
  };
  if (!given) {
    TetFaces::Overused bad;
    if (!tet_faces->Match(
            [&](uint32_t s, uint32_t t) {
              own_nbr[s] = t;
              own_nbr[t] = s;
            },
            &bad)) {
      return absl::InvalidArgumentError(absl::StrCat("face (", bad.a, ", ", bad.b, ", ", bad.c, ") is in ",
                                                     bad.count, " tets (", bad.slots[0] / 4, ", ", bad.slots[1] / 4,
                                                     ", ", bad.slots[2] / 4, ", ...): not a tetrahedralization"));
    }
  }

  Labelling out;

  // --- Constrained faces: find their slots; duplicates: first wins. --------
  // One bit per tet face slot: the face is constrained (the flood stops
  // there). A bit, not the face's index: 16 bytes per tet were a fifth of
  // the labelling's arrays at cube --max-volume 1e-6's heap peak.
  std::vector<uint64_t> constrained_slot((4 * nt + 63) / 64, 0);
  auto mark_constrained = [&](uint32_t s) { constrained_slot[s >> 6] |= uint64_t{1} << (s & 63); };
  std::vector<std::array<uint32_t, 2>> cface_slots(ncf, {kNoTet, kNoTet});
  {
    std::vector<std::pair<std::array<uint32_t, 3>, uint32_t>> keys(ncf);
    for (size_t i = 0; i < ncf; ++i) {
      keys[i] = {Sorted3(in.constrained_faces[i].v), static_cast<uint32_t>(i)};
    }
    std::sort(keys.begin(), keys.end());
    // Without a given face lookup (the table, or the array's stars): each
    // key's first record (smallest slot). The keys of one smallest vertex a
    // (a sorted run) are scanned for in a's bucket, or with more than
    // kConstraintScanRun of them the bucket is read once and its records
    // looked up in the run (the first of equal keys; tet_faces.h:
    // crease_pair_0.1deg's output, 10 M vertices).
    const bool find_in_buckets = !given || slot_array;
    std::vector<uint32_t> key_slot;
    std::vector<TetFace> star_bucket;
    if (find_in_buckets) {
      key_slot.assign(ncf, kNoTet);
      for (size_t i = 0; i < ncf;) {
        const uint32_t a = keys[i].first[0];
        size_t j = i;
        while (j < ncf && keys[j].first[0] == a) ++j;
        std::span<const TetFace> bucket;
        if (slot_array) {
          StarBucket(in.tets, stars, a, &star_bucket);
          bucket = star_bucket;
        } else {
          bucket = tet_faces->Bucket(a);
        }
        if (j - i <= kConstraintScanRun) {
          for (size_t r = i; r < j; ++r) {
            for (const TetFace& f : bucket) {
              if (f.b == keys[r].first[1] && f.c == keys[r].first[2]) {
                key_slot[r] = f.slot;  // records of one face come smallest slot first
                break;
              }
            }
          }
        } else {
          for (const TetFace& f : bucket) {
            const std::array<uint32_t, 3> k{a, f.b, f.c};
            const auto it = std::lower_bound(keys.begin() + i, keys.begin() + j, k,
                                             [](const auto& e, const std::array<uint32_t, 3>& x) { return e.first < x; });
            // Records of one face come smallest slot first: keep the first.
            if (it != keys.begin() + j && it->first == k && key_slot[it - keys.begin()] == kNoTet) {
              key_slot[it - keys.begin()] = f.slot;
            }
          }
        }
        i = j;
      }
    }
    for (size_t i = 0; i < ncf; ++i) {
      const auto& [k, idx] = keys[i];
      if (k[0] == k[1] || k[1] == k[2]) {
        return absl::InvalidArgumentError(
            absl::StrCat("constrained face ", idx, " (facet ", in.constrained_faces[idx].facet,
                         ") has a repeated vertex ", k[1]));
      }
      if (i > 0 && keys[i - 1].first == k) {
        // keys[i-1] may itself be a duplicate: find the first of the run.
        size_t r = i - 1;
        while (r > 0 && keys[r - 1].first == k) --r;
        out.issues.push_back(
            {LabelIssueKind::kDuplicateConstrainedFace,
             {idx, keys[r].second},
             absl::StrCat("constrained face ", idx, " (facet ", in.constrained_faces[idx].facet,
                          ", marker ", in.constrained_faces[idx].marker,
                          ") repeats constrained face ", keys[r].second, " (facet ",
                          in.constrained_faces[keys[r].second].facet, ", marker ",
                          in.constrained_faces[keys[r].second].marker, "): the first is kept")});
        continue;
      }
      // The face's first record (smallest slot): in the bucket of k[0], or
      // the smaller of the given slot and its neighbour.
      uint32_t first_slot = kNoTet;
      if (!find_in_buckets) {
        const uint32_t s = in.find_face(k[0], k[1], k[2]);
        if (s != kNoTet) {
          const uint32_t other = nbr(s);
          first_slot = other != kNoTet ? std::min(s, other) : s;
        }
      } else {
        first_slot = key_slot[i];
      }
      if (first_slot == kNoTet) {
        return absl::InvalidArgumentError(absl::StrCat(
            "constrained face ", idx, " (", k[0], ", ", k[1], ", ", k[2], ") of facet ",
            in.constrained_faces[idx].facet, " is not a face of the tetrahedralization"));
      }
      cface_slots[idx][0] = first_slot;
      mark_constrained(first_slot);
      if (const uint32_t other = nbr(first_slot); other != kNoTet) {
        cface_slots[idx][1] = other;
        mark_constrained(other);
      }
    }
  }
  if (asymmetric) {
    return absl::InvalidArgumentError("the neighbour tets of a constrained face do not name it back");
  }

  // --- Flood fill across non-constrained faces. ----------------------------
  // Components are numbered in order of their smallest tet index (tets are
  // scanned in order and each unlabelled one starts a new component).
  out.tet_component.assign(nt, kNoTet);
  std::vector<uint32_t> stack;
  for (size_t t0 = 0; t0 < nt; ++t0) {
    if (out.tet_component[t0] != kNoTet) continue;
    const uint32_t cid = static_cast<uint32_t>(out.components.size());
    Component comp;
    comp.first_tet = static_cast<uint32_t>(t0);
    out.tet_component[t0] = cid;
    stack.push_back(static_cast<uint32_t>(t0));
    while (!stack.empty()) {
      const uint32_t t = stack.back();
      stack.pop_back();
      ++comp.num_tets;
      const std::array<uint32_t, 4> n4 = nbr4(t);
      for (int f = 0; f < 4; ++f) {
        const uint32_t s = 4 * t + f;
        if ((constrained_slot[s >> 6] >> (s & 63) & 1) != 0) continue;
        const uint32_t other = n4[f];
        if (other == kNoTet) {
          comp.touches_box = true;
          continue;
        }
        const uint32_t u = other / 4;
        if (out.tet_component[u] == kNoTet) {
          out.tet_component[u] = cid;
          stack.push_back(u);
        }
      }
    }
    out.components.push_back(comp);
  }

  // --- Seeds. --------------------------------------------------------------
  std::vector<Vec3> region_points(in.region_seeds.size());
  for (size_t i = 0; i < in.region_seeds.size(); ++i) region_points[i] = in.region_seeds[i].point;
  const auto region_hits = LocatePoints(in.positions, tets, region_points, nbr4);
  const auto hole_hits = LocatePoints(in.positions, tets, in.hole_seeds, nbr4);

  // A seed on a constrained face (or edge/vertex of one) touches tets of
  // several components: the tie rule picks one; say so.
  auto note_ambiguous = [&](const std::vector<Hit>& hits, uint32_t chosen, int64_t seed_id,
                            const std::string& what) {
    for (const Hit& h : hits) {
      if (out.tet_component[h.tet] != out.tet_component[chosen]) {
        out.issues.push_back(
            {LabelIssueKind::kSeedOnFacet,
             {seed_id, chosen, h.tet},
             absl::StrCat(what, " lies on a constrained face between components ",
                          out.tet_component[chosen], " and ", out.tet_component[h.tet],
                          ": it labels the component of tet ", chosen,
                          " (tie rule: lexicographically smallest sorted vertex ids)")});
        return;
      }
    }
  };

  out.hole_tet.assign(in.hole_seeds.size(), kNoTet);
  for (size_t i = 0; i < in.hole_seeds.size(); ++i) {
    const std::string what = absl::StrCat("hole seed ", i, " ", PointString(in.hole_seeds[i]));
    const uint32_t t = ChooseTet(hole_hits[i], tets);
    out.hole_tet[i] = t;
    if (t == kNoTet) {
      out.issues.push_back({LabelIssueKind::kHoleSeedOutsideMesh,
                            {static_cast<int64_t>(i)},
                            absl::StrCat(what, " is in no tet of the mesh: ignored")});
      continue;
    }
    note_ambiguous(hole_hits[i], t, -1 - static_cast<int64_t>(i), what);
    Component& c = out.components[out.tet_component[t]];
    if (c.hole_seed < 0) c.hole_seed = static_cast<int32_t>(i);
  }

  out.seed_tet.assign(in.region_seeds.size(), kNoTet);
  for (size_t i = 0; i < in.region_seeds.size(); ++i) {
    const plc::RegionSeed& seed = in.region_seeds[i];
    const std::string what = absl::StrCat("region seed ", i, " ", PointString(seed.point),
                                          " (attribute ", seed.attribute, ")");
    const uint32_t t = ChooseTet(region_hits[i], tets);
    out.seed_tet[i] = t;
    if (t == kNoTet) {
      out.issues.push_back({LabelIssueKind::kSeedOutsideMesh,
                            {static_cast<int64_t>(i)},
                            absl::StrCat(what, " is in no tet of the mesh: ignored")});
      continue;
    }
    note_ambiguous(region_hits[i], t, static_cast<int64_t>(i), what);
    const uint32_t cid = out.tet_component[t];
    Component& c = out.components[cid];
    if (c.seed < 0) {
      c.seed = static_cast<int32_t>(i);
      continue;
    }
    const plc::RegionSeed& first = in.region_seeds[c.seed];
    // Bitwise comparison on purpose: any difference is a conflict.
    if (!(first.attribute == seed.attribute && first.max_volume == seed.max_volume)) {
      out.issues.push_back(
          {LabelIssueKind::kSeedConflict,
           {static_cast<int64_t>(i), c.seed, cid},
           absl::StrCat(what, " is in the same region as region seed ", c.seed, " (attribute ",
                        first.attribute, ", max volume ", first.max_volume,
                        "), which labels it: the first seed wins")});
    }
  }

  // --- Keep / drop. --------------------------------------------------------
  if (in.keep_bounding_box && !in.hole_seeds.empty()) {
    out.issues.push_back({LabelIssueKind::kHoleSeedsIgnored,
                          {static_cast<int64_t>(in.hole_seeds.size())},
                          absl::StrCat(in.hole_seeds.size(),
                                       " hole seed(s) ignored: keep_bounding_box keeps every tet")});
  }
  for (size_t cid = 0; cid < out.components.size(); ++cid) {
    Component& c = out.components[cid];
    c.kept = in.keep_bounding_box || (!c.touches_box && c.hole_seed < 0);
    if (c.seed >= 0 && !c.kept) {
      out.issues.push_back(
          {LabelIssueKind::kSeedDropped,
           {c.seed, static_cast<int64_t>(cid)},
           absl::StrCat("region seed ", c.seed, " ", PointString(in.region_seeds[c.seed].point),
                        " is in a removed component (",
                        c.hole_seed >= 0 ? absl::StrCat("hole seed ", c.hole_seed)
                                         : std::string("exterior: it touches the bounding box"),
                        "): ignored")});
      c.seed = -1;
    }
    if (c.seed >= 0) {
      c.attribute = in.region_seeds[c.seed].attribute;
      c.max_volume = in.region_seeds[c.seed].max_volume;
    }
    if (c.kept) out.num_kept_tets += c.num_tets;
  }
  if (out.num_kept_tets == 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "no tetrahedron is left after removing the exterior and the holes (", nt, " tets in ",
        out.components.size(),
        " component(s)): the facets enclose no volume (an open surface?) or hole seeds fill it"));
  }

  // --- Output faces: constrained faces with a kept tet on a side. ----------
  for (size_t i = 0; i < ncf; ++i) {
    const auto& slots = cface_slots[i];
    if (slots[0] == kNoTet) continue;  // a duplicate
    uint32_t t0 = slots[0] / 4;
    uint32_t t1 = slots[1] == kNoTet ? kNoTet : slots[1] / 4;
    const bool k0 = out.Kept(t0);
    const bool k1 = t1 != kNoTet && out.Kept(t1);
    if (!k0 && !k1) continue;
    if (!k0) std::swap(t0, t1);
    LabelledFace lf;
    lf.v = in.constrained_faces[i].v;
    lf.tets = {t0, t1};
    lf.marker = in.constrained_faces[i].marker;
    lf.facet = in.constrained_faces[i].facet;
    lf.constrained_face = static_cast<uint32_t>(i);
    out.faces.push_back(lf);
  }
  return out;
}

}  // namespace svrc::refine
