// The energy of the vertex flow (paper sections 3-4), term by term, evaluated from the paper's
// formulas. The flow minimises it through one encoding of the same terms as per-vertex 3x3
// factors (src/flow/flow_terms.h), which the tests hold against these evaluations.
//
// Notation: V = current positions (the unknowns), P = the positions the solve starts from (the
// input mesh M0, the proxy of the surface; with several iterations, the previous result), and
// per vertex i the principal curvatures k_i1, k_i2 of P with unit directions T_i1, T_i2 and
// normal N_i, all frozen during a solve.
//
//   K_i     = |k_i1| T_i1 T_i1^T + |k_i2| T_i2 T_i2^T                        (3x3, PSD)
//   f_em(e) = 1/2 (e_ij^T K_i e_ij + e_ji^T K_j e_ji),  e_ij = v_j - v_i      (Eq. 2-4)
//   F_em    = 1/|E| sum_e f_em(e)                                            (Eq. 5)
//   g_i     = sum_{j in N(i)} (K_i + K_j)(v_i - v_j) = |E| grad_{v_i} F_em  (Eq. 16)
//   F_tan   = 1/|E| sum_i [(T_i1 . g_i)^2 + (T_i2 . g_i)^2]                  (Eq. 13-15, 19)
//   h_i(v)  = c_i1 ((v - p_i).T_i1)^2 + c_i2 ((v - p_i).T_i2)^2 + ((v - p_i).N_i)^2,
//             c = d / (d + rho) = d |k| / (d |k| + 1), rho = 1 / |k|            (Eq. 6)
//   F_sd    = 1/|V| sum_i h_i(v_i)                                           (Eq. 7)
//   L(v_i)  = v_i - 1/deg(i) sum_{j in N(i)} v_j                             (Eq. 8)
//   F_smo   = 1/|V| sum_i mu_i |L(v_i) - r_i|^2,  mu_i = exp(-(|k_i1| + |k_i2|))  (Eq. 9-10)
//             r_i = 0 in the paper; by default the normal part of L(p_i) (FairnessTarget)
//   F_sliver = 1/|V| sum_{f sliver} sum_{corners i of f} ((v_i - p_i) . m_fi / h_fi)^2    (ours)
//             m_fi = the unit vector in f's plane across the edge opposite i, towards i, and
//             h_fi = the altitude of f at i (both at P); the slivers are the faces that start
//             below FlowOptions::guard.min_quality. It measures each sliver corner's move towards
//             its opposite edge in units of the distance at which the face flips.
//
// The system minimises F_tan + lambda F_sd + mu F_smo + sliver F_sliver
//   + epsilon lambda 1/|V| sum |v_i - p_i|^2.
// Two choices the paper leaves open are made here (docs/method-notes.md):
// - F_em enters through its tangential gradient (Eq. 13-19) with weight 1/|E| on the squared
//   rows, the same per-element averaging as F_sd's 1/|V|, so the balance of the terms does not
//   depend on the resolution. (The paper's literal F_em has its minimum at a collapsed mesh.)
// - F_smo is normalised by 1/|V| like F_sd (the paper gives no normalisation; unnormalised it
//   outweighs F_sd by |V| and shrinks the mesh), and epsilon (default 1e-6) keeps the system
//   definite where a vertex is flat (k = 0 gives it no tangential constraint otherwise).
// - F_sliver is not in the paper. F_tan's minimiser moves vertices by fractions of an edge
//   length, which crosses the altitudes of slivers; the guard then shortens those moves after
//   the fact. On a thin plate whose faces are mostly slivers (tests/flow: the genus-121 plate)
//   it shortened 55% of the vertices; with F_sliver at its default weight the solve itself
//   keeps sliver corners short of their opposite edges and moves their neighbours
//   consistently: 17% shortened, rho still +0.13 (+0.22 without). It is a sum of per-vertex
//   3x3 blocks, so it adds to D only, and it is zero on meshes without slivers.
// The terms are not scale-invariant by themselves: curvature has units 1/length. The flow
// evaluates them on a copy scaled to mean edge length 1 (flow.h).
#pragma once

#include "vertexflow/curvature.h"
#include "vertexflow/mesh.h"
#include "vertexflow/topology.h"

#include <vector>

