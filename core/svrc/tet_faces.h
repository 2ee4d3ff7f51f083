// Face adjacency of a tetrahedralization without hashing and without a
// global sort (docs/svrc-output.md): the 4T faces are bucketed by their
// smallest vertex (a counting sort) and equal faces are matched inside each
// bucket. Shared by LabelRegions (labelling.h) and the sliver pass (sliver.h).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "absl/functional/function_ref.h"

namespace svrc::refine {

// One face of one tet, in the bucket of its smallest vertex a: its other
// vertex ids a < b < c and its slot 4t + f (the face opposite local vertex
// f of tet t). 12 bytes: a is the bucket's (with a stored, the table was
// 64 bytes per tet, the sliver pass's peak on cube --max-volume 1e-6).
struct TetFace {
  uint32_t b, c, slot;
};

// Finding the records of k constraints (faces, edges) that share their
// smallest vertex a: each scanned for in a's bucket or star costs k × its
// size, quadratic in a's degree when k grows with it (an input vertex, the
// lowest id, in every facet triangle around it: crease_pair_0.1deg, session
// 40); one pass over the bucket or star with a binary search among the k
// costs its size × log k, several times the scan at the usual k (cube
// --max-volume 1e-4: +1.3% instructions). So up to this many the callers
// (the sliver pass, the labelling) scan, above it they make one pass; the
// cost stays linear in the tets either way.
inline constexpr size_t kConstraintScanRun = 16;

class TetFaces {
 public:
  // Vertex ids of `tets` must be < num_vertices (the callers check).
  TetFaces(std::span<const std::array<uint32_t, 4>> tets, size_t num_vertices);

  // The faces whose smallest vertex is a, in tet order (so the records of
  // one face come smallest slot first).
  std::span<const TetFace> Bucket(uint32_t a) const {
    return {faces_.data() + bucket_[a], faces_.data() + bucket_[a + 1]};
  }

  // A face shared by more than two tets: not a tetrahedralization.
  struct Overused {
    uint32_t a = 0, b = 0, c = 0;
    uint32_t count = 0;
    std::array<uint32_t, 3> slots{};  // its three smallest slots
  };
  // Calls pair(s, t) once for the two slots of each face in two tets. Stops
  // at the first bucket holding a face in more than two tets and returns
  // false with *bad = the smallest such face (a, b, c).
  bool Match(absl::FunctionRef<void(uint32_t, uint32_t)> pair, Overused* bad) const;

 private:
  std::vector<uint32_t> bucket_;  // faces of smallest vertex a: [bucket_[a], bucket_[a+1])
  std::vector<TetFace> faces_;
};

// The tets at each flagged vertex, in ascending tet index (CSR): those at v
// are tet[start[v] .. start[v+1]). Only flagged vertices get a star (the
// scatter of all 4T incidences was most of the cost; the callers flag the
// smallest vertices of their constraints). `alive` (empty: every slot) leaves
// out dead slots.
struct VertexStars {
  std::vector<uint32_t> start, tet;
};
VertexStars StarsOf(std::span<const std::array<uint32_t, 4>> tets, size_t num_vertices,
                    std::span<const uint8_t> flagged, std::span<const uint8_t> alive = {});
// TetFaces::Bucket(a) without the table: the faces at flagged vertex a whose
// smallest vertex is a, from a's star, in tet order (so the records of one
// face come smallest slot first), into *out.
void StarBucket(std::span<const std::array<uint32_t, 4>> tets, const VertexStars& stars, uint32_t a,
                std::vector<TetFace>* out);

}  // namespace svrc::refine
