// Protective balls (thesis §3.2.2). See balls.h.
#include "core/svrc/balls.h"

#include <cmath>
#include "core/util/grow.h"

namespace svrc::refine {

using geom::Vec3;

void DiametralBall(const Vec3& a, const Vec3& b, Vec3* center, double* radius) {
  *center = 0.5 * (a + b);
  *radius = 0.5 * geom::Dist(a, b);
}

void TriangleCircumball(const Vec3& a, const Vec3& b, const Vec3& c, Vec3* center, double* radius) {
  // With u = b−a, w = c−a, n = u×w: the circumcentre is
  //   a + (|u|²(w×n) + |w|²(n×u)) / (2|n|²)
  // (the standard formula; relative to a so that translation does not cost
  // precision). Degenerate triangles give a non-finite centre: callers only
  // build balls of mesh triangles, which are non-degenerate.
  const Vec3 u = b - a, w = c - a;
  const Vec3 n = geom::Cross(u, w);
  const Vec3 rel = (geom::Norm2(u) * geom::Cross(w, n) + geom::Norm2(w) * geom::Cross(n, u)) /
                   (2.0 * geom::Norm2(n));
  *center = a + rel;
  *radius = geom::Norm(rel);
}

BallId BallStore::Add(BallKind kind, const Vec3& center, double radius, FeatureId feature,
                      MeshId mesh, Cd cd, int n, std::array<PointId, 3> verts) {
  Record r;
  r.center = center;
  r.radius = radius;
  r.verts = verts;
  r.generation = 0;
  r.first_encroacher = kNonePoint;
  r.feature = feature;
  r.cd = cd;
  r.num_verts = static_cast<uint8_t>(n);
  r.alive = 1;
  r.kind = kind;
  r.encroach_queued = 0;
  ++num_alive_;
  if (!free_.empty()) {
    const BallId id(free_.back());
    free_.pop_back();
    r.generation = rec_[id.value()].generation;  // bumped by Kill: the dead ball's events stay stale
    rec_[id.value()] = r;
    mesh_[id.value()] = mesh;
    seq_[id.value()] = next_seq_++;
    return id;
  }
  const BallId id(size());
  util::ReserveForAppend(rec_);
  util::ReserveForAppend(mesh_);
  rec_.push_back(r);
  mesh_.push_back(mesh);
  util::ReserveForAppend(seq_);
  seq_.push_back(next_seq_++);
  return id;
}

BallId BallStore::AddVertexBall(PointId p, const Vec3& center, FeatureId feature, MeshId mesh,
                                Cd cd) {
  return Add(BallKind::kConf, center, 0.0, feature, mesh, cd, 1, {p, kNonePoint, kNonePoint});
}

BallId BallStore::AddPieceBall(PointId a, PointId b, const Vec3& pa, const Vec3& pb,
                               FeatureId feature, MeshId mesh) {
  Vec3 c;
  double r;
  DiametralBall(pa, pb, &c, &r);
  return Add(BallKind::kConf, c, r, feature, mesh, kCdSegment, 2, {a, b, kNonePoint});
}

BallId BallStore::AddTriangleBall(PointId a, PointId b, PointId c, const Vec3& center,
                                  double radius, FeatureId feature, MeshId mesh) {
  return Add(BallKind::kConf, center, radius, feature, mesh, kCdFacet, 3, {a, b, c});
}

void BallStore::Kill(BallId b) {
  Record& r = rec_[b.value()];
  if (!r.alive) return;
  r.alive = 0;
  ++r.generation;
  --num_alive_;
  if (recycle_) dying_.push_back(b);
}

EncroachOutcome BallStore::RecordEncroacher(BallId b, PointId v, bool native) {
  if (native) return EncroachOutcome::kEnqueue;
  PointId& first = rec_[b.value()].first_encroacher;
  if (!first.valid()) {
    first = v;
    return EncroachOutcome::kPartial;
  }
  return first == v ? EncroachOutcome::kNothing : EncroachOutcome::kEnqueue;
}

}  // namespace svrc::refine
