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

  uint32_t size() const { return static_cast<uint32_t>(center_.size()); }
  uint32_t NumAlive() const { return num_alive_; }

  const geom::Vec3& Center(BallId b) const { return center_[b.value()]; }
  double Radius(BallId b) const { return radius_[b.value()]; }
  BallKind Kind(BallId b) const { return kind_[b.value()]; }
  FeatureId Feature(BallId b) const { return feature_[b.value()]; }
  MeshId Mesh(BallId b) const { return mesh_[b.value()]; }
  Cd CdOf(BallId b) const { return cd_[b.value()]; }  // CD of the centre (Def 36)
  // The dual simplex: 1 (vertex ball), 2 (piece) or 3 (triangle) global points.
  int NumVertices(BallId b) const { return num_verts_[b.value()]; }
  PointId Vertex(BallId b, int i) const { return verts_[b.value()][i]; }
  bool IsVertexBall(BallId b) const { return num_verts_[b.value()] == 1; }
  PointId VertexPoint(BallId b) const { return verts_[b.value()][0]; }

  bool IsAlive(BallId b) const { return alive_[b.value()] != 0; }
  uint32_t Generation(BallId b) const { return generation_[b.value()]; }
  // The ball's dual simplex left its mesh (or the ball was destroyed): dead for
  // good, generation bumped so queued events and links can tell.
  void Kill(BallId b);

  // Figure 3.10's encroachment trap. `native`: CD(v) = dim of the mesh whose
  // cell v is (v was created in that mesh). A non-native encroacher only
  // triggers on the second *different* encroacher; re-linking the same vertex
  // after its cell changed must not count twice (guide §7).
  EncroachOutcome RecordEncroacher(BallId b, PointId v, bool native);
  PointId FirstEncroacher(BallId b) const { return first_encroacher_[b.value()]; }

  // An Encroached event for b is pending (avoids duplicate events).
  bool EncroachQueued(BallId b) const { return encroach_queued_[b.value()] != 0; }
  void SetEncroachQueued(BallId b, bool q) { encroach_queued_[b.value()] = q ? 1 : 0; }

 private:
  BallId Add(BallKind kind, const geom::Vec3& center, double radius, FeatureId feature, MeshId mesh,
             Cd cd, int n, std::array<PointId, 3> verts);

  std::vector<geom::Vec3> center_;
  std::vector<double> radius_;
  std::vector<BallKind> kind_;
  std::vector<FeatureId> feature_;
  std::vector<MeshId> mesh_;
  std::vector<Cd> cd_;
  std::vector<uint8_t> num_verts_;
  std::vector<std::array<PointId, 3>> verts_;
  std::vector<uint8_t> alive_;
  std::vector<uint32_t> generation_;
  std::vector<PointId> first_encroacher_;
  std::vector<uint8_t> encroach_queued_;
  uint32_t num_alive_ = 0;
};

}  // namespace svrc::refine
