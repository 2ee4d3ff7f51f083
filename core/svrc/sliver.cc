// Sliver removal by flips: see sliver.h and docs/svrc-output.md "Sliver removal".
#include "core/svrc/sliver.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <tuple>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "core/geometry/predicates.h"
#include "core/mesh/quality.h"

namespace svrc::refine {
namespace {

using geom::Vec3;
using Tet = std::array<uint32_t, 4>;
using Tri = std::array<uint32_t, 3>;
using Edge = std::array<uint32_t, 2>;

constexpr uint32_t kNone = 0xFFFFFFFFu;
constexpr double kInf = std::numeric_limits<double>::infinity();

Tri SortedTri(uint32_t a, uint32_t b, uint32_t c) {
  Tri t{a, b, c};
  std::sort(t.begin(), t.end());
  return t;
}

Edge SortedEdge(uint32_t a, uint32_t b) { return a < b ? Edge{a, b} : Edge{b, a}; }

// The face of tet t opposite its local vertex f, sorted.
Tri FaceKey(const Tet& t, int f) {
  Tri r{};
  int k = 0;
  for (int i = 0; i < 4; ++i) {
    if (i != f) r[k++] = t[i];
  }
  std::sort(r.begin(), r.end());
  return r;
}

// Quality of one tet. Computed on the vertices in sorted-id order, so a tet's
// value is a function of its vertex set alone: the strict "new worst > old
// worst" rule then orders the finitely many possible tetrahedralizations and
// the flip sequence cannot cycle.
struct Quality {
  double min_dihedral = 0;  // degrees
  double max_dihedral = 0;
  double radius_edge = 0;
};

Quality Measure(std::span<const Vec3> pos, Tet t) {
  std::sort(t.begin(), t.end());
  const mesh::TetQuality q = mesh::ComputeTetQuality(pos[t[0]], pos[t[1]], pos[t[2]], pos[t[3]]);
  return Quality{q.min_dihedral_deg, q.max_dihedral_deg, q.radius_edge};
}

// A flip under evaluation: the tets it replaces and the ones it creates.
struct Flip {
  enum Type { k23, k32, k44 } type = k23;
  std::array<uint32_t, 4> old_tets{};
  int num_old = 0;
  std::array<Tet, 4> new_tets{};
  std::array<Quality, 4> new_quality{};
  int num_new = 0;
  double new_min = -kInf;  // worst smallest dihedral among the new tets
};

// The mutable tetrahedralization: flat arrays, slots reused through a free
// list (LIFO, deterministic), neighbours per face (nbr[t][f] across the face
// opposite local vertex f).
class FlipMesh {
 public:
  FlipMesh(std::span<const Vec3> pos, const SliverOptions& options, SliverStats* stats)
      : pos_(pos), options_(options), stats_(stats) {}

  absl::Status Init(const SliverInput& in);
  void Run();
  absl::Status CheckConstraints() const;
  std::vector<Tet> Output() const;
  void Summarize(bool before);

 private:
  bool FaceConstrained(const Tri& f) const {
    return std::binary_search(cfaces_.begin(), cfaces_.end(), f);
  }
  bool EdgeConstrained(uint32_t a, uint32_t b) const {
    return std::binary_search(cedges_.begin(), cedges_.end(), SortedEdge(a, b));
  }
  uint32_t Allocate();
  void Push(uint32_t t);
  // Ring of tets around edge (p, q) of tet t: ring vertices u_0..u_{k-1} with
  // (p, q, u_i, u_{i+1}) the positively oriented tet ring_tets[i]. False when
  // the ring is open (the edge is on the hull) or has more than max_size tets.
  bool Ring(uint32_t t, uint32_t p, uint32_t q, int max_size, std::array<uint32_t, 4>* ring_tets,
            std::array<uint32_t, 4>* ring_verts, int* size) const;
  // Fills the quality of the new tets and checks orientation, gain and the
  // radius-edge bound. True iff the flip is legal and an improvement.
  bool Evaluate(Flip* flip);
  bool BestFlip(uint32_t t, Flip* best);
  void Apply(const Flip& flip, std::vector<uint32_t>* created);

