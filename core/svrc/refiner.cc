// The SVRC refiner, stages (a)–(b) of the guide's plan: M_Ω, 0-balls of input
// points, free segments with 1D meshes and piece ConfBalls. Figure numbers are
// the thesis'. See refiner.h and docs/svrc-design.md.
#include "core/svrc/refiner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <tuple>

#include "absl/strings/str_cat.h"
#include "core/geometry/predicates.h"
#include "core/plc/features.h"
#include "core/svrc/balls.h"
#include "core/svrc/containment.h"
#include "core/svrc/feature_meshes.h"
#include "core/svrc/location_graph.h"
#include "core/svrc/normalize.h"
#include "core/svrc/points.h"
#include "core/svrc/work_queue.h"

namespace svrc::refine {
namespace {

using geom::Vec3;

class Refiner {
 public:
  Refiner(const RefineOptions& options, Normalization norm, const Vec3& center, double half)
      : options_(options), norm_(norm), omega_(center, half) {}

  absl::Status Initialize(std::span<const Vec3> normalised, std::span<const SegmentInput> segments);
  absl::Status Run();
  absl::Status CheckInvariants(bool final);
  PointSetRefinement Output(std::span<const Vec3> input);

 private:
  // --- Destroy (Figure 3.4) -------------------------------------------------
  absl::Status Destroy(const WorkEvent& event);
  // A gap ball of M_Ω (Skinny₃ / Unresolved₃ of cell v): warp, else yield,
  // else insert the centre.
  absl::Status DestroyOmega(VertexId v);
  // A gap ball of segment mesh `seg` whose centre is the midpoint of the piece
  // starting at local vertex u (Encroached₁ of the piece ball, Skinny₁).
  absl::Status DestroySegmentPiece(uint32_t seg, uint32_t u);

  // --- ForceInsert (Figure 3.5) + UpdateLocation (3.6) + PropagateLocation (3.9)
  absl::Status ForceInsertOmega(PointId p, TetId hint);
  absl::Status ForceInsertSegment(uint32_t seg, uint32_t u, double t);

  // --- BLG helpers -------------------------------------------------------------
  // Cells of M_Ω that may meet B(c, r), given a vertex w nearest to c: BFS over
  // Delaunay neighbours filtered by the bisector bound (|xc|² − |wc|²) ≤ 2r|xw|
  // (a superset of the cells meeting B, which form a connected set).
  void CellsMeetingBall(const Vec3& c, double r, VertexId w, std::vector<VertexId>* out);
  // PropagateLocation of a ball of radius > 0 into M_Ω: link every cell that
  // may meet it, starting near `start`.
  void LinkBallToOmega(BallId b, VertexId start);
  // PropagateLocation of a 0-ball into M_Ω: link the cell containing its
  // point (an unresolved object), refresh that cell's events.
  void LinkVertexBallToOmega(BallId b, VertexId start);
  // AddLink(x, Ω, B) for a piece ball with Figure 3.10's encroachment trap.
  void AddPieceLink(VertexId x, BallId b);
  bool Encroaches(BallId b, VertexId x) const;
  void EnqueueEncroached(BallId b);

  // --- Events -----------------------------------------------------------------
  void RefreshEvents(VertexId v, const CellSize* size = nullptr);
  void RefreshSegmentEvents(uint32_t seg, uint32_t v);
  bool IsLive(const WorkEvent& event);
  bool IsSkinny(const CellSize& s) const { return s.outradius > options_.tau * s.inradius; }
  bool IsSkinny(const SegmentMesh::Size1& s) const { return s.outradius > options_.tau * s.inradius; }

  bool IsOmega(MeshId m) const { return m == kOmegaMesh; }
  uint32_t SegIndex(MeshId m) const { return m.value() - seg_mesh0_; }
  MeshId SegMesh(uint32_t seg) const { return MeshId(seg_mesh0_ + seg); }
  BallId VertexBallOf(PointId p) const {
    return p.value() < vertex_ball_.size() ? vertex_ball_[p.value()] : kNoneBall;
  }
  void SetVertexBall(PointId p, BallId b) {
    if (vertex_ball_.size() <= p.value()) vertex_ball_.resize(p.value() + 1, kNoneBall);
    vertex_ball_[p.value()] = b;
  }
  uint64_t TotalVertices() const { return omega_.dt().NumVertices() + stats_.segment_vertices; }

