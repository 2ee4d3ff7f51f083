// The SVRC refiner, stage (a) of the guide's plan (point-set SVR on M_Ω).
// Figure numbers are the thesis'. See refiner.h and docs/svrc-design.md.
#include "core/svrc/refiner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <tuple>

#include "absl/strings/str_cat.h"
#include "core/geometry/predicates.h"
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

class PointSetRefiner {
 public:
  PointSetRefiner(const RefineOptions& options, Normalization norm, const Vec3& center, double half)
      : options_(options), norm_(norm), omega_(center, half) {}

  absl::Status Initialize(std::span<const Vec3> normalised);
  absl::Status Run();
  absl::Status CheckInvariants(bool final);
  PointSetRefinement Output(std::span<const Vec3> input);

 private:
  // Figure 3.4. One call = one insertion into M_Ω.
  absl::Status Destroy(const WorkEvent& event);
  // Figure 3.5 with UpdateLocation (3.6) for F = Ω: relocate the 0-balls of
  // the changed cells, refresh the events of 𝒱'.
  absl::Status ForceInsert(PointId p, TetId hint);
  // The "v' is the centre of some work event" loop of Figure 3.5.
  void RefreshEvents(VertexId v);
  // PropagateLocation (3.9) of a new 0-ball into M_Ω: link it to the cell
  // containing its point; the cell becomes Unresolved.
  void LinkVertexBall(BallId b, VertexId near_hint);
  bool IsLive(const WorkEvent& event);
  bool IsSkinny(const CellSize& s) const { return s.outradius > options_.tau * s.inradius; }
  VertexId VertexOf(PointId p) const {
    const uint32_t v = points_.VertexIn(p, kOmegaMesh);
    return v == PointStore::kNoVertex ? VertexId() : VertexId(v);
  }

  RefineOptions options_;
  Normalization norm_;
  FeatureTable features_;
  PointStore points_;
  BallStore balls_;
  LocationGraph blg_;
  WorkQueues queues_;
  OmegaMesh omega_;
  uint32_t num_input_ = 0;
  std::vector<BallId> input_ball_;  // 0-ball of each input point (none for duplicates)
  std::vector<uint32_t> duplicate_of_;  // first input point with the same coordinates
  RefineStats stats_;
  uint64_t budget_ = 0;
  // The cell size computed by IsLive for the event Destroy gets next.
  CellSize last_size_;
  VertexId last_size_vertex_;
  uint32_t last_size_gen_ = 0;
  // Scratch.
  std::vector<VertexId> bfs_, nbrs_;
  std::vector<uint32_t> mark_;
  uint32_t stamp_ = 0;
  std::vector<BallId> balls_scratch_;
  std::vector<LocationObject> objects_;
};

absl::Status PointSetRefiner::Initialize(std::span<const Vec3> normalised) {
  num_input_ = static_cast<uint32_t>(normalised.size());
  features_ = FeatureTable::ForPointSet(num_input_);
  budget_ = options_.max_vertices != 0 ? options_.max_vertices
                                       : std::max<uint64_t>(1'000'000, 1000ull * num_input_);
  // Global ids = SoS priorities: inputs first (in input order), then corners.
  for (uint32_t i = 0; i < num_input_; ++i) {
    points_.Add(normalised[i], features_.OfPoint(i), kCdInputVertex);
  }
  std::array<PointId, 8> corners;
  for (int i = 0; i < 8; ++i) corners[i] = points_.Add(omega_.Corner(i), FeatureTable::Omega(), kCdSpace);
  omega_.SeedCorners(corners);
  for (int i = 0; i < 8; ++i) {
    points_.SetVertex(corners[i], kOmegaMesh, omega_.dt().NumVertices() - 8 + i);
  }
  // Figure 3.3: UpdateLocation(∅, M_F, F) for every feature, lowest dimension
  // first. For a point feature M_F = {p}: one 0-ball, propagated to Ω.
  // Exact duplicates are one feature point ("plc" merges them for PLCs; a raw
  // point set may still have them): the later copies become members of the
  // first one's vertex when it is inserted and get no 0-ball, otherwise the
  // copy would sit at a vertex forever, never within θr of a Voronoi corner.
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
      duplicate_of_[i] = (k > 0 && normalised[order[k - 1]] == normalised[i]) ? duplicate_of_[order[k - 1]] : i;
    }
  }
  input_ball_.resize(num_input_);
  VertexId hint(0);
  for (uint32_t i = 0; i < num_input_; ++i) {
    if (duplicate_of_[i] != i) {
      ++stats_.duplicates;
      continue;
    }
    const FeatureId f = features_.OfPoint(i);
    input_ball_[i] = balls_.AddVertexBall(PointId(i), normalised[i], f, MeshId(f.value()), kCdInputVertex);
    LinkVertexBall(input_ball_[i], hint);
  }
  for (uint32_t v = 0; v < omega_.NumVertices(); ++v) RefreshEvents(VertexId(v));
  return absl::OkStatus();
}

