// Geometric unsharp mask (unsharp.h): k rounds of uniform Laplacian smoothing, then the detail
// v - S^k(v) added back with weight w.
#include "vertexflow/unsharp.h"

#include "vertexflow/topology.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace vertexflow {
namespace {

// As the flow does (flow.cpp): the split's copies of held vertices are pinned, so every input
// vertex has one position to return.
UnsharpResult unsharp_on_manifold_split(const Vertices& V, const Faces& F, const Topology& topology,
                                        const UnsharpOptions& options) {
  const ManifoldSplit split = split_non_manifold(V, F, topology);
  UnsharpOptions on_split = options;
  on_split.refuse_non_manifold = true;
  on_split.constraints.pinned.clear();
  const auto n = static_cast<Index>(V.rows());
  for (const Index p : options.constraints.pinned)
    if (p < 0 || p >= n)
      throw std::invalid_argument("unsharp mask: pinned vertex " + std::to_string(p) + " is out of range");
  std::vector<char> hold(static_cast<std::size_t>(n), 0);
  for (const Index p : options.constraints.pinned) hold[static_cast<std::size_t>(p)] = 1;
  for (Index v = 0; v < n; ++v) {
    if (!hold[static_cast<std::size_t>(v)] && !split.held[static_cast<std::size_t>(v)]) continue;
    for (Index s = split.first_copy[static_cast<std::size_t>(v)]; s < split.first_copy[static_cast<std::size_t>(v) + 1];
         ++s)
      on_split.constraints.pinned.push_back(s);
  }
  const UnsharpResult on_copies = unsharp_mask(split.V, split.F, on_split);
  UnsharpResult result;
  result.V = V;
  for (Index v = 0; v < n; ++v)
    if (!split.held[static_cast<std::size_t>(v)])
      result.V.row(v) = on_copies.V.row(split.first_copy[static_cast<std::size_t>(v)]);
  // Counted per input vertex: a held vertex's extra copies were fixed too.
  result.fixed_vertices = on_copies.fixed_vertices - (static_cast<Index>(split.V.rows()) - n);
  result.non_manifold = split.counts();
  return result;
}

}  // namespace

UnsharpResult unsharp_mask(const Vertices& V, const Faces& F, const UnsharpOptions& options) {
  const Index n = static_cast<Index>(V.rows());
  if (n == 0 || F.rows() == 0) throw std::invalid_argument("unsharp mask: the mesh is empty");
  if (options.smoothing_iterations < 0)
    throw std::invalid_argument("unsharp mask: smoothing iterations must not be negative");
  if (!std::isfinite(options.weight)) throw std::invalid_argument("unsharp mask: the weight must be finite");
  const Topology topology = build_topology(F, n);
  if (!topology.is_manifold()) {
    if (options.refuse_non_manifold) throw std::invalid_argument("unsharp mask: " + describe_non_manifold(topology));
    return unsharp_on_manifold_split(V, F, topology, options);
  }

  std::vector<char> fixed(static_cast<std::size_t>(n), 0);
  for (Index i = 0; i < n; ++i)
    if ((options.constraints.fix_boundary && topology.is_boundary_vertex[static_cast<std::size_t>(i)]) ||
        topology.valence(i) == 0)
      fixed[static_cast<std::size_t>(i)] = 1;
  for (const Index p : options.constraints.pinned) {
    if (p < 0 || p >= n)
      throw std::invalid_argument("unsharp mask: pinned vertex " + std::to_string(p) + " is out of range");
    fixed[static_cast<std::size_t>(p)] = 1;
  }

  // Jacobi rounds of the umbrella operator: one pass over the one-rings each, linear in #E. A
  // serial loop: the default 5 rounds on the 1M-vertex bench mesh took about a quarter of the
  // time of the parallel build_topology above (measured on the shared 2-core machine).
  Vertices smooth = V, next = V;
  for (int round = 0; round < options.smoothing_iterations; ++round) {
    for (Index i = 0; i < n; ++i) {
      if (fixed[static_cast<std::size_t>(i)]) continue;
      const auto [begin, end] = topology.ring(i);
      Eigen::RowVector3d sum = Eigen::RowVector3d::Zero();
      for (const Index* j = begin; j != end; ++j) sum += smooth.row(*j);
      next.row(i) = sum / static_cast<double>(end - begin);
    }
    std::swap(smooth, next);
  }

  UnsharpResult result;
  result.V = V + options.weight * (V - smooth);
  result.fixed_vertices = static_cast<Index>(std::count(fixed.begin(), fixed.end(), char{1}));
  return result;
}

}  // namespace vertexflow