  std::span<const Vec3> pos_;
  const SliverOptions& options_;
  SliverStats* stats_;
  std::vector<Tet> tet_;
  std::vector<std::array<uint32_t, 4>> nbr_;
  std::vector<Quality> quality_;
  std::vector<uint32_t> version_;
  std::vector<uint8_t> alive_;
  std::vector<uint32_t> free_;
  std::vector<Tri> cfaces_;   // sorted, unique
  std::vector<Edge> cedges_;  // sorted, unique
  // Worst first, ties by slot: (min dihedral, slot, version).
  using Entry = std::tuple<double, uint32_t, uint32_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> queue_;
};

// Permutation parity of (a, b, c, d) relative to the order of t (the four are
// t's vertices): true iff even.
bool EvenOrder(const Tet& t, uint32_t a, uint32_t b, uint32_t c, uint32_t d) {
  const uint32_t want[4] = {a, b, c, d};
  int idx[4];
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      if (t[j] == want[i]) idx[i] = j;
    }
  }
  int inversions = 0;
  for (int i = 0; i < 4; ++i) {
    for (int j = i + 1; j < 4; ++j) inversions += idx[i] > idx[j];
  }
  return inversions % 2 == 0;
}

int LocalIndex(const Tet& t, uint32_t v) {
  for (int i = 0; i < 4; ++i) {
    if (t[i] == v) return i;
  }
  return -1;
}

struct FaceRec {
  Tri key;
  uint32_t tet;
  int face;
};

absl::Status FlipMesh::Init(const SliverInput& in) {
  const size_t n = pos_.size();
  const size_t num_tets = in.tets.size();
  if (num_tets >= kNone / 8) return absl::InvalidArgumentError("sliver: too many tets");
  tet_.assign(in.tets.begin(), in.tets.end());
  nbr_.assign(num_tets, {kNone, kNone, kNone, kNone});
  quality_.resize(num_tets);
  version_.assign(num_tets, 0);
  alive_.assign(num_tets, 1);
  for (size_t t = 0; t < num_tets; ++t) {
    const Tet& v = tet_[t];
    for (int i = 0; i < 4; ++i) {
      if (v[i] >= n) {
        return absl::InvalidArgumentError(absl::StrCat("sliver: tet ", t, " has vertex id ", v[i], " >= ", n));
      }
      for (int j = 0; j < i; ++j) {
        if (v[i] == v[j]) return absl::InvalidArgumentError(absl::StrCat("sliver: tet ", t, " repeats vertex ", v[i]));
      }
    }
    if (geom::Orient3d(pos_[v[0]], pos_[v[1]], pos_[v[2]], pos_[v[3]]) <= 0) {
      return absl::InvalidArgumentError(absl::StrCat("sliver: tet ", t, " is not positively oriented"));
    }
    quality_[t] = Measure(pos_, v);
  }
  // Adjacency by sorting the 4T faces (as LabelRegions does: no hashing).
  std::vector<FaceRec> faces;
  faces.reserve(4 * num_tets);
  for (uint32_t t = 0; t < num_tets; ++t) {
    for (int f = 0; f < 4; ++f) faces.push_back(FaceRec{FaceKey(tet_[t], f), t, f});
  }
  std::sort(faces.begin(), faces.end(), [](const FaceRec& a, const FaceRec& b) {
    return std::tie(a.key, a.tet, a.face) < std::tie(b.key, b.tet, b.face);
  });
  for (size_t i = 0; i < faces.size();) {
    size_t j = i + 1;
    while (j < faces.size() && faces[j].key == faces[i].key) ++j;
    if (j - i > 2) {
      return absl::InvalidArgumentError(absl::StrCat("sliver: face (", faces[i].key[0], ", ", faces[i].key[1], ", ",
                                                     faces[i].key[2], ") is in ", j - i, " tets"));
    }
    if (j - i == 2) {
      nbr_[faces[i].tet][faces[i].face] = faces[i + 1].tet;
      nbr_[faces[i + 1].tet][faces[i + 1].face] = faces[i].tet;
    }
    i = j;
  }
  for (const Tri& f : in.constrained_faces) {
    if (f[0] >= n || f[1] >= n || f[2] >= n || f[0] == f[1] || f[0] == f[2] || f[1] == f[2]) {
      return absl::InvalidArgumentError(
          absl::StrCat("sliver: constrained face (", f[0], ", ", f[1], ", ", f[2], ") has a bad vertex id"));
    }
    cfaces_.push_back(SortedTri(f[0], f[1], f[2]));
  }
  std::sort(cfaces_.begin(), cfaces_.end());
  cfaces_.erase(std::unique(cfaces_.begin(), cfaces_.end()), cfaces_.end());
  for (const Edge& e : in.constrained_edges) {
    if (e[0] >= n || e[1] >= n || e[0] == e[1]) {
      return absl::InvalidArgumentError(
          absl::StrCat("sliver: constrained edge (", e[0], ", ", e[1], ") has a bad vertex id"));
    }
    cedges_.push_back(SortedEdge(e[0], e[1]));
  }
  std::sort(cedges_.begin(), cedges_.end());
  cedges_.erase(std::unique(cedges_.begin(), cedges_.end()), cedges_.end());
  return CheckConstraints();
}