void PointSetRefiner::LinkVertexBall(BallId b, VertexId near_hint) {
  const Vec3& q = balls_.Center(b);
  const TetId hint = near_hint.valid() ? omega_.dt().VertexTet(near_hint) : TetId();
  const VertexId cell = omega_.dt().NearestVertex(q, hint);
  LinkFacts facts;
  facts.unresolved = true;
  blg_.AddLink(kOmegaMesh, cell.value(), LocationObject::Ball(b), facts, &balls_);
}

void PointSetRefiner::RefreshEvents(VertexId v) {
  const CellSize s = omega_.Size(v);
  const uint32_t gen = omega_.CellGeneration(v);
  // Unresolved: the cell holds a 0-ball whose point is not yet in M_Ω. Built as
  // the gap ball ⟨(farthest corner, R_v), Ω⟩ (guide §3 on Figure 3.11).
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

bool PointSetRefiner::IsLive(const WorkEvent& e) {
  const VertexId v(e.object);
  if (omega_.CellGeneration(v) != e.generation) return false;
  if (e.type == EventType::kUnresolved) return blg_.NumUnresolved(kOmegaMesh, v.value()) > 0;
  last_size_ = omega_.Size(v);
  last_size_vertex_ = v;
  last_size_gen_ = omega_.CellGeneration(v);
  if (e.type == EventType::kSkinny) return IsSkinny(last_size_);
  return true;
}

absl::Status PointSetRefiner::Run() {
  const auto start = std::chrono::steady_clock::now();
  const geom::PredicateStats pred0 = geom::GetPredicateStats();
  auto live = [this](const WorkEvent& e) { return IsLive(e); };
  while (std::optional<WorkEvent> event = queues_.DequeueLive(live)) {
    if (omega_.dt().NumVertices() >= budget_) {
      return absl::ResourceExhaustedError(absl::StrCat(
          "SVRC: vertex budget of ", budget_, " reached with ", queues_.size(), " events pending"));
    }
    if (options_.poll && stats_.insertions % options_.poll_interval == 0) {
      absl::Status s = options_.poll();
      if (!s.ok()) return s;
    }
    absl::Status s = Destroy(*event);
    if (!s.ok()) return s;
    if (options_.validate_every > 0 && stats_.insertions % options_.validate_every == 0) {
      s = CheckInvariants(false);
      if (!s.ok()) return s;
    }
  }
  const geom::PredicateStats& pred = geom::GetPredicateStats();
  stats_.predicate_calls = pred.TotalCalls() - pred0.TotalCalls();
  stats_.predicate_exact = pred.TotalExact() - pred0.TotalExact();
  stats_.predicate_sos = pred.TotalSos() - pred0.TotalSos();
  stats_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return absl::OkStatus();
}

absl::Status PointSetRefiner::Destroy(const WorkEvent& event) {
  // Line 1 (stale test) was done at Dequeue. The gap ball is rebuilt from the
  // cell now: ⟨(farthest corner of V(v) ∩ Ω, R_v), Ω⟩; CD(B) = CD(c) = (3,3).
  const VertexId v(event.object);
  const CellSize s = (last_size_vertex_ == v && last_size_gen_ == omega_.CellGeneration(v)) ? last_size_
                                                                                             : omega_.Size(v);
  const Vec3 c = s.corner;
  const double r = s.outradius;
  const Cd cd_ball = kCdSpace;

  // Line 2: 𝒱 = cells of M_Ω meeting B(c, r). Any x ∈ V(u) ∩ B has
  // |ux| ≤ |vx| ≤ 2r (v is nearest to c at distance r), so |uc| ≤ 3r: a BFS
  // over Delaunay neighbours restricted to that conservative superset finds
  // every cell meeting B (they form a connected set) — guide §3 allows
  // conservative inflation for location.
  // Filter: V(u) lies in the half-space of points nearer to u than to v, which
  // meets B(c, r) only if the signed distance from c to the bisector of uv,
  // (|uc|² − |vc|²) / (2|uv|), is at most r. The true set of cells meeting B
  // is connected and inside this superset, so a BFS over it from v finds all
  // of them (guide §3: conservative inflation is fine for location); the
  // relative slack keeps rounding on the conservative side.
  const Vec3& pv = omega_.dt().Point(v);
  const double vc2 = geom::Dist2(pv, c);
  auto may_meet = [&](const Vec3& pu) {
    return geom::Dist2(pu, c) - vc2 <= 2.0 * r * geom::Dist(pu, pv) * (1 + 1e-9) + 1e-12 * vc2;
  };
  ++stamp_;
  if (mark_.size() < omega_.NumVertices()) mark_.resize(omega_.NumVertices(), 0);
  bfs_.clear();
  // No ball is linked to any cell of M_Ω: 𝓑 = ∅, so 𝒲 = 𝒴 = ∅ and the centre
  // is inserted; skip the search.
  if (blg_.NumLinks() == 0) {
    const PointId p = points_.Add(c, FeatureTable::Omega(), kCdSpace);
    return ForceInsert(p, s.hint);
  }
  bfs_.push_back(v);
  mark_[v.value()] = stamp_;
  for (size_t i = 0; i < bfs_.size(); ++i) {
    omega_.dt().Neighbors(bfs_[i], &nbrs_);
    for (VertexId u : nbrs_) {
      if (mark_[u.value()] == stamp_) continue;
      mark_[u.value()] = stamp_;
      if (may_meet(omega_.dt().Point(u))) bfs_.push_back(u);
    }
  }
  stats_.destroy_cells_visited += bfs_.size();
  stats_.max_destroy_cells = std::max<uint64_t>(stats_.max_destroy_cells, bfs_.size());

  // Line 3: 𝓑 = ∪ Balls_Ω(u). Line 4: 𝒲 = 0-balls not yet in M_Ω within θr of c
  // with CD(p) < CD(B) (the printed inequality is reversed by OCR; guide §3).
  BallId warp;
  double warp_d2 = 0;
  const double theta_r2 = (options_.theta * r) * (options_.theta * r);
  for (VertexId u : bfs_) {
    balls_scratch_.clear();
    blg_.BallsOf(kOmegaMesh, u.value(), &balls_scratch_);
    for (BallId b : balls_scratch_) {
      if (!balls_.IsVertexBall(b)) continue;
      const PointId p = balls_.VertexPoint(b);
      if (points_.InMesh(p, kOmegaMesh)) continue;
      if (!(balls_.CdOf(b) < cd_ball)) continue;
      const double d2 = geom::Dist2(balls_.Center(b), c);
      if (d2 > theta_r2) continue;
      // Line 6: lowest CD, then nearest to c, then lowest id (determinism).
      if (!warp.valid()) {
        warp = b;
        warp_d2 = d2;
        continue;
      }
      const Cd a = balls_.CdOf(b), w = balls_.CdOf(warp);
      if (a < w || (a == w && (d2 < warp_d2 || (d2 == warp_d2 && p < balls_.VertexPoint(warp))))) {
        warp = b;
        warp_d2 = d2;
      }
    }
  }
  if (warp.valid()) {
    ++stats_.warps;
    // Start Bowyer–Watson next to the cell the point is linked to.
    std::vector<uint32_t> cells;
    blg_.CellsOf(LocationObject::Ball(warp), kOmegaMesh, &cells);
    const TetId hint = cells.empty() ? s.hint : omega_.dt().VertexTet(VertexId(cells[0]));
    return ForceInsert(balls_.VertexPoint(warp), hint);
  }
  // Line 9: 𝒴 = balls of lower CD with c strictly inside. Stage (a) has only
  // 0-balls, whose interior is empty, so 𝒴 = ∅ and the centre is inserted
  // (line 11). Yielding arrives with segment balls in stage (b).
  const PointId p = points_.Add(c, FeatureTable::Omega(), kCdSpace);
  return ForceInsert(p, s.hint);
}

absl::Status PointSetRefiner::ForceInsert(PointId p, TetId hint) {
  delaunay::Delaunay3& dt = omega_.dt();
  const Vec3 pos = points_.Xyz(p);
  const auto result = dt.Insert(pos, p.value(), hint);
  if (result.outcome == delaunay::Delaunay3::InsertOutcome::kDuplicate) {
    // Only an input point can coincide with a vertex (a Voronoi corner is never
    // a vertex): it is resolved by that vertex.
    if (p.value() >= num_input_) {
      return absl::InternalError(absl::StrCat("SVRC: Steiner point ", p.value(), " duplicates a vertex"));
    }
    ++stats_.duplicates;
    points_.SetVertex(p, kOmegaMesh, result.vertex.value());
    std::vector<uint32_t> cells;
    blg_.RemoveObjectLinks(LocationObject::Ball(input_ball_[p.value()]), kOmegaMesh, &cells);
    for (uint32_t cell : cells) RefreshEvents(VertexId(cell));
    return absl::OkStatus();
  }
  if (result.outcome != delaunay::Delaunay3::InsertOutcome::kInserted) {
    return absl::InternalError("SVRC: M_Ω insertion did not produce a vertex");
  }
  ++stats_.insertions;
  const VertexId nv = result.vertex;
  omega_.AddVertex(nv, p);
  points_.SetVertex(p, kOmegaMesh, nv.value());
  // The inserted point's own 0-ball is resolved in M_Ω: drop its links there.
  if (p.value() < num_input_) {
    blg_.RemoveObjectLinks(LocationObject::Ball(input_ball_[p.value()]), kOmegaMesh, nullptr);
  }
  // Copy: the span points into Delaunay3 scratch, and RefreshEvents queries it.
  const std::vector<VertexId> cavity(result.cavity_vertices.begin(), result.cavity_vertices.end());
  // UpdateLocation (3.6) for F = Ω: no new ConfBalls; re-intersect the lower
  // ConfBalls of the old cells with the new ones. An object in V_old(u) is in
  // V_new(u) or V_new(p): one exact distance comparison decides (ties: the
  // lower global id, as the perturbation does).
  for (VertexId u : cavity) {
    objects_.clear();
    blg_.RemoveCellLinks(kOmegaMesh, u.value(), &objects_);
    const Vec3& pu = dt.Point(u);
    for (const LocationObject& o : objects_) {
      const BallId b(o.id);
      const Vec3& q = balls_.Center(b);
      const int cmp = geom::CompareDistance(q, pu, pos);  // > 0: u is farther
      const bool to_new = cmp > 0 || (cmp == 0 && p.value() < omega_.PointOf(u).value());
      LinkFacts facts;
      facts.unresolved = balls_.IsVertexBall(b) && !points_.InMesh(balls_.VertexPoint(b), kOmegaMesh);
      blg_.AddLink(kOmegaMesh, to_new ? nv.value() : u.value(), o, facts, &balls_);
    }
  }
  // 𝒱' = 𝒱 ∪ {p}: new generations, then DecreaseSize / enqueue (Figure 3.5).
  for (VertexId u : cavity) omega_.BumpCell(u);
  for (VertexId u : cavity) RefreshEvents(u);
  RefreshEvents(nv);
  return absl::OkStatus();
}

absl::Status PointSetRefiner::CheckInvariants(bool final) {
  const delaunay::Delaunay3& dt = omega_.dt();
  // New tets locally Delaunay (hence globally): the kernel's full check.
  absl::Status s = dt.Validate(/*check_empty_sphere=*/true);
  if (!s.ok()) return s;
  if (!blg_.Validate()) return absl::InternalError("SVRC invariant: BLG directions disagree");
  if (!queues_.Validate()) return absl::InternalError("SVRC invariant: work queues corrupt");
  // Every unresolved input point is linked to exactly one cell of M_Ω, and
  // that cell contains it (its vertex is a nearest vertex).
  for (uint32_t i = 0; i < num_input_; ++i) {
    if (duplicate_of_[i] != i || points_.InMesh(PointId(i), kOmegaMesh)) continue;
    if (final) return absl::InternalError(absl::StrCat("SVRC invariant: input point ", i, " not in M_Ω"));
    std::vector<uint32_t> cells;
    blg_.CellsOf(LocationObject::Ball(input_ball_[i]), kOmegaMesh, &cells);
    if (cells.size() != 1) {
      return absl::InternalError(absl::StrCat("SVRC invariant: input point ", i, " linked to ", cells.size(), " cells"));
    }
    const Vec3& q = points_.Xyz(PointId(i));
    const Vec3& pu = dt.Point(VertexId(cells[0]));
    for (uint32_t w = 0; w < dt.NumVertices(); ++w) {
      if (geom::CompareDistance(q, pu, dt.Point(VertexId(w))) > 0) {
        return absl::InternalError(absl::StrCat("SVRC invariant: input point ", i, " linked to cell ", cells[0],
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
  if (final && !queues_.empty()) return absl::InternalError("SVRC invariant: events left at the end");
  return absl::OkStatus();
}

PointSetRefinement PointSetRefiner::Output(std::span<const Vec3> input) {
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
  for (uint32_t i = 0; i < num_input_; ++i) {
    const uint32_t v = points_.VertexIn(PointId(duplicate_of_[i]), kOmegaMesh);
    out.input_vertex[i] = v == PointStore::kNoVertex ? i : omega_.PointOf(VertexId(v)).value();
  }
  for (TetId t : dt.FiniteTets()) {
    std::array<uint32_t, 4> tet;
    for (int k = 0; k < 4; ++k) tet[k] = omega_.PointOf(dt.TetVertex(t, k)).value();
    out.tets.push_back(tet);
  }
  out.omega.Add(norm_.Backward(omega_.cube().lo));
  out.omega.Add(norm_.Backward(omega_.cube().hi));

  RefineStats& st = stats_;
  st.vertices = dt.NumVertices();
  st.input_vertices = num_input_ - st.duplicates;
  st.steiner_vertices = st.vertices - 8 - st.input_vertices;
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

absl::StatusOr<PointSetRefinement> RefinePointSet(std::span<const Vec3> points,
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
  PointSetRefiner refiner(options, *norm, box.Center(), half);
  absl::Status s = refiner.Initialize(normalised);
  if (!s.ok()) return s;
  s = refiner.Run();
  if (!s.ok()) return s;
  if (options.validate_every > 0) {
    s = refiner.CheckInvariants(/*final=*/true);
    if (!s.ok()) return s;
  }
  return refiner.Output(points);
}

}  // namespace svrc::refine
