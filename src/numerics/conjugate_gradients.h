// Internal: preconditioned conjugate gradients on a matrix-free symmetric positive definite
// operator over 3-blocks, with a Lanczos estimate of the iterations still needed.
//
// The operator and the preconditioner's coarse part are interfaces, so that the problem (the
// flow's normal equations, src/flow/flow_operator.h) stays apart from the iteration. What the
// iteration needs besides the product is fused into the passes over the vectors: the operator
// returns x . Hx from its last pass, and may do conjugate gradients' direction update in its
// first; the block-Jacobi step and the two dot products share one pass. The iteration is
// bound by memory traffic, and each separate pass costs a sweep over all vectors.
#pragma once

#include "numerics/block3.h"

#include <optional>
#include <utility>
#include <vector>

namespace vertexflow {

/// The preconditioned residual z = M r as the operator's first pass reads it, block by block:
/// stored, or formed from r and block-Jacobi's inverses where M has no correction (so that the
/// iteration keeps no vector z: 24 bytes per unknown block fewer; the same products, so the
/// same bytes).
class PreconditionedResidual {
 public:
  /// z as stored.
  explicit PreconditionedResidual(const BlockVector& z) : stored_(&z) {}
  /// z_i = inverse[i] r_i.
  PreconditionedResidual(const std::vector<InverseFactor3f>& inverse, const BlockVector& r)
      : inverse_(&inverse), r_(&r) {}

  [[nodiscard]] Eigen::Vector3d operator()(Index i) const {
    return stored_ ? Eigen::Vector3d(block_at(*stored_, i))
                   : Eigen::Vector3d((*inverse_)[static_cast<std::size_t>(i)] * block_at(*r_, i));
  }

 private:
  const BlockVector* stored_ = nullptr;
  const std::vector<InverseFactor3f>* inverse_ = nullptr;
  const BlockVector* r_ = nullptr;
};

/// A symmetric positive (semi-)definite operator on BlockVectors of `size()` blocks.
class BlockOperator {
 public:
  virtual ~BlockOperator() = default;
  /// y = H x; returns x . y (summed deterministically).
  virtual double apply(const BlockVector& x, BlockVector& y) = 0;
  /// p = z + beta p, then y = H p; returns p . y. Lets the direction update ride on the
  /// operator's first pass. A stored z may be y itself (ConjugateGradients keeps z where H p is
  /// written, since neither is needed while the other is): every block of z must be read before
  /// any of y is written.
  virtual double apply_updated(BlockVector& p, const PreconditionedResidual& z, double beta, BlockVector& y) = 0;
};

/// An additive correction to the block-Jacobi preconditioner, M = B + C.
class PreconditionerCorrection {
 public:
  virtual ~PreconditionerCorrection() = default;
  /// z += C r; returns r . z (summed deterministically, z after the update).
  virtual double add_to(const BlockVector& r, BlockVector& z) = 0;
};

/// Result of ConjugateGradients::run.
struct IterationResult {
  int iterations = 0;
  bool converged = false;
};

/// Preconditioned conjugate gradients for H d = b from d = 0, preconditioned by the inverses of
/// H's 3x3 diagonal blocks (zero blocks for unknowns held at 0) plus an optional correction.
/// Results are the same for any thread count.
class ConjugateGradients {
 public:
  /// `block_inverse[i]`: the inverse of H's diagonal block i, or zero where row i is held.
  /// `op`, `b` and `correction` must outlive the iteration.
  ConjugateGradients(BlockOperator& op, std::vector<InverseFactor3f> block_inverse, const BlockVector& b,
                     PreconditionerCorrection* correction = nullptr);

  /// Continues for at most max_iterations, stopping when |r| <= tolerance |b|.
  IterationResult run(int max_iterations, double tolerance);

  /// The iterations that the current preconditioner is predicted to need in all, from the
  /// extreme eigenvalues of the Lanczos matrix of the iterations so far (Saad, Iterative
  /// Methods, 6.7.3): 1/2 sqrt(kappa) ln(2 / tolerance), the conjugate-gradient bound. After a
  /// few dozen iterations the smallest eigenvalue is still overestimated, so this is a lower
  /// bound, and slow (flat) problems are underestimated most.
  [[nodiscard]] double predicted_iterations(double tolerance) const;

  /// Continues from the current iterate with another correction (a restart: the search
  /// directions so far were conjugate for the old preconditioner).
  void use_correction(PreconditionerCorrection* correction);

  [[nodiscard]] const BlockVector& solution() const { return d_; }
  /// The solution moved out, without a copy beside the iteration's vectors (whose moment is
  /// the flow's peak memory); the iteration cannot continue after it.
  [[nodiscard]] BlockVector take_solution() { return std::move(d_); }
  [[nodiscard]] int total_iterations() const { return total_iterations_; }
  /// |r| / |b| of the current iterate (0 for b = 0).
  [[nodiscard]] double relative_residual() const { return b_norm_ > 0 ? r_norm_ / b_norm_ : 0.0; }

 private:
  double precondition();  // z = B r (+ C r); returns r . z

  BlockOperator& op_;
  PreconditionerCorrection* correction_;  // null: block-Jacobi alone
  std::optional<double> pending_beta_;    // p = z + beta p, done by the next operator application
  std::vector<double> alphas_, betas_;    // of the iterations since the last preconditioner change
  std::vector<InverseFactor3f> inverse_;
  Index blocks_ = 0;
  BlockVector d_, r_, p_;
  // H p during an iteration's product, and z = M r from the update until the next product's
  // first pass has read it, where a correction needs z stored (block-Jacobi's z is formed where
  // it is read): one vector instead of two, 24 bytes per unknown block at the flow's peak.
  BlockVector hp_;
  double rz_ = 0, b_norm_ = 0, r_norm_ = 0;
  int total_iterations_ = 0;
};

}  // namespace vertexflow