  RefineOptions options_;
  Normalization norm_;
  FeatureTable features_;
  PointStore points_;
  BallStore balls_;
  LocationGraph blg_;
  WorkQueues queues_;
  OmegaMesh omega_;
  std::vector<SegmentMesh> segs_;
  uint32_t seg_mesh0_ = 0;  // MeshId of segment 0 (= its FeatureId)
  std::vector<uint32_t> seg_input_a_;  // input endpoint at t = 0 of each segment
  uint32_t num_input_ = 0;
  std::vector<uint32_t> duplicate_of_;  // first input point with the same coordinates
  std::vector<BallId> vertex_ball_;     // per global point: its 0-ball (kNoneBall: none)
  std::vector<uint32_t> piece_vertex_;  // per ball: local vertex starting its piece
  std::vector<uint32_t> piece_seg_;     // per ball: its segment
  // Balls that got a first, non-native encroacher (PartiallyEncroached).
  std::vector<BallId> partial_;
  RefineStats stats_;
  uint64_t budget_ = 0;
  // The cell size IsLive computed for the event Destroy gets next.
  CellSize last_size_;
  VertexId last_size_vertex_;
  uint32_t last_size_gen_ = 0;
  // Scratch.
  std::vector<VertexId> bfs_, nbrs_;
  std::vector<uint32_t> mark_;
  uint32_t stamp_ = 0;
  std::vector<uint32_t> ball_mark_;
  uint32_t ball_stamp_ = 0;
  std::vector<BallId> balls_scratch_;
  std::vector<LocationObject> objects_;
};

absl::Status Refiner::Initialize(std::span<const Vec3> normalised, std::span<const SegmentInput> segments) {
  num_input_ = static_cast<uint32_t>(normalised.size());
  // Exact duplicates are one feature point ("plc" merges them for PLCs; a raw
  // point set may still have them): the copies map to the first one's vertex
  // and get no 0-ball — a copy sitting on a vertex would never be within θr of
  // a Voronoi corner, and refinement would run to the budget.
  duplicate_of_.resize(num_input_);
  {
    std::vector<uint32_t> order(num_input_);
    for (uint32_t i = 0; i < num_input_; ++i) order[i] = i;
    auto key = [&](uint32_t i) {
      const Vec3& p = normalised[i];
      return std::make_tuple(p.x, p.y, p.z, i);
    };
    std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return key(a) < key(b); });
    for (size_t k = 0; k < order.size(); ++k) {
      const uint32_t i = order[k];
      duplicate_of_[i] =
          (k > 0 && normalised[order[k - 1]] == normalised[i]) ? duplicate_of_[order[k - 1]] : i;
    }
  }
  // The feature complex of points + free segments (superfeature lists).
  plc::FeatureComplex complex;
  complex.points.resize(num_input_);
  for (size_t s = 0; s < segments.size(); ++s) {
    const uint32_t a = segments[s].a, b = segments[s].b;
    if (a >= num_input_ || b >= num_input_) {
      return absl::InvalidArgumentError(absl::StrCat("segment ", s, ": endpoint out of range"));
    }
    if (duplicate_of_[a] == duplicate_of_[b]) {
      return absl::InvalidArgumentError(absl::StrCat("segment ", s, ": endpoints coincide"));
    }
    plc::FeatureSegment fs;
    fs.a = duplicate_of_[a];
    fs.b = duplicate_of_[b];
    fs.is_free = true;
    complex.segments.push_back(fs);
  }
  // Two segments meeting at a point at less than 90° make that point a crease
  // (Definitions 4–5): without collars (stage (d)) refinement around it would
  // never stop, so such inputs are refused rather than run to the budget.
  {
    std::vector<std::vector<uint32_t>> other_end(num_input_);
    for (const plc::FeatureSegment& fs : complex.segments) {
      other_end[fs.a].push_back(fs.b);
      other_end[fs.b].push_back(fs.a);
    }
    for (uint32_t o = 0; o < num_input_; ++o) {
      const auto& ends = other_end[o];
      for (size_t i = 0; i < ends.size(); ++i) {
        for (size_t j = i + 1; j < ends.size(); ++j) {
          if (geom::DotSign(normalised[o], normalised[ends[i]], normalised[o], normalised[ends[j]]) > 0) {
            return absl::UnimplementedError(absl::StrCat(
                "SVRC: segments at point ", o, " meet at an acute angle (a crease); collars are not implemented yet"));
          }
        }
      }
    }
  }
  features_ = FeatureTable::Build(complex);
  seg_mesh0_ = segments.empty() ? 0 : features_.OfSegment(0).value();
  budget_ = options_.max_vertices != 0 ? options_.max_vertices
                                       : std::max<uint64_t>(1'000'000, 1000ull * num_input_);
  // Global ids = SoS priorities: inputs first (in input order), then corners.
  for (uint32_t i = 0; i < num_input_; ++i) {
    points_.Add(normalised[i], features_.OfPoint(i), kCdInputVertex);
  }
  std::array<PointId, 8> corners;
  for (int i = 0; i < 8; ++i) corners[i] = points_.Add(omega_.Corner(i), FeatureTable::Omega(), kCdSpace);
  omega_.SeedCorners(corners);
  for (int i = 0; i < 8; ++i) points_.SetVertex(corners[i], kOmegaMesh, i);

  // Figure 3.3: UpdateLocation(∅, M_F, F) for every feature, lowest dimension
  // first. A point feature's mesh is {p}: one 0-ball, propagated to its
  // superfeatures. It is a vertex of its segments' meshes from the start
  // (their seeds), so only M_Ω has it unresolved.
  for (uint32_t i = 0; i < num_input_; ++i) {
    if (duplicate_of_[i] != i) {
      ++stats_.duplicates;
      continue;
    }
    const FeatureId f = features_.OfPoint(i);
    const BallId b = balls_.AddVertexBall(PointId(i), normalised[i], f, MeshId(f.value()), kCdInputVertex);
    SetVertexBall(PointId(i), b);
    LinkVertexBallToOmega(b, VertexId(0));
  }
  // Segment meshes, seeded with their endpoints (Ω_s = s); their pieces'
  // diametral ConfBalls go to M_Ω. The endpoints' 0-balls are the point
  // features' (one ball per global point; guide §7).
  for (uint32_t s = 0; s < complex.segments.size(); ++s) {
    const PointId a(complex.segments[s].a), b(complex.segments[s].b);
    segs_.emplace_back(a, b, points_.Xyz(a), points_.Xyz(b));
    seg_input_a_.push_back(a.value());
    points_.SetVertex(a, SegMesh(s), 0);
    points_.SetVertex(b, SegMesh(s), 1);
    SegmentMesh& m = segs_.back();
    m.VertexBall(0) = VertexBallOf(a);
    m.VertexBall(1) = VertexBallOf(b);
    const BallId piece = balls_.AddPieceBall(a, b, points_.Xyz(a), points_.Xyz(b), features_.OfSegment(s), SegMesh(s));
    m.PieceBall(0) = piece;
    if (piece_vertex_.size() <= piece.value()) {
      piece_vertex_.resize(piece.value() + 1);
      piece_seg_.resize(piece.value() + 1);
    }
    piece_vertex_[piece.value()] = 0;
    piece_seg_[piece.value()] = s;
    LinkBallToOmega(piece, VertexId(0));
  }
  for (uint32_t v = 0; v < omega_.NumVertices(); ++v) RefreshEvents(VertexId(v));
  for (uint32_t s = 0; s < segs_.size(); ++s) {
    for (uint32_t v = 0; v < segs_[s].NumVertices(); ++v) RefreshSegmentEvents(s, v);
  }
  return absl::OkStatus();
}

