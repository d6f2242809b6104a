// Garland-Heckbert simplification (simplify.h): through CGAL's edge-collapse framework, or
// vertexflow's own collapse (quadric_collapse.h).
#include "vertexflow/simplify.h"

#include "quadric_collapse.h"
#include "surface_mesh_conversion.h"

#include "vertexflow/topology.h"

#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Constrained_placement.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/GarlandHeckbert_plane_policies.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

namespace vertexflow {
namespace {

namespace SMS = CGAL::Surface_mesh_simplification;
using remesh_detail::Kernel;
using remesh_detail::SurfaceMesh;
using Quadrics = SMS::GarlandHeckbert_plane_policies<SurfaceMesh, Kernel>;

// Stops when one more collapse (two faces, or one at a free boundary edge) could go below the
// budget, so the result has `target` or `target + 1` faces. CGAL 5.5 only has an edge-count
// predicate, and the edge count of a mesh with boundary does not determine its face count.
struct FaceBudget {
  std::size_t target;
  template <typename Cost, typename Profile>
  bool operator()(const Cost& /*cost*/, const Profile& profile, std::size_t /*initial_edges*/,
                  std::size_t /*current_edges*/) const {
    // number_of_faces() counts live faces; BGL's num_faces() of a Surface_mesh includes removed ones.
    return profile.surface_mesh().number_of_faces() < target + 2;
  }
};

// The Cgal method: CGAL's edge_collapse with Garland-Heckbert quadrics on a Surface_mesh.
Mesh simplify_cgal(const Vertices& V, const Faces& F, const SimplifyOptions& options, SimplifyReport& report) {
  SurfaceMesh mesh = remesh_detail::to_surface_mesh(V, F, "simplify", &report.repairs.input_split);
  // Every collapse removes exactly one vertex (CGAL's return value counts removed edges).
  const auto vertices_before = mesh.number_of_vertices();
  if (report.target_faces < report.input_faces) {
    const FaceBudget stop{static_cast<std::size_t>(report.target_faces)};
    Quadrics quadrics(mesh);
    // A closed mesh has nothing to constrain: the unconstrained call collapses the same edges
    // to the same places, and skips Constrained_placement's walk around both ends of every
    // edge costed (15% of the run on a closed 1M-vertex mesh, measured with perf).
    const bool constrain_boundary = options.keep_boundary && std::any_of(mesh.edges().begin(), mesh.edges().end(),
                                                                         [&](auto e) { return mesh.is_border(e); });
    if (constrain_boundary) {
      // Boundary edges are constrained: never collapsed, and Constrained_placement puts any
      // collapse that touches a boundary vertex onto that vertex, so the loops stay exact.
      auto on_boundary = mesh.add_property_map<SurfaceMesh::Edge_index, bool>("e:vertexflow_boundary", false).first;
      for (const auto e : mesh.edges()) on_boundary[e] = mesh.is_border(e);
      const SMS::Constrained_placement<Quadrics, decltype(on_boundary)> placement(on_boundary, quadrics);
      SMS::edge_collapse(
          mesh, stop,
          CGAL::parameters::edge_is_constrained_map(on_boundary).get_cost(quadrics).get_placement(placement));
    } else {
      SMS::edge_collapse(mesh, stop, CGAL::parameters::get_cost(quadrics).get_placement(quadrics));
    }
  }

  report.collapses = static_cast<Index>(vertices_before - mesh.number_of_vertices());
  return remesh_detail::from_surface_mesh(mesh, &report.repairs);
}

// The Native method: the collapse on the manifold split of (V, F), then the CGAL path's repairs
// only where its result needs them (none was needed on any mesh measured; kept so that the
// output contract of simplify.h holds by construction, not by argument).
Mesh simplify_native(const Vertices& V, const Faces& F, const SimplifyOptions& options, SimplifyReport& report) {
  if (V.rows() == 0 || F.rows() == 0) throw std::invalid_argument("simplify: the mesh is empty");
  ManifoldSplit copy;
  bool split = false;
  {
    // build_topology also checks the indices and repeated vertices. Scoped: at 1M vertices the
    // topology is 200 MB that the collapse does not need.
    const Topology topology = build_topology(F, static_cast<Index>(V.rows()));
    split = !(topology.is_manifold() && topology.is_oriented);
    if (split) {
      copy = split_non_manifold(V, F, topology);
      report.repairs.input_split = copy.counts();
    }
  }
  remesh_detail::QuadricCollapseResult collapsed = remesh_detail::quadric_collapse(
      split ? copy.V : V, split ? copy.F : F, report.target_faces, options.keep_boundary);
  report.collapses = collapsed.collapses;
  Mesh& out = collapsed.mesh;
  const Topology result = build_topology(out.F, out.num_vertices());
  bool needs_repair = !(result.is_manifold() && result.is_oriented);
  for (Index f = 0; f < out.num_faces() && !needs_repair; ++f)
    needs_repair = face_normal(out.V, out.F, f).squaredNorm() == 0;
  if (!needs_repair) return std::move(out);
  const ManifoldSplitCounts input_split = report.repairs.input_split;
  SurfaceMesh mesh = remesh_detail::to_surface_mesh(out.V, out.F, "simplify");
  Mesh repaired = remesh_detail::from_surface_mesh(mesh, &report.repairs);
  report.repairs.input_split = input_split;
  return repaired;
}

}  // namespace

const std::map<std::string, SimplifyMethod>& simplify_method_names() {
  static const std::map<std::string, SimplifyMethod> names{{"cgal", SimplifyMethod::Cgal},
                                                           {"native", SimplifyMethod::Native}};
  return names;
}

std::string simplify_method_name(SimplifyMethod method) {
  return method == SimplifyMethod::Native ? "native" : "cgal";
}

SimplifyResult simplify(const Vertices& V, const Faces& F, const SimplifyOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  if (options.target_faces < 0) throw std::invalid_argument("simplify: the target face count is negative");
  if (options.target_faces == 0 && !(options.target_ratio > 0 && options.target_ratio <= 1))
    throw std::invalid_argument("simplify: the target ratio must be in (0, 1]");
  SimplifyReport report;
  report.input_faces = static_cast<Index>(F.rows());
  report.target_faces =
      options.target_faces > 0
          ? options.target_faces
          : std::max<Index>(1, static_cast<Index>(std::lround(options.target_ratio * static_cast<double>(F.rows()))));
  SimplifyResult result{options.method == SimplifyMethod::Native ? simplify_native(V, F, options, report)
                                                                 : simplify_cgal(V, F, options, report),
                        {}};
  report.output_faces = result.mesh.num_faces();
  report.reached_target = report.output_faces <= report.target_faces + 1;
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.report = report;
  return result;
}

}  // namespace vertexflow
