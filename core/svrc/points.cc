// Global point table (see points.h).
#include "core/svrc/points.h"

namespace svrc::refine {

PointId PointStore::Add(const geom::Vec3& xyz, FeatureId parent, Cd cd, bool crease) {
  const PointId id(size());
  xyz_.push_back(xyz);
  parent_.push_back(parent);
  cd_.push_back(cd);
  crease_.push_back(crease ? 1 : 0);
  member_head_.push_back(kNil);
  return id;
}

void PointStore::SetVertex(PointId p, MeshId mesh, uint32_t vertex) {
  for (uint32_t m = member_head_[p.value()]; m != kNil; m = members_[m].next) {
    if (members_[m].mesh == mesh) {
      members_[m].vertex = vertex;
      return;
    }
  }
  members_.push_back({mesh, vertex, member_head_[p.value()]});
  member_head_[p.value()] = static_cast<uint32_t>(members_.size() - 1);
}

uint32_t PointStore::VertexIn(PointId p, MeshId mesh) const {
  for (uint32_t m = member_head_[p.value()]; m != kNil; m = members_[m].next) {
    if (members_[m].mesh == mesh) return members_[m].vertex;
  }
  return kNoVertex;
}

}  // namespace svrc::refine