namespace vertexflow {

/// The frozen per-vertex data of the energy: the input's positions and curvature.
struct FlowFrame {
  Vertices P;           ///< input positions p_i
  Curvature curvature;  ///< of the input, at the same scale as P
  double d = 1;         ///< the radius d of Eq. 6 (same length unit as P)
  /// Per vertex, sum over its sliver corners of m_fi m_fi^T / h_fi^2 (F_sliver above, in the
  /// inverse square of P's length unit); empty: no slivers, F_sliver = 0.
  std::vector<Eigen::Matrix3d> sliver_stiffness;
};

/// What the fairness term F_smo pulls each umbrella vector L(v_i) towards.
enum class FairnessTarget {
  /// Zero: the paper's Eq. 8-10, mu_i |L(v_i)|^2. On curved surfaces L(p_i) has a normal part
  /// (the discrete mean curvature), so the input is not a rest state and every convex region
  /// shrinks: a 24-vertex chamfered cube lost 9.7% of its volume, an icosahedron 2%.
  Zero,
  /// The normal part of the input's umbrella vector: mu_i |L(v_i) - (L(p_i) . N_i) N_i|^2.
  /// The same pull towards an even tangential distribution (the tangential part of the target
  /// is zero, as in the paper), without the shrinking; the default.
  InputNormal,
};

/// Weights of the terms (Eq. 1).
struct EnergyWeights {
  /// Weight of the distance term F_sd: the user's "strength" knob, inverted. Smaller lets the
  /// vertices move further (stronger enhancement); useful range about 0.2 (strong) to 50
  /// (almost no change); 1 is the paper's default. Must be > 0.
  double lambda = 1.0;
  /// Weight of the fairness term F_smo (paper: 0.5). 0 removes it, which leaves flat regions
  /// unconstrained (docs/method-notes.md: "mu > 0 is required"). Must be >= 0.
  double mu = 0.5;
  /// Isotropic pull towards the input, relative to lambda: keeps the system definite at flat
  /// vertices, where neither F_em nor F_sd constrains tangential motion. Must be > 0.
  double epsilon = 1e-6;
  /// What F_smo pulls the umbrella vectors towards: by default the input's normal part, so that
  /// the fairness term evens out the sampling without shrinking the shape.
  FairnessTarget fairness_target = FairnessTarget::InputNormal;
  /// Weight of F_sliver, our addition (above): how firmly sliver corners are kept from their
  /// opposite edges during the solve. 0 leaves slivers to the guard alone. Measured on the
  /// genus-121 sliver plate (vertices the guard shortened; rho gained): 0: 55%, +0.22;
  /// 0.003: 29%, +0.22; 0.01: 21%, +0.16; 0.02: 17%, +0.13; 0.03: 16%, +0.11; 0.1: 8%, +0.06.
  /// Must be >= 0.
  double sliver = 0.02;
};

/// F_em of Eq. 2-5 at positions V (the paper's literal edge energy; not what is minimised).
double edge_metric_energy(const Vertices& V, const Topology& topology, const FlowFrame& frame);

/// g_i of every vertex at positions V (#V x 3): |E| times the gradient of F_em.
Vertices edge_metric_gradient(const Vertices& V, const Topology& topology, const FlowFrame& frame);

/// F_tan: the tangential part of F_em's gradient, squared and averaged (Eq. 13-19).
double tangential_edge_energy(const Vertices& V, const Topology& topology, const FlowFrame& frame);

/// F_sd of Eq. 6-7 at positions V.
double squared_distance_energy(const Vertices& V, const FlowFrame& frame);

/// F_smo of Eq. 8-10 at positions V (with the 1/|V| normalisation above), pulling each L(v_i)
/// towards the given target.
double fairness_energy(const Vertices& V, const Topology& topology, const FlowFrame& frame,
                       FairnessTarget target = FairnessTarget::InputNormal);

/// F_sliver at positions V (0 when frame.sliver_stiffness is empty).
double sliver_energy(const Vertices& V, const FlowFrame& frame);

/// The whole objective F_tan + lambda F_sd + mu F_smo + sliver F_sliver
/// + epsilon lambda / |V| sum |v - p|^2.
double total_flow_energy(const Vertices& V, const Topology& topology, const FlowFrame& frame,
                         const EnergyWeights& weights);

/// Coefficients c = d |k| / (d |k| + 1) of Eq. 6 for a curvature k (0 where k = 0).
inline double distance_coefficient(double d, double k) {
  const double dk = d * std::abs(k);
  return dk / (dk + 1.0);
}

}  // namespace vertexflow