absl::Status FlipMesh::CheckConstraints() const {
  std::vector<Tri> faces;
  std::vector<Edge> edges;
  for (size_t t = 0; t < tet_.size(); ++t) {
    if (!alive_[t]) continue;
    const Tet& v = tet_[t];
    for (int f = 0; f < 4; ++f) faces.push_back(FaceKey(v, f));
    for (int i = 0; i < 4; ++i) {
      for (int j = i + 1; j < 4; ++j) edges.push_back(SortedEdge(v[i], v[j]));
    }
  }
  std::sort(faces.begin(), faces.end());
  std::sort(edges.begin(), edges.end());
  for (const Tri& f : cfaces_) {
    if (!std::binary_search(faces.begin(), faces.end(), f)) {
      return absl::InvalidArgumentError(
          absl::StrCat("sliver: constrained face (", f[0], ", ", f[1], ", ", f[2], ") is not a face of the mesh"));
    }
  }
  for (const Edge& e : cedges_) {
    if (!std::binary_search(edges.begin(), edges.end(), e)) {
      return absl::InvalidArgumentError(
          absl::StrCat("sliver: constrained edge (", e[0], ", ", e[1], ") is not an edge of the mesh"));
    }
  }
  return absl::OkStatus();
}

uint32_t FlipMesh::Allocate() {
  uint32_t t;
  if (!free_.empty()) {
    t = free_.back();
    free_.pop_back();
  } else {
    t = static_cast<uint32_t>(tet_.size());
    tet_.push_back({});
    nbr_.push_back({kNone, kNone, kNone, kNone});
    quality_.push_back({});
    version_.push_back(0);
    alive_.push_back(0);
  }
  ++version_[t];
  alive_[t] = 1;
  return t;
}

void FlipMesh::Push(uint32_t t) {
  if (quality_[t].min_dihedral < options_.target_min_dihedral_deg) {
    queue_.emplace(quality_[t].min_dihedral, t, version_[t]);
  }
}

