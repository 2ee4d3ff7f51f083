// Sliver removal by flips: see sliver.h and docs/svrc-output.md "Sliver removal".
#include "core/svrc/sliver.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <queue>
#include <span>
#include <tuple>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "core/geometry/predicates.h"
#include "core/svrc/tet_faces.h"

namespace svrc::refine {
namespace {

using geom::Vec3;
using Tet = std::array<uint32_t, 4>;
using Tri = std::array<uint32_t, 3>;
using Edge = std::array<uint32_t, 2>;

constexpr uint32_t kNone = 0xFFFFFFFFu;
constexpr double kInf = std::numeric_limits<double>::infinity();
// A tet's six edges by vertex position; edge 5 − k joins the two vertices
// edge k misses.
constexpr int kTetEdge[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};

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
  double volume = 0;  // unsigned, floating point
  // False: the dihedral fields are not computed yet, and the tet is known to
  // have every dihedral angle strictly between the target and 180° − target
  // (FlipMesh::Init's volume test; FlipMesh::Dihedrals fills them on demand).
  bool dihedrals = true;
  // With dihedrals false: a lower bound on the smallest sin² of the six
  // angles (MeasureInput's, less a 1e-6 share, rounded down to a float, in
  // the struct's padding), from which FlipMesh::Summarize reads whether the
  // tet can hold an extreme.
  float sin2_lower = 0;
};
static_assert(sizeof(Quality) == 40);

// x ≥ 0 rounded down to a float.
float LowerFloat(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) > x) f = std::nextafter(f, 0.0f);
  return f;
}

void MeasureBounds(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, SliverTetQuality* out);
void MeasureDihedrals(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, SliverTetQuality* out);

// Measure in two halves for flip candidates: the bounds (radius-edge,
// volume; dihedral fields left 0), then, once every new tet of the flip has
// passed them, the dihedral angles. On cube --max-volume 1e-5 178k of the
// 690k candidate tets measured failed the radius-edge bound.
Quality MeasureBoundsOnly(std::span<const Vec3> pos, Tet t) {
  std::sort(t.begin(), t.end());
  SliverTetQuality q;
  MeasureBounds(pos[t[0]], pos[t[1]], pos[t[2]], pos[t[3]], &q);
  return Quality{0, 0, q.radius_edge, q.volume};
}
void FillDihedrals(std::span<const Vec3> pos, Tet t, Quality* out) {
  std::sort(t.begin(), t.end());
  SliverTetQuality q;
  MeasureDihedrals(pos[t[0]], pos[t[1]], pos[t[2]], pos[t[3]], &q);
  out->min_dihedral = q.min_dihedral_deg;
  out->max_dihedral = q.max_dihedral_deg;
  out->dihedrals = true;
}

// An input tet's quality, its dihedral angles left for later when its volume
// alone shows them all in (target, 180° − target): a dihedral θ at edge e
// between faces of areas A1, A2 gives 6|V| = 4·A1·A2·sin θ / |e| ≤ ℓ³ sin θ
// (each face's height over e is at most the longest edge ℓ), so
// 6|V| > ℓ³ · sin_target implies sin θ > sin(target) for all six. The factor
// 1 + 1e-6 keeps the rounding of |V| and ℓ³ (~1e-15 relative) on the safe
// side, far beyond the error of the angles themselves: a tet skipped here
// would have measured strictly above the target. On cube --max-volume 1e-5
// most input tets pass; the angles were 3% of the run's instructions.
Quality MeasureInput(std::span<const Vec3> pos, Tet t, double sin_target) {
  std::sort(t.begin(), t.end());
  SliverTetQuality q;
  const Vec3& a = pos[t[0]];
  const Vec3& b = pos[t[1]];
  const Vec3& c = pos[t[2]];
  const Vec3& d = pos[t[3]];
  MeasureBounds(a, b, c, d, &q);
  Quality out{0, 0, q.radius_edge, q.volume};
  if (sin_target > 0) {
    const Vec3 p[4] = {a, b, c, d};
    double e2[6], longest2 = 0;
    for (int k = 0; k < 6; ++k) {
      e2[k] = geom::Dist2(p[kTetEdge[k][0]], p[kTetEdge[k][1]]);
      longest2 = std::max(longest2, e2[k]);
    }
    if (6 * q.volume > longest2 * std::sqrt(longest2) * sin_target * (1 + 1e-6)) {
      out.dihedrals = false;
      const double sin_lower = 6 * q.volume / (longest2 * std::sqrt(longest2));
      out.sin2_lower = LowerFloat(sin_lower * sin_lower * (1 - 1e-6));
      return out;
    }
    // The exact sines (session 41): at edge e between faces with normals n1,
    // n2 (cross products of two of their edges, |n| = twice the area),
    // sin θ = 6|V|·|e| / (|n1|·|n2|). Squared, without a root: every
    // 36V²·|e|² > sin²(target)·(1 + 1e-6)·|n1|²·|n2|² puts all six in
    // (target, 180° − target). The bound above passes ~60% of a volume-bound
    // run's tets; this one nearly all the rest that are not near the target
    // (cube --max-volume 1e-5: dihedrals measured for 76,454 input tets
    // before it).
    const Vec3 u = b - a, v = c - a, w = d - a;
    const double det = geom::Dot(u, geom::Cross(v, w));
    // Face normals, by the vertex opposite: 0 (bcd), 1 (acd), 2 (abd), 3 (abc).
    const double nn[4] = {geom::Norm2(geom::Cross(c - b, d - b)), geom::Norm2(geom::Cross(v, w)),
                          geom::Norm2(geom::Cross(u, w)), geom::Norm2(geom::Cross(u, v))};
    const double lhs = det * det;
    const double rhs = sin_target * sin_target * (1 + 1e-6);
    bool all = std::isfinite(lhs) && lhs > 0;
    // Edge k lies on the faces opposite the two vertices it misses (edge 5 − k).
    for (int k = 0; k < 6 && all; ++k) all = lhs * e2[k] > rhs * nn[kTetEdge[5 - k][0]] * nn[kTetEdge[5 - k][1]];
    if (all) {
      out.dihedrals = false;
      double sin2 = kInf;
      for (int k = 0; k < 6; ++k) sin2 = std::min(sin2, lhs * e2[k] / (nn[kTetEdge[5 - k][0]] * nn[kTetEdge[5 - k][1]]));
      out.sin2_lower = std::isfinite(sin2) ? LowerFloat(sin2 * (1 - 1e-6)) : 0;
      return out;
    }
  }
  MeasureDihedrals(a, b, c, d, &q);
  out.min_dihedral = q.min_dihedral_deg;
  out.max_dihedral = q.max_dihedral_deg;
  return out;
}

