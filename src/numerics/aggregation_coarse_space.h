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
  /// Weights kept as two arrays, of indices and of values: a Weight of both takes 16 bytes with
  /// its padding, the two 8 (a third of the coarse space's bytes). The values are rounded to
  /// float once, when the space is made, and every use (restriction, prolongation, the
  /// problem's Galerkin matrix) reads the same rounded phi, so Phi M_c Phi^T stays symmetric
  /// positive semi-definite. Iterating gives each as a Weight by value, in double.
  class Weights {
   public:
    class iterator {
     public:
      iterator(const Index* index, const float* value) : index_(index), value_(value) {}
      Weight operator*() const { return {*index_, *value_}; }
      iterator& operator++() {
        ++index_, ++value_;
        return *this;
      }
      bool operator!=(const iterator& other) const { return index_ != other.index_; }

     private:
      const Index* index_;
      const float* value_;
    };
    Weights(const Index* index, const float* value, std::size_t size) : index_(index), value_(value), size_(size) {}
    [[nodiscard]] iterator begin() const { return {index_, value_}; }
    [[nodiscard]] iterator end() const { return {index_ + size_, value_ + size_}; }
    [[nodiscard]] std::size_t size() const { return size_; }

   private:
    const Index* index_;
    const float* value_;
    std::size_t size_;
  };

  /// The basis functions non-zero at vertex i, sorted by aggregate: phi_a = (I - omega (I - W))
  /// chi_a on free vertices, W the one-ring average, chi_a the indicator of aggregate a.
  [[nodiscard]] Weights basis(Index i) const {
    const auto v = static_cast<std::size_t>(i);
    return {basis_aggregate_.data() + basis_start_[v], basis_value_.data() + basis_start_[v],
            basis_start_[v + 1] - basis_start_[v]};
  }
  /// coarse = Phi^T r (3 per aggregate).
  void restrict_to(const BlockVector& r, BlockVector& coarse) const;

 private:
  Index n_ = 0;
  int count_ = 0;
  std::vector<std::size_t> basis_start_, member_start_;
  std::vector<Index> basis_aggregate_;  // per vertex: the aggregates a with phi_a(i) != 0, and
  std::vector<float> basis_value_;      // phi_a(i)
  std::vector<Index> member_vertex_;    // per aggregate: the vertices i with phi_a(i) != 0, and
  std::vector<float> member_value_;     // phi_a(i)
};

/// The correction Phi M_c Phi^T of a coarse space and its Galerkin matrix.
class CoarseSpaceCorrection : public PreconditionerCorrection {
 public:
  /// `galerkin_upper`: the upper half (diagonal included) of Phi^T H Phi; `prolongators`: those
  /// of its hierarchy (multigrid.h). Throws std::runtime_error if its coarsest level is not
  /// numerically positive definite.
  CoarseSpaceCorrection(std::shared_ptr<const AggregationCoarseSpace> space, BlockSparseMatrix galerkin_upper,
                        AdditiveMultilevel::Prolongators prolongators = AdditiveMultilevel::Prolongators::Smoothed);
  double add_to(const BlockVector& r, BlockVector& z) override;

 private:
  std::shared_ptr<const AggregationCoarseSpace> space_;
  std::unique_ptr<AdditiveMultilevel> coarse_;
  BlockVector restricted_, coarse_solution_;
};

}  // namespace vertexflow
