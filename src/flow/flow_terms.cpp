#include "flow_terms.h"

#include "numerics/parallel.h"

#include <algorithm>
#include <cmath>

namespace vertexflow {

FlowTerms make_flow_terms(const Topology& topology, const std::vector<char>& fixed, const FlowFrame& frame,
                          const EnergyWeights& weights, std::vector<Index> order) {
  FlowTerms t;
  t.n = static_cast<Index>(frame.P.rows());
  const auto n = static_cast<std::size_t>(t.n);
  t.original = std::move(order);
  // Mesh vertex -> local index, for the rings and the terms: not kept through the solve (4 bytes a
  // vertex).
  std::vector<Index> local(n);
  for (std::size_t k = 0; k < n; ++k) local[static_cast<std::size_t>(t.original[k])] = static_cast<Index>(k);
  t.ring_start.resize(n + 1);
  t.ring_start[0] = 0;
  for (std::size_t k = 0; k < n; ++k) t.ring_start[k + 1] = t.ring_start[k] + topology.valence(t.original[k]);
  t.ring.resize(static_cast<std::size_t>(t.ring_start[n]));
  t.fixed.resize(n);
  parallel_for_index(t.n, [&](Index k) {
    const Index v = t.original[static_cast<std::size_t>(k)];
    t.fixed[static_cast<std::size_t>(k)] = fixed[static_cast<std::size_t>(v)];
    const auto [begin, end] = topology.ring(v);
    Index* out = t.ring.data() + t.ring_start[static_cast<std::size_t>(k)];
    for (const Index* j = begin; j != end; ++j) *out++ = local[static_cast<std::size_t>(*j)];
  });
  t.K.assign_zero(n);
  t.G.assign_zero(n);
  t.P.assign_zero(n);
  t.D.assign_zero(n);
  t.smooth.resize(n);
  t.inv_degree.resize(n);
  t.rest.resize(n);
  const Curvature& c = frame.curvature;
  const double nv = std::max<double>(t.n, 1);
  const double w_em = topology.num_edges() > 0 ? 1.0 / topology.num_edges() : 0.0;
  const double w_sd = weights.lambda / nv, w_pull = weights.epsilon * weights.lambda / nv,
               w_sliver = weights.sliver / nv;
  // In the mesh's order, writing each vertex's terms at its local index: the curvature and the
  // positions are read in order, the rows of the terms written out of order (reading them out of
  // order, as the loop over local indices did, took a fifth more at 1M vertices).
  parallel_for_index(t.n, [&](Index i) {
    const auto v = static_cast<std::size_t>(local[static_cast<std::size_t>(i)]);
    const Eigen::Vector3d t1 = c.T1.row(i).transpose(), t2 = c.T2.row(i).transpose(), normal = c.N.row(i).transpose();
    t.K.set(v,
            Sym3f(Eigen::Matrix3d(std::abs(c.k1[i]) * t1 * t1.transpose() + std::abs(c.k2[i]) * t2 * t2.transpose())));
    t.P.set(v, Sym3f(Eigen::Matrix3d(w_em * (t1 * t1.transpose() + t2 * t2.transpose()))));
    Eigen::Matrix3d distance =
        w_sd * (distance_coefficient(frame.d, c.k1[i]) * t1 * t1.transpose() +
                distance_coefficient(frame.d, c.k2[i]) * t2 * t2.transpose() + normal * normal.transpose());
    distance.diagonal().array() += w_pull;
    if (!frame.sliver_stiffness.empty()) distance += w_sliver * frame.sliver_stiffness[static_cast<std::size_t>(i)];
    t.D.set(v, Sym3f(distance));
    const Index degree = topology.valence(i);
    t.inv_degree[v] = degree > 0 ? 1.0 / degree : 0.0;
    t.smooth[v] = degree > 0 ? weights.mu * std::exp(-(std::abs(c.k1[i]) + std::abs(c.k2[i]))) / nv : 0.0;
    t.rest[v].setZero();
    if (weights.fairness_target == FairnessTarget::InputNormal && degree > 0) {
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      const auto [begin, end] = topology.ring(i);
      for (const Index* j = begin; j != end; ++j) mean += frame.P.row(*j).transpose();  // mesh indices
      const Eigen::Vector3d umbrella = frame.P.row(i).transpose() - mean * t.inv_degree[v];
      t.rest[v] = umbrella.dot(normal) * normal;
    }
  });
  parallel_for_index(t.n, [&](Index i) {
    const auto [begin, end] = t.one_ring(i);
    Eigen::Matrix3d sum = static_cast<double>(end - begin) * t.K[static_cast<std::size_t>(i)].full();
    for (const Index* j = begin; j != end; ++j) sum += t.K[static_cast<std::size_t>(*j)].full();
    t.G.set(static_cast<std::size_t>(i), Sym3f(sum));
  });
  return t;
}

BlockVector to_local(const FlowTerms& t, const double* x) {
  BlockVector out(3 * static_cast<Eigen::Index>(t.n));
  parallel_for_index(t.n, [&](Index k) {
    out.segment<3>(3 * static_cast<Eigen::Index>(k)) =
        Eigen::Map<const Eigen::Vector3d>(x + 3 * static_cast<std::ptrdiff_t>(t.original[static_cast<std::size_t>(k)]));
  });
  return out;
}
void add_from_local(const FlowTerms& t, const BlockVector& x, double* out) {
  parallel_for_index(t.n, [&](Index k) {
    Eigen::Map<Eigen::Vector3d>(out + 3 * static_cast<std::ptrdiff_t>(t.original[static_cast<std::size_t>(k)])) +=
        x.segment<3>(3 * static_cast<Eigen::Index>(k));
  });
}

Eigen::Matrix3d diagonal_block(const FlowTerms& t, Index u) {
  Eigen::Matrix3d block = t.D[static_cast<std::size_t>(u)].full();
  double laplacian = 0;
  auto add = [&](Index i) {
    const Eigen::Matrix3d g = t.g_block(i, u);
    block.noalias() += g * t.P[static_cast<std::size_t>(i)].full() * g;
    laplacian += t.smooth[static_cast<std::size_t>(i)] * t.l_entry(i, u) * t.l_entry(i, u);
  };
  t.for_each_in_star(u, add);
  block.diagonal().array() += laplacian;
  return block;
}

}  // namespace vertexflow
