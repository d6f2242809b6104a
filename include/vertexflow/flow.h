// Vertex flow (Ji, Liu, Wang, Wang 2011): vertices slide over the surface towards curved
// regions, connectivity unchanged, by minimising F_total = F_em + lambda F_sd + mu F_smo
// (flow_energy.h) in one sparse least-squares solve.
//
// Scale and rigid motion: the flow runs on a copy translated to its centroid and scaled to
// mean edge length 1, where curvature times edge length is dimensionless and the balance of
// the terms does not depend on the mesh's size or resolution (docs/method-notes.md, point 1, "Scale"). The
// result is mapped back, so flowing a rotated, translated, uniformly scaled mesh gives the
// same transform of the result.
//
// Guarantees: boundary vertices (when fix_boundary) and pinned vertices do not move; no face
// turns by more than 90 degrees relative to the input and no face becomes degenerate. A face
// that would is repaired by halving the displacement of its vertices (per vertex, repeatedly,
// like CGAL's tangential relaxation step control); FlowReport counts the vertices limited.
//
// Non-manifold or inconsistently oriented meshes (scans, CAD exports) are flowed on their
// manifold split (manifold_split.h): faces oriented per component, edges of more than two faces
// cut, and every vertex whose neighbourhood is not one disc held where it is, bit for bit; the
// rest flows. The result has the input's vertices and faces, in order. FlowReport counts what
// was held; FlowOptions::refuse_non_manifold refuses such meshes instead.
//
// A surface without features comes back unchanged: when no vertex has a curvature radius below
// 1000 times the bounding-box diagonal (kFlatCurvature), there is nothing to enhance and the solves
// do not run (FlowReport::flat). Without curvature, Eq. 6 holds a vertex in its tangent plane only
// by the epsilon pull (1e-6), and the fairness rows of fixed boundary vertices, whose umbrella
// vectors point across the boundary, slid a flat 20x20 grid's inner vertices by up to 1.95 mean
// edge lengths (a grid with 1e-12 of noise by up to 0.47: its noise curvature, normalised by d,
// held them only partly). A flat region of a curved mesh (fandisk's facets) flows as before.
//
// Beyond the paper: FlowOptions::density adds density-weighted centroidal passes after the
// solves (off by default; DensityRelaxation says what they do and cost).
//
// Side effect: the sparse Cholesky runs with one BLAS thread, and vertex_flow sets the process's
// OpenBLAS thread count to 1 (when OpenBLAS is the BLAS): Debian's threaded OpenBLAS made the
// factorisation slower on 2 cores and its results depend on the thread count.
#pragma once

#include "vertexflow/curvature.h"
#include "vertexflow/flow_energy.h"
#include "vertexflow/guard.h"
#include "vertexflow/mesh.h"
#include "vertexflow/topology.h"

#include <string>
#include <vector>

