// Internal to the flow stage: the flow's energy (include/vertexflow/flow_energy.h) encoded as
// per-vertex 3x3 factors, the one encoding that every solver runs and that the energy tests
// check against the paper's formulas (tests/flow/test_flow_energy.cpp).
//
// The normal equations of the energy are H d = b for the displacement d = V - P, with
//   H = G P G + (L^T S L) (x) I_3 + D,     b = -(G P G P + L^T S (L P - R)),
// where, per vertex i (docs/method-notes.md, "The energy, written out"):
//   K_i = |k_i1| T_i1 T_i1^T + |k_i2| T_i2 T_i2^T                    (Eq. 2-4, as a quadratic form)
//   G   the 3n x 3n block operator (G x)_i = sum_{j in N(i)} (K_i + K_j)(x_i - x_j)
//       (the g_i of Eq. 16; symmetric)
//   P_i = 1/|E| (T_i1 T_i1^T + T_i2 T_i2^T): F_tan's weighted tangent projector (Eq. 13-19)
//   L   the uniform Laplacian of Eq. 8, S = diag(mu mu_i / |V|), mu_i = exp(-(|k1| + |k2|))
//       (Eq. 9-10), R the fairness targets r_i (FairnessTarget)
//   D_i = lambda/|V| (c_i1 T_i1 T_i1^T + c_i2 T_i2 T_i2^T + N_i N_i^T) + epsilon lambda/|V| I:
//       + sliver/|V| S_i: F_sd (Eq. 6-7), the pull and F_sliver (S_i = frame.sliver_stiffness).
// Rows and columns of fixed vertices are removed (their d is 0). So H x costs two passes over
// the one-rings (no matrix), and any block of H is a short sum over the vertices whose
// one-rings contain both of its vertices.
#pragma once

#include "numerics/block3.h"
#include "vertexflow/flow_energy.h"
#include "vertexflow/topology.h"

#include <utility>
#include <vector>

namespace vertexflow {

/// The per-vertex factors of H and b in normalised units, over the vertices renumbered by
/// `original` (local index -> mesh vertex; vertex_ordering.h: neighbours close in memory).
/// K, G, P and D are computed in double and stored in float (Sym3f in groups of four,
/// Sym3fGroups, block3.h): 96 bytes per vertex fewer through the solve, the flow's peak. H is
/// then exactly the (symmetric, positive definite) matrix of factors rounded to 6e-8 relative.
/// On the 1M armadillo the vertices moved by 1.7e-6 mean edge lengths on average, a tenth of
/// what the solver's tolerance allows (docs/benchmarks.md, "Float factors").
struct FlowTerms {
  Index n = 0;
  std::vector<Index> original;          ///< local index -> mesh vertex
  std::vector<Index> ring_start, ring;  ///< one-rings in local indices
  std::vector<char> fixed;
  Sym3fGroups K;                      ///< K_i
  Sym3fGroups G;                      ///< diagonal block of G: deg(i) K_i + sum_j K_j
  Sym3fGroups P;                      ///< 1/|E| times the tangent projector
  Sym3fGroups D;                      ///< F_sd and the pull
  std::vector<double> smooth;         ///< S_i = mu mu_i / |V| (0 for an isolated vertex)
  std::vector<double> inv_degree;     ///< 1 / deg(i) (0 for an isolated vertex)
  std::vector<Eigen::Vector3d> rest;  ///< fairness target r_i

  [[nodiscard]] std::pair<const Index*, const Index*> one_ring(Index i) const {
    return {ring.data() + ring_start[static_cast<std::size_t>(i)],
            ring.data() + ring_start[static_cast<std::size_t>(i) + 1]};
  }
  /// Calls visit(j) for i and then each vertex of its one-ring: the vertices whose rows of
  /// G and L involve i.
  template <class Visit>
  void for_each_in_star(Index i, Visit&& visit) const {
    visit(i);
    const auto [begin, end] = one_ring(i);
    for (const Index* j = begin; j != end; ++j) visit(*j);
  }
  /// The block G_iu of G for u in the star of i.
  [[nodiscard]] Eigen::Matrix3d g_block(Index i, Index u) const {
    return i == u ? G[static_cast<std::size_t>(i)].full()
                  : Eigen::Matrix3d(-(K[static_cast<std::size_t>(i)].full() + K[static_cast<std::size_t>(u)].full()));
  }
  /// The entry L_iu of the Laplacian for u in the star of i.
  [[nodiscard]] double l_entry(Index i, Index u) const {
    return i == u ? 1.0 : -inv_degree[static_cast<std::size_t>(i)];
  }
};

/// The factors of the energy of `frame` with `weights`, over the vertices in `order` (a
/// permutation of the mesh's vertices). `fixed` marks the vertices held at frame.P.
FlowTerms make_flow_terms(const Topology& topology, const std::vector<char>& fixed, const FlowFrame& frame,
                          const EnergyWeights& weights, std::vector<Index> order);

/// A vector over mesh vertices (3 per vertex, Vertices' storage) in local order.
BlockVector to_local(const FlowTerms& terms, const double* x);
/// out (3 per mesh vertex) += x (local order).
void add_from_local(const FlowTerms& terms, const BlockVector& x, double* out);

/// The 3x3 diagonal block of H at free vertex u: the sum over the star of u of G_iu P_i G_iu
/// and S_i L_iu^2, plus D_u.
Eigen::Matrix3d diagonal_block(const FlowTerms& terms, Index u);

}  // namespace vertexflow
