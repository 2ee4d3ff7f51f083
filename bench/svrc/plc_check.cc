// svrc_plc_check IN [--radius-edge R] [--max-volume V] [--keep-bounding-box]
//
// Meshes one PLC file through core::MeshPlc (the CLI's and the server's path)
// and checks what every output must satisfy (../shared/DESIGN.md "Output
// mesh"): conformity (keep_bounding_box aware), max_volume on every tet,
// radius-edge within the bound on every tet not touching a crease, and on the
// collar path the stitch's own guarantees (tets next to creases within the
// largest stitched dihedral; star and book σ within 60° unless the snap band
// was used), each region's own max volume, the attribute of the region around
// each region seed, and no tet around a volume hole point. Prints one line: OK / BAD (with the failed checks named) /
// FAIL (the mesher's error) / READ (the reader's). Exit 0 OK, 3 BAD, 2 FAIL,
// 1 READ or usage. bench/svrc/random_sweep.sh runs it over random PLCs.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "absl/strings/str_format.h"
#include "core/api.h"
#include "core/geometry/predicates.h"
#include "core/mesh/conformity.h"
#include "core/mesh/crease_vertices.h"
#include "core/mesh/quality.h"
#include "core/plc/readers.h"

namespace {

using namespace svrc;
using geom::Vec3;

// The tets whose closure holds p, by exact orientations; a flat tet holds
// nothing (a floating-point test put a far seed inside a cluster of tets
// 1e-9 across: random_plcs.py prism 59 before the collar shell).
std::vector<size_t> TetsAround(const mesh::TetMesh& m, const Vec3& p) {
  std::vector<size_t> out;
  for (size_t t = 0; t < m.tets.size(); ++t) {
    const auto& k = m.tets[t];
    const Vec3& a = m.positions[k[0]];
    const Vec3& b = m.positions[k[1]];
    const Vec3& c = m.positions[k[2]];
    const Vec3& d = m.positions[k[3]];
    if (geom::Orient3d(a, b, c, d) <= 0) continue;
    if (geom::Orient3d(p, b, c, d) >= 0 && geom::Orient3d(a, p, c, d) >= 0 && geom::Orient3d(a, b, p, d) >= 0 &&
        geom::Orient3d(a, b, c, p) >= 0) {
      out.push_back(t);
    }
  }
  return out;
}

int Usage() {
  std::fprintf(stderr, "usage: svrc_plc_check IN [--radius-edge R] [--max-volume V] [--keep-bounding-box]\n");
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) return Usage();
  core::MeshParams p;
  for (int i = 2; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--keep-bounding-box")) {
      p.keep_bounding_box = true;
    } else if (!std::strcmp(argv[i], "--max-volume") && i + 1 < argc) {
      p.max_volume = std::atof(argv[++i]);
    } else if (!std::strcmp(argv[i], "--radius-edge") && i + 1 < argc) {
      p.radius_edge = std::atof(argv[++i]);
    } else {
      return Usage();
    }
  }
  absl::StatusOr<plc::Plc> plc = plc::ReadPlcFile(argv[1]);
  if (!plc.ok()) {
    std::printf("READ %s\n", plc.status().ToString().c_str());
    return 1;
  }
  absl::StatusOr<mesh::TetMesh> m = core::MeshPlc(*plc, p);
  if (!m.ok()) {
    std::printf("FAIL %s\n", std::string(m.status().message()).substr(0, 400).c_str());
    return 2;
  }
  mesh::ConformityOptions o;
  o.keep_bounding_box = p.keep_bounding_box;
  const mesh::ConformityReport rep = mesh::CheckConformity(*plc, *m, o);
  const std::vector<uint8_t> crease_flags = mesh::CreaseVertexFlags(*plc, *m);
  const mesh::QualityReport q = mesh::ComputeQuality(*m, crease_flags);
  const double vmax = q.all.max_volume;
  const mesh::MeshStats& st = m->stats;
  const bool collars = st.Get("svrc.collars") > 0;
  const double stitched = std::max(st.Get("svrc.max_bounded_dihedral_deg"), st.Get("svrc.max_unbounded_dihedral_deg"));
  const bool vol_ok = p.max_volume <= 0 || vmax <= p.max_volume * (1 + 1e-9);
  const bool re_ok = q.other.num_tets == 0 || q.other.radius_edge.max <= p.radius_edge * (1 + 1e-9);
  // The output's coordinates are the stitch's rounded into the input's.
  const double crease_dih_rounded = mesh::MaxDihedralLessRounding(*m, crease_flags);
  const bool dih_ok = !collars || crease_dih_rounded <= stitched + 1e-6;
  const bool sigma_ok = !collars || st.Get("svrc.collar_snap") > 0 ||
                        (st.Get("svrc.star_sigma_max_deg") <= 60 + 1e-9 && st.Get("svrc.book_sigma_max_deg") <= 60 + 1e-9);
  // Each region's own bound, and the regions the seeds name.
  bool region_ok = true;
  for (size_t t = 0; t < m->tets.size() && region_ok; ++t) {
    const double rv = m->regions[m->tet_region[t]].max_volume;
    if (rv <= 0) continue;
    const auto& k = m->tets[t];
    const double v =
        mesh::ComputeTetQuality(m->positions[k[0]], m->positions[k[1]], m->positions[k[2]], m->positions[k[3]]).volume;
    if (std::abs(v) > rv * (1 + 1e-9)) region_ok = false;
  }
  bool seeds_ok = true;
  for (const plc::RegionSeed& r : plc->regions) {
    for (size_t t : TetsAround(*m, r.point)) {
      if (m->regions[m->tet_region[t]].attribute != r.attribute) seeds_ok = false;
    }
  }
  if (!p.keep_bounding_box) {
    for (const Vec3& h : plc->holes) {
      if (!TetsAround(*m, h).empty()) seeds_ok = false;
    }
  }
  const bool ok = rep.ok() && vol_ok && re_ok && dih_ok && sigma_ok && region_ok && seeds_ok;
  std::printf(
      "%s tets %zu conform %s vmax %.4g%s re_other %.4g%s dih_other %.3g..%.4g crease_tets %zu crease_dih_max %.2f "
      "stitched %.2f%s collars %g snap %g star_sigma %.1f%s mild_overrun %g regions %zu%s%s\n",
      ok ? "OK" : "BAD", m->tets.size(), rep.ok() ? "yes" : rep.Summary().substr(0, 200).c_str(), vmax,
      vol_ok ? "" : " VOLUME_OVER", q.other.radius_edge.max, re_ok ? "" : " RADIUS_EDGE_OVER", q.other.dihedral_deg.min,
      q.other.dihedral_deg.max, q.crease.num_tets, q.crease.dihedral_deg.max, stitched,
      dih_ok ? "" : absl::StrFormat(" DIHEDRAL_OVER(+%.3g)", crease_dih_rounded - stitched).c_str(),
      st.Get("svrc.collars"), st.Get("svrc.collar_snap"), st.Get("svrc.star_sigma_max_deg"), sigma_ok ? "" : " SIGMA_OVER",
      st.Get("mild_crease_budget_overrun"), m->regions.size(), region_ok ? "" : " REGION_VOLUME_OVER",
      seeds_ok ? "" : " SEED_REGION_WRONG");
  return ok ? 0 : 3;
}