namespace vertexflow {

/// How the flow's sparse linear system (the normal equations of flow_energy.h) is solved.
enum class LinearSolver {
  /// The direct factorisation at or below 1,000 free vertices (a few milliseconds, exact).
  /// Above, conjugate gradients: Multilevel from the start when the mesh has a flat region
  /// (|k1| + |k2| below 0.01 per mean edge length) of at least 500 connected free vertices,
  /// where block-Jacobi needs 3-8x more iterations (fandisk: 930 against 114). Otherwise
  /// Iterative, switching to Multilevel if the first 30 iterations predict more than about 105
  /// in all (Lanczos estimate of the condition number): spot 222 -> 88, max-planck-5k 146 ->
  /// 79; smooth meshes such as bunny_uniform (79) keep block-Jacobi, where the multilevel
  /// set-up costs more than it saves. If the iteration has not converged within 18 sqrt(free
  /// vertices) iterations (about what the factorisation would cost on this project's reference
  /// machine), the direct factorisation takes over when its predicted factor fits in 2 GiB,
  /// otherwise the iteration continues up to ten times that budget. So the total is at most
  /// about twice the cheaper method's (flow_solver.cpp explains the calibration).
  /// Deterministic: the choice depends only on the mesh, its curvature and the iteration's
  /// coefficients, never on timings.
  Automatic,
  /// Sparse Cholesky of the coupled 3n x 3n normal matrix (CHOLMOD). Exact to rounding, but its
  /// time grows like n^1.5 and its memory like n log n: about 2 GB at 100k vertices.
  Direct,
  /// Conjugate gradients preconditioned by the normal matrix's 3x3 diagonal blocks, started
  /// from the input positions, until the relative residual is below solver_tolerance.
  Iterative,
  /// Conjugate gradients as Iterative, with a multilevel preconditioner: block-Jacobi plus a
  /// smoothed-aggregation coarse space (aggregates of one-rings, their translations) whose
  /// Galerkin matrix is itself coarsened. It removes the slow smooth tangential modes of large
  /// flat regions, where only F_smo's bi-Laplacian holds the vertices; its set-up costs about
  /// 20-60 block-Jacobi iterations.
  Multilevel,
};

/// Density-weighted centroidal passes after the solves (FlowOptions::density). Not part of the
/// paper's energy: on inputs whose vertex areas vary for reasons other than curvature (vertex
/// clustering, some scans), the edge and fairness terms of the paper pull towards an
/// equilibrium set by the connectivity (a vertex's area grows with its valence) more than by
/// curvature, and the redistribution the flow exists for hardly shows (docs/redistribution.md).
///
/// Each pass moves every free interior vertex `step` of the way to the centroid of its faces'
/// centroids, weighted by face area times the face's sizing density (the mean of its corners'
///
///     density(v) = (epsilon + (|k1| + |k2|) * mean edge length)^exponent,
///
/// with the curvature of the surface the flow runs on at v's input position: the input's, or
/// the reference's at v's foot point. Each vertex keeps that density as it moves (it moves by
/// a fraction of an edge, over which the estimate does not change much), then is projected onto
/// the surface as the solve's result is and the pass is guarded as a solve
/// (FlowOptions::guard). Free boundary vertices (fix_boundary false) are left where the
/// solve put them: their centroids lie inside the surface. The passes need project_to_input
/// (validate_flow_options): unprojected, centroids inside convex regions shrink the mesh.
/// Repeated, the passes equalise area times density around the vertices (a centroidal Voronoi
/// relaxation on the fixed one-rings), which puts vertices where the curvature is. exponent 2
/// asks for edge lengths like 1 / |k|, which the +0.2 rho of issue 15 needs; a uniform edge
/// error (the paper's objective) asks for 1 / sqrt(|k|), exponent 1, and at sharp CAD creases
/// exponent 2 overshoots it (fandisk's edge-error CV: +46% with 30 passes, -19% at exponent
/// 1). 0 makes the passes an area-equalising tangential relaxation (like CGAL's
/// tangential_relaxation).
///
/// Measured (docs/redistribution.md): 30 passes raise rho by +0.22 to +0.26 on vertex-clustered
/// bunnies, where the flow alone gives +0.10 to +0.12. Like the flow, they slide vertices over
/// the input's facets: on 6k remeshes the mean distance to the true surface changes by -8% to
/// +19% (the flow alone: -5% to +6%), and on thin parts the Hausdorff distance rises (horse:
/// +97%). About 56 ms per pass at 90k vertices and 1.3 s at 1M (docs/benchmarks.md).
struct DensityRelaxation {
  /// The largest exponent: the densities of (0.1 + |k1| + |k2|)^10 span 1e-10 to 1e30 for
  /// curvatures up to 1e3 per mean edge length (camelhead's largest: 62). At 1e5 every density
  /// was 0 (|k1| + |k2| < 0.9) or inf, and a vertex had no centroid or a NaN one (issue 32: the
  /// same output as without the passes, exit 0). Exponent 2 already asks for edge lengths like
  /// 1 / |k|.
  static constexpr double max_exponent = 10;
  int passes = 0;         ///< 0: the paper's flow alone
  double exponent = 2.0;  ///< in [0, max_exponent]
  double epsilon = 0.1;   ///< > 0: the density of a flat region, per mean edge length
  double step = 0.5;      ///< in (0, 1]: the fraction of the way to the centroid per pass
};

struct FlowOptions {
  /// The weights of the energy's terms (flow_energy.h): lambda, the user's strength knob
  /// (default 1), mu (0.5), epsilon (1e-6), the fairness target (the input's normal part) and
  /// sliver (0.02), the weight of the term that keeps slivers from flipping in the solve.
  EnergyWeights weights;
  /// d of Eq. 6 is the principal curvature radius at this percentile of |k| (largest
  /// curvatures). 100 is the paper's literal "minimum radius of all vertices", which a single
  /// noisy vertex of a scan decides; 99 gives the same result on clean meshes and less drift
  /// on scans (docs/method-notes.md, point 4).
  double d_percentile = 99.0;
  /// Solves, each with curvature recomputed on the previous result. One by default: repeated
  /// solves kept lowering triangle quality without converging (docs/method-notes.md, point 5).
  int iterations = 1;
  /// After each solve, move every free vertex to the closest point of the input surface near
  /// it (a walk over the input's faces from the vertex's own, so it never jumps through a thin
  /// wall). The solve's F_sd holds vertices near the input only approximately: its quadric
  /// model of the surface and the Laplacian of F_smo let coarse meshes shrink or swell
  /// (measured: a 24-vertex chamfered cube +7% volume, an icosahedron -5%, a thin perforated
  /// plate +6%). Projected, the vertices slide over the input, which is what the flow is for.
  /// False gives the paper's unprojected solution.
  bool project_to_input = true;
  /// With the projection: an edge whose faces' normals differ by more than this angle
  /// (degrees) and that separates two patches (face sets connected across the other edges) is
  /// sharp. A vertex on exactly two sharp edges slides only along its crease, a vertex on one or
  /// three or more (a corner) stays, and no vertex crosses a crease; so CAD edges stay crisp and
  /// a coarse mesh does not lose its corners. Chains of edges above the angle that end inside a
  /// patch (under-sampled ridges, scan noise) are not creases: counting them froze 132 vertices
  /// of bunny_uniform (now 18) and cost 2 points of its edge-error CV reduction (-9.6% ->
  /// -11.8%). 180 or more disables it.
  double feature_angle = 40.0;
  /// Boundary (unless constraints.fix_boundary is false) and pinned vertices stay where they are.
  VertexConstraints constraints;
  /// Refuse (std::invalid_argument) a mesh that is not manifold or not consistently oriented
  /// instead of flowing its manifold split with the non-manifold vertices held (the CLI's
  /// --strict).
  bool refuse_non_manifold = false;
  /// The guard after every solve (guard.h): no face flips or degenerates, none ends below its
  /// quality floor. On the flow: without the floor, CAD creases produced 0.3% (fandisk) to 3%
  /// (spot) of faces below 0.3; the faces below guard.min_quality are also the slivers of
  /// F_sliver (flow_energy.h).
  GuardOptions guard;
  CurvatureOptions curvature;
  /// Solver of the linear system; the choice does not change the energy that is minimised.
  LinearSolver solver = LinearSolver::Automatic;
  /// Iterative solver: stop when |H d - b| <= solver_tolerance |b| (normal equations, starting
  /// residual b). Measured against a 1e-13 solve (largest / mean vertex distance from its
  /// position there, in mean edge lengths, on fandisk, camelhead, bunny_uniform, amo and
  /// horse-48k; the iteration counts of bunny_uniform and the 1M-vertex armadillo): 1e-6 within
  /// 1.1e-3 / 1.9e-5 (65 and 142 iterations), 1e-5 within 3.8e-3 / 2.7e-4 (52 and 111), 1e-4
  /// within 3.7e-2 / 2.4e-3 (37 and 85; camelhead's largest, 0.11, is a vertex the guard halved
  /// differently; with the solve's float storage 3.4e-2 / 2.2e-3 and 83 on the armadillo,
  /// docs/benchmarks.md, "Float storage in the solve"). From 1e-6 up, the iterations' products
  /// keep the operator's caches in float (about 5e-8 of rounding each). The flow moves vertices
  /// by 0.1-3 mean edge lengths and projects them onto the input afterwards, and every figure of
  /// bench/make_results.py stayed within 0.5% between 1e-6 and 1e-4 (but a sliver's quality,
  /// 8.0e-5 against 7.4e-5, and a zero at rounding level), while the solve is half or more of a
  /// large run: so 1e-4, 35-47% fewer iterations than 1e-6. Ask for 1e-6 or less where the
  /// displacement itself must be exact to 1e-3 of an edge (comparisons of solvers, tests of
  /// invariance); docs/benchmarks.md, "Solver tolerance 1e-4".
  double solver_tolerance = 1e-4;
  /// Density-weighted centroidal passes after the solves (none by default; DensityRelaxation).
  DensityRelaxation density;
};

struct FlowReport {
  double mean_edge_length = 0;  ///< of the input: the unit of the normalised problem
  double d = 0;                 ///< d of Eq. 6, in input units
  double solver_error = 0;      ///< relative residual of the last solve's normal equations
  /// The guard runs after every solve (options.iterations); these sum over the solves.
  Index flipped_before_guard = 0;      ///< faces the unguarded solution turned or degenerated
  Index low_quality_before_guard = 0;  ///< faces it left below their quality floor
  Index limited_vertices = 0;          ///< vertices the guard left short of their proposed move (any solve)
  Index density_limited_vertices = 0;  ///< the same for the density passes (FlowOptions::density), any pass
  Index fixed_vertices = 0;            ///< boundary, pinned, isolated and corner vertices
  /// Non-manifold input (manifold_split.h), all 0 for a manifold, oriented mesh:
  Index held_non_manifold_vertices = 0;  ///< vertices held because their faces form more than one fan
  Index reoriented_faces = 0;            ///< faces whose orientation disagreed with their component's
  Index cut_edges = 0;                   ///< edges treated as boundaries (non-manifold, orientation conflicts)
  double seconds_curvature = 0, seconds_assembly = 0, seconds_solve = 0, seconds_projection = 0, seconds_guard = 0;
  double seconds_density = 0;  ///< the density passes, their projection and guard included
  /// Direct: CHOLMOD's analysis and numeric factorisation; iterative: the preconditioner's set-up.
  double seconds_factorization = 0;
  LinearSolver solver_used = LinearSolver::Automatic;  ///< Direct, Iterative or Multilevel (the last solve)
  int solver_iterations = 0;  ///< conjugate-gradient iterations of the last solve (0: direct only)
  /// The surface the flow runs on has no curvature at its own scale (kFlatCurvature): no solve
  /// ran, free vertices stay (on a reference, they are only projected onto it and guarded).
  bool flat = false;
};

/// A surface is flat for the flow when its largest principal curvature |k| times its
/// bounding-box diagonal is below this (dimensionless: a radius beyond 1000 diagonals). The
/// bundled meshes measure 2.6 (chamfer-cube) to 6350 (camelhead), a sphere 3.46; a flat grid
/// with 1e-12 of noise 8.5e-10.
inline constexpr double kFlatCurvature = 1e-3;

struct FlowResult {
  Vertices V;  ///< new positions; faces are unchanged
  FlowReport report;
};

/// Checks every option against its allowed range: lambda > 0, mu >= 0, epsilon > 0, sliver >= 0
/// (all finite), d_percentile in [0, 100], iterations >= 1, density.passes in [0, 1000],
/// density.exponent in [0, DensityRelaxation::max_exponent], density.epsilon > 0, density.step in (0, 1] (all finite),
/// no density passes without project_to_input, feature_angle >= 0, the guard's options (validate_guard_options),
/// solver_tolerance in (0, 1), curvature.smoothing_rounds >= 0, and (when num_vertices >= 0) every pinned index in [0,
/// num_vertices). Throws std::invalid_argument naming the first option out of range and its allowed range.
void validate_flow_options(const FlowOptions& options, Index num_vertices = -1);

/// Moves the vertices of (V, F) by vertex flow. Throws std::invalid_argument for options out
/// of range (validate_flow_options), an empty mesh, a non-finite coordinate, a mesh without
/// extent, (with refuse_non_manifold) a non-manifold or inconsistently oriented mesh, or density
/// passes whose sizing density is not a finite positive number at some vertex.
FlowResult vertex_flow(const Vertices& V, const Faces& F, const FlowOptions& options = {});

/// The same with the topology of F (build_topology(F, V.rows())) computed by the caller, who
/// may need it too: the flow builds none of its own. Throws std::invalid_argument if the
/// topology was built for another vertex or face count.
FlowResult vertex_flow(const Vertices& V, const Faces& F, const Topology& topology, const FlowOptions& options = {});

/// The same, taking the topology: once the set-up has used them, the flow frees its face edges,
/// face adjacency, edge face counts, components and manifold flags (73 bytes per vertex that the
/// solve, the flow's peak, does not need), and leaves those fields empty. vertex_flow(V, F,
/// options) goes through this one.
FlowResult vertex_flow(const Vertices& V, const Faces& F, Topology&& topology, const FlowOptions& options = {});

/// The paper's flow with the true surface S known (issue 16): section 4.1 measures F_sd against S
/// and uses the input only "since S is usually unavailable". Here every solve takes from S, at
/// each vertex's closest point on it (its foot point), the anchor p_i and frame of F_sd and the
/// curvature tensor of F_em (S's principal_curvatures, options.curvature, blended over the foot
/// point's face by its barycentric weights and re-diagonalised in the plane normal to the
/// blended normal), and the projection puts the vertices on S instead of on the input. So the
/// vertices redistribute by S's curvature and stay on S: the distance to S is that of a mesh
/// inscribed in S, like the input's, not lower (fit_to_reference, fit.h, lowers it). Features,
/// boundaries, pins and the guard as vertex_flow (the guard's shortened vertices are not
/// projected). (VS, FS) is any triangle mesh of S, in the input's units. Throws as vertex_flow,
/// and std::invalid_argument for an empty S or a non-finite coordinate of S. A non-manifold or
/// inconsistently oriented input is handled as by vertex_flow (its manifold split flows on S,
/// its non-manifold vertices held) unless options.refuse_non_manifold. S itself may be any
/// triangle soup that principal_curvatures and the closest-point query accept.
FlowResult vertex_flow_on_reference(const Vertices& V, const Faces& F, const Vertices& VS, const Faces& FS,
                                    const FlowOptions& options = {});

}  // namespace vertexflow
