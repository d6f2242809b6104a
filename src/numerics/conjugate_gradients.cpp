#include "numerics/conjugate_gradients.h"

#include "numerics/parallel.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

namespace vertexflow {

ConjugateGradients::ConjugateGradients(BlockOperator& op, std::vector<InverseFactor3f> block_inverse,
                                       const BlockVector& b, PreconditionerCorrection* correction)
    : op_(op), correction_(nullptr), inverse_(std::move(block_inverse)), blocks_(static_cast<Index>(inverse_.size())) {
  d_.setZero(b.size());
  r_ = b;
  hp_.resize(b.size());
  p_.resize(b.size());
  // Block-Jacobi's start, p = z = B r (z is not kept: PreconditionedResidual), then a
  // correction's as use_correction starts it.
  rz_ = sum_over_vertices(blocks_, 0.0, [&](Index i) {
    const Eigen::Vector3d z = inverse_[static_cast<std::size_t>(i)] * block_at(r_, i);
    block_at(p_, i) = z;
    return block_at(r_, i).dot(z);
  });
  if (correction) use_correction(correction);
  b_norm_ = std::sqrt(deterministic_dot(b, b));
  r_norm_ = b_norm_;
}

IterationResult ConjugateGradients::run(int max_iterations, double tolerance) {
  IterationResult result;
  const double target = tolerance * b_norm_;
  if (r_norm_ <= target) {
    result.converged = true;
    return result;
  }
  while (result.iterations < max_iterations) {
    // p = z + beta p is still to be done when a previous iteration computed beta.
    const PreconditionedResidual preconditioned =
        correction_ ? PreconditionedResidual(hp_) : PreconditionedResidual(inverse_, r_);
    const double curvature =
        pending_beta_ ? op_.apply_updated(p_, preconditioned, *pending_beta_, hp_) : op_.apply(p_, hp_);
    pending_beta_.reset();
    if (!(curvature > 0)) break;  // H is positive definite; only rounding at convergence gets here
    const double alpha = rz_ / curvature;
    alphas_.push_back(alpha);
    // d += alpha p, r -= alpha H p, z = B r (stored over H p, block by block after reading it);
    // sums of r.r and r.z.
    const Eigen::Vector2d sums = sum_over_vertices(blocks_, Eigen::Vector2d::Zero().eval(), [&](Index i) {
      block_at(d_, i) += alpha * block_at(p_, i);
      const Eigen::Vector3d r = block_at(r_, i) - alpha * block_at(hp_, i);
      const Eigen::Vector3d z = inverse_[static_cast<std::size_t>(i)] * r;
      block_at(r_, i) = r;
      if (correction_) block_at(hp_, i) = z;
      return Eigen::Vector2d(r.squaredNorm(), r.dot(z));
    });
    r_norm_ = std::sqrt(sums[0]);
    double rz = sums[1];
    if (correction_) rz = correction_->add_to(r_, hp_);
    ++result.iterations;
    ++total_iterations_;
    if (r_norm_ <= target) {
      result.converged = true;
      break;
    }
    pending_beta_ = rz / rz_;
    betas_.push_back(*pending_beta_);
    rz_ = rz;
  }
  return result;
}

double ConjugateGradients::predicted_iterations(double tolerance) const {
  const auto k = static_cast<Eigen::Index>(std::min(alphas_.size(), betas_.size() + 1));
  if (k < 2) return 0;
  // The Lanczos tridiagonal matrix from the coefficients.
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(k, k);
  for (Eigen::Index j = 0; j < k; ++j) {
    const auto u = static_cast<std::size_t>(j);
    T(j, j) = 1 / alphas_[u] + (j > 0 ? betas_[u - 1] / alphas_[u - 1] : 0.0);
    if (j + 1 < k) T(j, j + 1) = T(j + 1, j) = std::sqrt(betas_[u]) / alphas_[u];
  }
  const Eigen::VectorXd eigenvalues =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(T, Eigen::EigenvaluesOnly).eigenvalues();
  const double kappa = eigenvalues[k - 1] / std::max(eigenvalues[0], 1e-300);
  return 0.5 * std::sqrt(kappa) * std::log(2 / tolerance);
}

void ConjugateGradients::use_correction(PreconditionerCorrection* correction) {
  correction_ = correction;
  // z in hp_'s storage (free between iterations).
  parallel_for_index(blocks_,
                     [&](Index i) { block_at(hp_, i) = inverse_[static_cast<std::size_t>(i)] * block_at(r_, i); });
  rz_ = correction_->add_to(r_, hp_);
  p_ = hp_;
  pending_beta_.reset();
  alphas_.clear();
  betas_.clear();
}

}  // namespace vertexflow