// ---------------------------------------------------------------- BLG helpers

void Refiner::CellsMeetingBall(const Vec3& c, double r, VertexId w, std::vector<VertexId>* out) {
  const delaunay::Delaunay3& dt = omega_.dt();
  const Vec3& pw = dt.Point(w);
  const double wc2 = geom::Dist2(pw, c);
  // V(x) lies in the half-space of points nearer to x than to w, which meets
  // B(c, r) only if the signed distance from c to the bisector of xw,
  // (|xc|² − |wc|²) / (2|xw|), is at most r. Conservative (guide §3 allows
  // inflation for location); the relative slack keeps rounding on that side.
  auto may_meet = [&](const Vec3& px) {
    return geom::Dist2(px, c) - wc2 <= 2.0 * r * geom::Dist(px, pw) * (1 + 1e-9) + 1e-12 * wc2;
  };
  ++stamp_;
  if (mark_.size() < dt.NumVertices()) mark_.resize(dt.NumVertices() + 64, 0);
  out->clear();
  out->push_back(w);
  mark_[w.value()] = stamp_;
  for (size_t i = 0; i < out->size(); ++i) {
    dt.Neighbors((*out)[i], &nbrs_);
    for (VertexId x : nbrs_) {
      if (mark_[x.value()] == stamp_) continue;
      mark_[x.value()] = stamp_;
      if (may_meet(dt.Point(x))) out->push_back(x);
    }
  }
}

bool Refiner::Encroaches(BallId b, VertexId x) const {
  // "x inside the diametral ball of piece ab" (Figure 3.10). The closed ball:
  // a vertex exactly on the sphere is counted, because then the empty-sphere
  // witness for ab is decided by the perturbation, which need not favour ab
  // (docs/svrc-design.md §2, §8). The piece's own endpoints are on the sphere
  // by definition and do not count.
  const PointId p = omega_.PointOf(x);
  if (p == balls_.Vertex(b, 0) || p == balls_.Vertex(b, 1)) return false;
  return geom::InDiametralSphere(points_.Xyz(balls_.Vertex(b, 0)), points_.Xyz(balls_.Vertex(b, 1)),
                                 omega_.dt().Point(x)) >= 0;
}

void Refiner::EnqueueEncroached(BallId b) {
  if (balls_.EncroachQueued(b)) return;
  const int dim = features_.Dim(balls_.Feature(b));
  WorkEvent e{EventType::kEncroached, static_cast<uint8_t>(dim), balls_.Mesh(b), b.value(),
              balls_.Generation(b), balls_.Radius(b), balls_.Center(b)};
  if (queues_.Enqueue(e).valid()) balls_.SetEncroachQueued(b, true);
}

void Refiner::AddPieceLink(VertexId x, BallId b) {
  LinkFacts facts;
  facts.encroaches = Encroaches(b, x);
  const PointId p = omega_.PointOf(x);
  facts.native = points_.CdOf(p).dim == 3;  // CD(x) = dim Ω: created in M_Ω
  facts.vertex_point = p;
  const AddLinkResult r = blg_.AddLink(kOmegaMesh, x.value(), LocationObject::Ball(b), facts, &balls_);
  if (r.encroach == EncroachOutcome::kEnqueue) EnqueueEncroached(b);
  if (r.encroach == EncroachOutcome::kPartial) partial_.push_back(b);
}

void Refiner::LinkBallToOmega(BallId b, VertexId start) {
  const delaunay::Delaunay3& dt = omega_.dt();
  const VertexId w = dt.NearestVertex(balls_.Center(b), dt.VertexTet(start));
  std::vector<VertexId> cells;
  CellsMeetingBall(balls_.Center(b), balls_.Radius(b), w, &cells);
  for (VertexId x : cells) AddPieceLink(x, b);
}

void Refiner::LinkVertexBallToOmega(BallId b, VertexId start) {
  const delaunay::Delaunay3& dt = omega_.dt();
  const VertexId cell = dt.NearestVertex(balls_.Center(b), dt.VertexTet(start));
  LinkFacts facts;
  facts.unresolved = true;
  const AddLinkResult r = blg_.AddLink(kOmegaMesh, cell.value(), LocationObject::Ball(b), facts, &balls_);
  if (r.cell_became_unresolved) RefreshEvents(cell);
}

// ---------------------------------------------------------------- events

void Refiner::RefreshEvents(VertexId v, const CellSize* size) {
  const CellSize s = size != nullptr ? *size : omega_.Size(v);
  const uint32_t gen = omega_.CellGeneration(v);
  // Unresolved: the cell holds a 0-ball whose point is not yet in M_Ω. Built
  // as the gap ball ⟨(farthest corner, R_v), Ω⟩ (guide §3 on Figure 3.11).
  EventHandle& u = omega_.UnresolvedEvent(v);
  if (blg_.NumUnresolved(kOmegaMesh, v.value()) > 0) {
    if (queues_.IsQueued(u)) {
      queues_.Refresh(u, gen, s.corner, s.outradius);
    } else {
      u = queues_.Enqueue({EventType::kUnresolved, 3, kOmegaMesh, v.value(), gen, s.outradius, s.corner});
    }
  } else if (queues_.IsQueued(u)) {
    queues_.Remove(u);
  }
  // Skinny: R_v/r_v > τ (Figure 3.5), gap ball at the farthest corner.
  EventHandle& k = omega_.SkinnyEvent(v);
  if (IsSkinny(s)) {
    if (queues_.IsQueued(k)) {
      queues_.Refresh(k, gen, s.corner, s.outradius);
    } else {
      k = queues_.Enqueue({EventType::kSkinny, 3, kOmegaMesh, v.value(), gen, s.outradius, s.corner});
    }
  } else if (queues_.IsQueued(k)) {
    queues_.Remove(k);
  }
}

