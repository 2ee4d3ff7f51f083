// The global point table of SVRC (guide §2 "Global points"): every input point
// and every Steiner point of every feature mesh, with its coordinates, parent
// feature and containment dimension (Definition 36), crease flag (set at
// creation, Th. §5.1.1) and its membership in feature meshes (mesh, vertex).
#pragma once

#include <cstdint>
#include <vector>

#include "core/geometry/vec3.h"
#include "core/svrc/containment.h"
#include "core/svrc/ids.h"
#include "core/util/pod_vector.h"

namespace svrc::refine {

class PointStore {
 public:
  // Adds a point. Global ids are dense and in creation order; they are also the
  // SoS priorities in every mesh (guide §5 item 2: one global order everywhere).
  PointId Add(const geom::Vec3& xyz, FeatureId parent, Cd cd, bool crease = false);

  uint32_t size() const { return static_cast<uint32_t>(xyz_.size()); }
  const geom::Vec3& Xyz(PointId p) const { return xyz_[p.value()]; }
  FeatureId Parent(PointId p) const { return parent_[p.value()]; }
  Cd CdOf(PointId p) const { return cd_[p.value()]; }
  bool IsCrease(PointId p) const { return crease_[p.value()] != 0; }

  // Membership: p is vertex `vertex` of mesh `mesh`.
  void SetVertex(PointId p, MeshId mesh, uint32_t vertex);
  // The vertex of p in `mesh`, or kNoneValue if p is not (yet) in it.
  uint32_t VertexIn(PointId p, MeshId mesh) const;
  bool InMesh(PointId p, MeshId mesh) const { return VertexIn(p, mesh) != kNoVertex; }
  static constexpr uint32_t kNoVertex = 0xFFFFFFFFu;

 private:
  static constexpr uint32_t kNil = 0xFFFFFFFFu;
  struct Membership {
    MeshId mesh;
    uint32_t vertex;
    uint32_t next;
  };
  util::PodVector<geom::Vec3> xyz_;
  util::PodVector<FeatureId> parent_;
  util::PodVector<Cd> cd_;
  util::PodVector<uint8_t> crease_;
  util::PodVector<uint32_t> member_head_;
  util::PodVector<Membership> members_;  // a singly-linked list per point; few entries each
};

}  // namespace svrc::refine