bool FlipMesh::Ring(uint32_t t, uint32_t p, uint32_t q, int max_size, std::array<uint32_t, 4>* ring_tets,
                    std::array<uint32_t, 4>* ring_verts, int* size) const {
  const Tet& v = tet_[t];
  uint32_t x = kNone, y = kNone;
  for (int i = 0; i < 4; ++i) {
    if (v[i] == p || v[i] == q) continue;
    (x == kNone ? x : y) = v[i];
  }
  if (!EvenOrder(v, p, q, x, y)) std::swap(x, y);
  // Tet i = (p, q, u_i, u_{i+1}); the next one is across the face (p, q,
  // u_{i+1}), the face opposite u_i. Adjacent positive tets sharing that face
  // have their apices on opposite sides, so (p, q, u_{i+1}, u_{i+2}) is again
  // an even order of the next tet.
  int k = 0;
  uint32_t cur = t;
  uint32_t ui = x, uj = y;
  while (true) {
    if (k == max_size) return false;
    (*ring_tets)[k] = cur;
    (*ring_verts)[k] = ui;
    ++k;
    const uint32_t next = nbr_[cur][LocalIndex(tet_[cur], ui)];
    if (next == kNone) return false;
    if (next == t) break;
    const Tet& w = tet_[next];
    uint32_t nu = kNone;
    for (int i = 0; i < 4; ++i) {
      if (w[i] != p && w[i] != q && w[i] != uj) nu = w[i];
    }
    cur = next;
    ui = uj;
    uj = nu;
  }
  *size = k;
  return true;
}

bool FlipMesh::Evaluate(Flip* flip) {
  ++stats_->candidates;
  for (int i = 0; i < flip->num_new; ++i) {
    const Tet& v = flip->new_tets[i];
    if (geom::Orient3d(pos_[v[0]], pos_[v[1]], pos_[v[2]], pos_[v[3]]) <= 0) {
      ++stats_->rejected_orientation;
      return false;
    }
  }
  double old_min = kInf, old_max_re = 0;
  for (int i = 0; i < flip->num_old; ++i) {
    const Quality& q = quality_[flip->old_tets[i]];
    old_min = std::min(old_min, q.min_dihedral);
    old_max_re = std::max(old_max_re, q.radius_edge);
  }
  const double re_bound = std::max(options_.max_radius_edge, old_max_re);
  double new_min = kInf;
  bool re_ok = true;
  for (int i = 0; i < flip->num_new; ++i) {
    const Quality q = Measure(pos_, flip->new_tets[i]);
    flip->new_quality[i] = q;
    new_min = std::min(new_min, q.min_dihedral);
    if (!(q.radius_edge <= re_bound)) re_ok = false;
  }
  flip->new_min = new_min;
  if (!(new_min > old_min)) {
    ++stats_->rejected_no_gain;
    return false;
  }
  if (!re_ok) {
    ++stats_->rejected_radius_edge;
    return false;
  }
  return true;
}