void Refiner::RefreshSegmentEvents(uint32_t seg, uint32_t v) {
  SegmentMesh& m = segs_[seg];
  const SegmentMesh::Size1 s = m.Size(v);
  EventHandle& k = m.SkinnyEvent(v);
  if (IsSkinny(s)) {
    const uint32_t w = m.Next(s.piece);
    const Vec3 corner = m.PointAt(0.5 * (m.T(s.piece) + m.T(w)));
    if (queues_.IsQueued(k)) {
      queues_.Refresh(k, m.CellGeneration(v), corner, s.outradius);
    } else {
      k = queues_.Enqueue({EventType::kSkinny, 1, SegMesh(seg), v, m.CellGeneration(v), s.outradius, corner});
    }
  } else if (queues_.IsQueued(k)) {
    queues_.Remove(k);
  }
}

bool Refiner::IsLive(const WorkEvent& e) {
  if (e.type == EventType::kEncroached) {
    const BallId b(e.object);
    balls_.SetEncroachQueued(b, false);
    return balls_.IsAlive(b) && balls_.Generation(b) == e.generation;
  }
  if (!IsOmega(e.mesh)) {
    SegmentMesh& m = segs_[SegIndex(e.mesh)];
    return m.CellGeneration(e.object) == e.generation && IsSkinny(m.Size(e.object));
  }
  const VertexId v(e.object);
  if (omega_.CellGeneration(v) != e.generation) return false;
  if (e.type == EventType::kUnresolved) return blg_.NumUnresolved(kOmegaMesh, v.value()) > 0;
  last_size_ = omega_.Size(v);
  last_size_vertex_ = v;
  last_size_gen_ = omega_.CellGeneration(v);
  if (e.type == EventType::kSkinny) return IsSkinny(last_size_);
  return true;
}

absl::Status Refiner::Run() {
  const auto start = std::chrono::steady_clock::now();
  const geom::PredicateStats pred0 = geom::GetPredicateStats();
  auto live = [this](const WorkEvent& e) { return IsLive(e); };
  uint64_t destroys = 0;
  while (true) {
  while (std::optional<WorkEvent> event = queues_.DequeueLive(live)) {
    if (TotalVertices() >= budget_) {
      return absl::ResourceExhaustedError(absl::StrCat(
          "SVRC: vertex budget of ", budget_, " reached with ", queues_.size(), " events pending"));
    }
    if (options_.poll && destroys % options_.poll_interval == 0) {
      absl::Status s = options_.poll();
      if (!s.ok()) return s;
    }
    ++destroys;
    absl::Status s = Destroy(*event);
    if (!s.ok()) return s;
    if (options_.validate_every > 0 && destroys % options_.validate_every == 0) {
      s = CheckInvariants(false);
      if (!s.ok()) return s;
    }
  }
  // The queues ran dry. A ball encroached only by one lower-dimensional
  // vertex (PartiallyEncroached, Figure 3.10) waits for a second encroacher;
  // if none came, its piece is still not a Delaunay edge of M_Ω — the
  // thesis' "unresolved ConfBall" (Figure 3.9) — so destroy it now
  // (docs/svrc-design.md §8 item 8).
  std::vector<BallId> partial;
  partial.swap(partial_);
  bool more = false;
  for (BallId b : partial) {
    if (!balls_.IsAlive(b)) continue;
    const uint32_t x = points_.VertexIn(balls_.FirstEncroacher(b), kOmegaMesh);
    if (x != PointStore::kNoVertex && Encroaches(b, VertexId(x))) {
      EnqueueEncroached(b);
      more = true;
    }
  }
  if (!more) break;
  }
  const geom::PredicateStats& pred = geom::GetPredicateStats();
  stats_.predicate_calls = pred.TotalCalls() - pred0.TotalCalls();
  stats_.predicate_exact = pred.TotalExact() - pred0.TotalExact();
  stats_.predicate_sos = pred.TotalSos() - pred0.TotalSos();
  stats_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return absl::OkStatus();
}

// ---------------------------------------------------------------- Destroy

absl::Status Refiner::Destroy(const WorkEvent& event) {
  if (event.type == EventType::kEncroached) {
    const BallId b(event.object);
    return DestroySegmentPiece(piece_seg_[b.value()], piece_vertex_[b.value()]);
  }
  if (!IsOmega(event.mesh)) {
    const uint32_t seg = SegIndex(event.mesh);
    return DestroySegmentPiece(seg, segs_[seg].Size(event.object).piece);
  }
  return DestroyOmega(VertexId(event.object));
}

absl::Status Refiner::DestroySegmentPiece(uint32_t seg, uint32_t u) {
  // Figure 3.4 in M_s for the gap ball centred at the piece's midpoint. Warp
  // (𝒲) and yield (𝒴) look at balls linked to M_s's cells, i.e. balls of its
  // subfeatures: a free segment's subfeatures are its endpoints, vertices of
  // M_s from the start, so 𝒲 = 𝒴 = ∅ until collar points (1,2) exist
  // (stage (d)). Line 11: insert the centre.
  SegmentMesh& m = segs_[seg];
  const double t = 0.5 * (m.T(u) + m.T(m.Next(u)));
  if (!(t > m.T(u) && t < m.T(m.Next(u)))) {
    return absl::InternalError(absl::StrCat("SVRC: segment ", seg, " piece too short to split (t = ", t, ")"));
  }
  return ForceInsertSegment(seg, u, t);
}

