// The figures of docs/metrics.md for a result, its input and an optional reference
// (include/vertexflow/compare.h).
#include "vertexflow/compare.h"

#include "vertexflow/statistics.h"
#include "vertexflow/topology.h"

#include "numerics/parallel.h"
#include "numerics/vertex_ordering.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

namespace vertexflow {
namespace {

std::string mesh_name(MeshRole role) {
  return std::string("the ") + to_string(role) + " mesh";
}

// The checks of checked_topology on a topology the caller built. Non-manifold meshes are
// measured as they are (the curvature estimator handles them: curvature.h).
void check_topology(const Mesh& mesh, MeshRole role, const Topology& topology) {
  if (topology.num_vertices != mesh.num_vertices() || topology.num_faces != mesh.num_faces())
    throw std::invalid_argument("compare_meshes: the topology given for " + mesh_name(role) +
                                " was built for another mesh");
  if (mesh.num_faces() == 0) throw CompareError(role, mesh_name(role) + " has no faces");
}

// The caller's topology, checked, or a checked one of our own in `own`.
const Topology& topology_of(const Mesh& mesh, MeshRole role, const MeshDerivedData& given, Topology& own) {
  if (!given.topology) return own = checked_topology(mesh, role);
  check_topology(mesh, role, *given.topology);
  return *given.topology;
}

void check_curvature(const Mesh& mesh, MeshRole role, const Curvature* curvature) {
  if (curvature && (curvature->k1.size() != mesh.num_vertices() || curvature->k2.size() != mesh.num_vertices() ||
                    curvature->T1.rows() != mesh.num_vertices() || curvature->T2.rows() != mesh.num_vertices()))
    throw std::invalid_argument("compare_meshes: the curvature given for " + mesh_name(role) + " has " +
                                std::to_string(curvature->k1.size()) + " vertices, the mesh " +
                                std::to_string(mesh.num_vertices()));
}

}  // namespace

Topology checked_topology(const Mesh& mesh, MeshRole role) {
  if (mesh.num_faces() == 0) throw CompareError(role, mesh_name(role) + " has no faces");
  Topology topology;
  try {
    topology = build_topology(mesh.F, mesh.num_vertices());
  } catch (const std::invalid_argument& e) {
    throw CompareError(role, mesh_name(role) + ": " + e.what());
  }
  check_topology(mesh, role, topology);
  return topology;
}

const char* to_string(MeshRole role) {
  switch (role) {
    case MeshRole::Result:
      return "result";
    case MeshRole::Input:
      return "input";
    case MeshRole::Reference:
      return "reference";
  }
  return "?";
}

MeanCurvaturePercentiles mean_curvature_percentiles(const Curvature& curvature) {
  const Eigen::VectorXd h = curvature.mean().cwiseAbs();
  const std::vector<double> p = percentiles(std::vector<double>(h.data(), h.data() + h.size()), {5, 50, 95, 99});
  return {p[0], p[1], p[2], p[3]};
}

SurfaceCurvatureAtPoints surface_curvature_at(const Vertices& P, const DistanceQuery& surface,
                                              const Curvature& surface_curvature, std::span<const Index> near_faces) {
  if (surface_curvature.k1.size() != surface.vertices().rows())
    throw std::invalid_argument("surface_curvature_at: curvature of " + std::to_string(surface_curvature.k1.size()) +
                                " vertices for a surface of " + std::to_string(surface.vertices().rows()));
  const Faces& F = surface.faces();
  SurfaceCurvatureAtPoints out;
  out.tensors.resize(static_cast<std::size_t>(P.rows()));
  out.magnitude.resize(P.rows());
  const Eigen::VectorXd magnitude = surface_curvature.absolute_sum();
  // The points are queried along a Morton curve, so that consecutive queries are close and each
  // starts from a good guess (the previous answer): at 1M vertices 0.98 s instead of 1.40 s in
  // vertex order. The answers do not depend on the order (distance.h: equally close faces go to
  // the lowest-numbered). They are taken in chunks, so that they take 4 MiB rather than 64 bytes
  // per point.
  if (!near_faces.empty() && static_cast<Eigen::Index>(near_faces.size()) != P.rows())
    throw std::invalid_argument("surface_curvature_at: " + std::to_string(near_faces.size()) + " guesses for " +
                                std::to_string(P.rows()) + " points");
  const std::vector<Index> order = space_filling_order(P);
  constexpr Eigen::Index kChunk = 65536;
  Vertices chunk;
  std::vector<Index> chunk_near;
  for (Eigen::Index start = 0; start < P.rows(); start += kChunk) {
    const Eigen::Index n = std::min(kChunk, P.rows() - start);
    chunk.resize(n, 3);
    if (!near_faces.empty()) chunk_near.resize(static_cast<std::size_t>(n));
    tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, n, 4096), [&](const auto& range) {
      for (Eigen::Index i = range.begin(); i != range.end(); ++i) {
        const Index row = order[static_cast<std::size_t>(start + i)];
        chunk.row(i) = P.row(row);
        if (!near_faces.empty()) chunk_near[static_cast<std::size_t>(i)] = near_faces[static_cast<std::size_t>(row)];
      }
    });
    const std::vector<ClosestPoint> closest = surface.closest_points(chunk, chunk_near);
    tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, n, 4096), [&](const auto& range) {
      for (Eigen::Index i = range.begin(); i != range.end(); ++i) {
        const Index row = order[static_cast<std::size_t>(start + i)];
        const ClosestPoint& c = closest[static_cast<std::size_t>(i)];
        Eigen::Matrix3d K = Eigen::Matrix3d::Zero();
        double m = 0;
        for (int k = 0; k < 3; ++k) {
          const Index v = F(c.face, k);
          K += c.barycentric[k] * surface_curvature.absolute_tensor(v);
          m += c.barycentric[k] * magnitude[v];
        }
        out.tensors[static_cast<std::size_t>(row)] = K;
        out.magnitude[row] = m;
      }
    });
  }
  return out;
}