// The smallest sin² of tet t's six dihedral angles, by MeasureInput's exact
// sines (sin θ = 6|V|·|e| / (|n1|·|n2|) at edge e), no atan2; 0 when not
// finite (a degenerate face). Summarize's lazy tets: one whose value exceeds
// sin²φ · (1 + 1e-6) has every angle in (φ, 180° − φ), with MeasureInput's
// margin over the rounding.
double MinSin2(std::span<const Vec3> pos, const Tet& t) {
  const Vec3& a = pos[t[0]];
  const Vec3& b = pos[t[1]];
  const Vec3& c = pos[t[2]];
  const Vec3& d = pos[t[3]];
  const Vec3 p[4] = {a, b, c, d};
  const Vec3 u = b - a, v = c - a, w = d - a;
  const double det = geom::Dot(u, geom::Cross(v, w));
  const double nn[4] = {geom::Norm2(geom::Cross(c - b, d - b)), geom::Norm2(geom::Cross(v, w)),
                        geom::Norm2(geom::Cross(u, w)), geom::Norm2(geom::Cross(u, v))};
  double best = kInf;
  for (int k = 0; k < 6; ++k) {
    const double e2 = geom::Dist2(p[kTetEdge[k][0]], p[kTetEdge[k][1]]);
    best = std::min(best, det * det * e2 / (nn[kTetEdge[5 - k][0]] * nn[kTetEdge[5 - k][1]]));
  }
  return std::isfinite(best) ? best : 0;
}

// Edge removal (Shewchuk, "Two discrete optimization algorithms for the
// topological improvement of tetrahedral meshes", 2002) handles rings of up
// to kMaxRing tets around an edge: 3-2 (n = 3), 4-4 (n = 4), 5-6, 6-8, 7-10.
// Klingner & Shewchuk found larger rings rarely help.
constexpr int kMaxRing = 7;
constexpr int kMaxNew = 2 * (kMaxRing - 2);
// Dense index of the ring triangles (a, c, b), a < c < b < kMaxRing: the
// edge removal keeps the qualities of C(7, 3) = 35 of them, not of a 7×7×7
// cube (whose construction zeroed 22 KB per candidate edge: 4% of the
// instructions of cube --max-volume 1e-4).
constexpr int kMaxRingTris = kMaxRing * (kMaxRing - 1) * (kMaxRing - 2) / 6;
constexpr auto kRingTri = [] {
  std::array<std::array<std::array<uint8_t, kMaxRing>, kMaxRing>, kMaxRing> idx{};
  int k = 0;
  for (int a = 0; a < kMaxRing; ++a) {
    for (int c = a + 1; c < kMaxRing; ++c) {
      for (int b = c + 1; b < kMaxRing; ++b) idx[a][c][b] = static_cast<uint8_t>(k++);
    }
  }
  return idx;
}();

// A flip under evaluation: the tets it replaces and the ones it creates.
struct Flip {
  int ring = 0;  // 0: a 2-3 flip; n >= 3: removal of an edge with n tets around it
  std::array<uint32_t, kMaxRing> old_tets{};
  int num_old = 0;
  std::array<Tet, kMaxNew> new_tets{};
  std::array<Quality, kMaxNew> new_quality{};
  int num_new = 0;
  double new_min = -kInf;  // worst smallest dihedral among the new tets
  double old_min = kInf;   // worst smallest dihedral among the replaced tets

  bool Replaces(uint32_t t) const {
    for (int i = 0; i < num_old; ++i) {
      if (old_tets[i] == t) return true;
    }
    return false;
  }
};

// What a tentative flip changed, to undo it (the lookahead of Run).
struct Journal {
  struct Saved {
    uint32_t slot;
    Tet tet;
    std::array<uint32_t, 4> nbr;
    Quality quality;
    uint32_t version;
    uint32_t component;
    uint8_t alive;
  };
  size_t num_slots = 0;  // tet_.size() before
  size_t free_size = 0;
  std::vector<uint32_t> free_tail;  // the last entries of free_ before
  std::vector<Saved> saved;         // slot states before their first change
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
  // After the flips: the per-slot work arrays (qualities, versions,
  // components) go before the outputs are built.
  void ReleaseWorkArrays() {
    std::vector<Quality>().swap(quality_);
    std::vector<uint32_t>().swap(version_);
    std::vector<uint32_t>().swap(component_);
    std::vector<double>().swap(component_max_volume_);
  }
  // The adjacency of Output()'s tets, by their index there
  // (SliverResult::neighbors).
  std::vector<std::array<uint32_t, 4>> OutputNeighbors() const;
  void Summarize(bool before);

 private:
  // Vertex -> live tets (StarsOf) for the first vertices of the constraints.
  VertexStars BuildConstraintStars() const;
  // CheckConstraints on stars already built for the current tets.
  absl::Status CheckConstraints(const VertexStars& stars) const;
  bool FaceConstrained(const Tri& f) const {
    return std::binary_search(cfaces_.begin(), cfaces_.end(), f);
  }
  bool EdgeConstrained(uint32_t a, uint32_t b) const {
    return std::binary_search(cedges_.begin(), cedges_.end(), SortedEdge(a, b));
  }
  uint32_t Allocate(Journal* journal);
  void Save(uint32_t slot, Journal* journal) const;
  void Undo(const Journal& journal);
  void Push(uint32_t t);
  // Ring of tets around edge (p, q) of tet t: ring vertices u_0..u_{k-1} with
  // (p, q, u_i, u_{i+1}) the positively oriented tet ring_tets[i]. False when
  // the ring is open (the edge is on the hull) or has more than max_size tets.
  bool Ring(uint32_t t, uint32_t p, uint32_t q, int max_size, std::array<uint32_t, kMaxRing>* ring_tets,
            std::array<uint32_t, kMaxRing>* ring_verts, int* size) const;
  // Whether a would-be new tet is strictly positive (exact Orient3d) and
  // within the radius-edge / volume bounds (`re_bound`, `volume_bound`);
  // fills the bounds half of its quality (the caller adds the dihedral
  // angles with FillDihedrals once all new tets of the flip passed).
  enum Reject { kOk = 0, kOrientation, kRadiusEdge, kVolume };
  Reject NewTet(const Tet& t, double re_bound, double volume_bound, Quality* q) const;
  // The 2-3 flip across face f of t, and the best removal of the edge
  // (v[i], v[j]) of t. False when the flip is illegal (constraint, orientation,
  // bounds); otherwise new_min/old_min are filled. The edge removal may also
  // return false when its best new_min would be <= floor (or <= its old_min,
  // with above_old): the caller rejects those, and the triangles that cannot
  // be part of any other triangulation are not measured in full.
  bool Build23(uint32_t t, int f, Flip* flip);
  bool BuildEdgeRemoval(uint32_t t, int i, int j, double floor, bool above_old, Flip* flip);
  // Every legal flip replacing t (2-3 across its faces, removal of its edges),
  // in a fixed order; edge removals the caller rejects for new_min <= floor()
  // (or <= their old_min, with above_old) may be left out. floor() is read
  // before each edge removal: a caller that keeps the best flip so far raises
  // it as it goes.
  template <typename Floor, typename Fn>
  void ForEachFlip(uint32_t t, bool above_old, Floor&& floor, Fn&& fn);
  // The legal flip replacing t with the largest new_min, among those with
  // new_min > max(floor, their own old_min). False if none.
  bool BestFlip(uint32_t t, double floor, Flip* best);
  bool RaisesCreaseAngle(const Flip& f) const;
  bool TouchesCrease(const Tet& t) const;  // a vertex flagged in options_.crease_vertex (non-empty)
  void Apply(const Flip& flip, std::vector<uint32_t>* created, Journal* journal);
  void Count(const Flip& flip);
  // Search for a stuck tet t: flips of nearby tets (not t) whose new tets are
  // all better than `floor` (t's quality), up to depth − 1 of them, after
  // which t has an improving flip. The best sequence (largest worst new
  // quality) goes to `seq`; the mesh is left as it was.
  bool Search(uint32_t t, int depth, double floor, std::vector<Flip>* seq, double* score);
  // An input tet outside the output (SliverOptions::skip_tet) that no flip
  // replaced (version 0): not queued, not measured, not in the stats.
  bool Skipped(uint32_t t) const {
    return t < options_.skip_tet.size() && options_.skip_tet[t] != 0 && version_[t] == 0;
  }
  // quality_[t] with its dihedral angles (computed now if Init left them).
  const Quality& Dihedrals(uint32_t t) const {
    Quality& q = quality_[t];
    if (!q.dihedrals) FillDihedrals(pos_, tet_[t], &q);
    return q;
  }

