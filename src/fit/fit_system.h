// Internal to the fit stage: the linear system of one round of fit.h's energy, for fixed data
// rows, and its two solvers. Both minimise the same energy; they differ in rounding only.
// - Direct: CHOLMOD (sparse_cholesky.h) on a pattern fixed for all rounds, ordered and analysed
//   once. Exact, but the ordering and factorisation grow faster than the mesh: at 346k vertices
//   (lod's first level of a 692k-vertex mesh) they took 5.2 s and 3.6 s of a 34 s fit.
// - Iterative: conjugate gradients (conjugate_gradients.h) on the round's step from the current
//   positions, block-Jacobi preconditioned, the anchored Laplacian applied matrix-free. The data
//   term is close to a finite-element mass matrix (samples per face area, and every vertex has a
//   row of its own), which diagonal scaling conditions well.
#pragma once

#include "vertexflow/fit.h"
#include "vertexflow/topology.h"

#include <memory>
#include <vector>

namespace vertexflow {

/// A point of the mesh as a combination of (up to) three vertices, and the point of the other
/// surface it should reach.
struct DataRow {
  Index face = -1;  ///< the face whose corners these are; -1 for a vertex (corners all equal)
  Eigen::Vector3i corners;
  Eigen::Vector3d weights;
  Eigen::Vector3d target;
  double weight = 1.0;  ///< relative to the other rows of its direction
};

/// The linear system of one round over the free vertices of a mesh whose connectivity stays.
class FitSystem {
 public:
  virtual ~FitSystem() = default;
  /// Minimises fit.h's energy for fixed data rows (either list may be empty) around the
  /// positions X; fixed vertices keep their rows of X bit for bit. Adds the solver's
  /// iterations (0 for the direct solve) to report.solver_iterations.
  virtual Vertices solve(const Vertices& X, const std::vector<DataRow>& to_mesh,
                         const std::vector<DataRow>& to_reference, const FitOptions& options, FitReport& report) = 0;
};

/// The system of the mesh (F, with `topology` its build_topology) whose vertices flagged in
/// `fixed` stay, for options.fairness and options.solver. The arguments must outlive the
/// system.
std::unique_ptr<FitSystem> make_fit_system(const Faces& F, const Topology& topology, const std::vector<char>& fixed,
                                           const FitOptions& options);

}  // namespace vertexflow
