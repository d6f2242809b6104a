// The enhance engine: one function that chooses and runs an enhance mode (the paper's flow, the
// flow on a reference, reference mode's fit, smooth mode, the unsharp baseline), the optional
// edge flips after it, and the provenance line, with every "this option applies to that mode
// only" rule in one place. The CLI's `enhance`, the batch engine (batch.h) and the Python
// module's enhance/enhance_file/batch are front ends of this call: they parse, read, write and
// print, and give the same bytes for the same options.
//
// Modes (provenance.h's EnhanceMode), chosen by EnhanceOptions and whether a reference is given:
//   method flow,    surface input,  no reference             Flow           vertex_flow (flow.h)
//   method flow,    surface input,  reference, method fit    ReferenceFit   fit_to_reference (fit.h)
//   method flow,    surface input,  reference, method flow   ReferenceFlow  vertex_flow_on_reference
//   method flow,    surface smooth, no reference             Smooth         fit_to_smooth_surface
//   method unsharp, surface input,  no reference             Unsharp        unsharp_mask (unsharp.h)
// Other combinations are refused (validate_enhance_options).
//
// Units and conventions are those of the methods' headers: lengths in the mesh's units, the
// result the same up to rounding for any rigid motion or uniform scale of the input (and the
// reference with it), identical bytes for any thread count.
#pragma once

#include "vertexflow/edge_flips.h"
#include "vertexflow/fit.h"
#include "vertexflow/flow.h"
#include "vertexflow/guard.h"
#include "vertexflow/provenance.h"
#include "vertexflow/reference_surface.h"
#include "vertexflow/unsharp.h"

#include <nlohmann/json.hpp>

#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace vertexflow {

/// `--method`: the paper's flow (and the modes built on its options) or the unsharp baseline.
enum class EnhanceMethod { Flow, Unsharp };
/// `--surface`: what the vertices approximate without a reference.
enum class EnhanceSurface { Input, Smooth };
/// `--reference-method`: what is done with a reference.
enum class ReferenceMethod { Fit, Flow };

/// Everything one enhance run takes besides the meshes. The options that several modes share
/// are set once here (constraints, guard, refuse_non_manifold, feature_angle, max_rounds); the
/// engine writes them into the chosen method's options, whose own copies of them must be left
/// at their defaults (validate_enhance_options refuses a change there, which would be ignored).
struct EnhanceOptions {
  EnhanceMethod method = EnhanceMethod::Flow;
  EnhanceSurface surface = EnhanceSurface::Input;
  ReferenceMethod reference_method = ReferenceMethod::Fit;

  /// Every mode: boundary and pinned vertices stay where they are.
  VertexConstraints constraints;
  /// Flow, ReferenceFlow, ReferenceFit, Smooth (the unsharp baseline has no guard); also the
  /// quality floor of the edge flips' new faces (EdgeFlipOptions::min_quality).
  GuardOptions guard;
  /// Flow, ReferenceFlow, Unsharp: refuse a non-manifold or inconsistently oriented mesh
  /// instead of running on its manifold split (manifold_split.h).
  bool refuse_non_manifold = false;
  /// Flow, ReferenceFlow (FlowOptions::feature_angle), Smooth (SmoothSurfaceOptions), degrees.
  double feature_angle = 40.0;
  /// ReferenceFit, Smooth: rounds of solve and guard at most; none keeps each mode's default
  /// (FitOptions::max_rounds 10, SmoothFitOptions's 1).
  std::optional<int> max_rounds;
  /// Flow (with or without density passes), Smooth: the caller asserts that the input's vertices
  /// lie on the true surface, so the method runs even on an input that looks decimated or like a
  /// subdivision control mesh (input_check.h) or, in smooth mode, whose provenance records a fit
  /// (SmoothFitOptions::max_poor_face_fraction and max_sharp_edge_fraction 1, already_fitted
  /// false). Without it such inputs are held: returned unchanged, with a warning and the report's
  /// "hold" section.
  bool assume_on_surface = false;

  /// Flow, ReferenceFlow: the flow's own options (weights, curvature, solver, projection,
  /// density passes).
  FlowOptions flow;
  /// ReferenceFit: the fit's own options (samples, weights, tolerance, seed).
  FitOptions fit;
  /// Smooth: the estimate's segments, the decimation threshold and the fit's weights.
  SmoothFitOptions smooth;
  /// Unsharp: weight and smoothing iterations.
  UnsharpOptions unsharp;

  /// Flow, ReferenceFit, Smooth: after the method, flip edges towards the reference (or the
  /// smooth estimate of the input) (edge_flips.h). The one option that changes the faces.
  bool edge_flips = false;
  /// With edge_flips in ReferenceFit: cycles of flips and refit (the other modes flip once).
  int flip_cycles = 2;
};

