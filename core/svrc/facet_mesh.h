// The 2D feature mesh M_F of a facet F (thesis §3.1, Definition 35): a Delaunay
// triangulation in F's plane frame inside the bounding square Ω_F (side
// 3·diam(F), seeded with its 4 corners), the "triangle in F" classification
// (guide §5 item 4) and R_v/r_v of cells clipped to Ω_F (Definition 11, Lemma 3).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "core/delaunay/delaunay2.h"
#include "core/geometry/vec3.h"
#include "core/plc/features.h"
#include "core/svrc/balls.h"
#include "core/svrc/ids.h"
#include "core/svrc/normalize.h"
#include "core/svrc/work_queue.h"

namespace svrc::refine {

// F's region in its frame: polygon loops (holes flagged) and every segment of
// the facet, in uv coordinates (the only coordinates M_F reads;
// docs/svrc-design.md §2). Points carry their global ids (SoS priorities).
struct FacetRegion {
  struct Loop {
    std::vector<geom::Vec2> uv;
    std::vector<PointId> points;  // same length as uv
    bool is_hole = false;
    double abs_area = 0;          // |shoelace area|, for the innermost-loop rule
  };
  std::vector<Loop> loops;
  // Every segment of F (boundary and in-facet), as uv endpoint pairs.
  std::vector<std::array<geom::Vec2, 2>> segments;
  std::vector<std::array<PointId, 2>> segment_points;
  std::vector<uint32_t> segment_ids;  // the complex's segment id of each

  // Isolated points in F's interior (they become vertices of M_F as well).
  std::vector<geom::Vec2> interior_uv;
  std::vector<PointId> interior_points;
  // Every point of F once (loop points, endpoints of its segments — in-facet
  // segments are not loops —, interior points), by increasing global id: the
  // vertices M_F must contain.
  std::vector<geom::Vec2> all_uv;
  std::vector<PointId> all_points;
  // Fills all_uv/all_points from loops, segments and interior points.
  void CollectPoints();

  // Adds a loop (computes its area).
  void AddLoop(std::vector<geom::Vec2> uv, std::vector<PointId> points, bool is_hole);

  // Where p lies with respect to F (exact Orient2d crossing tests): inside
  // iff some loop strictly contains p and the innermost such loop (smallest
  // area: valid loops are nested or disjoint) is not a hole.
  enum class Where : uint8_t { kOutside, kInside, kOnBoundary };
  Where Locate(geom::Vec2 p) const;

  // True iff a segment of F meets the open triangle abc (counter-clockwise).
  // Exact: the open triangle and the closed segment are disjoint iff one of
  // the triangle's edge lines or the segment's line separates them.
  bool CrossesSegment(geom::Vec2 a, geom::Vec2 b, geom::Vec2 c) const;

  // "Triangle in F" (guide §5 item 4): its centroid is inside F, or it meets
  // a segment of F (straddling triangles count until the segments conform).
  bool TriangleInFacet(geom::Vec2 a, geom::Vec2 b, geom::Vec2 c) const;

  // Bounding box of all loop points in uv.
  geom::Vec2 lo{0, 0}, hi{0, 0};
};

// True iff the closed segment s0s1 meets the open counter-clockwise triangle
// abc (exact: one of the triangle's edge lines or the segment's line
// separates them, the separating-axis theorem in 2D).
bool TriangleMeetsSegment(geom::Vec2 a, geom::Vec2 b, geom::Vec2 c, geom::Vec2 s0, geom::Vec2 s1);
namespace internal {
// The same by the side tests alone, without TriangleMeetsSegment's bounding-box
// reject (for the test that the reject never changes the answer).
bool TriangleMeetsSegmentBySides(geom::Vec2 a, geom::Vec2 b, geom::Vec2 c, geom::Vec2 s0, geom::Vec2 s1);
}  // namespace internal

// Builds F's region in the *normalised* frame: the frame's origin goes through
// the same exact map as the points (its u, v are unchanged: the map is a
// translation and a power-of-two scale), and every point of F is projected
// once into uv (rounded once, never recomputed; design §2). `point_ids[i]` is
// the global id of complex point i. Returns the normalised frame too.
FacetRegion BuildFacetRegion(const plc::FeatureComplex& complex, uint32_t facet,
                             const Normalization& norm, std::span<const PointId> point_ids,
                             plc::FacetFrame* normalised_frame);

// R_v (clipped to Ω_F), r_v and the farthest corner of a facet-mesh cell.
struct CellSize2 {
  double outradius = 0;
  double inradius = 0;
  geom::Vec2 corner;
  delaunay::Delaunay2::TriId hint;  // a triangle incident to v near the corner
  bool clipped = false;
};

class FacetMesh {
 public:
  using Delaunay2 = delaunay::Delaunay2;
  using VertexId2 = Delaunay2::VertexId;
  using TriId2 = Delaunay2::TriId;

  // Ω_F: the square of side 3·diam(F) (diam = diagonal of the uv box) centred
  // on F's uv box; its corners get the global ids `corner_ids` (lo, (hi,lo),
  // hi, (lo,hi)).
  FacetMesh(FacetRegion region, const std::array<PointId, 4>& corner_ids);

  const FacetRegion& region() const { return region_; }
  const Delaunay2& dt() const { return dt_; }
  geom::Vec2 SquareLo() const { return square_lo_; }
  geom::Vec2 SquareHi() const { return square_hi_; }
  // Corner i of Ω_F in the order of the constructor.
  geom::Vec2 Corner(int i) const;
  // Vertex i < 4 of M_F: a corner of the Delaunay quadrilateral, the square
  // of 3× Ω_F's side around it. Ω_F's cells are clipped to Ω_F, whose sides
  // are then strictly inside the triangulated square, so the clipped cell
  // corners on ∂Ω_F can be inserted like any Voronoi corner (as ∂Ω's in
  // M_Ω; docs/svrc-design.md §10). The 4 vertices' cells meet Ω_F in a
  // corner region only, shrinking to nothing as ∂Ω_F is sampled.
  geom::Vec2 QuadCorner(int i) const { return dt_.Point(VertexId2(static_cast<uint32_t>(i))); }

