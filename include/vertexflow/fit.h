// Fitting a mesh to a reference surface with its connectivity fixed (issue 16, reference mode).
//
// The paper's F_sd measures the distance to the true surface S and uses the input mesh only
// "since S is usually unavailable" (section 4.1). When S is available as a dense mesh, the
// vertices can do better than stay on the input: they can take the off-surface positions that
// minimise the two-sided distance between the mesh and S. This is the distance energy of Hoppe
// et al. 1993 ("Mesh optimization", E_dist), minimised over the vertex positions only:
//
//   E(x) = 1/N_S sum_j |p_j - x(a_j)|^2  +  w_v / N_M sum_s |x(s) - c_s|^2
//          + w_f / n sum_i |(L x)_i - (L x_k)_i|^2  +  w_p / n sum_i |x_i - (x_k)_i|^2
//
// - p_j: area-uniform samples of S; a_j their foot points on the current mesh (a face and
//   barycentric weights), and x(a_j) that point as a function of the corner positions.
// - s: points on the current mesh (each vertex and each face's centroid), c_s their closest
//   points on S: the mesh -> S direction, without which faces could bulge off S where no
//   sample of S pulls them back.
// - L: the uniform Laplacian, anchored to the positions x_k of the round's start: a weak
//   membrane that keeps the solve well posed where no sample falls, and resists tangential
//   drift; it does not pull the mesh towards a smoother shape.
// - The proximity term, a trust region around x_k: sliding along a flat surface barely changes
//   the distance, and the anchored Laplacian barely resists smooth sliding modes, so without it
//   those modes are decided by rounding (a 1e-16 perturbation of the input moved spot's
//   vertices by 1e-3 of its size after one round) and drift round after round.
// Each round fixes the foot points, solves the linear least-squares problem (three right-hand
// sides, one factorisation), and repairs flipped or too-poor faces with the flow's guard
// (guard.h: GuardOptions). Rounds repeat until the data part of E (the
// mean of the two directions' mean squared distances) falls by less than `tolerance` of its
// value in a round, or after max_rounds.
//
// Conventions: lengths in the meshes' units; the result is the same, up to rounding, for any
// rigid motion or uniform scaling of both meshes together (all weights are dimensionless and
// the samples are drawn per face area). Deterministic: identical bytes for any thread count.
// Connectivity is unchanged; boundary vertices (unless fix_boundary is false) and pinned
// vertices keep their input coordinates bit for bit.
#pragma once

#include "vertexflow/guard.h"
#include "vertexflow/input_check.h"
#include "vertexflow/mesh.h"
#include "vertexflow/reference_surface.h"

#include <cstdint>
#include <vector>