absl::Status Refiner::DestroyOmega(VertexId v) {
  // Line 1 (stale test) was done at Dequeue. The gap ball is rebuilt from the
  // cell: ⟨(farthest corner of V(v) ∩ Ω, R_v), Ω⟩; CD(B) = CD(c) = (3,3).
  const CellSize s = (last_size_vertex_ == v && last_size_gen_ == omega_.CellGeneration(v)) ? last_size_
                                                                                           : omega_.Size(v);
  const Vec3 c = s.corner;
  const double r = s.outradius;
  const Cd cd_ball = kCdSpace;
  const double theta_r2 = (options_.theta * r) * (options_.theta * r);
  for (int attempt = 0;; ++attempt) {
    if (attempt > 100000) return absl::InternalError("SVRC: Destroy yielded without end");
    if (blg_.NumLinks() == 0) {
      // 𝓑 = ∅: nothing to warp or yield to.
      return ForceInsertOmega(points_.Add(c, FeatureTable::Omega(), kCdSpace), s.hint);
    }
    // Line 2: 𝒱 = cells meeting B (v is nearest to c: c is its corner).
    CellsMeetingBall(c, r, v, &bfs_);
    stats_.destroy_cells_visited += bfs_.size();
    stats_.max_destroy_cells = std::max<uint64_t>(stats_.max_destroy_cells, bfs_.size());
    // Line 3: 𝓑 = ∪ Balls_Ω(u). Line 4: 𝒲 = 0-balls not yet in M_Ω within θr
    // of c with CD(p) < CD(B) (the printed inequality is reversed by OCR;
    // guide §3). Line 9: 𝒴 = lower-CD balls with c strictly inside.
    BallId warp, yield;
    double warp_d2 = 0;
    ++ball_stamp_;
    if (ball_mark_.size() < balls_.size()) ball_mark_.resize(balls_.size() + 64, 0);
    for (VertexId u : bfs_) {
      balls_scratch_.clear();
      blg_.BallsOf(kOmegaMesh, u.value(), &balls_scratch_);
      for (BallId b : balls_scratch_) {
        if (ball_mark_[b.value()] == ball_stamp_) continue;
        ball_mark_[b.value()] = ball_stamp_;
        if (!(balls_.CdOf(b) < cd_ball)) continue;
        if (balls_.IsVertexBall(b)) {
          const PointId p = balls_.VertexPoint(b);
          if (points_.InMesh(p, kOmegaMesh)) continue;
          const double d2 = geom::Dist2(balls_.Center(b), c);
          if (d2 > theta_r2) continue;
          // Line 6: lowest CD, then nearest to c, then lowest id (determinism).
          if (warp.valid()) {
            const Cd a = balls_.CdOf(b), w = balls_.CdOf(warp);
            if (!(a < w || (a == w && (d2 < warp_d2 || (d2 == warp_d2 && p < balls_.VertexPoint(warp)))))) continue;
          }
          warp = b;
          warp_d2 = d2;
        } else if (balls_.IsAlive(b)) {
          // Strict interior: c on the sphere does not force a yield.
          if (geom::InDiametralSphere(points_.Xyz(balls_.Vertex(b, 0)), points_.Xyz(balls_.Vertex(b, 1)), c) <= 0) {
            continue;
          }
          // Lowest CD, then the largest ball, then lowest id.
          if (yield.valid()) {
            const Cd a = balls_.CdOf(b), y = balls_.CdOf(yield);
            if (!(a < y || (a == y && (balls_.Radius(b) > balls_.Radius(yield) ||
                                       (balls_.Radius(b) == balls_.Radius(yield) && b < yield))))) {
              continue;
            }
          }
          yield = b;
        }
      }
    }
    if (warp.valid()) {
      ++stats_.warps;
      std::vector<uint32_t> cells;
      blg_.CellsOf(LocationObject::Ball(warp), kOmegaMesh, &cells);
      const TetId hint = cells.empty() ? s.hint : omega_.dt().VertexTet(VertexId(cells[0]));
      return ForceInsertOmega(balls_.VertexPoint(warp), hint);
    }
    if (!yield.valid()) {
      // Line 11: insert the centre.
      return ForceInsertOmega(points_.Add(c, FeatureTable::Omega(), kCdSpace), s.hint);
    }
    // Lines 13–14: destroy the lower ball first (one insertion into M_s), then
    // start over: the new segment point may now be a warp target. M_Ω did not
    // change, so the gap ball is still ours.
    ++stats_.yields;
    absl::Status st = DestroySegmentPiece(piece_seg_[yield.value()], piece_vertex_[yield.value()]);
    if (!st.ok()) return st;
  }
}

// ---------------------------------------------------------------- ForceInsert