  // Inserts p (uv, strictly inside Ω_F) as global point `id`; registers the
  // vertex and bumps the cells of the cavity boundary (Figure 3.5's 𝒱').
  Delaunay2::InsertResult Insert(geom::Vec2 uv, PointId id, TriId2 hint = Delaunay2::kNoneTri);

  PointId PointOf(VertexId2 v) const { return point_of_[v.value()]; }
  uint32_t NumVertices() const { return dt_.NumVertices(); }

  // "Triangle in F" for a live triangle of M_F (guide §5 item 4): the
  // centroid inside F, or straddling a segment of F — decided with the
  // vertices known to lie on each segment (SetOnSegment, and the segments'
  // endpoints), not by rounding (see facet_mesh.cc).
  bool InFacet(TriId2 t) const;
  // Triangle t meets the open part (a, b) of region segment k's line, decided
  // as InFacet decides it: two vertices of t on segment k (an edge of t on
  // its line) never meet it, whatever the rounding of a and b says; one
  // vertex on it, only if the other two are strictly on opposite sides.
  bool MeetsSegmentPart(TriId2 t, size_t k, geom::Vec2 a, geom::Vec2 b) const;
  // The index k in region().segment_ids of global segment seg, or -1.
  int32_t RegionSegment(uint32_t seg) const;
  // Vertex v is a point of region segment k (a segment mesh's Steiner point);
  // call before SyncTriangleBalls for the insertion that created v.
  void SetOnSegment(VertexId2 v, int32_t k);
  bool OnSegment(VertexId2 v, size_t k) const;
  // The live in-facet triangles, in slot order, as global point triples.
  std::vector<std::array<PointId, 3>> InFacetTriangles() const;

  // R_v, r_v and the farthest corner of V(v) ∩ Ω_F (Definition 11). Cells
  // whose circumcentres are all in Ω_F use them directly; the others (always
  // the 4 corners, whose cells are unbounded) are computed as Ω_F clipped by
  // the bisector half-plane of each Delaunay neighbour. `hint` is a triangle
  // incident to v (the corner is in the conflict region of one of them).
  CellSize2 Size(VertexId2 v) const;

  // --- triangle ConfBalls (thesis §3.2.2; stage (c) increment 2) ----------
  // The diametral ball of triangle t in 3D: centre = the uv circumcentre
  // mapped through `frame` (rounded once), radius = the uv circumradius
  // (design §2: M_F decides in uv; M_Ω tests encroachment on xyz with
  // InTriangleCircumball3d).
  void TriangleBall(TriId2 t, const plc::FacetFrame& frame, geom::Vec3* center,
                    double* radius) const;
  // Keeps one ConfBall per live in-facet triangle: kills the balls of the
  // triangles `r` destroyed, adds balls for the in-facet triangles it created
  // (in-facet status is fixed per triangle: it depends only on its vertices).
  // `added` (optional) receives the new balls, for linking into M_Ω. Call once
  // per Insert, with its result, before the next Insert.
  // `killed` (optional) receives the balls it killed, for unlinking.
  void SyncTriangleBalls(const Delaunay2::InsertResult& r, const plc::FacetFrame& frame,
                         FeatureId feature, MeshId mesh, BallStore* balls,
                         std::vector<BallId>* added = nullptr,
                         std::vector<BallId>* killed = nullptr);
  // All live in-facet triangles get balls (after the initial inserts).
  void CreateAllTriangleBalls(const plc::FacetFrame& frame, FeatureId feature, MeshId mesh,
                              BallStore* balls, std::vector<BallId>* added = nullptr);
  // The ball of live triangle t (kNoneBall if t is not in F).
  BallId TriBall(TriId2 t) const {
    return t.value() < tri_ball_.size() ? tri_ball_[t.value()] : kNoneBall;
  }

  void BumpCell(VertexId2 v) { ++cell_gen_[v.value()]; }
  uint32_t CellGeneration(VertexId2 v) const { return cell_gen_[v.value()]; }
  EventHandle& SkinnyEvent(VertexId2 v) { return skinny_event_[v.value()]; }
  EventHandle& UnresolvedEvent(VertexId2 v) { return unresolved_event_[v.value()]; }

 private:
  void Register(VertexId2 v, PointId p);

  FacetRegion region_;
  geom::Vec2 square_lo_, square_hi_;
  Delaunay2 dt_;
  std::vector<PointId> point_of_;
  std::vector<uint32_t> cell_gen_;
  std::vector<EventHandle> skinny_event_, unresolved_event_;
  std::vector<BallId> tri_ball_;  // by triangle slot; kNoneBall: none
  // InFacet of each live triangle, by slot, as SyncTriangleBalls and
  // CreateAllTriangleBalls found it (InFacetTriangles reads it).
  static constexpr uint8_t kInFacetUnknown = 0, kInFacetNo = 1, kInFacetYes = 2;
  std::vector<uint8_t> in_facet_;
  std::vector<int32_t> on_segment_;  // per vertex: region segment it lies on, -1: none
  mutable std::vector<Delaunay2::TriId> star_;
  mutable std::vector<VertexId2> nbrs_;
  mutable std::vector<geom::Vec2> poly_, scratch_;
};

}  // namespace svrc::refine
