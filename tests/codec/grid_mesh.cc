#include "tests/codec/grid_mesh.h"

#include <algorithm>
#include <array>
#include <random>

#include "core/mesh/canonical.h"

namespace svrc::codec::testing {
namespace {

int Det(const std::array<std::array<int, 3>, 4>& p) {
  int m[3][3];
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m[r][c] = p[r + 1][c] - p[0][c];
  }
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
         m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

}  // namespace

mesh::TetMesh MakeGridMesh(const GridMeshOptions& o) {
  mesh::TetMesh m;
  const int sx = o.nx + 1, sy = o.ny + 1, sz = o.nz + 1;
  auto vid = [&](int i, int j, int k) { return static_cast<uint32_t>(i + sx * (j + sy * k)); };
  std::mt19937_64 rng(o.seed);
  // 53 random bits to [-1, 1): std distributions differ between libraries.
  auto unit = [&] { return static_cast<double>(rng() >> 11) * 0x1p-52 - 1.0; };
  m.positions.resize(static_cast<size_t>(sx) * sy * sz);
  for (int k = 0; k < sz; ++k) {
    for (int j = 0; j < sy; ++j) {
      for (int i = 0; i < sx; ++i) {
        mesh::Vec3 p = o.origin + o.spacing * mesh::Vec3(i, j, k);
        const bool interior = i > 0 && i < o.nx && j > 0 && j < o.ny && k > 0 && k < o.nz;
        if (interior && o.jitter > 0) {
          p += o.jitter * o.spacing * mesh::Vec3(unit(), unit(), unit());
        }
        m.positions[vid(i, j, k)] = p;
      }
    }
  }
  m.num_input_vertices = static_cast<uint32_t>(std::min<size_t>(8, m.positions.size()));
  m.regions = {{1.0, 0.0}, {2.0, 0.5}};

  // Kuhn subdivision: for each permutation of the axes, the path from corner
  // (0,0,0) to (1,1,1) stepping one axis at a time.
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = 0; k < o.nz; ++k) {
    for (int j = 0; j < o.ny; ++j) {
      for (int i = 0; i < o.nx; ++i) {
        for (const auto& perm : perms) {
          std::array<std::array<int, 3>, 4> c{};
          for (int s = 1; s < 4; ++s) {
            c[s] = c[s - 1];
            c[s][perm[s - 1]] = 1;
          }
          if (Det(c) < 0) std::swap(c[2], c[3]);
          std::array<uint32_t, 4> t;
          for (int s = 0; s < 4; ++s) t[s] = vid(i + c[s][0], j + c[s][1], k + c[s][2]);
          m.tets.push_back(t);
          m.tet_region.push_back(2 * i < o.nx ? 0 : 1);
        }
      }
    }
  }
  // Boundary faces: each unit square split along the diagonal from its low
  // corner to its high corner (the Kuhn tets' face diagonals).
  auto quad = [&](uint32_t a, uint32_t b, uint32_t c, uint32_t d, int marker) {
    // a = low corner, d = high corner, b and c the others.
    m.triangles.push_back({a, b, d});
    m.triangles.push_back({a, d, c});
    m.triangle_marker.push_back(marker);
    m.triangle_marker.push_back(marker);
  };
  for (int b = 0; b < o.ny; ++b) {
    for (int c = 0; c < o.nz; ++c) {
      for (int side = 0; side < 2; ++side) {
        const int i = side ? o.nx : 0;
        quad(vid(i, b, c), vid(i, b + 1, c), vid(i, b, c + 1), vid(i, b + 1, c + 1), 1 + side);
      }
    }
  }
  for (int a = 0; a < o.nx; ++a) {
    for (int c = 0; c < o.nz; ++c) {
      for (int side = 0; side < 2; ++side) {
        const int j = side ? o.ny : 0;
        quad(vid(a, j, c), vid(a + 1, j, c), vid(a, j, c + 1), vid(a + 1, j, c + 1), 3 + side);
      }
    }
  }
  for (int a = 0; a < o.nx; ++a) {
    for (int b = 0; b < o.ny; ++b) {
      for (int side = 0; side < 2; ++side) {
        const int k = side ? o.nz : 0;
        quad(vid(a, b, k), vid(a + 1, b, k), vid(a, b + 1, k), vid(a + 1, b + 1, k), 5 + side);
      }
    }
  }
  if (o.hilbert_order) mesh::PermuteVertices(&m, mesh::SpatialOrder(m.positions));
  mesh::Canonicalize(&m);
  m.provenance = {"svrc 0.1.0", "synthetic grid", ""};
  return m;
}

}  // namespace svrc::codec::testing
