// Internal: parallel loops and reductions whose results do not depend on the thread count.
//
// Every parallel pass of the library goes through these: a loop over indices whose bodies are
// independent (any partition gives the same result), and sums taken per fixed chunk of indices
// and then added chunk by chunk in order, so that their rounding is the same for any number of
// threads (the library promises byte-identical results whatever the thread count).
#pragma once

#include "vertexflow/mesh.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <vector>

namespace vertexflow {

/// body(i) for every i in [0, n), in parallel in ranges of about `grain` indices, or in the
/// calling thread when n < serial_below (starting tasks costs more than a few hundred short
/// bodies). The bodies must be independent.
template <class Body>
void parallel_for_index(Index n, Body&& body, Index grain = 1024, Index serial_below = 0) {
  if (n < serial_below) {
    for (Index i = 0; i < n; ++i) body(i);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<Index>(0, n, grain), [&](const tbb::blocked_range<Index>& range) {
    for (Index i = range.begin(); i != range.end(); ++i) body(i);
  });
}

/// A copy of V (the same bytes as `Vertices copy = V`) written by all threads in ranges of rows:
/// a large copy made on one thread first touches all of its pages there, and on a VM that
/// costs most of the copy's time (docs/benchmarks.md, "Fresh pages on this VM").
inline Vertices copy_rows_in_parallel(const Vertices& V) {
  Vertices out(V.rows(), V.cols());
  const Index columns = static_cast<Index>(V.cols());
  tbb::parallel_for(
      tbb::blocked_range<Index>(0, static_cast<Index>(V.rows()), 16384), [&](const tbb::blocked_range<Index>& range) {
        std::copy(V.data() + std::ptrdiff_t{range.begin()} * columns, V.data() + std::ptrdiff_t{range.end()} * columns,
                  out.data() + std::ptrdiff_t{range.begin()} * columns);
      });
  return out;
}

/// The sum over the chunks [k chunk, min(n, (k + 1) chunk)) of chunk_sum(begin, end), the
/// chunks computed in parallel and added in order, starting from `zero`. T is a double or an
/// Eigen vector.
template <class T, class ChunkSum>
T deterministic_sum(std::ptrdiff_t n, std::ptrdiff_t chunk, const T& zero, ChunkSum&& chunk_sum) {
  const std::ptrdiff_t chunks = (n + chunk - 1) / chunk;
  std::vector<T> partial(static_cast<std::size_t>(chunks), zero);
  tbb::parallel_for(std::ptrdiff_t{0}, chunks, [&](std::ptrdiff_t k) {
    partial[static_cast<std::size_t>(k)] = chunk_sum(k * chunk, std::min(n, (k + 1) * chunk));
  });
  T total = zero;
  for (const T& part : partial) total += part;
  return total;
}

/// Vertices per chunk of sum_over_vertices.
inline constexpr Index kVerticesPerChunk = 2048;

/// The sum of body(i) over i in [0, n) (a double or an Eigen vector), body called once per
/// index in parallel; deterministic_sum's rounding.
template <class T, class Body>
T sum_over_vertices(Index n, const T& zero, Body&& body) {
  return deterministic_sum(n, kVerticesPerChunk, zero, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
    T sum = zero;
    for (auto i = static_cast<Index>(begin); i < static_cast<Index>(end); ++i) sum += body(i);
    return sum;
  });
}

}  // namespace vertexflow
