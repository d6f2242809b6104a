// Internal: walking around a vertex over faces that edge flips changed, shared by the enhance
// engine (which copy of a welded seam vertex a changed face takes) and attribute transport
// (which corner row it takes). Both ask the same question: on which side of a seam or chart
// boundary does the face lie around that vertex. Boundaries are never flipped and flips keep
// orientation, so walking around the vertex without crossing one reaches a face whose side is
// known.
#pragma once

#include "vertexflow/mesh.h"

#include <algorithm>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace vertexflow {

inline std::uint64_t half_edge_key(Index from, Index to) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(from)) << 32) | static_cast<std::uint32_t>(to);
}

/// The faces of F by their directed half-edges at the vertices `at` (a flag per vertex).
class HalfEdgeFaces {
 public:
  HalfEdgeFaces(const Faces& F, const std::vector<char>& at) : F_(F) {
    for (Eigen::Index f = 0; f < F.rows(); ++f)
      for (int k = 0; k < 3; ++k)
        if (at[static_cast<std::size_t>(F(f, k))]) {
          face_[half_edge_key(F(f, k), F(f, (k + 1) % 3))] = static_cast<Index>(f);
          face_[half_edge_key(F(f, (k + 2) % 3), F(f, k))] = static_cast<Index>(f);
        }
  }

  /// The face with the directed half-edge from -> to (one end flagged), or -1.
  [[nodiscard]] Index face(Index from, Index to) const {
    const auto it = face_.find(half_edge_key(from, to));
    return it == face_.end() ? -1 : it->second;
  }

  /// Walks around vertex x (flagged) from face f over faces that share an edge (x, y) with the
  /// last, crossing only edges for which crossable(x, y) holds, and returns the first
  /// answer(g, next, prev) >= 0 (g's corners after and before x), starting with g = f; -1 if
  /// none gives one.
  template <typename Answer, typename Crossable>
  Index walk_around(Index f, Index x, Answer answer, Crossable crossable) const {
    std::vector<Index> open{f}, seen{f};
    while (!open.empty()) {
      const Index g = open.back();
      open.pop_back();
      int k = 0;
      while (k < 3 && F_(g, k) != x) ++k;
      if (k == 3) continue;
      const Index next = F_(g, (k + 1) % 3), prev = F_(g, (k + 2) % 3);
      if (const Index a = answer(g, next, prev); a >= 0) return a;
      for (const auto& [y, across] : {std::pair{next, face(next, x)}, std::pair{prev, face(x, prev)}})
        if (across >= 0 && crossable(x, y) && std::find(seen.begin(), seen.end(), across) == seen.end()) {
          seen.push_back(across);
          open.push_back(across);
        }
    }
    return -1;
  }

 private:
  const Faces& F_;
  std::unordered_map<std::uint64_t, Index> face_;
};

}  // namespace vertexflow
