// The flow's energy terms (include/vertexflow/flow_energy.h), evaluated directly from the
// paper's formulas: the reference the tests hold the solver's encoding (flow_terms.h) against.
#include "vertexflow/flow_energy.h"

#include <cmath>
#include <vector>

namespace vertexflow {
namespace {

Eigen::Vector3d row3(const Vertices& M, Index i) {
  return M.row(i).transpose();
}

// Eq. 10.
double fairness_weight(const Curvature& c, Index i) {
  return std::exp(-(std::abs(c.k1[i]) + std::abs(c.k2[i])));
}

// h_i(v) of Eq. 6.
double squared_distance(const FlowFrame& frame, Index i, const Eigen::Vector3d& v) {
  const Curvature& c = frame.curvature;
  const Eigen::Vector3d r = v - row3(frame.P, i);
  const double a = r.dot(row3(c.T1, i)), b = r.dot(row3(c.T2, i)), n = r.dot(row3(c.N, i));
  return distance_coefficient(frame.d, c.k1[i]) * a * a + distance_coefficient(frame.d, c.k2[i]) * b * b + n * n;
}

// L(v_i) of Eq. 8 (zero for an isolated vertex).
Eigen::Vector3d laplacian(const Vertices& V, const Topology& topology, Index i) {
  const auto [begin, end] = topology.ring(i);
  if (begin == end) return Eigen::Vector3d::Zero();
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Index* j = begin; j != end; ++j) mean += row3(V, *j);
  return row3(V, i) - mean / static_cast<double>(end - begin);
}

// The umbrella vector the fairness term pulls L(v_i) towards (flow_energy.h, FairnessTarget).
Eigen::Vector3d fairness_rest(const Topology& topology, const FlowFrame& frame, Index i, FairnessTarget target) {
  if (target == FairnessTarget::Zero) return Eigen::Vector3d::Zero();
  const Eigen::Vector3d n = row3(frame.curvature.N, i);
  return laplacian(frame.P, topology, i).dot(n) * n;
}

}  // namespace

double edge_metric_energy(const Vertices& V, const Topology& topology, const FlowFrame& frame) {
  double sum = 0;
  for (Index e = 0; e < topology.num_edges(); ++e) {
    const Index i = topology.edges(e, 0), j = topology.edges(e, 1);
    const Eigen::Vector3d eij = row3(V, j) - row3(V, i);
    const Curvature& c = frame.curvature;
    // Eq. 2 and 3 with the directions of each endpoint; Eq. 4 averages them.
    const double fi = std::abs(c.k1[i]) * std::pow(eij.dot(row3(c.T1, i)), 2) +
                      std::abs(c.k2[i]) * std::pow(eij.dot(row3(c.T2, i)), 2);
    const double fj = std::abs(c.k1[j]) * std::pow(eij.dot(row3(c.T1, j)), 2) +
                      std::abs(c.k2[j]) * std::pow(eij.dot(row3(c.T2, j)), 2);
    sum += 0.5 * (fi + fj);
  }
  return topology.num_edges() > 0 ? sum / topology.num_edges() : 0.0;
}

Vertices edge_metric_gradient(const Vertices& V, const Topology& topology, const FlowFrame& frame) {
  Vertices g = Vertices::Zero(V.rows(), 3);
  for (Index i = 0; i < static_cast<Index>(V.rows()); ++i) {
    const Eigen::Matrix3d Ki = frame.curvature.absolute_tensor(i);
    const auto [begin, end] = topology.ring(i);
    Eigen::Vector3d gi = Eigen::Vector3d::Zero();
    for (const Index* j = begin; j != end; ++j)
      gi += (Ki + frame.curvature.absolute_tensor(*j)) * (row3(V, i) - row3(V, *j));
    g.row(i) = gi.transpose();
  }
  return g;
}

double tangential_edge_energy(const Vertices& V, const Topology& topology, const FlowFrame& frame) {
  const Vertices g = edge_metric_gradient(V, topology, frame);
  double sum = 0;
  for (Index i = 0; i < static_cast<Index>(V.rows()); ++i) {
    sum += std::pow(g.row(i).dot(frame.curvature.T1.row(i)), 2) + std::pow(g.row(i).dot(frame.curvature.T2.row(i)), 2);
  }
  return topology.num_edges() > 0 ? sum / topology.num_edges() : 0.0;
}

double squared_distance_energy(const Vertices& V, const FlowFrame& frame) {
  double sum = 0;
  for (Index i = 0; i < static_cast<Index>(V.rows()); ++i) sum += squared_distance(frame, i, row3(V, i));
  return V.rows() > 0 ? sum / static_cast<double>(V.rows()) : 0.0;
}

double fairness_energy(const Vertices& V, const Topology& topology, const FlowFrame& frame, FairnessTarget target) {
  double sum = 0;
  for (Index i = 0; i < static_cast<Index>(V.rows()); ++i)
    sum += fairness_weight(frame.curvature, i) *
           (laplacian(V, topology, i) - fairness_rest(topology, frame, i, target)).squaredNorm();
  return V.rows() > 0 ? sum / static_cast<double>(V.rows()) : 0.0;
}

double sliver_energy(const Vertices& V, const FlowFrame& frame) {
  if (frame.sliver_stiffness.empty() || V.rows() == 0) return 0.0;
  double sum = 0;
  for (Index i = 0; i < static_cast<Index>(V.rows()); ++i) {
    const Eigen::Vector3d move = row3(V, i) - row3(frame.P, i);
    sum += move.dot(frame.sliver_stiffness[static_cast<std::size_t>(i)] * move);
  }
  return sum / static_cast<double>(V.rows());
}

double total_flow_energy(const Vertices& V, const Topology& topology, const FlowFrame& frame,
                         const EnergyWeights& weights) {
  const double n = static_cast<double>(V.rows());
  const double pull = n > 0 ? (V - frame.P).squaredNorm() / n : 0.0;
  return tangential_edge_energy(V, topology, frame) + weights.lambda * squared_distance_energy(V, frame) +
         weights.mu * fairness_energy(V, topology, frame, weights.fairness_target) +
         weights.sliver * sliver_energy(V, frame) + weights.epsilon * weights.lambda * pull;
}

}  // namespace vertexflow