bool FlipMesh::BestFlip(uint32_t t, Flip* best) {
  bool found = false;
  auto consider = [&](Flip& f) {
    if (Evaluate(&f) && (!found || f.new_min > best->new_min)) {
      *best = f;
      found = true;
    }
  };
  const Tet v = tet_[t];
  // 2-3 across each face: t = (.., d = v[f], ..) and its neighbour n with apex
  // e. Replacing, in turn, each vertex of the shared face by e gives the three
  // tets around the new edge de; each is positive iff e lies on the same side
  // as the replaced vertex, i.e. iff segment de crosses the face's interior.
  for (int f = 0; f < 4; ++f) {
    const uint32_t n = nbr_[t][f];
    if (n == kNone) continue;
    const Tri face = FaceKey(v, f);
    if (FaceConstrained(face)) {
      ++stats_->rejected_constraint;
      continue;
    }
    const Tet& w = tet_[n];
    uint32_t e = kNone;
    for (int i = 0; i < 4; ++i) {
      if (w[i] != face[0] && w[i] != face[1] && w[i] != face[2]) e = w[i];
    }
    Flip flip;
    flip.type = Flip::k23;
    flip.old_tets = {t, n, 0, 0};
    flip.num_old = 2;
    for (int i = 0, k = 0; i < 4; ++i) {
      if (i == f) continue;
      Tet nt = v;
      nt[i] = e;
      flip.new_tets[k++] = nt;
    }
    flip.num_new = 3;
    consider(flip);
  }
  // 3-2 and 4-4 removing each edge pq of t whose ring is closed with 3 or 4
  // tets (p, q, u_i, u_{i+1}), all positive. Oriented boundary of that ring:
  // +[q, u_i, u_{i+1}] and −[p, u_i, u_{i+1}]; the tets (u_0, u_1, u_2, q) and
  // (u_1, u_0, u_2, p) have the same boundary (plus the inner face u_0u_1u_2
  // with both signs), and so do the fans over a diagonal of the 4-ring.
  // Positive tets with the boundary of the old ones tile exactly its union.
  static constexpr int kEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  for (const auto& ij : kEdges) {
    const uint32_t p = v[ij[0]], q = v[ij[1]];
    std::array<uint32_t, 4> ring_tets{}, u{};
    int k = 0;
    if (!Ring(t, p, q, 4, &ring_tets, &u, &k)) continue;
    if (k < 3) continue;  // not in a valid mesh
    bool blocked = EdgeConstrained(p, q);
    for (int i = 0; i < k && !blocked; ++i) blocked = FaceConstrained(SortedTri(p, q, u[i]));
    if (blocked) {
      ++stats_->rejected_constraint;
      continue;
    }
    if (k == 3) {
      Flip flip;
      flip.type = Flip::k32;
      flip.old_tets = {ring_tets[0], ring_tets[1], ring_tets[2], 0};
      flip.num_old = 3;
      flip.new_tets[0] = {u[0], u[1], u[2], q};
      flip.new_tets[1] = {u[1], u[0], u[2], p};
      flip.num_new = 2;
      consider(flip);
    } else {
      for (int r = 0; r < 2; ++r) {
        // Diagonal u_r u_{r+2}: triangles (u_r, u_{r+1}, u_{r+2}), (u_r, u_{r+2}, u_{r+3}).
        const uint32_t a = u[r], b = u[r + 1], c = u[(r + 2) % 4], d = u[(r + 3) % 4];
        Flip flip;
        flip.type = Flip::k44;
        flip.old_tets = ring_tets;
        flip.num_old = 4;
        flip.new_tets[0] = {a, b, c, q};
        flip.new_tets[1] = {a, c, d, q};
        flip.new_tets[2] = {b, a, c, p};
        flip.new_tets[3] = {c, a, d, p};
        flip.num_new = 4;
        consider(flip);
      }
    }
  }
  return found;
}

