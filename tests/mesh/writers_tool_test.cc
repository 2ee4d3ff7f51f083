// The writers' output read back by independent tools from Debian: gmsh 4.8
// (.msh, .mesh), VTK 9 through python3-vtk9 (.vtu), tetgen 1.5 -r (.node/.ele/.face).
// A missing tool is a failure (scripts/setup.sh installs them).
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "absl/strings/str_cat.h"
#include "core/mesh/read_tetgen.h"
#include "core/mesh/writers.h"
#include "gtest/gtest.h"
#include "tests/mesh/mesh_test_util.h"
#include "tests/test_support.h"

namespace svrc::mesh {
namespace {

namespace fs = std::filesystem;
using testing::HaveTool;
using testing::RunIn;

// Debian's interpreter: python3-vtk9 is installed for it, not for a pyenv one.
constexpr char kPython[] = "/usr/bin/python3";

// Markers 0 and -4 (remapped to positive physical tags in .msh), two regions,
// coordinates that need 17 digits.
TetMesh Sample() {
  const plc::Plc p = testing::BoxPlc(Vec3(0.1, -1.0 / 3, 1e6), Vec3(2.0 / 3, 1.0 / 7, 1e6 + 1));
  TetMesh m = testing::KuhnBoxMesh(p, 2);
  m.regions = {Region{1.5, 0}, Region{7, 0}};
  for (size_t i = 0; i < m.tets.size(); ++i) m.tet_region[i] = i % 3 == 0 ? 1 : 0;
  for (auto& mk : m.triangle_marker) mk = mk == 1 ? 0 : (mk == 2 ? -4 : mk);
  m.provenance = {"0.1.0", "radius_edge=2", "00ff"};
  return m;
}

// A gmsh MSH 2.2 file (what we ask gmsh to re-save): nodes by tag and
// elements with (type, physical, elementary, nodes).
struct Msh22 {
  std::map<int64_t, Vec3> nodes;
  struct Element {
    int type, physical, elementary;
    std::vector<int64_t> nodes;
  };
  std::vector<Element> elements;
};

Msh22 ReadMsh22(const std::string& path) {
  Msh22 m;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line == "$Nodes") {
      size_t n;
      in >> n;
      for (size_t i = 0; i < n; ++i) {
        int64_t tag;
        std::string x, y, z;
        in >> tag >> x >> y >> z;
        m.nodes[tag] = Vec3(std::strtod(x.c_str(), nullptr), std::strtod(y.c_str(), nullptr),
                            std::strtod(z.c_str(), nullptr));
      }
    } else if (line == "$Elements") {
      size_t n;
      in >> n;
      for (size_t i = 0; i < n; ++i) {
        int64_t id;
        int type, ntags;
        in >> id >> type >> ntags;
        std::vector<int> tags(ntags);
        for (int& t : tags) in >> t;
        const int nn = type == 4 ? 4 : (type == 2 ? 3 : (type == 1 ? 2 : 1));
        Msh22::Element e{type, ntags > 0 ? tags[0] : 0, ntags > 1 ? tags[1] : 0, {}};
        e.nodes.resize(nn);
        for (auto& v : e.nodes) in >> v;
        m.elements.push_back(e);
      }
    }
  }
  return m;
}

std::string GmshResave(const std::string& dir, const std::string& file, int* rc) {
  const std::string out = file + ".resaved.msh";
  *rc = RunIn(dir,
            absl::StrCat("gmsh -setnumber General.AbortOnError 4 '", file, "' -0 -o '", out,
                         "' -format msh22"),
            file + ".gmsh.log");
  return (fs::path(dir) / out).string();
}

std::multiset<std::array<uint32_t, 4>> SortedTets(const TetMesh& m) {
  std::multiset<std::array<uint32_t, 4>> s;
  for (auto t : m.tets) {
    std::sort(t.begin(), t.end());
    s.insert(t);
  }
  return s;
}

