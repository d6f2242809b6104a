#include "numerics/aggregation_coarse_space.h"

#include "numerics/parallel.h"

#include <algorithm>
#include <utility>

namespace vertexflow {
namespace {

// Damping of the Jacobi step. Measured, multilevel iterations of the flow on fandisk / spot /
// max-planck-5k: 0.4: 158 / 85 / 73; 2/3 (the textbook value): 129 / 74 / 68; 0.9: 114 / 69 /
// 65; 1.1: 162 / 72 / 68. At 1 a vertex surrounded by other aggregates loses its own.
constexpr double kBasisSmoothing = 0.9;
// Restriction in the calling thread below this many aggregates (tasks cost more).
constexpr Index kSerialAggregatesBelow = 2048;

}  // namespace

AggregationCoarseSpace::AggregationCoarseSpace(const std::vector<Index>& start, const std::vector<Index>& neighbours,
                                               const std::vector<char>& fixed)
    : n_(static_cast<Index>(fixed.size())) {
  const std::vector<int> aggregate = aggregate_nodes(start, neighbours, fixed, count_);
  const auto n = static_cast<std::size_t>(n_);
  // Each vertex gets room for its whole one-ring first, about twice what its basis functions
  // take; they are then packed into the two arrays kept through the set-up and the solve.
  std::vector<std::size_t> room(n + 1, 0);
  for (std::size_t i = 0; i < n; ++i) room[i + 1] = room[i] + 1 + static_cast<std::size_t>(start[i + 1] - start[i]);
  std::vector<Weight> weights(room[n]);
  std::vector<std::size_t> basis_size(n, 0);
  parallel_for_index(n_, [&](Index i) {
    const auto v = static_cast<std::size_t>(i);
    if (fixed[v]) return;
    Weight* out = weights.data() + room[v];
    std::size_t size = 0;
    auto add = [&](Index a, double value) {
      for (std::size_t k = 0; k < size; ++k)
        if (out[k].aggregate == a) {
          out[k].value += value;
          return;
        }
      out[size++] = {a, value};
    };
    add(aggregate[v], 1 - kBasisSmoothing);
    const Index degree = start[v + 1] - start[v];
    const double w = kBasisSmoothing * (degree > 0 ? 1.0 / degree : 0.0);
    for (Index k = start[v]; k < start[v + 1]; ++k) {
      const auto j = static_cast<std::size_t>(neighbours[static_cast<std::size_t>(k)]);
      if (aggregate[j] >= 0) add(aggregate[j], w);
    }
    std::sort(out, out + size, [](const Weight& x, const Weight& y) { return x.aggregate < y.aggregate; });
    basis_size[v] = size;
  });
  basis_start_.assign(n + 1, 0);
  for (std::size_t i = 0; i < n; ++i) basis_start_[i + 1] = basis_start_[i] + basis_size[i];
  basis_aggregate_.resize(basis_start_[n]);
  basis_value_.resize(basis_start_[n]);
  parallel_for_index(n_, [&](Index i) {
    const auto v = static_cast<std::size_t>(i);
    for (std::size_t k = 0; k < basis_size[v]; ++k) {
      basis_aggregate_[basis_start_[v] + k] = weights[room[v] + k].aggregate;
      basis_value_[basis_start_[v] + k] = static_cast<float>(weights[room[v] + k].value);
    }
  });
  std::vector<Weight>().swap(weights);
  const auto na = static_cast<std::size_t>(count_);
  member_start_.assign(na + 1, 0);
  for (const Index a : basis_aggregate_) ++member_start_[static_cast<std::size_t>(a) + 1];
  for (std::size_t a = 0; a < na; ++a) member_start_[a + 1] += member_start_[a];
  member_vertex_.resize(member_start_[na]);
  member_value_.resize(member_start_[na]);
  std::vector<std::size_t> fill(member_start_.begin(), member_start_.end() - 1);
  for (std::size_t i = 0; i < n; ++i)
    for (const Weight& w : basis(static_cast<Index>(i))) {
      const std::size_t at = fill[static_cast<std::size_t>(w.aggregate)]++;
      member_vertex_[at] = static_cast<Index>(i);
      member_value_[at] = static_cast<float>(w.value);
    }
}

void AggregationCoarseSpace::restrict_to(const BlockVector& r, BlockVector& coarse) const {
  auto restrict_one = [&](Index a) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (std::size_t k = member_start_[static_cast<std::size_t>(a)]; k < member_start_[static_cast<std::size_t>(a) + 1];
         ++k)
      sum += double(member_value_[k]) * block_at(r, member_vertex_[k]);
    block_at(coarse, a) = sum;
  };
  parallel_for_index(count_, restrict_one, 1024, kSerialAggregatesBelow);
}

CoarseSpaceCorrection::CoarseSpaceCorrection(std::shared_ptr<const AggregationCoarseSpace> space,
                                             BlockSparseMatrix galerkin_upper,
                                             AdditiveMultilevel::Prolongators prolongators)
    : space_(std::move(space)),
      coarse_(std::make_unique<AdditiveMultilevel>(std::move(galerkin_upper), AdditiveMultilevel::Storage::UpperHalf,
                                                   AdditiveMultilevel::kCoarsestUnknowns, prolongators)) {
  restricted_.resize(3 * space_->size());
}

double CoarseSpaceCorrection::add_to(const BlockVector& r, BlockVector& z) {
  space_->restrict_to(r, restricted_);
  coarse_->apply(restricted_, coarse_solution_);
  return sum_over_vertices(space_->num_vertices(), 0.0, [&](Index i) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const AggregationCoarseSpace::Weight& w : space_->basis(i))
      sum += w.value * block_at(coarse_solution_, w.aggregate);
    block_at(z, i) += sum;
    return block_at(r, i).dot(block_at(z, i));
  });
}

}  // namespace vertexflow