MeshComparison compare_meshes(const Mesh& result, const Mesh& input, const Mesh* reference,
                              const CompareOptions& options) {
  return compare_meshes(result, input, reference, options, ComparePrecomputed{});
}

MeshComparison compare_meshes(const Mesh& result, const Mesh& input, const Mesh* reference,
                              const CompareOptions& options, const ComparePrecomputed& precomputed) {
  Topology own_result_topology, own_input_topology, own_reference_topology;
  const Topology& result_topology = topology_of(result, MeshRole::Result, precomputed.result, own_result_topology);
  const Topology& input_topology = topology_of(input, MeshRole::Input, precomputed.input, own_input_topology);
  const Topology& reference_topology =
      reference ? topology_of(*reference, MeshRole::Reference, precomputed.reference, own_reference_topology)
                : own_reference_topology;
  check_curvature(result, MeshRole::Result, precomputed.result.curvature);
  check_curvature(input, MeshRole::Input, precomputed.input.curvature);
  if (reference) check_curvature(*reference, MeshRole::Reference, precomputed.reference.curvature);
  // The caller's curvature, or our own computed below.
  const auto curvature_of = [](const MeshDerivedData& given, const Curvature& own) -> const Curvature& {
    return given.curvature ? *given.curvature : own;
  };

  MeshComparison c;
  c.has_reference = reference != nullptr;
  c.length_scale = bounding_box(reference ? reference->V : input.V).diagonal();

  // Memory (issue 29): one distance tree at a time, each over the mesh's own V and F (not a
  // copy) and freed after its queries; samples bounded (SamplingOptions), and each surface
  // curvature at the vertices used and freed before the next. Every figure is as when all were
  // built at once: each depends only on its samples and the tree it queries.
  //
  // First, at once: each mesh's samples (one draw each: the result's serve the input and the
  // reference), the curvatures not given, and the first tree (the input's).
  using Borrow = DistanceQuery::Borrow;
  std::optional<DistanceQuery> query;
  SurfaceSamples result_samples, input_samples, reference_samples;
  Curvature own_result_curvature, own_input_curvature, own_reference_curvature;
  // Mesh quality, degenerate and flipped faces (partly serial loops) alongside.
  const auto quality = [&] {
    tbb::parallel_invoke([&] { c.quality_input = summarize_quality(triangle_quality(input.V, input.F)); },
                         [&] { c.quality_result = summarize_quality(triangle_quality(result.V, result.F)); });
    c.degenerate_faces_input = static_cast<Index>(degenerate_faces(input.V, input.F).size());
    c.degenerate_faces_result = static_cast<Index>(degenerate_faces(result.V, result.F).size());
    c.same_connectivity = result.V.rows() == input.V.rows() && result.F.rows() == input.F.rows() && result.F == input.F;
    if (c.same_connectivity) c.flipped_faces = static_cast<Index>(flipped_faces(input.V, result.V, input.F).size());
  };
  tbb::parallel_invoke(
      quality, [&] { query.emplace(input.V, input.F, Borrow{}); },
      [&] { result_samples = sample_surface(result.V, result.F, options.sampling); },
      [&] { input_samples = sample_surface(input.V, input.F, options.sampling); },
      [&] {
        if (!precomputed.result.curvature)
          own_result_curvature = principal_curvatures(result.V, result.F, result_topology, options.curvature);
      },
      [&] {
        if (!precomputed.input.curvature)
          own_input_curvature = principal_curvatures(input.V, input.F, input_topology, options.curvature);
      },
      [&] {
        if (!reference) return;
        tbb::parallel_invoke([&] { reference_samples = sample_surface(reference->V, reference->F, options.sampling); },
                             [&] {
                               if (!precomputed.reference.curvature)
                                 own_reference_curvature = principal_curvatures(reference->V, reference->F,
                                                                                reference_topology, options.curvature);
                             });
      });
  const Curvature& result_curvature = curvature_of(precomputed.result, own_result_curvature);
  const Curvature& input_curvature = curvature_of(precomputed.input, own_input_curvature);
  const Curvature& reference_curvature = curvature_of(precomputed.reference, own_reference_curvature);

  // Approximation uniformity and redistribution of one mesh from the surface's curvature at its
  // vertices, which are then freed.
  const auto uniformity = [](const Mesh& mesh, const Topology& topology, const SurfaceCurvatureAtPoints& at,
                             EdgeErrorStats& edge_error, double& rho) {
    edge_error = edge_error_stats(mesh.V, topology, at.tensors);
    rho = redistribution_rho(at.magnitude, mesh.V, mesh.F);
  };

  // The input's tree: result -> input, reference -> input, and without a reference the input
  // surface's curvature at the result's vertices.
  const DistanceStats result_to_input = one_sided_distance(result_samples, *query);
  DistanceStats reference_to_input;
  if (reference) {
    reference_to_input = one_sided_distance(reference_samples, *query);
  } else {
    // With the input's connectivity, result vertex i is near input vertex i: of its faces, the
    // one whose centroid is nearest is a good first guess for the search.
    std::vector<Index> near_faces;
    if (c.same_connectivity) {
      near_faces.assign(static_cast<std::size_t>(result.V.rows()), -1);
      parallel_for_index(static_cast<Index>(result.V.rows()), [&](Index v) {
        const auto u = static_cast<std::size_t>(v);
        double best = std::numeric_limits<double>::infinity();
        for (auto k = static_cast<std::size_t>(input_topology.face_offsets[u]);
             k < static_cast<std::size_t>(input_topology.face_offsets[u + 1]); ++k) {
          const Index f = input_topology.vertex_faces[k];
          const Eigen::RowVector3d centroid =
              input.V.row(input.F(f, 0)) + input.V.row(input.F(f, 1)) + input.V.row(input.F(f, 2));
          const double d = (centroid - 3 * result.V.row(v)).squaredNorm();
          if (d < best) {
            best = d;
            near_faces[u] = f;
          }
        }
      });
    }
    uniformity(result, result_topology, surface_curvature_at(result.V, *query, input_curvature, near_faces),
               c.edge_error_result, c.redistribution_rho_result);
    // The input's own curvature at its own vertices: no interpolation, and no tensors stored.
    c.edge_error_input = edge_error_stats(input.V, input_topology, input_curvature);
    c.redistribution_rho_input = redistribution_rho(input_curvature.absolute_sum(), input.V, input.F);
  }
  query.reset();

  // The result's tree: input -> result, reference -> result.
  query.emplace(result.V, result.F, Borrow{});
  c.result_input = symmetric_distance(result_to_input, one_sided_distance(input_samples, *query));
  DistanceStats reference_to_result;
  if (reference) reference_to_result = one_sided_distance(reference_samples, *query);
  query.reset();

  // The reference's tree: result -> reference, input -> reference, and the reference's
  // curvature at both meshes' vertices.
  if (reference) {
    query.emplace(reference->V, reference->F, Borrow{});
    c.result_reference = symmetric_distance(one_sided_distance(result_samples, *query), reference_to_result);
    c.input_reference = symmetric_distance(one_sided_distance(input_samples, *query), reference_to_input);
    uniformity(input, input_topology, surface_curvature_at(input.V, *query, reference_curvature), c.edge_error_input,
               c.redistribution_rho_input);
    uniformity(result, result_topology, surface_curvature_at(result.V, *query, reference_curvature),
               c.edge_error_result, c.redistribution_rho_result);
    query.reset();
  }
  c.abs_mean_curvature_input = mean_curvature_percentiles(input_curvature);
  c.abs_mean_curvature_result = mean_curvature_percentiles(result_curvature);
  return c;
}

}  // namespace vertexflow