TEST(WritersTool, GmshReadsMsh41) {
  ASSERT_TRUE(HaveTool("gmsh")) << "gmsh not installed (scripts/setup.sh installs it)";
  const TetMesh m = Sample();
  const std::string dir = svrc::testing::MakeTempDir("msh");
  ASSERT_TRUE(WriteMeshFile(m, dir + "/s.msh").ok());
  int rc = 0;
  const Msh22 g = ReadMsh22(GmshResave(dir, "s.msh", &rc));
  ASSERT_EQ(rc, 0) << svrc::testing::ReadFileOrFail(dir + "/s.msh.gmsh.log");
  ASSERT_EQ(g.nodes.size(), m.positions.size());
  for (size_t i = 0; i < m.positions.size(); ++i) {
    const Vec3 p = g.nodes.at(static_cast<int64_t>(i + 1));
    // gmsh re-saves with 16 significant digits.
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(p[a], m.positions[i][a], 1e-15 * std::max(1.0, std::fabs(p[a]))) << i;
    }
  }
  // Physical tags: region r -> r + 1; markers 3..6 as they are, 0 and -4
  // remapped to 7 and 8 (in marker order: -4 -> 7, 0 -> 8).
  std::map<std::pair<int, int>, int> want, got;
  for (size_t i = 0; i < m.tets.size(); ++i) ++want[{4, m.tet_region[i] + 1}];
  for (int32_t mk : m.triangle_marker) ++want[{2, mk == -4 ? 7 : (mk == 0 ? 8 : mk)}];
  TetMesh back;
  back.positions = m.positions;
  for (const auto& e : g.elements) {
    ++got[{e.type, e.physical}];
    if (e.type == 4) {
      back.tets.push_back({static_cast<uint32_t>(e.nodes[0] - 1), static_cast<uint32_t>(e.nodes[1] - 1),
                           static_cast<uint32_t>(e.nodes[2] - 1), static_cast<uint32_t>(e.nodes[3] - 1)});
    }
  }
  EXPECT_EQ(got, want);
  EXPECT_EQ(SortedTets(back), SortedTets(m));
  const std::string text = svrc::testing::ReadFileOrFail(dir + "/s.msh");
  EXPECT_NE(text.find("$Comments\nsvrc 0.1.0\nparameters: radius_edge=2\ninput sha256: 00ff\n"),
            std::string::npos);
  // The same invocation fails on a truncated file.
  std::ofstream(dir + "/t.msh") << text.substr(0, text.size() / 2);
  GmshResave(dir, "t.msh", &rc);
  EXPECT_NE(rc, 0) << "gmsh accepted a truncated .msh";
}

TEST(WritersTool, GmshReadsMedit) {
  ASSERT_TRUE(HaveTool("gmsh")) << "gmsh not installed (scripts/setup.sh installs it)";
  const TetMesh m = Sample();
  const std::string dir = svrc::testing::MakeTempDir("medit");
  ASSERT_TRUE(WriteMeshFile(m, dir + "/s.mesh").ok());
  int rc = 0;
  const Msh22 g = ReadMsh22(GmshResave(dir, "s.mesh", &rc));
  ASSERT_EQ(rc, 0) << svrc::testing::ReadFileOrFail(dir + "/s.mesh.gmsh.log");
  // gmsh renumbers Medit vertices: compare coordinates as sets, and elements
  // through their coordinates; refs become elementary tags.
  ASSERT_EQ(g.nodes.size(), m.positions.size());
  auto key = [](const Vec3& p) {
    return std::array<double, 3>{std::round(p.x * 1e9), std::round(p.y * 1e9),
                                 std::round(p.z * 1e9)};
  };
  std::multiset<std::array<double, 3>> a, b;
  for (const auto& [tag, p] : g.nodes) a.insert(key(p));
  for (const Vec3& p : m.positions) b.insert(key(p));
  EXPECT_EQ(a, b);
  std::map<std::pair<int, int>, int> want, got;
  for (size_t i = 0; i < m.tets.size(); ++i) ++want[{4, m.tet_region[i]}];
  for (int32_t mk : m.triangle_marker) ++want[{2, mk}];
  std::multiset<std::array<std::array<double, 3>, 4>> gt, mt;
  for (const auto& e : g.elements) {
    ++got[{e.type, e.elementary}];
    if (e.type == 4) {
      std::array<std::array<double, 3>, 4> t;
      for (int k = 0; k < 4; ++k) t[k] = key(g.nodes.at(e.nodes[k]));
      std::sort(t.begin(), t.end());
      gt.insert(t);
    }
  }
  for (const auto& q : m.tets) {
    std::array<std::array<double, 3>, 4> t;
    for (int k = 0; k < 4; ++k) t[k] = key(m.positions[q[k]]);
    std::sort(t.begin(), t.end());
    mt.insert(t);
  }
  EXPECT_EQ(got, want);
  EXPECT_EQ(gt, mt);
}

constexpr char kVtkScript[] = R"(
import sys, vtk
errors = []
r = vtk.vtkXMLUnstructuredGridReader()
r.AddObserver("ErrorEvent", lambda obj, ev: errors.append(ev))
r.SetFileName(sys.argv[1])
r.Update()
if r.GetErrorCode() != 0 or errors:
    sys.exit(2)
g = r.GetOutput()
print("points", g.GetNumberOfPoints())
print("cells", g.GetNumberOfCells())
for i in range(g.GetNumberOfPoints()):
    p = g.GetPoint(i)
    print("p", repr(p[0]), repr(p[1]), repr(p[2]))
cd = g.GetCellData()
arr = cd.GetArray(sys.argv[2])
for i in range(g.GetNumberOfCells()):
    c = g.GetCell(i)
    ids = [c.GetPointId(k) for k in range(c.GetNumberOfPoints())]
    print("c", g.GetCellType(i), int(arr.GetTuple1(i)), *ids)
)";

