// Internal: the fine level of a two-level preconditioner for problems on a mesh's vertex graph
// with 3 unknowns per vertex: M = B + Phi M_c Phi^T, with B block-Jacobi (in
// ConjugateGradients), Phi a coarse space of smoothed aggregates and M_c the additive
// multilevel operator (multigrid.h) of the Galerkin matrix H_c = Phi^T H Phi, which the
// problem supplies (it knows H's structure; for the flow, src/flow/flow_operator.h).
//
// Why: block-Jacobi leaves the smooth modes to the iteration, and where a problem's only
// tangential stiffness is a bi-Laplacian (the flow's flat regions) their condition number
// grows like the region's diameter to the fourth power: fandisk's flat faces took 930
// iterations. Phi spans the translations of aggregates of one-rings, smoothed by one damped
// Jacobi step of the uniform Laplacian so that neighbouring basis functions overlap (with
// piecewise-constant ones the bi-Laplacian of a coarse function is large at aggregate
// borders).
#pragma once

#include "numerics/block3.h"
#include "numerics/conjugate_gradients.h"
#include "numerics/multigrid.h"

#include <memory>
#include <span>
#include <vector>

namespace vertexflow {

class AggregationCoarseSpace {
 public:
  /// phi_a(i) of aggregate a at vertex i.
  struct Weight {
    Index aggregate;  ///< (in member lists: the vertex)
    double value;
  };

  /// The graph (CSR: vertex i's neighbours are neighbours[start[i] .. start[i + 1])), and the
  /// vertices held fixed (no unknowns, in no aggregate, phi = 0 there).
  AggregationCoarseSpace(const std::vector<Index>& start, const std::vector<Index>& neighbours,
                         const std::vector<char>& fixed);

  [[nodiscard]] int size() const { return count_; }
  [[nodiscard]] Index num_vertices() const { return n_; }
  /// The basis functions non-zero at vertex i, sorted by aggregate: phi_a = (I - omega (I - W))
  /// chi_a on free vertices, W the one-ring average, chi_a the indicator of aggregate a.
  [[nodiscard]] std::span<const Weight> basis(Index i) const {
    const auto v = static_cast<std::size_t>(i);
    return {basis_.data() + basis_start_[v], basis_start_[v + 1] - basis_start_[v]};
  }
  /// coarse = Phi^T r (3 per aggregate).
  void restrict_to(const BlockVector& r, BlockVector& coarse) const;

 private:
  Index n_ = 0;
  int count_ = 0;
  std::vector<std::size_t> basis_start_, member_start_;
  std::vector<Weight> basis_;    // per vertex: (aggregate, phi_a(i))
  std::vector<Weight> members_;  // per aggregate: (vertex, phi_a(i))
};

/// The correction Phi M_c Phi^T of a coarse space and its Galerkin matrix.
class CoarseSpaceCorrection : public PreconditionerCorrection {
 public:
  /// `galerkin_upper`: the upper half (diagonal included) of Phi^T H Phi. Throws
  /// std::runtime_error if its coarsest level is not numerically positive definite.
  CoarseSpaceCorrection(std::shared_ptr<const AggregationCoarseSpace> space, BlockSparseMatrix galerkin_upper);
  double add_to(const BlockVector& r, BlockVector& z) override;

 private:
  std::shared_ptr<const AggregationCoarseSpace> space_;
  std::unique_ptr<AdditiveMultilevel> coarse_;
  BlockVector restricted_, coarse_solution_;
};

}  // namespace vertexflow