absl::Status Refiner::ForceInsertOmega(PointId p, TetId hint) {
  delaunay::Delaunay3& dt = omega_.dt();
  const Vec3 pos = points_.Xyz(p);
  const auto result = dt.Insert(pos, p.value(), hint);
  if (result.outcome != delaunay::Delaunay3::InsertOutcome::kInserted) {
    // Duplicate input points were merged at Initialize and a warp target lying
    // in B is warped to rather than inserted next to, so a coincidence is a bug.
    return absl::InternalError(absl::StrCat("SVRC: point ", p.value(), " coincides with a vertex of M_Ω"));
  }
  ++stats_.insertions;
  const VertexId nv = result.vertex;
  omega_.AddVertex(nv, p);
  points_.SetVertex(p, kOmegaMesh, nv.value());
  // The point's own 0-ball is resolved in M_Ω: drop its links there.
  const BallId own = VertexBallOf(p);
  if (own.valid()) blg_.RemoveObjectLinks(LocationObject::Ball(own), kOmegaMesh, nullptr);
  // 𝒱 = cavity vertices, 𝒱' = 𝒱 ∪ {p}. Copy: the span points into Delaunay3
  // scratch, which later queries reuse.
  std::vector<VertexId> changed(result.cavity_vertices.begin(), result.cavity_vertices.end());
  changed.push_back(nv);
  for (VertexId u : changed) omega_.BumpCell(u);
  std::vector<CellSize> sizes(changed.size());
  for (size_t i = 0; i < changed.size(); ++i) sizes[i] = omega_.Size(changed[i]);
  // UpdateLocation (3.6) for F = Ω: no new ConfBalls; re-intersect the lower
  // ConfBalls of the old cells with the new cells. A point in V_old(u) is in
  // V_new(u) or V_new(p): one exact distance comparison (ties: the lower
  // global id, as the perturbation). A ball of radius r meets V(x) only if
  // |xc| ≤ r + R_x (V(x) ⊂ B(x, R_x)): a conservative test over 𝒱'.
  ++ball_stamp_;
  if (ball_mark_.size() < balls_.size()) ball_mark_.resize(balls_.size() + 64, 0);
  std::vector<BallId> moved_pieces;
  for (size_t i = 0; i + 1 < changed.size(); ++i) {
    const VertexId u = changed[i];
    objects_.clear();
    blg_.RemoveCellLinks(kOmegaMesh, u.value(), &objects_);
    const Vec3& pu = dt.Point(u);
    for (const LocationObject& o : objects_) {
      const BallId b(o.id);
      if (!balls_.IsAlive(b)) continue;
      if (!balls_.IsVertexBall(b)) {
        if (ball_mark_[b.value()] != ball_stamp_) {
          ball_mark_[b.value()] = ball_stamp_;
          moved_pieces.push_back(b);
        }
        continue;
      }
      if (points_.InMesh(balls_.VertexPoint(b), kOmegaMesh)) continue;
      const Vec3& q = balls_.Center(b);
      const int cmp = geom::CompareDistance(q, pu, pos);  // > 0: u is farther
      const bool to_new = cmp > 0 || (cmp == 0 && p.value() < omega_.PointOf(u).value());
      LinkFacts facts;
      facts.unresolved = true;
      blg_.AddLink(kOmegaMesh, to_new ? nv.value() : u.value(), o, facts, &balls_);
    }
  }
  for (BallId b : moved_pieces) {
    const Vec3& c = balls_.Center(b);
    const double r = balls_.Radius(b);
    for (size_t i = 0; i < changed.size(); ++i) {
      if (geom::Dist(dt.Point(changed[i]), c) <= (r + sizes[i].outradius) * (1 + 1e-9)) {
        AddPieceLink(changed[i], b);
      }
    }
  }
  // Figure 3.5's loop over 𝒱': DecreaseSize / enqueue Skinny and Unresolved.
  for (size_t i = 0; i < changed.size(); ++i) RefreshEvents(changed[i], &sizes[i]);
  return absl::OkStatus();
}

absl::Status Refiner::ForceInsertSegment(uint32_t seg, uint32_t u, double t) {
  SegmentMesh& m = segs_[seg];
  const uint32_t w = m.Next(u);
  const FeatureId f = features_.OfSegment(seg);
  const MeshId mesh = SegMesh(seg);
  const PointId p = points_.Add(m.PointAt(t), f, kCdSegment);
  const uint32_t mid = m.Split(u, t, p);
  points_.SetVertex(p, mesh, mid);
  ++stats_.segment_vertices;
  // UpdateLocation (3.6) in M_s: the old piece uw dies (its links in M_Ω go),
  // the new simplices at 𝒱' = {u, mid, w} with |T| = dim F + 1 = 2 (pieces)
  // or |T| = 1 (mid's 0-ball) become ConfBalls (the endpoints' 0-balls do not
  // change: one ball per global point).
  const BallId old_piece = m.PieceBall(u);
  std::vector<uint32_t> old_cells;
  balls_.Kill(old_piece);
  blg_.RemoveObjectLinks(LocationObject::Ball(old_piece), kOmegaMesh, &old_cells);
  const BallId left = balls_.AddPieceBall(m.PointOf(u), p, points_.Xyz(m.PointOf(u)), points_.Xyz(p), f, mesh);
  const BallId right = balls_.AddPieceBall(p, m.PointOf(w), points_.Xyz(p), points_.Xyz(m.PointOf(w)), f, mesh);
  const BallId vb = balls_.AddVertexBall(p, points_.Xyz(p), f, mesh, kCdSegment);
  m.PieceBall(u) = left;
  m.PieceBall(mid) = right;
  m.VertexBall(mid) = vb;
  SetVertexBall(p, vb);
  if (piece_vertex_.size() < balls_.size()) {
    piece_vertex_.resize(balls_.size());
    piece_seg_.resize(balls_.size());
  }
  piece_vertex_[left.value()] = u;
  piece_vertex_[right.value()] = mid;
  piece_seg_[left.value()] = piece_seg_[right.value()] = seg;
  // PropagateLocation (3.9) to the superfeatures of a free segment: M_Ω only.
  // New objects are located by a search from the old piece's cells.
  const VertexId start = old_cells.empty() ? VertexId(0) : VertexId(old_cells[0]);
  LinkBallToOmega(left, start);
  LinkBallToOmega(right, start);
  LinkVertexBallToOmega(vb, start);
  // 𝒱 = {u, w} changed, 𝒱' = {u, mid, w}: Skinny₁ refresh (Figure 3.5).
  m.BumpCell(u);
  m.BumpCell(w);
  RefreshSegmentEvents(seg, u);
  RefreshSegmentEvents(seg, mid);
  RefreshSegmentEvents(seg, w);
  return absl::OkStatus();
}