/// The mode `options` choose, with or without a reference (table above). Throws
/// EnhanceOptionError for a combination the table does not have.
EnhanceMode enhance_mode(const EnhanceOptions& options, bool has_reference);

/// The report's name of a mode: "flow", "reference", "reference-flow", "smooth", "unsharp".
const char* enhance_mode_name(EnhanceMode mode);

/// The options each method runs with: the method's own options with the shared ones written in.
FlowOptions effective_flow_options(const EnhanceOptions& options);
FitOptions effective_fit_options(const EnhanceOptions& options);
/// `already_fitted` comes from the input's provenance (find_fit_provenance), unless
/// assume_on_surface.
SmoothFitOptions effective_smooth_options(const EnhanceOptions& options, bool already_fitted = false);
UnsharpOptions effective_unsharp_options(const EnhanceOptions& options);

/// How an option is named in a message: as the CLI's flag ("--lambda"), the Python keyword
/// ("lam") or the C++ member ("flow.weights.lambda").
enum class OptionNaming { Cli, Python, Cpp };

/// An option that does not apply to the chosen mode, or a combination of options that do not
/// go together. what() is one line, naming the option as the front end calls it.
class EnhanceOptionError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Checks `options` for a run with or without a reference on a mesh of `num_vertices`
/// vertices (-1: unknown, pins are not checked): the mode exists (enhance_mode), every option
/// that does not apply to the mode is at its default (the table of enhance_options.h says which
/// apply where), flip_cycles only with edge_flips, no edge flips with Unsharp or ReferenceFlow,
/// the methods' own copies of the shared options untouched, and then the method's own ranges
/// (validate_flow_options, the fit's, the unsharp mask's). Throws EnhanceOptionError (a mode
/// rule) or std::invalid_argument (a range), naming the option as `naming` says.
void validate_enhance_options(const EnhanceOptions& options, bool has_reference, Index num_vertices = -1,
                              OptionNaming naming = OptionNaming::Cpp);

/// Where the engine reports progress: `phase` gets one line per step (what runs, then what it
/// measured and how long it took), `warning` one line per warning (also in
/// EnhanceResult::warnings). Either may be empty.
struct EnhanceCallbacks {
  std::function<void(const std::string&)> phase;
  std::function<void(const std::string&)> warning;
};

struct EnhanceResult {
  /// The result: the input's face list, exactly (or the flipped faces: same count, each face
  /// keeping its index, edge_flips.h), its attributes re-sampled where vertices moved
  /// (attributes.h), and its comments with this run's provenance line appended (provenance.h).
  Mesh mesh;
  EnhanceMode mode = EnhanceMode::Flow;
  /// The report's method sections: "method", "options", what the method reported (solver,
  /// guard, fit, non_manifold, ...), "seconds" of its phases, "edge_flips", "provenance", and
  /// "reference_trees_built" in the reference modes (the trees over the reference's faces this
  /// run built: 1 for the fit with its flips and refits; the flow on S builds its own, in its
  /// normalised units, and a report's distances then build the ReferenceSurface's), and
  /// "reference_memory_bytes" (what the ReferenceSurface holds after the run: its V and F, its
  /// tree and samples; ReferenceSurface::memory_bytes). The front ends add the files, the
  /// read and write times and the metrics (enhance_metrics).
  nlohmann::json report;
  /// This run's provenance line (also the last of mesh.comments).
  std::string provenance;
  /// One line each, without a file name: a non-manifold input run on its split, smooth mode
  /// holding its input, ...
  std::vector<std::string> warnings;
};

/// What a reference must be to stand for the input's surface. Each axis-aligned bounding box is
/// grown by 1% of the input's diagonal (flat inputs and references have boxes of zero
/// thickness); then the boxes must overlap along every axis over at least half of the input's
/// extent (kReferenceCoverage), and the diagonals differ by at most kReferenceSizeFactor either
/// way. A reference shifted by 1e6, scaled by 1e-9 or reduced to one triangle was fitted or
/// flowed to, with exit 0, moving vertices by 6-8 edge lengths. The bundled pairs (bunny_uniform
/// and bunny_adaptive on bunny, amo_adaptive on amo) measure diagonals within 0.2% and a full
/// overlap. Throws std::invalid_argument, one line: "the reference NAME ..." (NAME left out for
/// an unnamed reference) and the rule.
inline constexpr double kReferenceCoverage = 0.5;
inline constexpr double kReferenceSizeFactor = 10;
void check_reference_fits(const Mesh& mesh, const ReferenceSurface& reference);

