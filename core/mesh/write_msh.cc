// Gmsh MSH 4.1 ASCII (Gmsh reference manual §10.1 "MSH file format"). One
// volume entity per region id r (entity and physical tag r+1, named
// "region r attribute a"): tets, element type 4. One surface entity per facet
// marker m: triangles, element type 2, physical tag m when m > 0 (markers
// <= 0 get the next free positive tags; the physical name "facet_marker m"
// always carries the value). All nodes are classified on the first volume
// entity. Provenance: a $Comments section (unknown sections are skipped by
// MSH readers).
#include <algorithm>
#include <map>
#include <string>

#include "absl/strings/str_cat.h"
#include "core/mesh/writer_util.h"
#include "core/mesh/writers_internal.h"

namespace svrc::mesh::internal {
namespace {

struct Entity {
  int tag = 0;
  int physical = 0;
  std::string name;
  geom::Box3 box;
  std::vector<size_t> elements;
};

void AppendBox(std::string* out, const geom::Box3& b) {
  for (const Vec3& p : {b.lo, b.hi}) {
    for (int a = 0; a < 3; ++a) {
      *out += ' ';
      AppendDouble(out, b.Empty() ? 0.0 : p[a]);
    }
  }
}

}  // namespace

FileList FormatMsh(const TetMesh& mesh, const std::string& msh_path) {
  std::map<int32_t, Entity> volumes;  // by region id
  for (size_t i = 0; i < mesh.tets.size(); ++i) {
    Entity& e = volumes[RegionId(mesh, i)];
    e.elements.push_back(i);
    for (uint32_t v : mesh.tets[i]) e.box.Add(mesh.positions[v]);
  }
  int tag = 1;
  for (auto& [r, e] : volumes) {
    e.tag = tag++;
    e.physical = r + 1 > 0 ? r + 1 : e.tag;
    const double a = r >= 0 && static_cast<size_t>(r) < mesh.regions.size()
                         ? mesh.regions[r].attribute
                         : 0.0;
    std::string attr;
    AppendDouble(&attr, a);
    e.name = absl::StrCat("region ", r, " attribute ", attr);
  }
  if (volumes.empty()) {  // nodes need an entity to live on
    Entity& e = volumes[0];
    e.tag = 1;
    for (const Vec3& p : mesh.positions) e.box.Add(p);
  }
  std::map<int32_t, Entity> surfaces;  // by marker
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    Entity& e = surfaces[TriangleMarker(mesh, i)];
    e.elements.push_back(i);
    for (uint32_t v : mesh.triangles[i]) e.box.Add(mesh.positions[v]);
  }
  int next_free = 1;
  for (const auto& [m, e] : surfaces) next_free = std::max(next_free, m + 1);
  tag = 1;
  for (auto& [m, e] : surfaces) {
    e.tag = tag++;
    e.physical = m > 0 ? m : next_free++;
    e.name = absl::StrCat("facet_marker ", m);
  }

  std::string out = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Comments\n";
  for (const std::string& l : ProvenanceLines(mesh.provenance)) {
    absl::StrAppend(&out, SingleLine(l), "\n");
  }
  absl::StrAppend(&out, "$EndComments\n$PhysicalNames\n");
  size_t num_physical = surfaces.size();
  for (const auto& [r, e] : volumes) num_physical += e.physical > 0 ? 1 : 0;
  absl::StrAppend(&out, num_physical, "\n");
  for (const auto& [m, e] : surfaces) absl::StrAppend(&out, "2 ", e.physical, " \"", e.name, "\"\n");
  for (const auto& [r, e] : volumes) {
    if (e.physical > 0) absl::StrAppend(&out, "3 ", e.physical, " \"", e.name, "\"\n");
  }
  absl::StrAppend(&out, "$EndPhysicalNames\n$Entities\n0 0 ", surfaces.size(), " ",
                  volumes.size(), "\n");
  for (const auto& [m, e] : surfaces) {
    absl::StrAppend(&out, e.tag);
    AppendBox(&out, e.box);
    absl::StrAppend(&out, " 1 ", e.physical, " 0\n");
  }
  for (const auto& [r, e] : volumes) {
    absl::StrAppend(&out, e.tag);
    AppendBox(&out, e.box);
    if (e.physical > 0) {
      absl::StrAppend(&out, " 1 ", e.physical, " 0\n");
    } else {
      absl::StrAppend(&out, " 0 0\n");
    }
  }
  absl::StrAppend(&out, "$EndEntities\n$Nodes\n");
  const size_t n = mesh.positions.size();
  if (n == 0) {
    absl::StrAppend(&out, "0 0 0 0\n");
  } else {
    absl::StrAppend(&out, "1 ", n, " 1 ", n, "\n3 ", volumes.begin()->second.tag, " 0 ", n, "\n");
    for (size_t i = 0; i < n; ++i) absl::StrAppend(&out, i + 1, "\n");
    for (const Vec3& p : mesh.positions) {
      AppendDouble(&out, p.x);
      out += ' ';
      AppendDouble(&out, p.y);
      out += ' ';
      AppendDouble(&out, p.z);
      out += '\n';
    }
  }
  absl::StrAppend(&out, "$EndNodes\n$Elements\n");
  size_t blocks = 0;
  for (const auto& [r, e] : volumes) blocks += e.elements.empty() ? 0 : 1;
  blocks += surfaces.size();
  const size_t num_elements = mesh.tets.size() + mesh.triangles.size();
  absl::StrAppend(&out, blocks, " ", num_elements, " ", num_elements ? 1 : 0, " ", num_elements,
                  "\n");
  for (const auto& [r, e] : volumes) {
    if (e.elements.empty()) continue;
    absl::StrAppend(&out, "3 ", e.tag, " 4 ", e.elements.size(), "\n");
    for (size_t i : e.elements) {
      const auto& t = mesh.tets[i];
      absl::StrAppend(&out, i + 1, " ", t[0] + 1, " ", t[1] + 1, " ", t[2] + 1, " ", t[3] + 1,
                      "\n");
    }
  }
  for (const auto& [m, e] : surfaces) {
    absl::StrAppend(&out, "2 ", e.tag, " 2 ", e.elements.size(), "\n");
    for (size_t i : e.elements) {
      const auto& t = mesh.triangles[i];
      absl::StrAppend(&out, mesh.tets.size() + i + 1, " ", t[0] + 1, " ", t[1] + 1, " ",
                      t[2] + 1, "\n");
    }
  }
  absl::StrAppend(&out, "$EndElements\n");
  return {{msh_path, std::move(out)}};
}

}  // namespace svrc::mesh::internal