struct VtkGrid {
  std::vector<Vec3> points;
  std::vector<std::vector<int64_t>> cells;  // type, tag, ids...
};

VtkGrid ReadWithVtk(const std::string& dir, const std::string& file, const std::string& array,
                    int* rc) {
  std::ofstream(dir + "/read_vtu.py") << kVtkScript;
  const std::string out = file + ".txt";
  *rc = RunIn(dir, absl::StrCat(kPython, " read_vtu.py '", file, "' ", array), out);
  VtkGrid g;
  std::istringstream in(svrc::testing::ReadFileOrFail(dir + "/" + out));
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::string kind;
    ls >> kind;
    if (kind == "p") {
      std::string x, y, z;
      ls >> x >> y >> z;
      g.points.push_back(Vec3(std::strtod(x.c_str(), nullptr), std::strtod(y.c_str(), nullptr),
                              std::strtod(z.c_str(), nullptr)));
    } else if (kind == "c") {
      std::vector<int64_t> c;
      int64_t v;
      while (ls >> v) c.push_back(v);
      g.cells.push_back(c);
    }
  }
  return g;
}

TEST(WritersTool, VtkReadsVtu) {
  ASSERT_TRUE(fs::exists(kPython)) << kPython;
  ASSERT_EQ(std::system(absl::StrCat(kPython, " -c 'import vtk' >/dev/null 2>&1").c_str()), 0)
      << "python3-vtk9 not installed (scripts/setup.sh installs it)";
  const TetMesh m = Sample();
  const std::string dir = svrc::testing::MakeTempDir("vtu");
  ASSERT_TRUE(WriteMeshFile(m, dir + "/s.vtu").ok());
  int rc = 0;
  const VtkGrid v = ReadWithVtk(dir, "s.vtu", "region", &rc);
  ASSERT_EQ(rc, 0) << svrc::testing::ReadFileOrFail(dir + "/s.vtu.txt");
  EXPECT_EQ(v.points, m.positions);  // bit-exact: Float64 base64, repr() round-trips
  ASSERT_EQ(v.cells.size(), m.tets.size());
  for (size_t i = 0; i < m.tets.size(); ++i) {
    EXPECT_EQ(v.cells[i], (std::vector<int64_t>{10, m.tet_region[i], m.tets[i][0], m.tets[i][1],
                                                m.tets[i][2], m.tets[i][3]}));
  }
  const VtkGrid b = ReadWithVtk(dir, "s.boundary.vtu", "facet_marker", &rc);
  ASSERT_EQ(rc, 0) << svrc::testing::ReadFileOrFail(dir + "/s.boundary.vtu.txt");
  EXPECT_EQ(b.points, m.positions);
  ASSERT_EQ(b.cells.size(), m.triangles.size());
  for (size_t i = 0; i < m.triangles.size(); ++i) {
    EXPECT_EQ(b.cells[i], (std::vector<int64_t>{5, m.triangle_marker[i], m.triangles[i][0],
                                                m.triangles[i][1], m.triangles[i][2]}));
  }
  EXPECT_NE(svrc::testing::ReadFileOrFail(dir + "/s.vtu").find("input sha256: 00ff"),
            std::string::npos);
  // The reader reports a truncated file.
  const std::string text = svrc::testing::ReadFileOrFail(dir + "/s.vtu");
  std::ofstream(dir + "/t.vtu") << text.substr(0, text.size() / 2);
  ReadWithVtk(dir, "t.vtu", "region", &rc);
  EXPECT_NE(rc, 0) << "VTK accepted a truncated .vtu";
}

TEST(WritersTool, TetgenReconstructsFromNodeEle) {
  ASSERT_TRUE(HaveTool("tetgen")) << "tetgen not installed (scripts/setup.sh installs it)";
  const TetMesh m = Sample();
  const std::string dir = svrc::testing::MakeTempDir("tetgen_r");
  ASSERT_TRUE(WriteMeshFile(m, dir + "/s.node").ok());
  const int rc = RunIn(dir, "stdbuf -o0 tetgen -rQ s", "tetgen.log");
  ASSERT_EQ(rc, 0) << svrc::testing::ReadFileOrFail(dir + "/tetgen.log");
  auto back = ReadTetgenMesh(dir + "/s.1.node");
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->positions, m.positions);  // tetgen writes %.17g too
  EXPECT_EQ(SortedTets(*back), SortedTets(m));
  // Region attributes survive (as values).
  std::multiset<double> a, b;
  for (size_t i = 0; i < m.tets.size(); ++i) a.insert(m.regions[m.tet_region[i]].attribute);
  for (size_t i = 0; i < back->tets.size(); ++i) {
    b.insert(back->regions[back->tet_region[i]].attribute);
  }
  EXPECT_EQ(a, b);
}

}  // namespace
}  // namespace svrc::mesh
