// Faces that repeat an earlier face (mesh/duplicate_faces.h).
#include "mesh/duplicate_faces.h"

#include "common/bucket_by_key.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>

namespace vertexflow {

std::vector<char> find_duplicate_faces(const Index* tris, std::size_t nf, Index num_vertices) {
  // Each face's sorted corners, and the faces bucketed by their smallest corner in face order: a
  // counting sort in two fixed chunks of faces, counted and placed on both threads, which gives
  // the buckets of one serial pass (that pass was most of the 0.06 s this took at 2M faces).
  std::vector<std::array<Index, 3>> keys(nf);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nf, 16384), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t f = range.begin(); f != range.end(); ++f) {
      std::array<Index, 3> k{tris[3 * f], tris[3 * f + 1], tris[3 * f + 2]};
      std::sort(k.begin(), k.end());
      keys[f] = k;
    }
  });
  constexpr std::size_t kChunks = 2;
  KeyBuckets<Index, Index> buckets = bucket_by_key_in_chunks<Index, Index>(
      static_cast<std::size_t>(num_vertices), kChunks, [&](std::size_t chunk, auto&& emit) {
        const auto [first, last] = chunk_range(nf, kChunks, chunk);
        for (std::size_t f = first; f < last; ++f) emit(static_cast<std::size_t>(keys[f][0]), static_cast<Index>(f));
      });
  const std::vector<Index>& start = buckets.start;
  std::vector<Index>& order = buckets.items;
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