// ---------------------------------------------------------------- checks

absl::Status Refiner::CheckInvariants(bool final) {
  const delaunay::Delaunay3& dt = omega_.dt();
  // New tets locally Delaunay (hence globally): the kernel's full check.
  absl::Status s = dt.Validate(/*check_empty_sphere=*/true);
  if (!s.ok()) return s;
  if (!blg_.Validate()) return absl::InternalError("SVRC invariant: BLG directions disagree");
  if (!queues_.Validate()) return absl::InternalError("SVRC invariant: work queues corrupt");
  // Every unresolved point (input or segment point) is linked to exactly one
  // cell of M_Ω, that cell contains it, and the cell has an Unresolved event.
  for (uint32_t i = 0; i < points_.size(); ++i) {
    const PointId p(i);
    const BallId b = VertexBallOf(p);
    if (!b.valid() || points_.InMesh(p, kOmegaMesh)) continue;
    if (final) return absl::InternalError(absl::StrCat("SVRC invariant: point ", i, " not in M_Ω"));
    std::vector<uint32_t> cells;
    blg_.CellsOf(LocationObject::Ball(b), kOmegaMesh, &cells);
    if (cells.size() != 1) {
      return absl::InternalError(absl::StrCat("SVRC invariant: point ", i, " linked to ", cells.size(), " cells"));
    }
    const Vec3& q = points_.Xyz(p);
    const Vec3& pu = dt.Point(VertexId(cells[0]));
    for (uint32_t w = 0; w < dt.NumVertices(); ++w) {
      if (geom::CompareDistance(q, pu, dt.Point(VertexId(w))) > 0) {
        return absl::InternalError(absl::StrCat("SVRC invariant: point ", i, " linked to cell ", cells[0],
                                                " but vertex ", w, " is nearer"));
      }
    }
    if (!queues_.IsQueued(omega_.UnresolvedEvent(VertexId(cells[0])))) {
      return absl::InternalError(absl::StrCat("SVRC invariant: cell ", cells[0], " holds unresolved point ", i,
                                              " but has no Unresolved event"));
    }
  }
  // Every τ-skinny cell owns a live Skinny event; at the end there is none.
  for (uint32_t w = 0; w < dt.NumVertices(); ++w) {
    const VertexId v(w);
    const CellSize cs = omega_.Size(v);
    if (!IsSkinny(cs)) continue;
    if (final) {
      return absl::InternalError(absl::StrCat("SVRC invariant: cell ", w, " skinny at the end: R/r = ",
                                              cs.outradius / cs.inradius));
    }
    const EventHandle h = omega_.SkinnyEvent(v);
    if (!queues_.IsQueued(h) || queues_.Get(h).generation != omega_.CellGeneration(v)) {
      return absl::InternalError(absl::StrCat("SVRC invariant: skinny cell ", w, " has no live Skinny event"));
    }
  }
  for (uint32_t sg = 0; sg < segs_.size(); ++sg) {
    SegmentMesh& m = segs_[sg];
    for (uint32_t v = 0; v != SegmentMesh::kNil; v = m.Next(v)) {
      if (IsSkinny(m.Size(v))) {
        if (final || !queues_.IsQueued(m.SkinnyEvent(v))) {
          return absl::InternalError(absl::StrCat("SVRC invariant: segment ", sg, " cell ", v, " skinny without event"));
        }
      }
      if (m.Next(v) == SegmentMesh::kNil) break;
      // Every piece ball with a native M_Ω vertex inside is queued; with only
      // non-native encroachers, the first is recorded (Figure 3.10). At the
      // end no piece ball is encroached and every piece is a Delaunay edge.
      const BallId b = m.PieceBall(v);
      if (!balls_.IsAlive(b)) return absl::InternalError("SVRC invariant: dead piece ball in a segment mesh");
      for (uint32_t w = 0; w < dt.NumVertices(); ++w) {
        const VertexId x(w);
        if (!Encroaches(b, x)) continue;
        if (final) {
          return absl::InternalError(absl::StrCat("SVRC invariant: piece ", v, " of segment ", sg,
                                                  " encroached at the end by vertex ", w));
        }
        const bool native = points_.CdOf(omega_.PointOf(x)).dim == 3;
        if (native && !balls_.EncroachQueued(b)) {
          return absl::InternalError(absl::StrCat("SVRC invariant: piece ", v, " of segment ", sg,
                                                  " encroached by native vertex ", w, " but not queued"));
        }
        if (!native && !balls_.EncroachQueued(b) && !balls_.FirstEncroacher(b).valid()) {
          return absl::InternalError(absl::StrCat("SVRC invariant: piece ", v, " of segment ", sg,
                                                  " encroached by vertex ", w, " but no encroacher recorded"));
        }
      }
    }
  }
  if (final && !queues_.empty()) return absl::InternalError("SVRC invariant: events left at the end");
  return absl::OkStatus();
}