void FlipMesh::Apply(const Flip& flip, std::vector<uint32_t>* created) {
  // The outer faces of the replaced tets and who is across them.
  struct Outer {
    Tri key;
    uint32_t tet;  // kNone: a hull face
  };
  std::array<Outer, 16> outer{};
  int num_outer = 0;
  auto is_old = [&](uint32_t x) {
    for (int i = 0; i < flip.num_old; ++i) {
      if (flip.old_tets[i] == x) return true;
    }
    return false;
  };
  for (int i = 0; i < flip.num_old; ++i) {
    const uint32_t o = flip.old_tets[i];
    for (int f = 0; f < 4; ++f) {
      const uint32_t n = nbr_[o][f];
      if (n != kNone && is_old(n)) continue;
      outer[num_outer++] = Outer{FaceKey(tet_[o], f), n};
    }
  }
  for (int i = 0; i < flip.num_old; ++i) {
    const uint32_t o = flip.old_tets[i];
    alive_[o] = 0;
    ++version_[o];
    nbr_[o] = {kNone, kNone, kNone, kNone};
  }
  // Reuse the old slots (LIFO: the last replaced first).
  for (int i = 0; i < flip.num_old; ++i) free_.push_back(flip.old_tets[i]);
  std::array<uint32_t, 4> slots{};
  for (int i = 0; i < flip.num_new; ++i) {
    slots[i] = Allocate();
    tet_[slots[i]] = flip.new_tets[i];
    quality_[slots[i]] = flip.new_quality[i];
    nbr_[slots[i]] = {kNone, kNone, kNone, kNone};
  }
  for (int i = 0; i < flip.num_new; ++i) {
    const uint32_t s = slots[i];
    for (int f = 0; f < 4; ++f) {
      const Tri key = FaceKey(tet_[s], f);
      uint32_t across = kNone;
      bool inner = false;
      for (int j = 0; j < flip.num_new && !inner; ++j) {
        if (j == i) continue;
        const int g = [&] {
          for (int h = 0; h < 4; ++h) {
            if (FaceKey(tet_[slots[j]], h) == key) return h;
          }
          return -1;
        }();
        if (g >= 0) {
          across = slots[j];
          inner = true;
        }
      }
      if (!inner) {
        for (int o = 0; o < num_outer; ++o) {
          if (outer[o].key != key) continue;
          across = outer[o].tet;
          if (across != kNone) {
            for (int h = 0; h < 4; ++h) {
              if (FaceKey(tet_[across], h) == key) nbr_[across][h] = s;
            }
          }
          break;
        }
      }
      nbr_[s][f] = across;
    }
    created->push_back(s);
  }
  switch (flip.type) {
    case Flip::k23: ++stats_->flips_23; break;
    case Flip::k32: ++stats_->flips_32; break;
    case Flip::k44: ++stats_->flips_44; break;
  }
}

void FlipMesh::Run() {
  const uint64_t cap = options_.max_flips > 0 ? options_.max_flips : 4 * static_cast<uint64_t>(tet_.size()) + 1000;
  std::vector<uint32_t> created;
  for (uint32_t pass = 0; pass < options_.max_passes; ++pass) {
    ++stats_->passes;
    for (uint32_t t = 0; t < tet_.size(); ++t) {
      if (alive_[t]) Push(t);
    }
    uint64_t flips_in_pass = 0;
    while (!queue_.empty()) {
      const auto [q, t, ver] = queue_.top();
      queue_.pop();
      if (!alive_[t] || version_[t] != ver) continue;  // replaced since it was queued
      Flip best;
      if (!BestFlip(t, &best)) {
        ++stats_->stuck;
        continue;
      }
      created.clear();
      Apply(best, &created);
      ++flips_in_pass;
      for (uint32_t s : created) Push(s);
      if (stats_->flips() >= cap) {
        stats_->hit_flip_cap = true;
        break;
      }
    }
    queue_ = {};
    if (flips_in_pass == 0 || stats_->hit_flip_cap) break;
  }
}

void FlipMesh::Summarize(bool before) {
  uint64_t count = 0, bad = 0;
  double min_dih = kInf, max_dih = 0, max_re = 0;
  for (size_t t = 0; t < tet_.size(); ++t) {
    if (!alive_[t]) continue;
    const Quality& q = quality_[t];
    ++count;
    bad += q.min_dihedral < options_.target_min_dihedral_deg;
    min_dih = std::min(min_dih, q.min_dihedral);
    max_dih = std::max(max_dih, q.max_dihedral);
    max_re = std::max(max_re, q.radius_edge);
  }
  if (count == 0) min_dih = 0;
  if (before) {
    stats_->tets_before = count;
    stats_->bad_before = bad;
    stats_->min_dihedral_before = min_dih;
    stats_->max_dihedral_before = max_dih;
    stats_->max_radius_edge_before = max_re;
  } else {
    stats_->tets_after = count;
    stats_->bad_after = bad;
    stats_->min_dihedral_after = min_dih;
    stats_->max_dihedral_after = max_dih;
    stats_->max_radius_edge_after = max_re;
  }
}