namespace vertexflow {

/// How a fit solves each round's linear system (src/fit/fit_system.h explains both). They
/// minimise the same energy and differ by rounding only: on the remeshes of data/ the RMS
/// distances of the two agree to 12 digits (docs/benchmarks.md, "Fit solvers").
enum class FitSolver {
  /// Conjugate gradients on each round's step, block-Jacobi preconditioned, to a relative
  /// residual of kFitIterativeTolerance (about 20 iterations a round on every mesh measured);
  /// the direct solve takes over a round whose iteration has not converged within
  /// FitOptions::max_solver_iterations. Faster than Direct at every size measured (4.5k to 346k
  /// vertices).
  Iterative,
  /// CHOLMOD's sparse Cholesky factorisation. Its fill-reducing ordering and factorisation grow
  /// faster than the mesh: 5.2 s and 3.6 s for 346k vertices.
  Direct,
};

/// The relative residual |b - A d| / |b| at which the iterative solve of a round's step stops.
inline constexpr double kFitIterativeTolerance = 1e-10;

struct FitOptions {
  /// Area-uniform samples of the reference per vertex of the mesh. Measured on a 6k remesh of
  /// bunny.off: 10 gives a mean distance within 0.5% of 20's (-45.4% and -45.8% of the
  /// input's) in 25% less time; 5 lost 5 points of the Hausdorff gain.
  double samples_per_vertex = 10;
  /// w_v: the weight of the mesh -> reference direction relative to the reference -> mesh one.
  double mesh_to_reference_weight = 1.0;
  /// w_f: the weight of the anchored Laplacian (see above). 0 leaves it out (smooth mode, where
  /// every face has data); reference mode keeps it for the faces no sample of S falls on.
  double fairness = 0.05;
  /// w_p: the weight of the proximity term (see above).
  double proximity = 0.01;
  /// Rounds of foot points and solve at most, and the relative decrease of the data energy in
  /// one round below which they stop. The first round gains most (RMS -32% on the bunny
  /// remesh), later ones 1-3% each, mostly by sliding vertices along the surface, which lowers
  /// the minimum quality (30 rounds: RMS -56%, minimum quality 0.65 -> 0.30); 5% of the
  /// energy (about 2.5% of the RMS) stops after 4-6 rounds.
  int max_rounds = 10;
  double tolerance = 0.05;
  /// Boundary (unless constraints.fix_boundary is false) and pinned vertices keep their input
  /// coordinates bit for bit.
  VertexConstraints constraints;
  /// The guard after each round (guard.h), as the flow's.
  GuardOptions guard;
  /// Seed of the reference's samples. They are drawn from a stream derived from it
  /// (fit_sample_seed), never the one SamplingOptions::seed gives the measurements (compare,
  /// the reports, lod): with equal seeds (both default to 1) the fit's samples were the first
  /// of the measurement's, so a fit was scored partly on its own data points (amo's lod gain
  /// over QEM: -11.5% measured that way, -10.5% with the fit on another stream).
  std::uint64_t seed = 1;
  /// How each round's linear system is solved (FitSolver), and the iterations of one round's
  /// iterative solve after which the direct solve takes over (no mesh measured came near it).
  FitSolver solver = FitSolver::Iterative;
  int max_solver_iterations = 1000;
};

/// The seed of the stream the fit draws its samples of the reference from, for FitOptions::seed:
/// a SplitMix64 step of seed ^ a fixed tag, so that it differs from any small measurement seed.
std::uint64_t fit_sample_seed(std::uint64_t seed);

struct FitReport {
  /// RMS of the data energy's two directions, sqrt((mean d^2 S->M + mean d^2 M->S) / 2), in
  /// the meshes' units: at the start (index 0) and after each round. Smooth mode: the
  /// area-weighted RMS distance between the data points and their targets on the patches.
  std::vector<double> rms_distance;
  int rounds = 0;
  bool converged = false;  ///< stopped by the tolerance, not by max_rounds
  Index reference_samples = 0;
  Index flipped_before_guard = 0;  ///< summed over rounds
  Index low_quality_before_guard = 0;
  Index limited_vertices = 0;  ///< vertices the guard left short in any round
  /// Wall-clock seconds: seconds_tree is the reference's tree, built alongside its samples and
  /// the ordering and analysis of the linear system; the others sum over the rounds.
  double seconds_tree = 0, seconds_queries = 0, seconds_solve = 0, seconds_guard = 0;
  /// The conjugate-gradient iterations summed over the rounds (0 for FitSolver::Direct), and
  /// the rounds whose iteration did not converge and were solved directly instead.
  int solver_iterations = 0;
  int solver_fallbacks = 0;
  /// Smooth mode: building the patches (0 in reference mode); seconds_tree is then the
  /// system's set-up.
  double seconds_surface = 0;
  /// Smooth mode: the fraction of the input's interior faces (input_check.h) below quality
  /// 0.3, and whether it was held as decimated for exceeding
  /// SmoothFitOptions::max_poor_face_fraction (returned unchanged).
  double poor_face_fraction = 0;
  bool held_as_decimated = false;
  /// Smooth mode: the share of the input's interior edges sharper than kSharpEdgeAngle
  /// (input_check.h), and whether it was held as a subdivision control mesh for exceeding
  /// SmoothFitOptions::max_sharp_edge_fraction (returned unchanged; decimation is tested first).
  double sharp_edge_fraction = 0;
  bool held_as_control_mesh = false;
  /// Smooth mode: the input was held as already fitted (SmoothFitOptions::already_fitted).
  bool held_as_fitted = false;
};

struct FitResult {
  Vertices V;
  FitReport report;
};

/// The smooth-surface estimate of smooth mode: PN triangles (Vlachos et al. 2001) over the
/// mesh, each face a cubic Bezier triangle through its corners with the corners' normals. A
/// corner's normal is the angle-weighted mean of the normals of the faces around its vertex
/// within feature_angle of its own face's (so each side of a crease has its own), and an edge
/// whose faces meet at more than feature_angle, or with one face or more than two, stays
/// straight: creases are not rounded.
struct SmoothSurfaceOptions {
  /// Each face is tessellated into segments^2 triangles. Measured on bunny_uniform and the 6k
  /// remeshes of armadillo and horse (mean distance to the dense mesh, smooth mode): 3 is
  /// within 0.3 points of 4 in 25% less time; 2 loses 2-4 points.
  int segments = 3;
  double feature_angle = 40.0;  ///< degrees, as FlowOptions::feature_angle
};

/// The estimate tessellated: segments^2 triangles per face of F (a triangle soup: the faces'
/// shared vertices are repeated). Throws std::invalid_argument for segments < 1 or a negative
/// feature angle.
Mesh smooth_surface_estimate(const Vertices& V, const Faces& F, const SmoothSurfaceOptions& options = {});

/// Smooth mode: the vertices fitted to the PN-triangle patches of the input, for when no dense
/// mesh of the true surface exists. Each face's data are the centroids of its segments^2
/// subdivision triangles, each paired with the point of the face's patch at the same
/// barycentric coordinates (the correspondence is fixed by the patch's parameters, so no
/// closest-point search is needed), weighted by the face's area; the energy is fit.h's with
/// these as the only data rows, and the guard of fit_to_reference follows each solve. One
/// round by default: the correspondence does not change between rounds, and a second round
/// gained 0.2 points of mean distance for 30% more time.
///
/// The patches interpolate the input's vertices, so the fit assumes they lie on the true
/// surface, as they do on scans, remeshes, subdivision and iso-surface output: there the faces
/// move out to the surface they cut across (mean distance to the dense mesh -12% to -42% on
/// 6k remeshes of bunny, amo, armadillo and horse). On meshes whose vertices were placed off
/// the surface to fit it (QEM decimation with optimal placement, a previous run of a fitting
/// mode) the fit moves them further out: the 3k-vertex `simplify` outputs of the same four
/// models got 26-100% worse. Geometry alone cannot tell the two apart (a sphere's inscribed and
/// best-fitting meshes are the same mesh at two scales), but decimation leaves a mark that
/// remeshing and scanning do not: thin triangles. Inputs with more than
/// max_poor_face_fraction of their interior faces (no corner on a boundary edge, input_check.h)
/// below quality 0.3 (triangle_quality, quality.h) are therefore held as decimated: returned
/// unchanged, with FitReport::held_as_decimated set.
/// Measured fractions: 2.95-20.5% on QEM outputs of 9 data meshes at 10% and 25% of their faces,
/// 0% on the remeshes, at most 1.9% on the data meshes that are not decimated (fertility);
/// camelhead (7.6%) and max-planck-5k (8.8%) are decimated scans. The control mesh of a
/// subdivision surface has its vertices off the limit surface too, outside it where the patches
/// bulge out: inputs with more than max_sharp_edge_fraction of their interior edges sharper than
/// 40 degrees are held as control meshes (FitReport::held_as_control_mesh; input_check.h gives the
/// measured shares). A previous run of smooth mode keeps the input's triangle
/// shapes, so its mark is in the file instead: the provenance line each run of `enhance` writes
/// (provenance.h). An input whose comments record a smooth-mode or reference-mode fit is held
/// as already fitted (already_fitted; on bunny_adaptive the first run lowers the mean distance
/// by 30%, and a second, fitted anyway, raises the first's by 37%; docs/results.md).
struct SmoothFitOptions {
  SmoothSurfaceOptions surface;
  /// Inputs with a larger fraction of faces below quality 0.3 are held as decimated (above);
  /// 1 fits every input.
  double max_poor_face_fraction = kMaxPoorFaceFraction;
  /// Inputs with a larger share of interior edges sharper than kSharpEdgeAngle are held as
  /// subdivision control meshes (above); 1 fits every input.
  double max_sharp_edge_fraction = kMaxSharpEdgeFraction;
  /// The caller knows the vertices were placed off the surface by an earlier fit (the input's
  /// provenance, find_fit_provenance in provenance.h): the input is returned unchanged, with
  /// FitReport::held_as_fitted set, before the quality test.
  bool already_fitted = false;
  /// The fit's weights and guard; one round (above). samples_per_vertex, mesh_to_reference_weight
  /// and seed are not used: the data are the patches' points. No fairness: every face has data,
  /// so the proximity term alone keeps the solve definite, and the system keeps the faces'
  /// pattern, whose factor fills in far less than the anchored Laplacian's (measured on the 6k
  /// remeshes and bunny_uniform: mean distance within 0.3 points of fairness 0.05, in 40-60% of
  /// the time).
  FitOptions fit = [] {
    FitOptions o;
    o.max_rounds = 1;
    o.fairness = 0;
    return o;
  }();
};

/// Smooth mode (above). Throws std::invalid_argument as fit_to_reference, as
/// smooth_surface_estimate, and for max_poor_face_fraction or max_sharp_edge_fraction outside
/// [0, 1].
FitResult fit_to_smooth_surface(const Vertices& V, const Faces& F, const SmoothFitOptions& options = {});

/// Checks the options' ranges: samples_per_vertex > 0, weights >= 0 and finite (proximity > 0),
/// max_rounds >= 1, tolerance >= 0, the guard's (validate_guard_options), and pinned indices in
/// [0, num_vertices) (when num_vertices >= 0). Throws std::invalid_argument prefixed with `what`.
void validate_fit_options(const FitOptions& options, Index num_vertices = -1, const char* what = "fit to reference");

/// Moves the vertices of (V, F) to minimise the two-sided distance to the reference surface
/// (VR, FR), as described above. Throws std::invalid_argument for an empty mesh or reference,
/// a non-finite coordinate, or options out of range (validate_fit_options).
FitResult fit_to_reference(const Vertices& V, const Faces& F, const Vertices& VR, const Faces& FR,
                           const FitOptions& options = {});

/// The same against a reference built once by the caller (reference_surface.h), whose tree and
/// samples the fit reuses: the result is the same, bit for bit.
FitResult fit_to_reference(const Vertices& V, const Faces& F, const ReferenceSurface& reference,
                           const FitOptions& options = {});

}  // namespace vertexflow
