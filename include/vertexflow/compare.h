// Every figure of docs/metrics.md for one result of the flow, its input and optionally a
// dense reference of the same surface (the `vertexflow compare` command).
//
// Roles: "input" is the mesh given to the flow (M0), "result" the mesh it returned (M),
// "reference" an optional dense mesh of the same surface (S). The "surface" whose curvature
// the uniformity and redistribution figures use is the reference when given, else the input.
//
// Choices made where metrics.md leaves room (stated once, here):
// - Surface curvature at a vertex of the result (or the input) is the surface's curvature at
//   that vertex's closest point on the surface: the per-vertex tensors K (Eq. 2,
//   Curvature::absolute_tensor) and the magnitudes |k1| + |k2| of the surface's vertices,
//   interpolated with the barycentric coordinates of the closest point. A vertex that lies on
//   the surface's vertex gets that vertex's values exactly. This is the same rule with or
//   without a reference, and works whatever the connectivity of the result.
// - Lengths are absolute (mesh units); `length_scale` is the bounding-box diagonal of the
//   reference (the input's without one) to report them relatively.
// - Flipped faces need the same faces in both meshes (result.F == input.F, same vertex
//   count); otherwise `flipped_faces` is empty ("not applicable"). Degenerate faces are
//   counted on each mesh regardless.
// - Curvature is estimated with principal_curvatures (curvature.h) on all three meshes; a
//   non-manifold mesh is measured as it is (the estimator uses its manifold split).
#pragma once

#include "vertexflow/curvature.h"
#include "vertexflow/distance.h"
#include "vertexflow/mesh.h"
#include "vertexflow/metrics.h"
#include "vertexflow/quality.h"
#include "vertexflow/topology.h"

#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace vertexflow {

/// Which mesh a CompareError is about.
enum class MeshRole { Result, Input, Reference };

/// "result", "input" or "reference".
const char* to_string(MeshRole role);

/// Thrown by compare_meshes for a mesh it cannot measure (no faces, bad indices); what()
/// describes the problem, role() says which mesh.
class CompareError : public std::invalid_argument {
 public:
  CompareError(MeshRole role, const std::string& message) : std::invalid_argument(message), role_(role) {}
  [[nodiscard]] MeshRole role() const { return role_; }

 private:
  MeshRole role_;
};

struct CompareOptions {
  /// Sampling of every distance (the same seed on each mesh).
  SamplingOptions sampling;
  /// The curvature estimator of the surface and of the |H| percentiles.
  CurvatureOptions curvature;
};

/// Percentiles (nearest rank, statistics.h) of |H| = |k1 + k2| / 2 over the vertices.
struct MeanCurvaturePercentiles {
  double p5 = 0, p50 = 0, p95 = 0, p99 = 0;
};

/// Percentiles 5, 50, 95, 99 of |H| of `curvature`.
MeanCurvaturePercentiles mean_curvature_percentiles(const Curvature& curvature);

/// A surface's curvature at points, from their closest points on it (see the choices above).
struct SurfaceCurvatureAtPoints {
  std::vector<Eigen::Matrix3d> tensors;  ///< interpolated K (Curvature::absolute_tensor), one per point
  Eigen::VectorXd magnitude;             ///< interpolated |k1| + |k2| (= trace of the tensor)
};

/// Interpolates `surface_curvature` (per vertex of the mesh behind `surface`) at the closest
/// points of the rows of P. `near_faces`, empty or one per row of P, are guesses of a face of
/// that mesh near each row's answer, -1 for none (DistanceQuery::closest_points): they make the
/// search faster, not its answers different. Throws std::invalid_argument if the curvature does
/// not have one entry per vertex of that mesh, or as closest_points does for the guesses.
SurfaceCurvatureAtPoints surface_curvature_at(const Vertices& P, const DistanceQuery& surface,
                                              const Curvature& surface_curvature,
                                              std::span<const Index> near_faces = {});

/// Everything metrics.md asks for (except the level-of-detail and timing figures).
struct MeshComparison {
  /// Bounding-box diagonal of the reference, or of the input without one.
  double length_scale = 0;
  bool has_reference = false;

  /// Shape fidelity, absolute lengths. a = result, b = input.
  SymmetricDistance result_input;
  /// a = result, b = reference; empty without a reference.
  std::optional<SymmetricDistance> result_reference;
  /// a = input, b = reference: the baseline result_reference is judged against; empty without
  /// a reference.
  std::optional<SymmetricDistance> input_reference;

  /// Approximation uniformity: delta_e = f_em / 8 on the edges of each mesh, with the
  /// surface's curvature at the edges' endpoints.
  EdgeErrorStats edge_error_input;
  EdgeErrorStats edge_error_result;

  /// Vertex redistribution: Spearman rho of surface |k1| + |k2| and vertex density.
  double redistribution_rho_input = 0;
  double redistribution_rho_result = 0;

  /// Feature prominence: |H| of each mesh's own curvature.
  MeanCurvaturePercentiles abs_mean_curvature_input;
  MeanCurvaturePercentiles abs_mean_curvature_result;

  /// Triangle quality 2r/R.
  QualityStats quality_input;
  QualityStats quality_result;

  /// Faces with area below kDegenerateAreaRelative * diagonal^2 of their own mesh.
  Index degenerate_faces_input = 0;
  Index degenerate_faces_result = 0;

  /// Whether result and input have the same faces (and vertex count).
  bool same_connectivity = false;
  /// Faces whose normal turned by more than 90 degrees from input to result; empty (not
  /// applicable) unless same_connectivity.
  std::optional<Index> flipped_faces;
};

/// Measures `result` against `input` and, when not null, `reference`. Colours and vertex
/// properties are ignored. Throws CompareError for a mesh without faces.
/// Parallel (TBB); the figures do not depend on the thread count.
MeshComparison compare_meshes(const Mesh& result, const Mesh& input, const Mesh* reference,
                              const CompareOptions& options = {});

/// What compare_meshes derives from one mesh before measuring it, for a caller that has it
/// already: `vertexflow enhance` builds the faces' topology for the flow and needs both meshes'
/// curvature for its HTML report too, so each is computed once per command. Non-owning; a null
/// member is computed by compare_meshes as without it.
struct MeshDerivedData {
  /// build_topology(mesh.F, mesh.num_vertices()); meshes with the same faces may share one.
  const Topology* topology = nullptr;
  /// principal_curvatures(mesh.V, mesh.F, topology, options.curvature): the mesh's own
  /// curvature at its own scale, with the comparison's estimator options. Only its size is
  /// checked: the curvature of other positions or options gives wrong figures.
  const Curvature* curvature = nullptr;
};

/// Precomputed data of the meshes of one comparison (the reference's is ignored without one).
struct ComparePrecomputed {
  MeshDerivedData result, input, reference;
};

/// The same with data the caller has computed already: the same figures, bit for bit. A given
/// topology is checked as compare_meshes checks its own (CompareError for a mesh without
/// faces); a topology or curvature for another vertex or face count throws
/// std::invalid_argument.
MeshComparison compare_meshes(const Mesh& result, const Mesh& input, const Mesh* reference,
                              const CompareOptions& options, const ComparePrecomputed& precomputed);

/// The topology of `mesh`, built and checked as compare_meshes does: CompareError naming
/// `role` ("the result mesh has no faces", or the reason build_topology refuses its faces)
/// otherwise. For a caller that builds the topology itself, so that its errors read as the
/// comparison's.
Topology checked_topology(const Mesh& mesh, MeshRole role);

}  // namespace vertexflow