std::vector<Tet> FlipMesh::Output() const {
  std::vector<Tet> out;
  out.reserve(tet_.size());
  for (size_t t = 0; t < tet_.size(); ++t) {
    if (alive_[t]) out.push_back(tet_[t]);
  }
  return out;
}

}  // namespace

void SliverStats::ExportTo(mesh::MeshStats* out) const {
  out->Set("sliver.tets_before", static_cast<double>(tets_before));
  out->Set("sliver.tets_after", static_cast<double>(tets_after));
  out->Set("sliver.bad_before", static_cast<double>(bad_before));
  out->Set("sliver.bad_after", static_cast<double>(bad_after));
  out->Set("sliver.min_dihedral_before", min_dihedral_before);
  out->Set("sliver.min_dihedral_after", min_dihedral_after);
  out->Set("sliver.max_dihedral_before", max_dihedral_before);
  out->Set("sliver.max_dihedral_after", max_dihedral_after);
  out->Set("sliver.max_radius_edge_before", max_radius_edge_before);
  out->Set("sliver.max_radius_edge_after", max_radius_edge_after);
  out->Set("sliver.flips_23", static_cast<double>(flips_23));
  out->Set("sliver.flips_32", static_cast<double>(flips_32));
  out->Set("sliver.flips_44", static_cast<double>(flips_44));
  out->Set("sliver.passes", static_cast<double>(passes));
  out->Set("sliver.candidates", static_cast<double>(candidates));
  out->Set("sliver.rejected_orientation", static_cast<double>(rejected_orientation));
  out->Set("sliver.rejected_constraint", static_cast<double>(rejected_constraint));
  out->Set("sliver.rejected_radius_edge", static_cast<double>(rejected_radius_edge));
  out->Set("sliver.rejected_no_gain", static_cast<double>(rejected_no_gain));
  out->Set("sliver.stuck", static_cast<double>(stuck));
  out->Set("sliver.hit_flip_cap", hit_flip_cap ? 1 : 0);
  out->Set("sliver.seconds", seconds);
}

absl::StatusOr<SliverResult> RemoveSlivers(const SliverInput& input, const SliverOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  if (!(options.target_min_dihedral_deg >= 0) || !(options.max_radius_edge > 0)) {
    return absl::InvalidArgumentError("sliver: target must be >= 0 and the radius-edge bound > 0");
  }
  SliverResult result;
  FlipMesh mesh(input.positions, options, &result.stats);
  absl::Status s = mesh.Init(input);
  if (!s.ok()) return s;
  mesh.Summarize(/*before=*/true);
  mesh.Run();
  mesh.Summarize(/*before=*/false);
  s = mesh.CheckConstraints();
  if (!s.ok()) return absl::InternalError(absl::StrCat("sliver: after flipping: ", s.message()));
  result.tets = mesh.Output();
  result.stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

absl::StatusOr<SliverResult> RemoveSlivers(std::span<const geom::Vec3> positions,
                                           std::span<const std::array<uint32_t, 4>> tets,
                                           std::span<const ConstrainedFace> faces,
                                           std::span<const std::vector<uint32_t>> segment_chains,
                                           const SliverOptions& options) {
  std::vector<Tri> cfaces;
  cfaces.reserve(faces.size());
  for (const ConstrainedFace& f : faces) cfaces.push_back(f.v);
  std::vector<Edge> cedges;
  for (const std::vector<uint32_t>& chain : segment_chains) {
    for (size_t i = 0; i + 1 < chain.size(); ++i) cedges.push_back({chain[i], chain[i + 1]});
  }
  SliverInput in;
  in.positions = positions;
  in.tets = tets;
  in.constrained_faces = cfaces;
  in.constrained_edges = cedges;
  return RemoveSlivers(in, options);
}

}  // namespace svrc::refine