PointSetRefinement Refiner::Output(std::span<const Vec3> input) {
  const delaunay::Delaunay3& dt = omega_.dt();
  PointSetRefinement out;
  out.num_input = num_input_;
  out.positions.resize(points_.size());
  for (uint32_t i = 0; i < points_.size(); ++i) {
    // Inputs come back bit-exactly from the original array; Steiner points
    // through the exact-scale, one-rounding back map.
    out.positions[i] = i < num_input_ ? input[i] : norm_.Backward(points_.Xyz(PointId(i)));
  }
  out.input_vertex.resize(num_input_);
  for (uint32_t i = 0; i < num_input_; ++i) out.input_vertex[i] = duplicate_of_[i];
  for (TetId t : dt.FiniteTets()) {
    std::array<uint32_t, 4> tet;
    for (int k = 0; k < 4; ++k) tet[k] = omega_.PointOf(dt.TetVertex(t, k)).value();
    out.tets.push_back(tet);
  }
  out.omega.Add(norm_.Backward(omega_.cube().lo));
  out.omega.Add(norm_.Backward(omega_.cube().hi));
  for (uint32_t sg = 0; sg < segs_.size(); ++sg) {
    const SegmentMesh& m = segs_[sg];
    std::vector<uint32_t> chain;
    for (uint32_t v = 0; v != SegmentMesh::kNil; v = m.Next(v)) chain.push_back(m.PointOf(v).value());
    if (chain.front() != seg_input_a_[sg]) std::reverse(chain.begin(), chain.end());
    out.segment_chains.push_back(std::move(chain));
  }

  RefineStats& st = stats_;
  st.vertices = dt.NumVertices();
  st.input_vertices = num_input_ - st.duplicates;
  st.steiner_vertices = st.vertices - 8 - st.input_vertices - st.segment_vertices;
  const WorkQueues::Stats& q = queues_.stats();
  for (int i = 0; i < kNumEventTypes; ++i) {
    st.events_pushed[i] = q.pushed[i];
    st.events_popped[i] = q.popped[i];
    st.events_stale[i] = q.stale[i];
  }
  st.buckets_walked = q.buckets_walked;
  st.max_bucket_walk = q.max_walk_one_op;
  st.links_added = blg_.stats().links_added;
  st.links_removed = blg_.stats().links_removed;
  st.clipped_cells = omega_.stats().clipped_queries;
  std::vector<VertexId> nbrs;
  for (uint32_t w = 0; w < dt.NumVertices(); ++w) {
    dt.Neighbors(VertexId(w), &nbrs);
    st.max_degree = std::max<uint32_t>(st.max_degree, static_cast<uint32_t>(nbrs.size()));
    const CellSize cs = omega_.Size(VertexId(w));
    if (cs.inradius > 0) st.max_aspect = std::max(st.max_aspect, cs.outradius / cs.inradius);
  }
  out.stats = st;
  return out;
}

}  // namespace

void RefineStats::ExportTo(mesh::MeshStats* out) const {
  static const char* kTypes[] = {"skinny", "encroached", "unresolved", "collar"};
  out->Set("svrc.vertices", static_cast<double>(vertices));
  out->Set("svrc.vertices_dim0", static_cast<double>(input_vertices));
  out->Set("svrc.vertices_dim1", static_cast<double>(segment_vertices));
  out->Set("svrc.vertices_dim3", static_cast<double>(steiner_vertices));
  out->Set("svrc.insertions", static_cast<double>(insertions));
  out->Set("svrc.warps", static_cast<double>(warps));
  out->Set("svrc.yields", static_cast<double>(yields));
  for (int i = 0; i < 4; ++i) {
    out->Set(absl::StrCat("svrc.events_pushed.", kTypes[i]), static_cast<double>(events_pushed[i]));
    out->Set(absl::StrCat("svrc.events_popped.", kTypes[i]), static_cast<double>(events_popped[i]));
    out->Set(absl::StrCat("svrc.events_stale.", kTypes[i]), static_cast<double>(events_stale[i]));
  }
  out->Set("svrc.buckets_walked", static_cast<double>(buckets_walked));
  out->Set("svrc.links_added", static_cast<double>(links_added));
  out->Set("svrc.links_removed", static_cast<double>(links_removed));
  out->Set("svrc.max_degree", max_degree);
  out->Set("svrc.max_aspect", max_aspect);
  out->Set("svrc.predicate_calls", static_cast<double>(predicate_calls));
  out->Set("svrc.predicate_exact", static_cast<double>(predicate_exact));
  out->Set("svrc.predicate_sos", static_cast<double>(predicate_sos));
  out->Set("svrc.seconds_refine", seconds);
}

absl::StatusOr<PointSetRefinement> RefinePointsAndSegments(std::span<const Vec3> points,
                                                           std::span<const SegmentInput> segments,
                                                           const RefineOptions& options) {
  if (!(options.tau > 0) || !(options.theta > 0 && options.theta < 1)) {
    return absl::InvalidArgumentError("SVRC: need tau > 0 and 0 < theta < 1");
  }
  absl::StatusOr<Normalization> norm = ChooseNormalization(points);
  if (!norm.ok()) return norm.status();
  std::vector<Vec3> normalised(points.size());
  geom::Box3 box;
  for (size_t i = 0; i < points.size(); ++i) {
    normalised[i] = norm->Forward(points[i]);
    box.Add(normalised[i]);
  }
  // Ω: a cube of side 3·diam centred on the input's box (Definition 35); a
  // single point gets a unit cube.
  const double diam = box.Diagonal();
  const double half = diam > 0 ? 1.5 * diam : 0.5;
  Refiner refiner(options, *norm, box.Center(), half);
  absl::Status s = refiner.Initialize(normalised, segments);
  if (!s.ok()) return s;
  s = refiner.Run();
  if (!s.ok()) return s;
  if (options.validate_every > 0) {
    s = refiner.CheckInvariants(/*final=*/true);
    if (!s.ok()) return s;
  }
  return refiner.Output(points);
}

absl::StatusOr<PointSetRefinement> RefinePointSet(std::span<const Vec3> points,
                                                  const RefineOptions& options) {
  return RefinePointsAndSegments(points, {}, options);
}

}  // namespace svrc::refine
