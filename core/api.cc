#include "core/api.h"

#include <algorithm>
#include <chrono>
#include <new>
#include <string_view>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "core/delaunay/point_set.h"
#include "core/geometry/predicates.h"
#include "core/mesh/conformity.h"
#include "core/mesh/crease_vertices.h"
#include "core/mesh/quality.h"
#include "core/mesh/stats_payload.h"
#include "core/mesh/writers.h"
#include "core/plc/validate.h"
#include "core/svrc/assemble.h"
#include "core/svrc/refiner.h"
#include "core/svrc/sliver.h"

namespace svrc::core {
namespace {

// A PLC without segments and facets: its Delaunay tetrahedralization (issue
// #2), vertices in input order (exact duplicates merged into their first
// occurrence and left unreferenced), tets canonical, one region 0.
absl::StatusOr<mesh::TetMesh> MeshPointSet(const plc::Plc& plc, const ProgressCallback& progress,
                                           const CancelToken* cancel) {
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  const geom::PredicateStats pred_before = geom::GetPredicateStats();
  delaunay::PointSetOptions options;
  if (progress) {
    options.progress = [&](uint64_t done, uint64_t total) {
      Progress p;
      p.phase = "delaunay";
      p.vertices = done;
      p.queue_size = total - done;
      p.elapsed_seconds = elapsed();
      progress(p);
    };
  }
  if (cancel) options.cancel = [cancel] { return cancel->Check(); };
  auto result = delaunay::TetrahedralizePointSet(plc.vertices, options);
  if (!result.ok()) {
    if (result.status().code() == absl::StatusCode::kInvalidArgument) {
      return absl::InvalidArgumentError(
          absl::StrCat(plc.source_name.empty() ? "<memory>" : plc.source_name, ": ",
                       result.status().message()));
    }
    return result.status();
  }
  const geom::PredicateStats& pred_after = geom::GetPredicateStats();

  mesh::TetMesh out;
  out.positions = plc.vertices;
  out.num_input_vertices = static_cast<uint32_t>(plc.vertices.size());
  out.tets = std::move(result->tets);
  out.tet_region.assign(out.tets.size(), 0);
  out.regions.push_back(mesh::Region{});
  out.provenance.svrc_version = Version();
  out.provenance.parameters = "mode=point_set";
  out.provenance.input_sha256 = plc.input_sha256;
  auto& st = out.stats;
  st.Set("input_vertices", static_cast<double>(plc.vertices.size()));
  st.Set("duplicate_vertices", result->num_duplicates);
  st.Set("output_vertices", static_cast<double>(plc.vertices.size() - result->num_duplicates));
  st.Set("tets", static_cast<double>(out.tets.size()));
  st.Set("delaunay_walk_steps", static_cast<double>(result->kernel_stats.walk_steps));
  st.Set("delaunay_tets_created", static_cast<double>(result->kernel_stats.tets_created));
  st.Set("predicate_calls", static_cast<double>(pred_after.TotalCalls() - pred_before.TotalCalls()));
  st.Set("predicate_exact_fallbacks",
         static_cast<double>(pred_after.TotalExact() - pred_before.TotalExact()));
  st.Set("predicate_sos_decisions", static_cast<double>(pred_after.TotalSos() - pred_before.TotalSos()));
  st.Set("insphere_exact_fallbacks",
         static_cast<double>(pred_after.exact[static_cast<int>(geom::Pred::kInSphere)] -
                             pred_before.exact[static_cast<int>(geom::Pred::kInSphere)]));
  st.Set("orient3d_exact_fallbacks",
         static_cast<double>(pred_after.exact[static_cast<int>(geom::Pred::kOrient3d)] -
                             pred_before.exact[static_cast<int>(geom::Pred::kOrient3d)]));
  st.Set("seconds_sort", result->seconds_sort);
  st.Set("seconds_delaunay", result->seconds_insert);
  st.Set("seconds_output", result->seconds_output);
  st.Set("seconds_total", elapsed());
  if (progress) {
    Progress p;
    p.phase = "done";
    p.vertices = plc.vertices.size() - result->num_duplicates;
    p.elapsed_seconds = elapsed();
    progress(p);
  }
  return out;
}

// Creases of this angle (degrees) and more are refined through without collars; sharper ones get collars.
constexpr double kCollarAngleDeg = 45;

// The phase of the second refinement when one without collars overran its
// budget or left a tet away from the creases above the bound (Progress::phase).
constexpr const char* kRefineCollarsPhase = "refine-collars";

// The first crease of the complex, as "crease at segment (a, b): features meet
// at X degrees" / "crease at point i (x, y, z)"; empty if none.
// `sharpest` receives the smallest crease angle in degrees (0 for a crease
// point off every crease segment: segments meeting at an acute angle).
std::string FirstCrease(const plc::FeatureComplex& complex, double* sharpest) {
  *sharpest = 90;
  plc::SegmentId worst = plc::kNoId;
  std::vector<uint8_t> on_crease_segment(complex.points.size(), 0);
  for (plc::SegmentId s = 0; s < complex.segments.size(); ++s) {
    const plc::FeatureSegment& fs = complex.segments[s];
    if (!fs.crease) continue;
    on_crease_segment[fs.a] = on_crease_segment[fs.b] = 1;
    if (worst == plc::kNoId || fs.min_angle < complex.segments[worst].min_angle) worst = s;
  }
  for (uint32_t i = 0; i < complex.points.size(); ++i) {
    if (complex.points[i].crease && !on_crease_segment[i]) {
      *sharpest = 0;
      return absl::StrCat("crease at ", complex.PointName(i), ": segments or facets meet there at ",
                          complex.points[i].min_angle * 180 / M_PI, " degrees < 90");
    }
  }
  if (worst != plc::kNoId) {
    *sharpest = complex.segments[worst].min_angle * 180 / M_PI;
    return absl::StrCat("crease at ", complex.SegmentName(worst), ": features meet at ", *sharpest, " degrees < 90");
  }
  for (uint32_t i = 0; i < complex.points.size(); ++i) {
    if (complex.points[i].crease) {
      return absl::StrCat("crease at ", complex.PointName(i), ": features meet below 90 degrees");
    }
  }
  return {};
}

// The vertex budget of a PLC whose creases are all mild (45°–90°), refined
// through without collars: it ends a run that does not settle next to a
// crease. 20000 + 4 per input point, plus what max_volume itself asks for:
// the box of the input over the smallest max volume (global or of a
// region). Measured: cube.poly gives 0.41 vertices per (volume / max_volume)
// at 1e-5; without the volume term b_internal/example.poly (box 2×2×5) with
// --max-volume 1e-4 ended FAILED_PRECONDITION at 20,112 vertices.
// A smaller --max-vertices wins.
uint64_t CreaseBudget(const plc::FeatureComplex& complex, const MeshParams& params) {
  uint64_t budget = 20000 + 4 * static_cast<uint64_t>(complex.points.size());
  double vmax = params.max_volume > 0 ? params.max_volume : HUGE_VAL;
  for (const plc::RegionSeed& r : complex.regions) {
    if (r.max_volume > 0) vmax = std::min(vmax, r.max_volume);
  }
  if (vmax < HUGE_VAL && !complex.points.empty()) {
    geom::Box3 box;
    for (const plc::FeaturePoint& p : complex.points) box.Add(p.p);
    const geom::Vec3 e = box.hi - box.lo;
    // With keep_bounding_box the complex holds Ω's cube as facets, so this
    // is Ω's volume (tetra.poly --keep-bounding-box --max-volume 1e-4 ran
    // out of the input box's budget, 100,016 vertices, before session 35).
    const double boxes = e.x * e.y * e.z / vmax;
    // Capped: a budget past 2^40 vertices is no budget; memory ends it first.
    budget += static_cast<uint64_t>(std::min(boxes, 1e12));
  }
  if (params.max_vertices != 0) budget = std::min<uint64_t>(budget, params.max_vertices);
  return budget;
}

// One flag per refiner vertex: a crease point (refiner point i = complex
// point i) or a vertex of a crease segment's chain.
std::vector<uint8_t> CreaseVerticesOf(const refine::PointSetRefinement& refined, const plc::FeatureComplex& complex) {
  std::vector<uint8_t> crease(refined.normalised_positions.size(), 0);
  for (uint32_t i = 0; i < complex.points.size(); ++i) {
    if (complex.points[i].crease) crease[i] = 1;
  }
  for (uint32_t s = 0; s < complex.segments.size(); ++s) {
    if (!complex.segments[s].crease) continue;
    for (uint32_t v : refined.segment_chains[s]) crease[v] = 1;
  }
  return crease;
}

// The largest radius-edge ratio (mesh::ComputeTetQuality's, the checkers')
// among the kept tets of a refinement that touch no crease vertex
// (CreaseVerticesOf); 0 if the labelling is not known
// (PointSetRefinement::tet_outside empty) or no such tet is kept.
double WorstRadiusEdgeAwayFromCreases(const refine::PointSetRefinement& refined, const plc::FeatureComplex& complex) {
  if (refined.tet_outside.size() != refined.tets.size()) return 0;
  const std::vector<uint8_t> crease = CreaseVerticesOf(refined, complex);
  const std::vector<geom::Vec3>& p = refined.normalised_positions;
  double worst = 0;
  for (size_t t = 0; t < refined.tets.size(); ++t) {
    if (refined.tet_outside[t]) continue;
    const std::array<uint32_t, 4>& q = refined.tets[t];
    if (crease[q[0]] || crease[q[1]] || crease[q[2]] || crease[q[3]]) continue;
    worst = std::max(worst, mesh::ComputeTetQuality(p[q[0]], p[q[1]], p[q[2]], p[q[3]]).radius_edge);
  }
  return worst;
}

}  // namespace

bool HugePageHeapPays(const plc::Plc& plc, const MeshParams& params) {
  bool long_run = params.max_volume > 0 || plc.vertices.size() >= 1000;
  for (const plc::RegionSeed& r : plc.regions) long_run = long_run || r.max_volume > 0;
  if (!long_run) return false;
  if (plc.segments.empty() && plc.facets.empty()) return true;  // a point set: no creases
  absl::StatusOr<plc::FeatureComplex> complex = plc::PreparePlc(plc, {}, {}, nullptr);
  if (!complex.ok()) return false;
  double sharpest = 90;
  return FirstCrease(*complex, &sharpest).empty() || sharpest >= kCollarAngleDeg;
}

namespace {

// SVRC_DUMP_NONCONFORMING on an unsealed mesh (the labelling flooded every
// tet as exterior, so there is no mesh to write): the conformity checker on
// the whole mesh with its box, on the tets before the sliver flips (if kept)
// and after them, to stderr; and, before the flips, the tets near each
// uncovered facet (a vertex in its box grown by its diameter) to
// DUMP.facetN.vtu, small enough to study where millions of tets are not.
void DiagnoseUnsealed(const plc::Plc& plc, const refine::PointSetRefinement& refined,
                      const std::vector<refine::ConstrainedFace>& faces, const refine::CoordinateMap& map,
                      const std::vector<plc::PointId>& point_of_vertex,
                      const std::vector<std::array<uint32_t, 4>>& tets_before_flips, const char* dump) {
  for (int stage = 0; stage < 2; ++stage) {
    if (stage == 0 && tets_before_flips.empty()) continue;
    const char* when = stage == 0 ? "before" : "after";
    mesh::MeshStats scratch;
    absl::StatusOr<refine::OutputStageResult> boxed =
        refine::BuildOutputMesh(plc, refined.normalised_positions, stage == 0 ? tets_before_flips : refined.tets,
                                point_of_vertex, faces, map, /*keep_box=*/true, &scratch);
    if (!boxed.ok()) {
      std::fprintf(stderr, "SVRC_DUMP_NONCONFORMING: %s the flips: %s\n", when, boxed.status().ToString().c_str());
      continue;
    }
    mesh::ConformityOptions box_options;
    box_options.keep_bounding_box = true;
    const mesh::ConformityReport rep = mesh::CheckConformity(plc, boxed->mesh, box_options);
    std::fprintf(stderr, "SVRC_DUMP_NONCONFORMING: the unsealed mesh with its box, %s the flips: %s\n", when,
                 rep.Summary().c_str());
    for (const mesh::Violation& v : rep.violations) {
      if (stage != 0 || v.kind != mesh::ViolationKind::kFacetNotCovered || v.ids.empty()) continue;
      const int64_t f = v.ids[0];
      if (f < 0 || static_cast<size_t>(f) >= plc.facets.size()) continue;
      geom::Box3 own;  // the facet's box; `grown` by its diagonal
      for (const auto& poly : plc.facets[f].polygons) {
        for (uint32_t i : poly.vertices) own.Add(plc.vertices[i]);
      }
      const double grow = own.Diagonal();
      const geom::Box3 grown{own.lo - geom::Vec3{grow, grow, grow}, own.hi + geom::Vec3{grow, grow, grow}};
      mesh::TetMesh near = boxed->mesh;
      near.tets.clear();
      near.tet_region.clear();
      near.triangles.clear();
      near.triangle_marker.clear();
      for (size_t t = 0; t < boxed->mesh.tets.size(); ++t) {
        const auto& tet = boxed->mesh.tets[t];
        if (std::none_of(tet.begin(), tet.end(), [&](uint32_t q) { return grown.Contains(boxed->mesh.positions[q]); })) {
          continue;
        }
        near.tets.push_back(tet);
        if (!boxed->mesh.tet_region.empty()) near.tet_region.push_back(boxed->mesh.tet_region[t]);
      }
      // The mesh's points lying (nearly) on the facet's plane inside its box
      // that are no corner of its constrained faces: the faces around such a
      // point cover part of F but are not F's (the labelling floods through
      // them). Each with its containment dimension pair, creation index and
      // distance to the nearest collar centre: which construction made it.
      {
        const auto& ring = plc.facets[f].polygons[0].vertices;
        geom::Vec3 n{0, 0, 0};
        for (size_t i = 0; i < ring.size(); ++i) {
          n = n + geom::Cross(plc.vertices[ring[i]], plc.vertices[ring[(i + 1) % ring.size()]]);
        }
        n = n * (1 / std::sqrt(geom::Dot(n, n)));
        const geom::Vec3 o = plc.vertices[ring[0]];
        std::vector<uint8_t> corner(refined.positions.size(), 1);  // 1: skip (no vertex of the tets)
        for (const auto& t : refined.tets) {
          for (uint32_t q : t) corner[q] = 0;
        }
        for (const refine::ConstrainedFace& cf : faces) {
          if (cf.facet != static_cast<uint32_t>(f)) continue;
          for (uint32_t q : cf.v) corner[q] = 1;
        }
        for (size_t q = 0; q < refined.positions.size(); ++q) {
          const geom::Vec3& x = refined.positions[q];
          if (corner[q] || !own.Contains(x)) continue;
          const double h = geom::Dot(x - o, n);
          if (!(std::fabs(h) < 1e-12 * grow)) continue;
          double collar = HUGE_VAL;  // the nearest collar ball's distance over its radius
          const geom::Vec3 xn = refined.normalised_positions[q];
          for (const auto& c : refined.collars) collar = std::min(collar, geom::Dist(xn, c.center) / c.radius);
          std::fprintf(stderr,
                       "SVRC_DUMP_NONCONFORMING: facet %lld: point %zu (%.17g, %.17g, %.17g) is %.3g off its plane "
                       "and no corner of its faces: cd pair %d, %s, nearest collar at %.6g radii\n",
                       static_cast<long long>(f), q, x.x, x.y, x.z, h,
                       q < refined.point_cd.size() ? refined.point_cd[q] : -1,
                       q < refined.num_input ? "an input point" : "a Steiner point", collar);
        }
      }
      const std::string path = absl::StrCat(dump, ".facet", f, ".vtu");
      const absl::Status ws = mesh::WriteMeshFile(near, path);
      std::fprintf(stderr, "SVRC_DUMP_NONCONFORMING: %zu tets near facet %lld: %s: %s\n", near.tets.size(),
                   static_cast<long long>(f), path.c_str(), ws.ok() ? "written" : ws.ToString().c_str());
    }
  }
}

// A PLC with segments or facets: SVRC refinement (core/svrc, thesis ch. 3),
// then region labelling and assembly (docs/svrc-output.md).
// The input's box, as refine::NormaliseInput makes Ω: the cube of side
// 3·diam centred on the bounding box of the vertices (a unit cube for a
// single point).
geom::Box3 OmegaCubeOf(const plc::Plc& plc) {
  geom::Box3 box;
  for (const geom::Vec3& p : plc.vertices) box.Add(p);
  const double diam = box.Diagonal();
  const double half = diam > 0 ? 1.5 * diam : 0.5;
  const geom::Vec3 c = box.Center();
  return geom::Box3{c - geom::Vec3{half, half, half}, c + geom::Vec3{half, half, half}};
}

// `plc` with Ω's cube as six more facets (8 more vertices, after the
// input's) and no hole seeds.
plc::Plc WithBoundingBoxFacets(const plc::Plc& plc) {
  plc::Plc out = plc;
  const geom::Box3 cube = OmegaCubeOf(plc);
  const uint32_t n = static_cast<uint32_t>(out.vertices.size());
  for (int i = 0; i < 8; ++i) {
    out.vertices.push_back({(i & 1) ? cube.hi.x : cube.lo.x, (i & 2) ? cube.hi.y : cube.lo.y,
                            (i & 4) ? cube.hi.z : cube.lo.z});
  }
  if (!out.vertex_markers.empty()) out.vertex_markers.resize(out.vertices.size(), 0);
  if (!out.vertex_lines.empty()) out.vertex_lines.resize(out.vertices.size(), 0);
  static constexpr uint32_t kQuads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                            {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : kQuads) {
    plc::Facet f;
    f.polygons.push_back(plc::Polygon{{n + q[0], n + q[1], n + q[2], n + q[3]}});
    out.facets.push_back(std::move(f));
  }
  if (!out.facet_lines.empty()) out.facet_lines.resize(out.facets.size(), 0);
  out.holes.clear();
  return out;
}

// Removes the triangles on Ω's cube (WithBoundingBoxFacets) from the
// output: they lie on no input facet. A triangle is on a face of the cube
// when its three vertices have that face's coordinate within the on-feature
// tolerance (axis-aligned facets keep it exactly).
void DropBoxTriangles(const plc::Plc& user_plc, mesh::TetMesh* m) {
  const geom::Box3 cube = OmegaCubeOf(user_plc);
  const std::array<geom::Vec3, 2> corners = {cube.lo, cube.hi};
  const double tol = mesh::OnFeatureTolerance(corners);
  auto on_box = [&](const std::array<uint32_t, 3>& t) {
    for (int k = 0; k < 3; ++k) {
      for (double b : {cube.lo[k], cube.hi[k]}) {
        if (std::all_of(t.begin(), t.end(), [&](uint32_t v) { return std::fabs(m->positions[v][k] - b) <= tol; })) {
          return true;
        }
      }
    }
    return false;
  };
  size_t w = 0;
  for (size_t i = 0; i < m->triangles.size(); ++i) {
    if (on_box(m->triangles[i])) continue;
    m->triangles[w] = m->triangles[i];
    if (i < m->triangle_marker.size()) m->triangle_marker[w] = m->triangle_marker[i];
    ++w;
  }
  m->triangles.resize(w);
  if (m->triangle_marker.size() > w) m->triangle_marker.resize(w);
}

absl::StatusOr<mesh::TetMesh> MeshPlcSvrc(const plc::Plc& user_plc, const MeshParams& params,
                                          const ProgressCallback& progress, const CancelToken* cancel) {
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  auto report = [&](const char* phase, uint64_t vertices, uint64_t queue, double radius) {
    if (!progress) return;
    Progress p;
    p.phase = phase;
    p.vertices = vertices;
    p.queue_size = queue;
    p.largest_work_radius = radius;
    p.elapsed_seconds = elapsed();
    progress(p);
  };
  if (!(params.radius_edge > 0) || !std::isfinite(params.radius_edge)) {
    return absl::InvalidArgumentError("radius_edge must be a positive number");
  }
  if (!(params.theta > 0 && params.theta < 1)) return absl::InvalidArgumentError("theta must be in (0, 1)");
  if (!(params.collar_size_eps >= 0 && params.collar_size_eps <= 1)) {
    return absl::InvalidArgumentError("collar_size_eps must be in [0, 1] (0: the angle test)");
  }
  if (!(params.min_dihedral < kMaxMinDihedralDeg)) {
    return absl::InvalidArgumentError(absl::StrCat("min_dihedral must be below ", kMaxMinDihedralDeg,
                                                   " degrees (no tetrahedron has a larger smallest dihedral angle); got ",
                                                   params.min_dihedral));
  }
  report("validate", 0, 0, 0);
  // keep_bounding_box (and a PLC without facets, which encloses nothing):
  // the output is all of Ω, the cube of side 3·diam around the input. Its six
  // faces join the PLC as facets, so the box is meshed like any domain:
  // radius-edge within the bound up to its faces, max_volume per tet. As
  // scaffolding, Ω's tets next to ∂Ω were never refined for quality: cube.poly
  // --keep-bounding-box had radius-edge 44 there, nested_boxes_3 with
  // max_volume 3e-2 8.6e7 and dihedrals of 180° (session 35). The box's
  // triangles are not input facets and leave the output's triangles; hole
  // seeds are ignored, as they were (the whole Ω is returned).
  const bool keep_box = params.keep_bounding_box || user_plc.facets.empty();
  const plc::Plc boxed = keep_box ? WithBoundingBoxFacets(user_plc) : plc::Plc{};
  const plc::Plc& plc = keep_box ? boxed : user_plc;
  plc::ValidationReport vreport;
  absl::StatusOr<plc::FeatureComplex> complex = plc::PreparePlc(plc, {}, {}, &vreport);
  if (!complex.ok()) {
    return complex.status();  // INVALID_ARGUMENT naming the source, ids and lines (plc/validate.h)
  }
  const double seconds_validate = elapsed();
  refine::RefineOptions options;
  options.tau = 2.0 * params.radius_edge;
  options.theta = params.theta;
  options.max_vertices = params.max_vertices;
  options.max_volume = params.max_volume;
  options.output_tet_neighbors = true;  // for the sliver pass (below)
  if (params.min_dihedral > 0) {
    // Sliver removal to a target (thesis §6.2.1; docs/svrc-design.md §8
    // item 69): the sliver rounds break every kept tet below it, at the best
    // of 16 points near its circumcentre, splitting a facet triangle or
    // segment piece where each would; then the flips aim at it too (below).
    options.sliver_break_deg = std::max(options.sliver_break_deg, params.min_dihedral);
    options.sliver_break_rounds = 32;
    options.sliver_candidates = 16;
    options.sliver_yield = true;
    options.sliver_ramp_deg = 5;
  }
  // With the box as facets nothing is outside the domain but what lies
  // outside the box (refine's Ω is now larger than it).
  options.keep_bounding_box = false;
  if (cancel != nullptr || progress) {
    options.poll = [&]() -> absl::Status {
      if (cancel != nullptr) {
        absl::Status s = cancel->Check();
        if (!s.ok()) return s;
      }
      return absl::OkStatus();
    };
  }
  // After a mild-crease fallback (below) the second run's "refine" reports
  // are "refine-collars": within one phase the counters only increase.
  bool rerun = false;
  options.progress = [&](const char* phase, uint64_t vertices, uint64_t queue, double radius) {
    report(rerun && std::string_view(phase) == refine::refine_phase::kRefine ? kRefineCollarsPhase : phase, vertices,
           queue, radius);
  };
  report("refine", 0, 0, 0);
  // Creases (Definitions 4-5). Mild ones (>= kCollarAngleDeg) are refined
  // through under a small vertex budget (kCreaseBudget): they finish and pass
  // the conformity checker (b_internal/example.poly, 63°; tetra.poly). Sharper
  // ones get collars (thesis §3.1.2, stages (d)-(f): collar balls, COLLAR
  // events on the collar surface, RipStitchCollar); the stitched mesh is
  // checked before it is returned (below), and an input the collar stage
  // cannot finish yet ends FAILED_PRECONDITION naming its sharpest crease.
  double sharpest = 90;
  const std::string crease = FirstCrease(*complex, &sharpest);
  bool use_collars = !crease.empty() && sharpest < kCollarAngleDeg;
  // The head of every collar-stage error: the crease and its angle (none
  // for a crease point off the crease segments, whose 0 only means "always
  // collared": random_plcs.py near 9's message said "sharpest 0 degrees" of
  // a triangle's 37° corner).
  const std::string crease_head =
      absl::StrCat("SVRC: ", crease, sharpest > 0 ? absl::StrCat(" (sharpest ", sharpest, " degrees)") : "", ": ");
  const auto set_collar_options = [&]() {
    options.collars = true;
    options.collar_surface = true;
    options.max_rep_angle = params.max_rep_angle * M_PI / 180;
    options.collar_size_eps = params.collar_size_eps;
    options.collar_tet_quality = params.collar_tet_quality;
    options.attempt_creases = false;
    options.max_vertices = params.max_vertices;
  };
  if (use_collars) {
    set_collar_options();
  } else if (!crease.empty()) {
    options.attempt_creases = true;
    options.max_vertices = CreaseBudget(*complex, params);
  }
  absl::StatusOr<refine::PointSetRefinement> refined = refine::RefinePlc(*complex, options);
  // A mild crease that does not settle within its budget gets collars, as a
  // sharp one does (thesis §3.1.2 collars every crease below 90°): a box cut
  // by a plane meeting two of its faces at 46°–51° ended FAILED_PRECONDITION
  // at 20,056 vertices before session 36 (docs/svrc-collars.md "Session 36").
  // Not when the caller's own max_vertices was the budget.
  // Likewise when it ends with a tet away from the creases above the
  // radius-edge bound: hull_41 of the random sweep (a 61.7° crease ending in
  // a narrow corner) crowded 501 vertices within 1e-9 of the corner and left
  // a tet of edge 1.3e-13 and radius-edge 3.36 touching no crease vertex.
  uint64_t mild_budget = 0;
  double mild_worst = 0;
  bool mild_failed = false;
  if (refined.ok() && !crease.empty() && !use_collars) {
    const double worst = WorstRadiusEdgeAwayFromCreases(*refined, *complex);
    if (worst > params.radius_edge * (1 + 1e-9)) mild_worst = worst;
  }
  const bool overran = !refined.ok() && !crease.empty() && !use_collars &&
                       refined.status().code() == absl::StatusCode::kResourceExhausted &&
                       (params.max_vertices == 0 || options.max_vertices < params.max_vertices);
  // And when it stops at the resolution of doubles: hull_158 of the sweep
  // crowded a crease corner until two points of one segment rounded to the
  // same place (INTERNAL "point 13275 could not be inserted into facet mesh
  // 2 (coincides with point 12659 ...)").
  const bool mild_error = !refined.ok() && !crease.empty() && !use_collars &&
                          (refined.status().code() == absl::StatusCode::kInternal ||
                           refined.status().code() == absl::StatusCode::kFailedPrecondition);
  if (overran || mild_worst > 0 || mild_error) {
    if (overran) mild_budget = options.max_vertices;
    mild_failed = mild_error;
    use_collars = true;
    set_collar_options();
    rerun = true;
    report(kRefineCollarsPhase, 0, 0, 0);
    refined = absl::AbortedError("superseded by the run with collars");  // frees the first run's mesh first
    refined = refine::RefinePlc(*complex, options);
  }
  if (!refined.ok()) {
    if (!crease.empty() && !use_collars && refined.status().code() == absl::StatusCode::kResourceExhausted) {
      return mesh::Rewrap(absl::StatusCode::kFailedPrecondition,
                          absl::StrCat("SVRC: ", crease, "; refinement without collars did not finish within ",
                                       options.max_vertices, " vertices"),
                          refined.status());
    }
    if (use_collars && (refined.status().code() == absl::StatusCode::kResourceExhausted ||
                        refined.status().code() == absl::StatusCode::kFailedPrecondition)) {
      // Below radius_edge 2 the collar path's cell test (aspect τ = 2 ×
      // radius_edge) refines the collars' neighbourhood much further, and
      // the thesis proves termination only for τ > 2√2 (its collar theorem
      // assumes τ > 4√2; docs/svrc-collars.md "Session 14", "Session 28"):
      // say so, a budget overrun or a COLLAR round that does not settle
      // alone reads like a bug. Measured at 1.5 (session 28): the COLLAR
      // rounds of crease_pair_30deg, segment_fan.poly and schonhardt.off
      // diverge (with a 10x lower RepBall floor all three reach the
      // 1,000,000-vertex budget).
      std::string hint;
      if (params.radius_edge < 2.0) {
        hint = absl::StrCat("; radius_edge ", params.radius_edge,
                            " is below 2: with creases below 45 degrees the refinement near the collars grows fast "
                            "as the bound tightens and may not settle (two facets at 30 degrees: 33,176 tets at 2, "
                            "171,695 at 1.65, 387,287 at 1.58, no mesh at 1.5); try a larger radius_edge");
      }
      return mesh::Rewrap(absl::StatusCode::kFailedPrecondition,
                          absl::StrCat(crease_head, "the collar stage did not finish: ", refined.status().message(), hint),
                          refined.status());
    }
    return refined.status();
  }
  const double seconds_refine = elapsed() - seconds_validate;
  report("assemble", refined->stats.vertices, 0, 0);
  const std::vector<refine::ConstrainedFace> faces = refine::ConstrainedFacesOf(*refined, *complex);
  mesh::MeshStats stats;
  refined->stats.ExportTo(&stats);
  // Sliver removal by flips (core/svrc/sliver.h; docs/svrc-output.md §7): keeps facet triangles, segment pieces,
  // radius-edge <= params.radius_edge and (if any is set) max volumes; default target kDefaultSliverTargetDeg.
  refine::SliverOptions sliver;
  sliver.max_radius_edge = params.radius_edge;
  // min_dihedral: the flips aim at it too, up to kMaxFlipTargetDeg. Past
  // that nearly every tet is "bad" for the pass and its time grows with them
  // (cube --max-volume 1e-5 at 35°: 40 s of flips, 33,678 tets left below
  // the target either way; docs/svrc-design.md §8 item 69).
  constexpr double kMaxFlipTargetDeg = 25;
  if (params.min_dihedral > 0) {
    sliver.target_min_dihedral_deg =
        std::max(sliver.target_min_dihedral_deg, std::min(params.min_dihedral, kMaxFlipTargetDeg));
  }
  // The labelling the refiner kept up: exterior tets are not worked on.
  if (refined->tet_outside.size() == refined->tets.size()) sliver.skip_tet = refined->tet_outside;
  sliver.keep_max_volume = params.max_volume > 0 || std::any_of(plc.regions.begin(), plc.regions.end(),
                                                                 [](const plc::RegionSeed& r) { return r.max_volume > 0; });
  // Crease vertices on either path: a flip may relax the radius-edge bound
  // only for new tets touching a crease.
  if (!crease.empty()) sliver.crease_vertex = CreaseVerticesOf(*refined, *complex);
  sliver.output_neighbors = true;
  // SVRC_DUMP_NONCONFORMING (debugging aid, below): the tets before the flips.
  const char* dump_env = std::getenv("SVRC_DUMP_NONCONFORMING");
  const bool dumping = dump_env != nullptr && *dump_env != '\0';
  std::vector<std::array<uint32_t, 4>> tets_before_flips;
  if (dumping && use_collars) tets_before_flips = refined->tets;
  absl::StatusOr<refine::SliverResult> flipped =
      refine::RemoveSlivers(refined->normalised_positions, refined->tets, faces, refined->segment_chains, sliver,
                            refined->tet_neighbors.size() == refined->tets.size() ? &refined->tet_neighbors : nullptr);
  if (!flipped.ok()) return flipped.status();
  flipped->stats.ExportTo(&stats);
  refined->tets = std::move(flipped->tets);
  // The flips' final adjacency: the output labelling builds no face table
  // (docs/svrc-design.md §8 item 82).
  std::vector<std::array<uint32_t, 4>> neighbors = std::move(flipped->neighbors);
  // The refiner's exact normalisation x' = (x − t)·2^−e.
  const refine::CoordinateMap map = refine::CoordinateMapOf(*refined);
  absl::StatusOr<refine::OutputStageResult> out =
      refine::BuildOutputMesh(plc, refined->normalised_positions, refined->tets, complex->point_of_vertex, faces, map,
                              /*keep_bounding_box=*/false, &stats, neighbors);
  std::vector<std::array<uint32_t, 4>>().swap(neighbors);
  if (!out.ok()) {
    // The labelling says "no tetrahedron is left" (INVALID_ARGUMENT) for an
    // open surface or hole seeds that fill every region. Validation has
    // already proved the facets enclose a volume, so without hole seeds that
    // verdict is the mesher's: its facet faces leak (measured once, on
    // f_real/hinge.stl after the collar stage, 25 min: docs/svrc-collars.md
    // "Session 6"). Say so instead of blaming the input.
    if (out.status().code() == absl::StatusCode::kInvalidArgument && plc.holes.empty() && !complex->facets.empty()) {
      absl::Status st = use_collars
                            ? absl::FailedPreconditionError(absl::StrCat(
                                  crease_head, "the stitched mesh does not seal the facets: ", out.status().message()))
                            : absl::InternalError(absl::StrCat("SVRC: the output mesh does not seal the facets of a ",
                                                               "closed PLC: ", out.status().message()));
      // Debugging aid (SVRC_DUMP_NONCONFORMING, as below): where the facets leak.
      if (dumping) {
        DiagnoseUnsealed(plc, *refined, faces, map, complex->point_of_vertex, tets_before_flips, dump_env);
      }
      mesh::AttachStats(stats, &st);
      return st;
    }
    return out.status();
  }
  if (out->report.num_nonpositive_tets != 0) {
    return absl::InternalError(absl::StrCat("SVRC: ", out->report.num_nonpositive_tets,
                                            " tets inverted by mapping Steiner points back to input coordinates"));
  }
  mesh::TetMesh mesh = std::move(out->mesh);
  if (keep_box) DropBoxTriangles(user_plc, &mesh);
  if (use_collars) {
    // The collar stage is new and its conformity next to the creases is
    // shown per input (docs/svrc-collars.md), not proven for every PLC:
    // check it here and never return a mesh that does not conform.
    report("check", mesh.positions.size(), 0, 0);
    // With keep_bounding_box the mesh fills Ω: its hull faces are boundary,
    // not open, and the enclosed volume is the box's (before session 7 the
    // check ran without this and refused every creased input with
    // --keep-bounding-box: 66 "open faces" on knife_edge.poly).
    mesh::ConformityOptions check_options;
    check_options.keep_bounding_box = keep_box;
    const mesh::ConformityReport check = mesh::CheckConformity(user_plc, mesh, check_options);
    if (!check.ok()) {
      // Debugging aid for the collar stage (docs/svrc-collars.md): the
      // refused mesh, written where SVRC_DUMP_NONCONFORMING points (any
      // format of mesh::WriteMeshFile), so it can be studied without
      // re-running a long job. Never set in production.
      if (dumping) {
        const absl::Status ws = mesh::WriteMeshFile(mesh, dump_env);
        std::fprintf(stderr, "SVRC_DUMP_NONCONFORMING: %s: %s\n", dump_env, ws.ok() ? "written" : ws.ToString().c_str());
      }
      absl::Status st = absl::FailedPreconditionError(
          absl::StrCat(crease_head, "the stitched mesh next to the creases does not conform: ", check.Summary()));
      mesh::AttachStats(stats, &st);
      return st;
    }
    // max_volume inside the collars: the stitched stars and books are not
    // refined by size events (the points inside are removed); the size
    // passes after the stitch put points of S into those above the bound
    // (Refiner::QueueOversizedStitchRepairs, since session 35). Whatever
    // they leave above it is refused, not returned.
    for (size_t t = 0; t < mesh.tets.size(); ++t) {
      const auto& v = mesh.tets[t];
      const geom::Vec3 a = mesh.positions[v[0]];
      const double vol =
          geom::Dot(mesh.positions[v[1]] - a, geom::Cross(mesh.positions[v[2]] - a, mesh.positions[v[3]] - a)) / 6;
      double bound = params.max_volume > 0 ? params.max_volume : HUGE_VAL;
      const int32_t r = mesh.tet_region.empty() ? -1 : mesh.tet_region[t];
      if (r >= 0 && mesh.regions[r].max_volume > 0) bound = std::min(bound, mesh.regions[r].max_volume);
      if (vol > bound * (1 + 1e-9)) {
        return absl::FailedPreconditionError(absl::StrCat(
            crease_head, "a tet of volume ", vol,
            " next to the creases exceeds max_volume ", bound, " after the size passes next to the collars"));
      }
    }
  }
  if (params.min_dihedral > 0) {
    // Best effort, as tetgen's -q/D: the sliver rounds and the flips aim at
    // the target but nothing guarantees it (docs/svrc-design.md §8 item 69
    // gives what is reached); what is left below it is counted, away from
    // the creases (whose angles bound the tets' next to them), and the CLI
    // says so. The mesh meets every other bound either way.
    const std::vector<uint8_t> crease_flags =
        crease.empty() ? std::vector<uint8_t>{} : mesh::CreaseVertexFlags(plc, mesh);
    const mesh::MinDihedralShortfall below = mesh::BelowMinDihedral(mesh, crease_flags, params.min_dihedral);
    mesh.stats.Set("min_dihedral.target", params.min_dihedral);
    mesh.stats.Set("min_dihedral.below", static_cast<double>(below.num_below));
    mesh.stats.Set("min_dihedral.smallest", below.smallest_deg);
  }
  mesh.provenance.svrc_version = Version();
  mesh.provenance.parameters = absl::StrCat("mode=svrc radius_edge=", params.radius_edge, " theta=", params.theta,
                                            use_collars ? absl::StrCat(" max_rep_angle=", params.max_rep_angle) : "",
                                            use_collars && params.collar_size_eps > 0
                                                ? absl::StrCat(" collar_size_eps=", params.collar_size_eps)
                                                : "",
                                            use_collars && !params.collar_tet_quality ? " collar_cell_test=1" : "",
                                            params.min_dihedral > 0 ? absl::StrCat(" min_dihedral=", params.min_dihedral)
                                                                    : "",
                                            " keep_bounding_box=", params.keep_bounding_box ? 1 : 0);
  mesh.provenance.input_sha256 = user_plc.input_sha256;
  mesh.stats.Set("tets", static_cast<double>(mesh.tets.size()));
  mesh.stats.Set("output_vertices", static_cast<double>(mesh.positions.size()));
  // The mild creases' vertex budget the run without collars overran before
  // it took collars (0: no fallback).
  mesh.stats.Set("mild_crease_budget_overrun", static_cast<double>(mild_budget));
  // ... or the radius-edge ratio away from the creases it left (0: none).
  mesh.stats.Set("mild_crease_radius_edge_over", mild_worst);
  // ... or whether it ended with an error (1).
  mesh.stats.Set("mild_crease_error", mild_failed ? 1 : 0);
  mesh.stats.Set("seconds_validate", seconds_validate);
  mesh.stats.Set("seconds_refine", seconds_refine);
  mesh.stats.Set("seconds_total", elapsed());
  report("done", mesh.positions.size(), 0, 0);
  return mesh;
}

}  // namespace

absl::Status CancelToken::Check() const {
  if (IsCancelled()) return absl::CancelledError("job cancelled");
  if (DeadlinePassed()) return absl::DeadlineExceededError("job deadline exceeded");
  return absl::OkStatus();
}

std::string Version() { return absl::StrCat("svrc ", SVRC_VERSION); }

absl::StatusOr<mesh::TetMesh> MeshPlc(const plc::Plc& plc, const MeshParams& params,
                                      const ProgressCallback& progress,
                                      const CancelToken* cancel) {
  // An allocation that fails ends the job, not the process: the mesher's
  // state lives in RAII containers, so unwinding frees it. Measured: two
  // facets at 0.1° under a 13 GB address-space limit died of an uncaught
  // std::bad_alloc (SIGABRT) at 8.4 M vertices (session 16); in the server
  // that killed every job of the process.
  try {
    if (plc.IsPointSet()) return MeshPointSet(plc, progress, cancel);
    return MeshPlcSvrc(plc, params, progress, cancel);
  } catch (const std::bad_alloc&) {
    return absl::ResourceExhaustedError(
        "out of memory: an allocation failed while meshing (the mesh needs more memory than this process may "
        "use; a smaller max_vertices fails earlier with a precise count, a coarser radius_edge or max_volume "
        "needs less)");
  }
}

}  // namespace svrc::core