/// Runs the mode `options` choose on `mesh` (its V, F, attributes and comments; the comments'
/// provenance lines let smooth mode hold an input that an earlier fit placed off its surface),
/// with `reference` for the reference modes (nullptr otherwise). Validates first
/// (validate_enhance_options, OptionNaming::Cpp; MeshAttributes::validate, as an
/// EnhanceOptionError) and throws as the chosen method does (std::invalid_argument for a mesh it
/// refuses).
///
/// A reference must be the input's surface in the input's units (check_reference_fits): a
/// std::invalid_argument, one line naming the reference, refuses one that does not.
///
/// Flow and Smooth first check the input (input_check.h): one that looks decimated or like a
/// subdivision control mesh (and, in smooth mode, one whose provenance records a fit) is held,
/// its vertices returned unchanged, with one warning that names the reason and suggests a
/// reference, unless assume_on_surface. The report's "hold" section records the decision
/// (held, reason, poor_face_fraction, sharp_edge_fraction, thresholds, assume_on_surface).
///
/// The face list comes back as it went in. Faces the methods cannot work on (a repeated vertex,
/// zero area by mesh.h's bound, a repeat of an earlier face) stay in it, and their vertices are
/// held, as are vertices without faces (the report's "face_list" counts them). Chart boundaries
/// (texture seams, material and other label boundaries: docs/attributes.md) are creases for
/// the flow (VertexConstraints::crease_edges) and are never flipped. Seams stored cut open (copies
/// of a vertex at the same position whose boundary edges pair up, as formats with one texture
/// coordinate per vertex store them) are welded for the methods and held the same way, so every
/// copy ends at one position and the result is the welded mesh's (the report's "cut_seams"
/// section counts them). Each moved vertex's attributes are re-sampled where it lands on the
/// input surface, in each of its charts (the report's "attributes" section says how many and how
/// far).
EnhanceResult enhance(const Mesh& mesh, const ReferenceSurface* reference, const EnhanceOptions& options,
                      const EnhanceCallbacks& callbacks = {});

/// What an enhance run keeps for enhance_metrics on the same input, so that the metrics do not
/// build it again: the input's topology as the flow left it (flow.h: the parts only its set-up
/// reads are released), about 140 bytes per vertex, when the flow ran on all of the input's faces
/// (no face held out, no seam welded, no attributes); otherwise nothing. At 9.7M vertices the
/// report's metrics built it in 3-4.5 s (docs/benchmarks.md). Opaque: only enhance_metrics reads
/// it, and only for the mesh it was kept for (its faces are checked).
class EnhanceMetricsReuse {
 public:
  EnhanceMetricsReuse();
  ~EnhanceMetricsReuse();
  EnhanceMetricsReuse(EnhanceMetricsReuse&&) noexcept;
  EnhanceMetricsReuse& operator=(EnhanceMetricsReuse&&) noexcept;
  /// Whether the run kept anything.
  [[nodiscard]] bool empty() const;
  /// Frees what is kept.
  void clear();
  /// What is kept, opaque: defined and read in the library only.
  struct Kept;
  [[nodiscard]] const Kept* kept() const { return kept_.get(); }
  void keep(std::unique_ptr<Kept> kept);

 private:
  std::unique_ptr<Kept> kept_;
};

/// enhance(), keeping in `reuse` what enhance_metrics(mesh, ...) can take instead of computing
/// it again (EnhanceMetricsReuse); `reuse` is cleared first. The result is enhance()'s.
EnhanceResult enhance(const Mesh& mesh, const ReferenceSurface* reference, const EnhanceOptions& options,
                      const EnhanceCallbacks& callbacks, EnhanceMetricsReuse& reuse);

/// The metrics of docs/metrics.md for an enhance result against its input: counts, flipped and
/// degenerate faces (flipped per face index when the faces differ, edge_flips.h), quality,
/// displacement and drift in mean input edge lengths, redistribution rho, edge-error CV, |H|
/// p95, volume change; with `reference`, "distance_to_reference": both meshes' two-sided mean,
/// RMS and Hausdorff distance to it, in the meshes' units. Each mesh's curvature is computed
/// once; pass `curvatures` to receive them (for the HTML report). Throws CompareError
/// (compare.h) for a mesh compare_meshes refuses.
struct EnhanceCurvatures {
  Curvature input;
  Curvature result;
};
/// `reuse`, when given, is what the run kept for this input (EnhanceMetricsReuse); kept data for
/// another mesh (other faces) is ignored. The figures are the same bytes with or without it.
nlohmann::json enhance_metrics(const Mesh& input, const Mesh& result, const ReferenceSurface* reference = nullptr,
                               EnhanceCurvatures* curvatures = nullptr, const EnhanceMetricsReuse* reuse = nullptr);

}  // namespace vertexflow
