// Faces that repeat an earlier face (mesh/duplicate_faces.h).
#include "mesh/duplicate_faces.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>

namespace vertexflow {

std::vector<char> find_duplicate_faces(const Index* tris, std::size_t nf, Index num_vertices) {
  std::vector<std::array<Index, 3>> keys(nf);
  std::vector<Index> start(static_cast<std::size_t>(num_vertices) + 1, 0);
  for (std::size_t f = 0; f < nf; ++f) {
    std::array<Index, 3> k{tris[3 * f], tris[3 * f + 1], tris[3 * f + 2]};
    std::sort(k.begin(), k.end());
    keys[f] = k;
    ++start[static_cast<std::size_t>(k[0]) + 1];
  }
  for (std::size_t v = 0; v < static_cast<std::size_t>(num_vertices); ++v) start[v + 1] += start[v];
  std::vector<Index> order(nf);
  {
    std::vector<Index> fill(start.begin(), start.end() - 1);
    for (std::size_t f = 0; f < nf; ++f) order[static_cast<std::size_t>(fill[keys[f][0]]++)] = static_cast<Index>(f);
  }
  std::vector<char> duplicate(nf, 0);
  // Buckets are independent and each writes only its own faces' flags: parallel and
  // deterministic.
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, static_cast<std::size_t>(num_vertices), 8192),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t v = range.begin(); v != range.end(); ++v) {
                        const auto begin = order.begin() + start[v];
                        const auto end = order.begin() + start[v + 1];
                        if (end - begin < 2) continue;
                        // Faces within a bucket are in increasing face order, so the first of equal keys is kept.
                        // Buckets hold about six faces: an insertion sort (stable, no allocation) beats
                        // std::stable_sort, which allocates a buffer per call.
                        const auto less = [&](Index a, Index b) {
                          return keys[static_cast<std::size_t>(a)] < keys[static_cast<std::size_t>(b)];
                        };
                        if (end - begin <= 32) {
                          for (auto it = begin + 1; it != end; ++it) {
                            const Index value = *it;
                            auto hole = it;
                            for (; hole != begin && less(value, *(hole - 1)); --hole) *hole = *(hole - 1);
                            *hole = value;
                          }
                        } else {
                          std::stable_sort(begin, end, less);
                        }
                        for (auto it = begin + 1; it != end; ++it) {
                          if (keys[*it] == keys[*(it - 1)]) duplicate[static_cast<std::size_t>(*it)] = 1;
                        }
                      }
                    });
  return duplicate;
}

}  // namespace vertexflow
