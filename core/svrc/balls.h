// Protective balls of SVRC (thesis §3.2.2): conforming balls (ConfBalls) —
// diametral balls of segment pieces and facet triangles lying on their feature,
// radius-0 balls of feature-mesh vertices — and, later, representation balls
// (RepBalls, Definition 38). Struct-of-arrays with alive flags and generations
// (a killed ball's events and links are detectably stale), plus the
// PartiallyEncroached state of Figure 3.10 as "first encroacher" id.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/geometry/vec3.h"
#include "core/svrc/containment.h"
#include "core/svrc/ids.h"
#include "core/util/pod_vector.h"

namespace svrc::refine {

enum class BallKind : uint8_t { kConf = 0, kRep = 1 };

// Diametral ball of segment ab: centre = midpoint, radius = |ab|/2.
void DiametralBall(const geom::Vec3& a, const geom::Vec3& b, geom::Vec3* center, double* radius);
// Smallest ball through a, b, c with its centre in their plane (the
// circumball), computed relative to a (guide §7: constructions in local
// coordinates). For a triangle of a facet mesh prefer the facet-frame version
// (FeatureMeshes) and pass the result to AddTriangleBall.
void TriangleCircumball(const geom::Vec3& a, const geom::Vec3& b, const geom::Vec3& c,
                        geom::Vec3* center, double* radius);

// What AddLink should do after seeing `v` strictly inside a ConfBall
// (Figure 3.10).
enum class EncroachOutcome : uint8_t {
  kNothing,   // same encroacher seen again (a re-link after a cell change): no event
  kPartial,   // first encroacher recorded (PartiallyEncroached := true)
  kEnqueue,   // native encroacher, or a second, different one: enqueue Encroached
};

class BallStore {
 public:
  // A radius-0 ConfBall protecting vertex `p` of M_F (p at `center`).
  BallId AddVertexBall(PointId p, const geom::Vec3& center, FeatureId feature, MeshId mesh, Cd cd);
  // The diametral ConfBall of piece ab of segment `feature` (CD (1,3): its
  // centre is on the segment's interior).
  BallId AddPieceBall(PointId a, PointId b, const geom::Vec3& pa, const geom::Vec3& pb,
                      FeatureId feature, MeshId mesh);
  // The diametral ConfBall of triangle abc of facet `feature`, centre/radius
  // given (CD (2,3)).
  BallId AddTriangleBall(PointId a, PointId b, PointId c, const geom::Vec3& center, double radius,
                         FeatureId feature, MeshId mesh);

  uint32_t size() const { return static_cast<uint32_t>(rec_.size()); }
  uint32_t NumAlive() const { return num_alive_; }

  const geom::Vec3& Center(BallId b) const { return rec_[b.value()].center; }
  double Radius(BallId b) const { return rec_[b.value()].radius; }
  BallKind Kind(BallId b) const { return rec_[b.value()].kind; }
  FeatureId Feature(BallId b) const { return rec_[b.value()].feature; }
  MeshId Mesh(BallId b) const { return mesh_[b.value()]; }
  // The order balls were made in (0, 1, 2, ...): the id while no record is
  // recycled. Destroy's tie-breaks read it instead of the id, so recycling
  // records does not change which ball wins (issue #5).
  uint32_t Seq(BallId b) const { return seq_[b.value()]; }
  Cd CdOf(BallId b) const { return rec_[b.value()].cd; }  // CD of the centre (Def 36)
  // The dual simplex: 1 (vertex ball), 2 (piece) or 3 (triangle) global points.
  int NumVertices(BallId b) const { return rec_[b.value()].num_verts; }
  PointId Vertex(BallId b, int i) const { return rec_[b.value()].verts[i]; }
  bool IsVertexBall(BallId b) const { return rec_[b.value()].num_verts == 1; }
  PointId VertexPoint(BallId b) const { return rec_[b.value()].verts[0]; }

  bool IsAlive(BallId b) const { return rec_[b.value()].alive != 0; }
  uint32_t Generation(BallId b) const { return rec_[b.value()].generation; }
  // The ball's dual simplex left its mesh (or the ball was destroyed): dead,
  // generation bumped so queued events and links can tell.
  void Kill(BallId b);

  // Record recycling (issue #5: on cube --max-volume 1e-4, 4,386 of 8,374
  // records were dead at the end). With it on, a killed ball's record waits
  // until TakeDying hands it to the caller, which makes sure nothing names
  // it any more (links, lists, per-ball arrays) and gives it back with
  // Recycle(); Add then takes the newest recycled record first. A recycled
  // record keeps its generation, so events queued for the dead ball stay
  // stale. Off: ids are never reused.
  void EnableRecycling(bool on) { recycle_ = on; }
  // The balls killed since the last call, into *out (its old contents are
  // dropped; the two buffers trade places, so neither reallocates once warm).
  void TakeDying(std::vector<BallId>* out) {
    out->clear();
    out->swap(dying_);
  }
  void Recycle(BallId b) { free_.push_back(b.value()); }

  // Figure 3.10's encroachment trap. `native`: CD(v) = dim of the mesh whose
  // cell v is (v was created in that mesh). A non-native encroacher only
  // triggers on the second *different* encroacher; re-linking the same vertex
  // after its cell changed must not count twice (guide §7).
  EncroachOutcome RecordEncroacher(BallId b, PointId v, bool native);
  PointId FirstEncroacher(BallId b) const { return rec_[b.value()].first_encroacher; }

  // An Encroached event for b is pending (avoids duplicate events).
  bool EncroachQueued(BallId b) const { return rec_[b.value()].encroach_queued != 0; }
  void SetEncroachQueued(BallId b, bool q) { rec_[b.value()].encroach_queued = q ? 1 : 0; }

 private:
  BallId Add(BallKind kind, const geom::Vec3& center, double radius, FeatureId feature, MeshId mesh,
             Cd cd, int n, std::array<PointId, 3> verts);

  // One cache line per ball (issue #5): Destroy and UpdateLocation read a
  // ball's centre, radius, CD, vertices and liveness together for balls in
  // random id order; as twelve parallel arrays that was one miss per field.
  struct alignas(64) Record {
    geom::Vec3 center;
    double radius = 0;
    std::array<PointId, 3> verts;
    uint32_t generation = 0;
    PointId first_encroacher;
    FeatureId feature;
    Cd cd;
    uint8_t num_verts = 0;
    uint8_t alive = 0;
    BallKind kind = BallKind::kConf;
    uint8_t encroach_queued = 0;
  };
  static_assert(sizeof(Record) == 64);
  util::PodVector<Record> rec_;
  util::PodVector<MeshId> mesh_;  // rarely read
  util::PodVector<uint32_t> seq_;  // rarely read (tie-breaks)
  uint32_t next_seq_ = 0;
  uint32_t num_alive_ = 0;
  bool recycle_ = false;
  std::vector<BallId> dying_;
  std::vector<uint32_t> free_;
};

}  // namespace svrc::refine
