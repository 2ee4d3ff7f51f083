// Output assembly: see assemble.h and docs/svrc-output.md.
#include "core/svrc/assemble.h"

#include <algorithm>
#include <cmath>
#include <tuple>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/geometry/predicates.h"
#include "core/mesh/canonical.h"

namespace svrc::refine {
namespace {

using geom::Vec3;

constexpr uint32_t kNoVertex = 0xFFFFFFFFu;

// The face opposite local vertex f of a positively oriented tet (v0,v1,v2,v3),
// ordered so that (b−a)×(c−a) points into the tet, i.e. Orient3d(a,b,c,v_f) > 0
// (the sign convention of core/geometry/predicates.h). Each is an even
// permutation of (face, apex) relative to (v0,v1,v2,v3).
constexpr int kInwardFace[4][3] = {{1, 3, 2}, {0, 2, 3}, {0, 3, 1}, {0, 1, 2}};

std::array<uint32_t, 4> Sorted4(std::array<uint32_t, 4> v) {
  std::sort(v.begin(), v.end());
  return v;
}

}  // namespace

Vec3 CoordinateMap::ToMesher(const Vec3& x) const {
  return {std::ldexp(x.x - translation.x, -exponent), std::ldexp(x.y - translation.y, -exponent),
          std::ldexp(x.z - translation.z, -exponent)};
}

Vec3 CoordinateMap::ToInput(const Vec3& y) const {
  return {std::ldexp(y.x, exponent) + translation.x, std::ldexp(y.y, exponent) + translation.y,
          std::ldexp(y.z, exponent) + translation.z};
}

absl::StatusOr<AssembledMesh> AssembleMesh(const AssembleInput& in) {
  if (in.plc == nullptr || in.labelling == nullptr) {
    return absl::InvalidArgumentError("AssembleMesh: plc and labelling are required");
  }
  const plc::Plc& plc = *in.plc;
  const Labelling& lab = *in.labelling;
  const size_t nv = in.positions.size();
  const size_t nt = in.tets.size();
  const size_t nin = plc.vertices.size();
  if (lab.tet_component.size() != nt) {
    return absl::InvalidArgumentError(absl::StrCat("labelling has ", lab.tet_component.size(),
                                                   " tets, the mesh ", nt));
  }
  if (in.input_vertex.size() != nin) {
    return absl::InvalidArgumentError(absl::StrCat("input_vertex has ", in.input_vertex.size(),
                                                   " entries for ", nin, " PLC vertices"));
  }
  if (nin + nv >= (size_t{1} << 32) - 1) {
    return absl::InvalidArgumentError("too many vertices for 32-bit ids");
  }
  for (size_t t = 0; t < nt; ++t) {
    for (uint32_t v : in.tets[t]) {
      if (v >= nv) return absl::InvalidArgumentError(absl::StrCat("tet ", t, ": vertex ", v, " out of range"));
    }
  }

  AssembledMesh result;
  AssembleReport& rep = result.report;
  mesh::TetMesh& m = result.mesh;
  rep.num_input_vertices = static_cast<uint32_t>(nin);

  // --- Vertices. -------------------------------------------------------------
  // Input vertices keep their PLC ids and their PLC coordinates (bit-exact by
  // construction, not by trusting the back map); a mesher vertex that is the
  // image of several exact duplicates becomes the first of them.
  std::vector<uint32_t> out_id(nv, kNoVertex);
  for (size_t i = 0; i < nin; ++i) {
    const uint32_t mv = in.input_vertex[i];
    if (mv >= nv) {
      return absl::InvalidArgumentError(
          absl::StrCat("input vertex ", i, " maps to mesher vertex ", mv, " out of range"));
    }
    const Vec3 back = in.map.ToInput(in.positions[mv]);
    const Vec3& p = plc.vertices[i];
    if (!(back == p)) {
      return absl::InternalError(absl::StrFormat(
          "input vertex %d (%.17g, %.17g, %.17g) maps to mesher vertex %d, which maps back to "
          "(%.17g, %.17g, %.17g): not the input point",
          i, p.x, p.y, p.z, mv, back.x, back.y, back.z));
    }
    if (out_id[mv] == kNoVertex) out_id[mv] = static_cast<uint32_t>(i);
  }
  std::vector<char> used(nv, 0);
  for (size_t t = 0; t < nt; ++t) {
    if (!lab.Kept(static_cast<uint32_t>(t))) {
      ++rep.num_dropped_tets;
      continue;
    }
    for (uint32_t v : in.tets[t]) used[v] = 1;
  }
  std::vector<uint32_t> steiner;  // mesher ids, increasing
  std::vector<Vec3> steiner_pos;
  for (size_t v = 0; v < nv; ++v) {
    if (!used[v]) {
      if (out_id[v] == kNoVertex) ++rep.num_dropped_vertices;
      continue;
    }
    if (out_id[v] != kNoVertex) continue;
    steiner.push_back(static_cast<uint32_t>(v));
    steiner_pos.push_back(in.map.ToInput(in.positions[v]));
  }
  for (size_t i = 0; i < nin; ++i) {
    const uint32_t mv = in.input_vertex[i];
    if (!used[mv] || out_id[mv] != i) ++rep.num_unused_input_vertices;
  }
  rep.num_steiner_vertices = static_cast<uint32_t>(steiner.size());
  const std::vector<uint32_t> order = mesh::SpatialOrder(steiner_pos);
  m.positions.reserve(nin + steiner.size());
  m.positions.assign(plc.vertices.begin(), plc.vertices.end());
  for (size_t k = 0; k < order.size(); ++k) {
    out_id[steiner[order[k]]] = static_cast<uint32_t>(nin + k);
    m.positions.push_back(steiner_pos[order[k]]);
  }
  m.num_input_vertices = static_cast<uint32_t>(nin);

  // --- Tets and regions. -----------------------------------------------------
  // Regions: seeded components in seed order, then unseeded kept components
  // by their smallest sorted output tet (independent of the tet list's order
  // and of the mesher's vertex numbering).
  const size_t nc = lab.components.size();
  std::vector<std::array<uint32_t, 4>> comp_min(
      nc, {kNoVertex, kNoVertex, kNoVertex, kNoVertex});
  std::vector<uint32_t> kept_tets;
  kept_tets.reserve(lab.num_kept_tets);
  for (size_t t = 0; t < nt; ++t) {
    if (!lab.Kept(static_cast<uint32_t>(t))) continue;
    kept_tets.push_back(static_cast<uint32_t>(t));
    const auto& tv = in.tets[t];
    const std::array<uint32_t, 4> o{out_id[tv[0]], out_id[tv[1]], out_id[tv[2]], out_id[tv[3]]};
    const uint32_t c = lab.tet_component[t];
    comp_min[c] = std::min(comp_min[c], Sorted4(o));
  }
  std::vector<uint32_t> kept_comps;
  for (size_t c = 0; c < nc; ++c) {
    if (lab.components[c].kept && lab.components[c].num_tets > 0) kept_comps.push_back(static_cast<uint32_t>(c));
  }
  auto comp_key = [&](uint32_t c) {
    const Component& k = lab.components[c];
    return std::make_tuple(k.seed < 0 ? 1 : 0, k.seed < 0 ? 0 : k.seed, comp_min[c]);
  };
  std::sort(kept_comps.begin(), kept_comps.end(),
            [&](uint32_t a, uint32_t b) { return comp_key(a) < comp_key(b); });
  std::vector<int32_t> comp_region(nc, -1);
  for (size_t r = 0; r < kept_comps.size(); ++r) {
    const Component& k = lab.components[kept_comps[r]];
    comp_region[kept_comps[r]] = static_cast<int32_t>(r);
    mesh::Region reg;
    reg.attribute = k.attribute;
    reg.max_volume = k.max_volume;
    m.regions.push_back(reg);
  }
  rep.num_regions = static_cast<uint32_t>(m.regions.size());

  m.tets.reserve(kept_tets.size());
  m.tet_region.reserve(kept_tets.size());
  for (uint32_t t : kept_tets) {
    const auto& tv = in.tets[t];
    const std::array<uint32_t, 4> o{out_id[tv[0]], out_id[tv[1]], out_id[tv[2]], out_id[tv[3]]};
    if (geom::Orient3d(m.positions[o[0]], m.positions[o[1]], m.positions[o[2]],
                       m.positions[o[3]]) <= 0) {
      ++rep.num_nonpositive_tets;
    }
    m.tets.push_back(o);
    m.tet_region.push_back(comp_region[lab.tet_component[t]]);
  }

  // --- Triangles. ------------------------------------------------------------
  auto region_of = [&](uint32_t t) -> int32_t {
    if (t == kNoTet || !lab.Kept(t)) return -1;
    return comp_region[lab.tet_component[t]];
  };
  auto local_apex = [&](uint32_t t, const std::array<uint32_t, 3>& f) -> int {
    for (int i = 0; i < 4; ++i) {
      const uint32_t v = in.tets[t][i];
      if (v != f[0] && v != f[1] && v != f[2]) return i;
    }
    return -1;
  };
  m.triangles.reserve(lab.faces.size());
  m.triangle_marker.reserve(lab.faces.size());
  for (const LabelledFace& f : lab.faces) {
    if (f.tets[0] >= nt || (f.tets[1] != kNoTet && f.tets[1] >= nt)) {
      return absl::InvalidArgumentError(absl::StrCat("labelled face ", f.constrained_face,
                                                     ": tet out of range"));
    }
    const int32_t r0 = region_of(f.tets[0]);
    const int32_t r1 = region_of(f.tets[1]);
    if (r0 < 0) {
      return absl::InvalidArgumentError(absl::StrCat("labelled face ", f.constrained_face,
                                                     ": tets[0] is not kept"));
    }
    const int a0 = local_apex(f.tets[0], f.v);
    const int a1 = f.tets[1] == kNoTet ? -1 : local_apex(f.tets[1], f.v);
    if (a0 < 0 || (f.tets[1] != kNoTet && a1 < 0)) {
      return absl::InvalidArgumentError(absl::StrCat("labelled face ", f.constrained_face,
                                                     " is not a face of its tets"));
    }
    uint32_t front = f.tets[0];
    int apex = a0;
    if (r1 >= 0) {
      const bool take1 =
          r1 < r0 || (r1 == r0 && out_id[in.tets[f.tets[1]][a1]] < out_id[in.tets[f.tets[0]][a0]]);
      if (take1) {
        front = f.tets[1];
        apex = a1;
      }
    }
    const auto& tv = in.tets[front];
    m.triangles.push_back({out_id[tv[kInwardFace[apex][0]]], out_id[tv[kInwardFace[apex][1]]],
                           out_id[tv[kInwardFace[apex][2]]]});
    m.triangle_marker.push_back(f.marker);
  }

  mesh::Canonicalize(&m);

  if (in.stats != nullptr) m.stats = *in.stats;
  m.stats.Set("output.vertices", static_cast<double>(m.positions.size()));
  m.stats.Set("output.input_vertices", static_cast<double>(nin));
  m.stats.Set("output.unused_input_vertices", rep.num_unused_input_vertices);
  m.stats.Set("output.steiner_vertices", rep.num_steiner_vertices);
  m.stats.Set("output.tets", static_cast<double>(m.tets.size()));
  m.stats.Set("output.dropped_tets", rep.num_dropped_tets);
  m.stats.Set("output.triangles", static_cast<double>(m.triangles.size()));
  m.stats.Set("output.regions", rep.num_regions);
  m.stats.Set("output.components", static_cast<double>(nc));
  m.stats.Set("output.label_warnings", static_cast<double>(lab.issues.size()));
  m.stats.Set("output.nonpositive_tets", rep.num_nonpositive_tets);
  return result;
}

absl::StatusOr<OutputStageResult> BuildOutputMesh(const plc::Plc& plc,
                                                  std::span<const Vec3> positions,
                                                  std::span<const std::array<uint32_t, 4>> tets,
                                                  std::span<const uint32_t> input_vertex,
                                                  std::span<const ConstrainedFace> constrained_faces,
                                                  const CoordinateMap& map, bool keep_bounding_box,
                                                  const mesh::MeshStats* stats,
                                                  std::span<const std::array<uint32_t, 4>> neighbor_tets) {
  std::vector<plc::RegionSeed> seeds = plc.regions;
  for (plc::RegionSeed& s : seeds) s.point = map.ToMesher(s.point);
  std::vector<Vec3> holes(plc.holes.size());
  for (size_t i = 0; i < holes.size(); ++i) holes[i] = map.ToMesher(plc.holes[i]);

  LabelInput li;
  li.positions = positions;
  li.tets = tets;
  li.constrained_faces = constrained_faces;
  li.region_seeds = seeds;
  li.hole_seeds = holes;
  li.keep_bounding_box = keep_bounding_box;
  li.neighbor_tets = neighbor_tets;
  absl::StatusOr<Labelling> lab = LabelRegions(li);
  if (!lab.ok()) return lab.status();

  AssembleInput ai;
  ai.plc = &plc;
  ai.positions = positions;
  ai.tets = tets;
  ai.input_vertex = input_vertex;
  ai.map = map;
  ai.labelling = &*lab;
  ai.stats = stats;
  absl::StatusOr<AssembledMesh> am = AssembleMesh(ai);
  if (!am.ok()) return am.status();

  OutputStageResult out;
  out.mesh = std::move(am->mesh);
  out.report = am->report;
  out.issues = std::move(lab->issues);
  return out;
}

}  // namespace svrc::refine
