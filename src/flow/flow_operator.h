// Internal to the flow stage: H of flow_terms.h applied without forming it, and its projection
// onto a coarse space (the Galerkin matrix of LinearSolver::Multilevel).
#pragma once

#include "flow_terms.h"
#include "numerics/aggregation_coarse_space.h"
#include "numerics/conjugate_gradients.h"
#include "numerics/multigrid.h"

namespace vertexflow {

/// H x without forming H: a pointwise pass (K x), then two passes over the one-rings: q = P G x
/// and r = S (L x - R) (the weighted rows of F_tan and F_smo) with K q; then G q + L^T r + D x.
/// The per-vertex factors are stored as symmetric 3x3 (Sym3f) and the dot product x . y that
/// conjugate gradients need is summed in the last pass: about a third fewer bytes per iteration
/// than full 3x3 blocks and separate passes, while applying K once per vertex and pass (applying
/// it per neighbour instead, with no K x array, saved more bytes but cost more time: the
/// iteration is as much bound by arithmetic as by memory here). Rows of fixed vertices are zero.
class FlowOperator : public BlockOperator {
 public:
  /// How the passes keep K x and (q, K q, r) between them. Double: H x exactly as the factors
  /// define it (to double rounding). Float: 48 bytes per vertex instead of 96, part of the
  /// solve's peak memory, and the neighbours' records summed in float before one conversion
  /// (the passes are bound by arithmetic: a product on the 1M armadillo takes 25.0 ms against
  /// 29.9 ms, bench_flow's operator/ cases); each product then carries a rounding of about 5e-8
  /// relative (the residual of an exact solution measured through it: 2e-8 to 9e-8 on the data
  /// meshes), so it serves iterations stopped well above that (FlowSystemSolver's iterations at
  /// tolerances of 1e-6 and more: at 1e-6 the data meshes take the iterations of exact products,
  /// plus or minus four).
  enum class CachePrecision { Double, Float };

  explicit FlowOperator(const FlowTerms& terms, CachePrecision precision = CachePrecision::Double);
  /// Products from here on keep their caches in `precision` (the other's are freed).
  void use_cache_precision(CachePrecision precision);

  double apply(const BlockVector& x, BlockVector& y) override;
  double apply_updated(BlockVector& p, const PreconditionedResidual& z, double beta, BlockVector& y) override;

  /// b = -(G P G x + L^T S (L x - R)) at x = the frame's positions (local order): the negative
  /// half-gradient of the energy at d = 0, the normal equations' right-hand side (D drops out).
  BlockVector right_hand_side(const BlockVector& x);

  /// Frees the per-vertex caches (96 or 48 bytes per vertex) until the next product allocates
  /// them again: the multilevel set-up, one of the flow's peaks on that path, runs between b and
  /// the first product and does not need them.
  void release_caches();

 private:
  template <class First>
  double passes(const BlockVector& x, BlockVector& y, bool with_d, bool with_rest, First&& first);
  template <class Cache, class First>
  double passes(std::vector<Cache>& kx, std::vector<Cache>& qkr, const BlockVector& x, BlockVector& y, bool with_d,
                bool with_rest, First&& first);

  const FlowTerms& t_;
  CachePrecision precision_;
  // Per vertex: K x, and q, K q, r; in the precision chosen (the other pair stays empty).
  std::vector<float> kx_float_, qkr_float_;
  std::vector<double> kx_double_, qkr_double_;
};

/// The upper half (diagonal included) of the Galerkin matrix Phi^T H Phi, summed vertex by
/// vertex from H's factors rather than through H: (G Phi)^T P (G Phi) + (L Phi)^T S (L Phi) (x)
/// I + Phi^T D Phi.
BlockSparseMatrix galerkin_upper(const FlowTerms& terms, const AggregationCoarseSpace& space);

}  // namespace vertexflow