  std::span<const Vec3> pos_;
  const SliverOptions& options_;
  SliverStats* stats_;
  std::vector<Tet> tet_;
  std::vector<std::array<uint32_t, 4>> nbr_;
  mutable std::vector<Quality> quality_;  // dihedrals filled on demand (Dihedrals)
  std::vector<uint32_t> version_;
  std::vector<uint8_t> alive_;
  std::vector<uint32_t> component_;            // per slot
  std::vector<double> component_max_volume_;   // largest input tet volume per component
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

absl::Status FlipMesh::Init(const SliverInput& in) {
  const size_t n = pos_.size();
  const size_t num_tets = in.tets.size();
  if (num_tets >= kNone / 8) return absl::InvalidArgumentError("sliver: too many tets");
  tet_.assign(in.tets.begin(), in.tets.end());
  if (in.neighbors == nullptr) nbr_.assign(num_tets, {kNone, kNone, kNone, kNone});
  quality_.resize(num_tets);
  version_.assign(num_tets, 0);
  // Lazy angles need 0 < target < 90° (sin is increasing there).
  const double target = options_.target_min_dihedral_deg;
  const double sin_target = target > 0 && target < 90 ? std::sin(target * (3.14159265358979323846 / 180)) : 0;
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
    // Exactly flat tets (Orient3d = 0) are accepted: a Delaunay kernel with
    // symbolic perturbation can leave them where points are exactly coplanar
    // (∂Ω). A flip only ever replaces them by strictly positive tets with the
    // same boundary, which still tile the same region.
    if (geom::Orient3d(pos_[v[0]], pos_[v[1]], pos_[v[2]], pos_[v[3]]) < 0) {
      return absl::InvalidArgumentError(absl::StrCat("sliver: tet ", t, " is negatively oriented"));
    }
    // A skipped tet (outside the output) is never queued, never part of a
    // flip (none crosses a constrained face) and not in the stats: not
    // measured (its Quality stays default).
    if (!Skipped(static_cast<uint32_t>(t))) quality_[t] = MeasureInput(pos_, v, sin_target);
  }
  // Adjacency: the 4T faces grouped by their vertex sets, as LabelRegions
  // does (tet_faces.h: no hashing, no sort of all 4T records, which took ~5%
  // of a volume-bound run). Same pairs and the same error (the smallest face
  // in > 2 tets) as sorting all records by (key, tet, face). Kept until the
  // constrained faces are marked below.
  // A mesher's own adjacency (SliverInput::neighbors) replaces the table:
  // ids in range, and the constrained faces found in the stars of their
  // smallest vertices (the same (tet, face) records as the table's buckets).
  std::optional<TetFaces> tet_faces;
  if (in.neighbors != nullptr) {
    if (in.neighbors->size() != num_tets) {
      return absl::InvalidArgumentError(
          absl::StrCat("sliver: ", in.neighbors->size(), " neighbour rows for ", num_tets, " tets"));
    }
    nbr_ = std::move(*in.neighbors);
    in.neighbors->clear();
    // In range; the rest is trusted (a symmetry check reading each
    // neighbour's row cost as much as the table saved at cube 1e-6).
    for (uint32_t t = 0; t < num_tets; ++t) {
      for (int f = 0; f < 4; ++f) {
        const uint32_t m = nbr_[t][f];
        if (m != kNone && (m >= num_tets || m == t)) {
          return absl::InvalidArgumentError(absl::StrCat("sliver: tet ", t, " face ", f, " has neighbour ", m));
        }
      }
    }
  } else {
    tet_faces.emplace(std::span<const Tet>(tet_), n);
    TetFaces::Overused bad;
    if (!tet_faces->Match(
            [&](uint32_t s, uint32_t t) {
              nbr_[s / 4][s % 4] = t / 4;
              nbr_[t / 4][t % 4] = s / 4;
            },
            &bad)) {
      return absl::InvalidArgumentError(
          absl::StrCat("sliver: face (", bad.a, ", ", bad.b, ", ", bad.c, ") is in ", bad.count, " tets"));
    }
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
  // Constrained faces per tet (bit f: the face opposite f), found in the
  // bucket of their smallest vertex: the flood below then tests a bit, not
  // FaceKey + a binary search over cfaces_ for each of the 4T faces. A face
  // that is not in the mesh marks nothing (CheckConstraints reports it).
  // The constrained faces of one smallest vertex a (a sorted run of
  // cfaces_) are scanned for in a's bucket, or with more than
  // kConstraintScanRun of them the bucket is read once and its faces looked
  // up in the run (tet_faces.h; crease_pair_0.1deg's 10 M-vertex output was
  // in this pass's constraint lookups when stopped after 9 minutes).
  std::vector<uint8_t> constrained(num_tets, 0);
  auto mark = [&](const TetFace& f) { constrained[f.slot / 4] |= static_cast<uint8_t>(1u << (f.slot % 4)); };
  // The stars of the constraints' first vertices, built once for both uses:
  // without the table, a's faces there with a smallest stand in for its
  // bucket; CheckConstraints reads them (with the table, built after it is
  // freed).
  const bool table = tet_faces.has_value();
  VertexStars stars;
  if (!table) stars = BuildConstraintStars();
  std::vector<TetFace> bucket;
  auto bucket_of = [&](uint32_t a) -> std::span<const TetFace> {
    if (table) return tet_faces->Bucket(a);
    StarBucket(tet_, stars, a, &bucket);
    return bucket;
  };
  for (size_t i = 0; i < cfaces_.size();) {
    const uint32_t a = cfaces_[i][0];
    size_t j = i;
    while (j < cfaces_.size() && cfaces_[j][0] == a) ++j;
    const std::span<const TetFace> faces_at_a = bucket_of(a);
    if (j - i <= kConstraintScanRun) {
      for (size_t r = i; r < j; ++r) {
        for (const TetFace& f : faces_at_a) {
          if (f.b == cfaces_[r][1] && f.c == cfaces_[r][2]) mark(f);
        }
      }
    } else {
      for (const TetFace& f : faces_at_a) {
        if (std::binary_search(cfaces_.begin() + i, cfaces_.begin() + j, Tri{a, f.b, f.c})) mark(f);
      }
    }
    i = j;
  }
  tet_faces.reset();
  std::vector<TetFace>().swap(bucket);
  if (table) stars = BuildConstraintStars();
  absl::Status s = CheckConstraints(stars);
  if (!s.ok()) return s;
  stars = {};
  // Components: flood fill across non-constrained faces, in tet order.
  component_.assign(num_tets, kNone);
  std::vector<uint32_t> stack;
  for (uint32_t seed = 0; seed < num_tets; ++seed) {
    if (component_[seed] != kNone) continue;
    const uint32_t c = static_cast<uint32_t>(component_max_volume_.size());
    component_max_volume_.push_back(0);
    component_[seed] = c;
    stack.push_back(seed);
    while (!stack.empty()) {
      const uint32_t t = stack.back();
      stack.pop_back();
      component_max_volume_[c] = std::max(component_max_volume_[c], quality_[t].volume);
      for (int f = 0; f < 4; ++f) {
        const uint32_t n = nbr_[t][f];
        if (n == kNone || component_[n] != kNone || ((constrained[t] >> f) & 1)) continue;
        component_[n] = c;
        stack.push_back(n);
      }
    }
  }
  return absl::OkStatus();
}

VertexStars FlipMesh::BuildConstraintStars() const {
  if (cfaces_.empty() && cedges_.empty()) return {};
  std::vector<uint8_t> needed(pos_.size(), 0);
  for (const Tri& f : cfaces_) needed[f[0]] = 1;
  for (const Edge& e : cedges_) needed[e[0]] = 1;
  return StarsOf(tet_, pos_.size(), needed, alive_);
}

absl::Status FlipMesh::CheckConstraints() const { return CheckConstraints(BuildConstraintStars()); }

absl::Status FlipMesh::CheckConstraints(const VertexStars& stars) const {
  // Each constraint is looked up in the star of its first vertex.
  // O(T + constraints · degree), no sort.
  if (cfaces_.empty() && cedges_.empty()) return absl::OkStatus();
  const std::vector<uint32_t>& start = stars.start;
  const std::vector<uint32_t>& star = stars.tet;
  // The constraints whose first vertex is a (sorted runs of cfaces_ and
  // cedges_) are each scanned for in a's star, or with more than
  // kConstraintScanRun of them the star is read once and the faces and edges
  // of its tets at a are looked up in the runs (tet_faces.h;
  // crease_pair_0.1deg was here when stopped after 9 minutes). The first
  // one missing in sorted order is reported.
  auto has = [&](const Tet& t, uint32_t v) { return t[0] == v || t[1] == v || t[2] == v || t[3] == v; };
  std::vector<uint8_t> face_found(cfaces_.size(), 0), edge_found(cedges_.size(), 0);
  for (size_t i = 0, ie = 0; i < cfaces_.size() || ie < cedges_.size();) {
    const uint32_t a = std::min(i < cfaces_.size() ? cfaces_[i][0] : UINT32_MAX,
                                ie < cedges_.size() ? cedges_[ie][0] : UINT32_MAX);
    size_t j = i, je = ie;
    while (j < cfaces_.size() && cfaces_[j][0] == a) ++j;
    while (je < cedges_.size() && cedges_[je][0] == a) ++je;
    if ((j - i) + (je - ie) <= kConstraintScanRun) {
      for (size_t r = i; r < j; ++r) {
        for (uint32_t k = start[a]; k < start[a + 1] && !face_found[r]; ++k) {
          face_found[r] = has(tet_[star[k]], cfaces_[r][1]) && has(tet_[star[k]], cfaces_[r][2]);
        }
      }
      for (size_t r = ie; r < je; ++r) {
        for (uint32_t k = start[a]; k < start[a + 1] && !edge_found[r]; ++k) {
          edge_found[r] = has(tet_[star[k]], cedges_[r][1]);
        }
      }
      i = j;
      ie = je;
      continue;
    }
    for (uint32_t k = start[a]; k < start[a + 1]; ++k) {
      const Tet& t = tet_[star[k]];
      std::array<uint32_t, 3> other;  // t's vertices but a, ascending
      for (int m = 0, o = 0; m < 4; ++m) {
        if (t[m] != a) other[o++] = t[m];
      }
      std::sort(other.begin(), other.end());
      for (int x = 0; x < 3; ++x) {
        // Faces and edges keyed by their sorted vertices: a is their smallest
        // exactly when it is below the others.
        if (other[x] > a && ie < je) {
          const auto e = std::lower_bound(cedges_.begin() + ie, cedges_.begin() + je, Edge{a, other[x]});
          if (e != cedges_.begin() + je && *e == Edge{a, other[x]}) edge_found[e - cedges_.begin()] = 1;
        }
        for (int y = x + 1; y < 3 && i < j; ++y) {
          if (other[x] < a) continue;
          const Tri key{a, other[x], other[y]};
          const auto f = std::lower_bound(cfaces_.begin() + i, cfaces_.begin() + j, key);
          if (f != cfaces_.begin() + j && *f == key) face_found[f - cfaces_.begin()] = 1;
        }
      }
    }
    i = j;
    ie = je;
  }
  for (size_t i = 0; i < cfaces_.size(); ++i) {
    if (face_found[i]) continue;
    const Tri& f = cfaces_[i];
    return absl::InvalidArgumentError(
        absl::StrCat("sliver: constrained face (", f[0], ", ", f[1], ", ", f[2], ") is not a face of the mesh"));
  }
  for (size_t i = 0; i < cedges_.size(); ++i) {
    if (edge_found[i]) continue;
    const Edge& e = cedges_[i];
    return absl::InvalidArgumentError(
        absl::StrCat("sliver: constrained edge (", e[0], ", ", e[1], ") is not an edge of the mesh"));
  }
  return absl::OkStatus();
}

uint32_t FlipMesh::Allocate(Journal* journal) {
  uint32_t t;
  if (!free_.empty()) {
    t = free_.back();
    free_.pop_back();
    Save(t, journal);
  } else {
    t = static_cast<uint32_t>(tet_.size());
    tet_.push_back({});
    nbr_.push_back({kNone, kNone, kNone, kNone});
    quality_.push_back({});
    version_.push_back(0);
    alive_.push_back(0);
    component_.push_back(0);
  }
  ++version_[t];
  alive_[t] = 1;
  return t;
}

void FlipMesh::Save(uint32_t slot, Journal* journal) const {
  if (journal == nullptr || slot >= journal->num_slots) return;  // new slots are truncated on undo
  journal->saved.push_back(
      Journal::Saved{slot, tet_[slot], nbr_[slot], quality_[slot], version_[slot], component_[slot], alive_[slot]});
}

void FlipMesh::Undo(const Journal& journal) {
  for (auto it = journal.saved.rbegin(); it != journal.saved.rend(); ++it) {
    tet_[it->slot] = it->tet;
    nbr_[it->slot] = it->nbr;
    quality_[it->slot] = it->quality;
    version_[it->slot] = it->version;
    component_[it->slot] = it->component;
    alive_[it->slot] = it->alive;
  }
  tet_.resize(journal.num_slots);
  nbr_.resize(journal.num_slots);
  quality_.resize(journal.num_slots);
  version_.resize(journal.num_slots);
  alive_.resize(journal.num_slots);
  component_.resize(journal.num_slots);
  free_.resize(journal.free_size - journal.free_tail.size());
  free_.insert(free_.end(), journal.free_tail.begin(), journal.free_tail.end());
}

void FlipMesh::Push(uint32_t t) {
  if (Skipped(t)) return;
  if (!quality_[t].dihedrals) return;  // every angle above the target
  if (quality_[t].min_dihedral < options_.target_min_dihedral_deg) {
    queue_.emplace(quality_[t].min_dihedral, t, version_[t]);
  }
}

bool FlipMesh::Ring(uint32_t t, uint32_t p, uint32_t q, int max_size, std::array<uint32_t, kMaxRing>* ring_tets,
                    std::array<uint32_t, kMaxRing>* ring_verts, int* size) const {
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

FlipMesh::Reject FlipMesh::NewTet(const Tet& t, double re_bound, double volume_bound, Quality* q) const {
  if (geom::Orient3d(pos_[t[0]], pos_[t[1]], pos_[t[2]], pos_[t[3]]) <= 0) return kOrientation;
  *q = MeasureBoundsOnly(pos_, t);
  if (!(q->radius_edge <= re_bound)) return kRadiusEdge;
  if (!options_.crease_vertex.empty() && q->radius_edge > options_.max_radius_edge && !TouchesCrease(t)) {
    return kRadiusEdge;
  }
  if (options_.keep_max_volume && !(q->volume <= volume_bound)) return kVolume;
  return kOk;
}

void CountReject(int why, SliverStats* stats) {
  switch (why) {
    case 1: ++stats->rejected_orientation; break;
    case 2: ++stats->rejected_radius_edge; break;
    case 3: ++stats->rejected_volume; break;
    default: break;
  }
}

bool FlipMesh::Build23(uint32_t t, int f, Flip* flip) {
  const uint32_t n = nbr_[t][f];
  if (n == kNone) return false;  // a hull face
  ++stats_->candidates;
  const Tet v = tet_[t];
  const Tri face = FaceKey(v, f);
  if (FaceConstrained(face)) {
    ++stats_->rejected_constraint;
    return false;
  }
  const Tet& w = tet_[n];
  uint32_t e = kNone;
  for (int i = 0; i < 4; ++i) {
    if (w[i] != face[0] && w[i] != face[1] && w[i] != face[2]) e = w[i];
  }
  // t = (.., d = v[f], ..) and its neighbour n with apex e. Replacing, in
  // turn, each vertex of the shared face by e gives the three tets around the
  // new edge de; each is positive iff e lies on the same side as the replaced
  // vertex, i.e. iff segment de crosses the face's interior.
  flip->ring = 0;
  flip->old_tets[0] = t;
  flip->old_tets[1] = n;
  flip->num_old = 2;
  flip->old_min = std::min(Dihedrals(t).min_dihedral, Dihedrals(n).min_dihedral);
  const double re_bound =
      std::max(options_.max_radius_edge, std::max(quality_[t].radius_edge, quality_[n].radius_edge));
  const double volume_bound = component_max_volume_[component_[t]];
  flip->num_new = 0;
  flip->new_min = kInf;
  for (int i = 0; i < 4; ++i) {
    if (i == f) continue;
    Tet nt = v;
    nt[i] = e;
    Quality q;
    const Reject why = NewTet(nt, re_bound, volume_bound, &q);
    if (why != kOk) {
      CountReject(why, stats_);
      return false;
    }
    flip->new_tets[flip->num_new] = nt;
    flip->new_quality[flip->num_new++] = q;
  }
  for (int i = 0; i < flip->num_new; ++i) {
    FillDihedrals(pos_, flip->new_tets[i], &flip->new_quality[i]);
    flip->new_min = std::min(flip->new_min, flip->new_quality[i].min_dihedral);
  }
  return true;
}

bool FlipMesh::BuildEdgeRemoval(uint32_t t, int i, int j, double floor, bool above_old, Flip* flip) {
  const uint32_t p = tet_[t][i], q = tet_[t][j];
  std::array<uint32_t, kMaxRing> ring_tets{}, u{};
  int n = 0;
  if (!Ring(t, p, q, kMaxRing, &ring_tets, &u, &n)) return false;  // hull edge or ring too large
  if (n < 3) return false;                                          // not in a valid mesh
  ++stats_->candidates;
  bool blocked = EdgeConstrained(p, q);
  for (int k = 0; k < n && !blocked; ++k) blocked = FaceConstrained(SortedTri(p, q, u[k]));
  if (blocked) {
    ++stats_->rejected_constraint;
    return false;
  }
  double old_min = kInf, re_bound = options_.max_radius_edge;
  for (int k = 0; k < n; ++k) {
    old_min = std::min(old_min, Dihedrals(ring_tets[k]).min_dihedral);
    re_bound = std::max(re_bound, quality_[ring_tets[k]].radius_edge);
  }
  const double volume_bound = component_max_volume_[component_[t]];
  // A triangle whose tets' worst angle is <= prune can be in no triangulation
  // the caller accepts. Leaving it out (−∞) changes no value above prune in
  // the program below, nor which split attains it (ties: the smallest c), so
  // an accepted flip comes out the same; its second tet's angles are then
  // not measured once the first's are <= prune.
  const double prune =
      !options_.prune_edge_removals ? -kInf : above_old ? std::max(floor, old_min) : floor;
  // The ring's oriented boundary is +[q, u_k, u_k+1] and −[p, u_k, u_k+1].
  // For a triangulation of the ring polygon u_0..u_{n-1} (triangles in ring
  // order), the tets (a, b, c, q) and (b, a, c, p) over its triangles have the
  // same boundary; positive tets with the boundary of the old ones tile
  // exactly their union. Best triangulation (largest worst quality) by
  // dynamic programming over polygon intervals (Shewchuk 2002, Klincsek 1980):
  // best[a][b] = max over a < c < b of min(best[a][c], best[c][b], tri(a, c, b)).
  // Triangles are measured on demand (tri), each at most once: first those on
  // the edge u_0 u_{n-1}, one of which every triangulation holds (none valid:
  // no flip, the common case), then only where the program below could use
  // the value: min(best[a][c], best[c][b]) above both the interval's best so
  // far and prune (otherwise the candidate loses whatever the triangle is).
  Quality tri_q[kMaxRingTris][2];
  double tri_v[kMaxRingTris];
  uint64_t tri_done = 0;  // bit kRingTri[a][c][b]: tri_v measured
  static_assert(kMaxRingTris <= 64);
  int worst_reject = kOk;
  bool pruned = false;
  auto tri = [&](int a, int c, int b) -> double {
    const int k = kRingTri[a][c][b];
    if ((tri_done >> k) & 1) return tri_v[k];
    tri_done |= uint64_t{1} << k;
    tri_v[k] = -kInf;
    const Tet up{u[a], u[c], u[b], q}, down{u[c], u[a], u[b], p};
    Quality* tq = tri_q[k];
    const Reject r1 = NewTet(up, re_bound, volume_bound, &tq[0]);
    const Reject r2 = r1 == kOk ? NewTet(down, re_bound, volume_bound, &tq[1]) : kOk;
    if (r1 != kOk || r2 != kOk) {
      worst_reject = std::max(worst_reject, static_cast<int>(r1 != kOk ? r1 : r2));
      return tri_v[k];
    }
    FillDihedrals(pos_, up, &tq[0]);
    if (!(tq[0].min_dihedral > prune)) {
      pruned = true;
      ++stats_->pruned_triangles;
      return tri_v[k];
    }
    FillDihedrals(pos_, down, &tq[1]);
    tri_v[k] = std::min(tq[0].min_dihedral, tq[1].min_dihedral);
    return tri_v[k];
  };
  if (!options_.prune_edge_removals) {  // the reference: every triangle measured
    for (int a = 0; a < n; ++a) {
      for (int c = a + 1; c < n; ++c) {
        for (int b = c + 1; b < n; ++b) tri(a, c, b);
      }
    }
  }
  bool base = false;
  for (int c = 1; c + 1 < n && !base; ++c) base = tri(0, c, n - 1) > -kInf;
  double best[kMaxRing][kMaxRing];
  int arg[kMaxRing][kMaxRing];
  best[0][n - 1] = -kInf;
  for (int len = 1; len < n && base; ++len) {
    for (int a = 0; a + len < n; ++a) {
      const int b = a + len;
      if (len == 1) {
        best[a][b] = kInf;
        arg[a][b] = -1;
        continue;
      }
      best[a][b] = -kInf;
      arg[a][b] = -1;
      for (int c = a + 1; c < b; ++c) {
        const double sub = std::min(best[a][c], best[c][b]);
        if (!(sub > std::max(best[a][b], prune))) {
          pruned = pruned || (sub > -kInf && !(sub > prune));  // for the rejection's count only
          continue;
        }
        const double v = std::min(sub, tri(a, c, b));
        if (v > best[a][b]) {  // ties: the smallest c
          best[a][b] = v;
          arg[a][b] = c;
        }
      }
    }
  }
  if (!(best[0][n - 1] > -kInf)) {
    if (worst_reject == kOk && pruned) {
      ++stats_->rejected_no_gain;
    } else {
      CountReject(worst_reject == kOk ? kOrientation : worst_reject, stats_);
    }
    return false;
  }
  flip->ring = n;
  flip->num_old = n;
  for (int k = 0; k < n; ++k) flip->old_tets[k] = ring_tets[k];
  flip->old_min = old_min;
  flip->new_min = best[0][n - 1];
  flip->num_new = 0;
  int stack[kMaxRing][2];
  int top = 0;
  stack[top][0] = 0;
  stack[top++][1] = n - 1;
  while (top > 0) {
    --top;
    const int a = stack[top][0], b = stack[top][1];
    const int c = arg[a][b];
    if (c < 0) continue;
    flip->new_tets[flip->num_new] = {u[a], u[c], u[b], q};
    flip->new_quality[flip->num_new++] = tri_q[kRingTri[a][c][b]][0];  // measured: c = arg[a][b]
    flip->new_tets[flip->num_new] = {u[c], u[a], u[b], p};
    flip->new_quality[flip->num_new++] = tri_q[kRingTri[a][c][b]][1];
    stack[top][0] = a;
    stack[top++][1] = c;
    stack[top][0] = c;
    stack[top++][1] = b;
  }
  return true;
}

template <typename Floor, typename Fn>
void FlipMesh::ForEachFlip(uint32_t t, bool above_old, Floor&& floor, Fn&& fn) {
  for (int f = 0; f < 4; ++f) {
    Flip flip;
    if (Build23(t, f, &flip)) fn(flip);
  }
  static constexpr int kEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  for (const auto& ij : kEdges) {
    Flip flip;
    if (BuildEdgeRemoval(t, ij[0], ij[1], floor(), above_old, &flip)) fn(flip);
  }
}

// The stitched stars and books keep the dihedral bound of docs/svrc-collars.md
// §1: a flip may not give a tet touching a crease a larger dihedral than the
// largest of the replaced tets that touch a crease (measured before this
// test: crease_pair 10°'s largest dihedral next to the creases went from
// 156.4° stitched to 165.4° after the flips). Only those: a flip also
// replacing a sliver away from the creases (dihedral up to 178.6°) made a
// star of 140.5° into a tet of 146.8° at a floating triangle's corner
// (session 36, random "float" input seed 4).
bool FlipMesh::TouchesCrease(const Tet& t) const {
  const std::vector<uint8_t>& c = options_.crease_vertex;
  return c[t[0]] || c[t[1]] || c[t[2]] || c[t[3]];
}

bool FlipMesh::RaisesCreaseAngle(const Flip& f) const {
  if (options_.crease_vertex.empty()) return false;
  double old_max = 0;
  for (int i = 0; i < f.num_old; ++i) {
    if (TouchesCrease(tet_[f.old_tets[i]])) old_max = std::max(old_max, Dihedrals(f.old_tets[i]).max_dihedral);
  }
  for (int i = 0; i < f.num_new; ++i) {
    if (f.new_quality[i].max_dihedral > old_max && TouchesCrease(f.new_tets[i])) return true;
  }
  return false;
}

bool FlipMesh::BestFlip(uint32_t t, double floor, Flip* best) {
  bool found = false;
  // A flip is taken only above floor, its old_min and the best so far.
  auto prune = [&] { return found ? std::max(floor, best->new_min) : floor; };
  ForEachFlip(t, /*above_old=*/true, prune, [&](const Flip& f) {
    if (!(f.new_min > f.old_min) || !(f.new_min > floor)) {
      ++stats_->rejected_no_gain;
      return;
    }
    if (RaisesCreaseAngle(f)) {
      ++stats_->rejected_crease_angle;
      return;
    }
    if (!found || f.new_min > best->new_min) {
      *best = f;
      found = true;
    }
  });
  return found;
}

void FlipMesh::Apply(const Flip& flip, std::vector<uint32_t>* created, Journal* journal) {
  // The outer faces of the replaced tets and who is across them.
  struct Outer {
    Tri key;
    uint32_t tet;  // kNone: a hull face
  };
  std::array<Outer, 4 * kMaxRing> outer{};
  int num_outer = 0;
  for (int i = 0; i < flip.num_old; ++i) {
    const uint32_t o = flip.old_tets[i];
    for (int f = 0; f < 4; ++f) {
      const uint32_t n = nbr_[o][f];
      if (n != kNone && flip.Replaces(n)) continue;
      outer[num_outer++] = Outer{FaceKey(tet_[o], f), n};
    }
  }
  const uint32_t component = component_[flip.old_tets[0]];
  for (int i = 0; i < flip.num_old; ++i) {
    const uint32_t o = flip.old_tets[i];
    Save(o, journal);
    alive_[o] = 0;
    ++version_[o];
    nbr_[o] = {kNone, kNone, kNone, kNone};
  }
  // Reuse the old slots (LIFO: the last replaced first).
  for (int i = 0; i < flip.num_old; ++i) free_.push_back(flip.old_tets[i]);
  std::array<uint32_t, kMaxNew> slots{};
  for (int i = 0; i < flip.num_new; ++i) {
    slots[i] = Allocate(journal);
    tet_[slots[i]] = flip.new_tets[i];
    quality_[slots[i]] = flip.new_quality[i];
    component_[slots[i]] = component;
    nbr_[slots[i]] = {kNone, kNone, kNone, kNone};
  }
  for (int i = 0; i < flip.num_new; ++i) {
    const uint32_t s = slots[i];
    for (int f = 0; f < 4; ++f) {
      if (nbr_[s][f] != kNone) continue;  // linked from the other side already
      const Tri key = FaceKey(tet_[s], f);
      bool inner = false;
      for (int j = 0; j < flip.num_new && !inner; ++j) {
        if (j == i) continue;
        for (int h = 0; h < 4; ++h) {
          if (FaceKey(tet_[slots[j]], h) == key) {
            nbr_[s][f] = slots[j];
            nbr_[slots[j]][h] = s;
            inner = true;
            break;
          }
        }
      }
      if (inner) continue;
      for (int o = 0; o < num_outer; ++o) {
        if (outer[o].key != key) continue;
        const uint32_t across = outer[o].tet;
        nbr_[s][f] = across;
        if (across != kNone) {
          for (int h = 0; h < 4; ++h) {
            if (FaceKey(tet_[across], h) == key) {
              Save(across, journal);
              nbr_[across][h] = s;
            }
          }
        }
        break;
      }
    }
    created->push_back(s);
  }
}

void FlipMesh::Count(const Flip& flip) {
  switch (flip.ring) {
    case 0: ++stats_->flips_23; break;
    case 3: ++stats_->flips_32; break;
    case 4: ++stats_->flips_44; break;
    default: ++stats_->flips_edge_removal; break;
  }
}

bool FlipMesh::Search(uint32_t t, int depth, double floor, std::vector<Flip>* seq, double* score) {
  Flip last;
  if (BestFlip(t, floor, &last)) {
    seq->assign(1, last);
    *score = last.new_min;
    return true;
  }
  if (depth <= 1) return false;
  // Nearby tets: the face neighbours of t and the tets around its edges.
  std::vector<uint32_t> near;
  for (int f = 0; f < 4; ++f) {
    if (nbr_[t][f] != kNone) near.push_back(nbr_[t][f]);
  }
  static constexpr int kEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  for (const auto& ij : kEdges) {
    std::array<uint32_t, kMaxRing> ring_tets{}, u{};
    int n = 0;
    if (Ring(t, tet_[t][ij[0]], tet_[t][ij[1]], kMaxRing, &ring_tets, &u, &n)) {
      for (int k = 0; k < n; ++k) {
        if (ring_tets[k] != t) near.push_back(ring_tets[k]);
      }
    }
  }
  std::sort(near.begin(), near.end());
  near.erase(std::unique(near.begin(), near.end()), near.end());
  // Try every first flip F1 that leaves t alone and makes only tets better
  // than t, then search again from there; keep the sequence with the best
  // worst new quality. The sequence replaces t and the tets of its flips by
  // tets all better than t: the worst quality of the tets it touches strictly
  // rises, as for one flip.
  bool found = false;
  std::vector<Flip> rest;
  std::vector<uint32_t> scratch;
  for (uint32_t s : near) {
    // F1 is taken only above floor and, once a sequence is found, its score.
    auto prune = [&] { return found ? std::max(floor, *score) : floor; };
    ForEachFlip(s, /*above_old=*/false, prune, [&](const Flip& f1) {
      if (f1.Replaces(t) || !(f1.new_min > floor)) return;
      if (found && !(f1.new_min > *score)) return;  // cannot beat the best sequence
      // The crease rule of BestFlip holds for every flip of a sequence: a
      // first flip that gave a tet touching a crease a larger dihedral than
      // the tets it replaced made random_plcs.py float 104's 132.9° next to
      // a crease corner, above the stitched stars' 129.5°.
      if (RaisesCreaseAngle(f1)) {
        ++stats_->rejected_crease_angle;
        return;
      }
      Journal journal;
      journal.num_slots = tet_.size();
      journal.free_size = free_.size();
      const size_t keep = std::min<size_t>(free_.size(), kMaxNew + kMaxRing);
      journal.free_tail.assign(free_.end() - static_cast<std::ptrdiff_t>(keep), free_.end());
      scratch.clear();
      Apply(f1, &scratch, &journal);
      double rest_score = -kInf;
      if (Search(t, depth - 1, floor, &rest, &rest_score)) {
        const double total = std::min(f1.new_min, rest_score);
        if (!found || total > *score) {
          *score = total;
          seq->assign(1, f1);
          seq->insert(seq->end(), rest.begin(), rest.end());
          found = true;
        }
      }
      Undo(journal);
    });
  }
  return found;
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
      created.clear();
      Flip best;
      if (BestFlip(t, -kInf, &best)) {
        Apply(best, &created, nullptr);
        Count(best);
      } else {
        // The deeper search only for tets within the radius-edge bound: the
        // refiner guarantees it for every tet of a bounded domain, so the
        // others are exterior tets next to ∂Ω (clipped cells), which the
        // output drops; searching around them is wasted time.
        std::vector<Flip> seq;
        double score = -kInf;
        if (options_.lookahead_depth < 2 || !(quality_[t].radius_edge <= options_.max_radius_edge) ||
            !Search(t, static_cast<int>(options_.lookahead_depth), Dihedrals(t).min_dihedral, &seq, &score)) {
          ++stats_->stuck;
          continue;
        }
        for (const Flip& f : seq) {
          Apply(f, &created, nullptr);
          Count(f);
        }
        ++stats_->lookahead_sequences;
      }
      ++flips_in_pass;
      for (uint32_t s : created) {
        if (alive_[s]) Push(s);
      }
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
  uint64_t count = 0, measured = 0, bad = 0;
  double min_dih = kInf, max_dih = 0, max_re = 0;
  bool lazy = false;
  for (size_t t = 0; t < tet_.size(); ++t) {
    if (!alive_[t]) continue;
    ++count;
    // The extremes and the bad count are over the tets the pass works on:
    // with the exterior's, cube --max-volume 1e-3 reported a smallest angle
    // of 0.62° and a radius-edge of 48.8 for an output of 15.05° and 1.29.
    if (Skipped(static_cast<uint32_t>(t))) continue;
    ++measured;
    const Quality& q = quality_[t];
    max_re = std::max(max_re, q.radius_edge);
    if (!q.dihedrals) {
      lazy = true;  // not bad; its angles lie in (target, 180° − target)
      continue;
    }
    bad += q.min_dihedral < options_.target_min_dihedral_deg;
    min_dih = std::min(min_dih, q.min_dihedral);
    max_dih = std::max(max_dih, q.max_dihedral);
  }
  // The lazy tets (angles in (target, 180° − target)) decide the extremes
  // only when no measured tet reaches below the target / above 180° −
  // target. Then each is measured unless its sines show all its angles in
  // (φ, 180° − φ) ⊆ [min, max] so far, φ = max(min, 180° − max) < 90°
  // (Quality::sin2_lower, else MinSin2): the extremes come out as if every
  // tet were measured, at a fraction of the cost (the kept tets of cube
  // --max-volume 1e-5 have no angle near 165°; measuring them all was 168 M
  // instructions, 30% of the pass; with MinSin2 for each, 64 M; now 26 M).
  const double target = options_.target_min_dihedral_deg;
  if (lazy && (!(min_dih < target) || !(max_dih >= 180 - target))) {
    constexpr double kDegToRad = 3.14159265358979323846 / 180;
    double phi = kInf, bound = kInf;  // sin²φ · (1 + 1e-6), for the φ of the extremes so far
    for (size_t t = 0; t < tet_.size(); ++t) {
      if (!alive_[t] || Skipped(static_cast<uint32_t>(t)) || quality_[t].dihedrals) continue;
      if (const double now = std::max(min_dih, 180 - max_dih); now != phi) {
        phi = now;
        const double sp = phi < 90 ? std::sin(phi * kDegToRad) : 0;
        bound = phi < 90 ? sp * sp * (1 + 1e-6) : kInf;
      }
      // The bound Init kept, then the tet's own sines.
      if (quality_[t].sin2_lower > bound) continue;
      if (bound < kInf && MinSin2(pos_, tet_[t]) > bound) continue;
      const Quality& q = Dihedrals(static_cast<uint32_t>(t));
      min_dih = std::min(min_dih, q.min_dihedral);
      max_dih = std::max(max_dih, q.max_dihedral);
    }
  }
  if (measured == 0) min_dih = 0;
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

std::vector<std::array<uint32_t, 4>> FlipMesh::OutputNeighbors() const {
  // Output() keeps the live slots in slot order: a slot's index there is its
  // rank among them (dead slots are named by no live tet).
  std::vector<uint32_t> rank(tet_.size(), kNone);
  uint32_t live = 0;
  for (size_t t = 0; t < tet_.size(); ++t) {
    if (alive_[t]) rank[t] = live++;
  }
  std::vector<std::array<uint32_t, 4>> out;
  out.reserve(live);
  for (size_t t = 0; t < tet_.size(); ++t) {
    if (!alive_[t]) continue;
    std::array<uint32_t, 4> row;
    for (int f = 0; f < 4; ++f) row[f] = nbr_[t][f] == kNone ? kNone : rank[nbr_[t][f]];
    out.push_back(row);
  }
  return out;
}

}  // namespace

namespace {

// The two halves of MeasureSliverTet: |volume| and radius-edge (what the
// flip bounds test), then the dihedral angles (most of the cost), which a
// flip candidate only needs once all its new tets passed the bounds. The
// expressions of mesh::ComputeTetQuality (core/mesh/quality.cc), in the same
// order (-ffp-contract=off: the same roundings), so every value is the same
// double; the pass's stats and the output's quality report agree.

void MeasureBounds(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, SliverTetQuality* out) {
  const Vec3 p[4] = {a, b, c, d};
  SliverTetQuality& q = *out;
  double shortest2 = kInf;
  for (const auto& e : kTetEdge) shortest2 = std::min(shortest2, geom::Dist2(p[e[0]], p[e[1]]));
  const Vec3 u = b - a, v = c - a, w = d - a;
  const double det = geom::Dot(u, geom::Cross(v, w));
  q.volume = std::fabs(det / 6);
  if (det != 0 && shortest2 > 0) {
    const Vec3 num = geom::Norm2(u) * geom::Cross(v, w) + geom::Norm2(v) * geom::Cross(w, u) +
                     geom::Norm2(w) * geom::Cross(u, v);
    q.radius_edge = geom::Norm(num) / (2 * std::fabs(det)) / std::sqrt(shortest2);
  } else {
    q.radius_edge = kInf;
  }
}

void MeasureDihedrals(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, SliverTetQuality* out) {
  static constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;
  const Vec3 p[4] = {a, b, c, d};
  SliverTetQuality& q = *out;
  // Dihedral angle at edge k: atan2(y_k, x_k) with y_k = |n1 × n2| >= 0 and
  // x_k = n1 · n2. Only the smallest and the largest are wanted, and atan2
  // is most of the cost. P(y, x) = y / (x + y) for x >= 0, 1 + |x| / (|x| + y)
  // for x < 0, is a pseudo-angle: increasing in the angle θ of (x, y) on
  // [0, π], with dP/dθ = 1 / (|cos θ| + sin θ)² <= 1, so θ_k − θ_j >= P_k − P_j.
  // Computed, it is off by at most ~4.4e-16 (two roundings relative to
  // values <= 1, one addition); std::atan2 is within 1 ulp (<= 4.4e-16 on
  // [0, π]). So an edge with P_k > P_min + 1e-12 has θ_k > θ_min + 9.9e-13
  // and its atan2 value exceeds the one at P's minimum: it cannot be the
  // smallest angle (likewise for the largest). The angles of the remaining
  // candidates are computed as before, and min/max over them is the min/max
  // over all six. A pair with a NaN or infinite P (y = x = 0: a degenerate
  // face) takes the plain loop.
  double ys[6], xs[6], ps[6];
  bool finite = true;
  double pmin = kInf, pmax = -kInf;
  for (int k = 0; k < 6; ++k) {
    const Vec3& pi = p[kTetEdge[k][0]];
    const Vec3 e = p[kTetEdge[k][1]] - pi;
    const Vec3 n1 = geom::Cross(e, p[kTetEdge[5 - k][0]] - pi);
    const Vec3 n2 = geom::Cross(e, p[kTetEdge[5 - k][1]] - pi);
    ys[k] = geom::Norm(geom::Cross(n1, n2));
    xs[k] = geom::Dot(n1, n2);
    ps[k] = xs[k] >= 0 ? ys[k] / (xs[k] + ys[k]) : 1 + (-xs[k]) / (ys[k] - xs[k]);
    finite = finite && std::isfinite(ps[k]);
    pmin = std::min(pmin, ps[k]);
    pmax = std::max(pmax, ps[k]);
  }
  constexpr double kMargin = 1e-12;
  q.min_dihedral_deg = kInf;
  q.max_dihedral_deg = 0;
  for (int k = 0; k < 6; ++k) {
    if (finite && ps[k] > pmin + kMargin && ps[k] < pmax - kMargin) continue;
    const double angle = std::atan2(ys[k], xs[k]) * kRadToDeg;
    q.min_dihedral_deg = std::min(q.min_dihedral_deg, angle);
    q.max_dihedral_deg = std::max(q.max_dihedral_deg, angle);
  }
}

}  // namespace

SliverTetQuality MeasureSliverTet(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  SliverTetQuality q;
  MeasureBounds(a, b, c, d, &q);
  MeasureDihedrals(a, b, c, d, &q);
  return q;
}

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
  out->Set("sliver.flips_edge_removal", static_cast<double>(flips_edge_removal));
  out->Set("sliver.lookahead_sequences", static_cast<double>(lookahead_sequences));
  out->Set("sliver.passes", static_cast<double>(passes));
  out->Set("sliver.candidates", static_cast<double>(candidates));
  out->Set("sliver.pruned_triangles", static_cast<double>(pruned_triangles));
  out->Set("sliver.rejected_orientation", static_cast<double>(rejected_orientation));
  out->Set("sliver.rejected_constraint", static_cast<double>(rejected_constraint));
  out->Set("sliver.rejected_radius_edge", static_cast<double>(rejected_radius_edge));
  out->Set("sliver.rejected_volume", static_cast<double>(rejected_volume));
  out->Set("sliver.rejected_no_gain", static_cast<double>(rejected_no_gain));
  out->Set("sliver.rejected_crease_angle", static_cast<double>(rejected_crease_angle));
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
  mesh.ReleaseWorkArrays();
  result.tets = mesh.Output();
  if (options.output_neighbors) result.neighbors = mesh.OutputNeighbors();
  result.stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

absl::StatusOr<SliverResult> RemoveSlivers(std::span<const geom::Vec3> positions,
                                           std::span<const std::array<uint32_t, 4>> tets,
                                           std::span<const ConstrainedFace> faces,
                                           std::span<const std::vector<uint32_t>> segment_chains,
                                           const SliverOptions& options,
                                           std::vector<std::array<uint32_t, 4>>* neighbors) {
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
  in.neighbors = neighbors;
  return RemoveSlivers(in, options);
}

}  // namespace svrc::refine
