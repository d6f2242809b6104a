// The enhance engine (enhance.h): the mode rules, the run of one mode, the edge flips after it,
// and the provenance line.
#include "vertexflow/enhance.h"

#include "attributes/transport.h"
#include "enhance/workable_faces.h"
#include "mesh/cut_seams.h"
#include "mesh/duplicate_faces.h"
#include "mesh/fan_walk.h"

#include "vertexflow/enhance_options.h"
#include "vertexflow/input_check.h"
#include "vertexflow/progress.h"
#include "vertexflow/report_json.h"
#include "vertexflow/timing.h"
#include "vertexflow/topology.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <optional>
#include <unordered_map>
#include <unordered_set>
#include <utility>

namespace vertexflow {
namespace {

// How a mode is called in a message, as each front end writes it.
std::string mode_display(EnhanceMode mode, OptionNaming naming) {
  const bool cli = naming == OptionNaming::Cli, python = naming == OptionNaming::Python;
  switch (mode) {
    case EnhanceMode::Flow:
      return "the paper's flow";
    case EnhanceMode::ReferenceFit:
      return cli ? "--reference" : python ? "reference=(V, F)" : "a reference fit";
    case EnhanceMode::ReferenceFlow:
      return cli ? "--reference-method flow" : python ? "reference_method='flow'" : "reference_method Flow";
    case EnhanceMode::Smooth:
      return cli ? "--surface smooth" : python ? "surface='smooth'" : "surface Smooth";
    case EnhanceMode::Unsharp:
      return cli ? "--method unsharp" : python ? "method='unsharp'" : "method Unsharp";
  }
  return "?";
}

std::string name_of(std::string_view python_name, OptionNaming naming) {
  return option_display_name(*find_enhance_option(python_name), naming);
}

[[noreturn]] void refuse(const std::string& what) {
  throw EnhanceOptionError(what);
}

// Throws if `value` is not the default of `reference_value` (a method's copy of a shared
// option): the engine would overwrite it.
template <typename T>
void require_default(const T& value, const T& default_value, const char* member, const char* shared) {
  if (!(value == default_value))
    refuse(fmt::format("{} is set by EnhanceOptions::{} for every mode; leave it at its default", member, shared));
}

void require_shared_untouched(const EnhanceOptions& o) {
  const FlowOptions flow;
  const FitOptions fit;
  const SmoothFitOptions smooth;
  const UnsharpOptions unsharp;
  require_default(o.flow.constraints.fix_boundary, flow.constraints.fix_boundary, "flow.constraints", "constraints");
  require_default(o.flow.constraints.pinned, flow.constraints.pinned, "flow.constraints", "constraints");
  require_default(o.fit.constraints.fix_boundary, fit.constraints.fix_boundary, "fit.constraints", "constraints");
  require_default(o.fit.constraints.pinned, fit.constraints.pinned, "fit.constraints", "constraints");
  require_default(o.smooth.fit.constraints.fix_boundary, smooth.fit.constraints.fix_boundary, "smooth.fit.constraints",
                  "constraints");
  require_default(o.smooth.fit.constraints.pinned, smooth.fit.constraints.pinned, "smooth.fit.constraints",
                  "constraints");
  require_default(o.unsharp.constraints.fix_boundary, unsharp.constraints.fix_boundary, "unsharp.constraints",
                  "constraints");
  require_default(o.unsharp.constraints.pinned, unsharp.constraints.pinned, "unsharp.constraints", "constraints");
  for (const auto& [guard, member] : {std::pair{&o.flow.guard, "flow.guard"}, std::pair{&o.fit.guard, "fit.guard"},
                                      std::pair{&o.smooth.fit.guard, "smooth.fit.guard"}}) {
    require_default(guard->min_quality, GuardOptions{}.min_quality, member, "guard");
    require_default(guard->sliver_floor, GuardOptions{}.sliver_floor, member, "guard");
    require_default(guard->max_halvings, GuardOptions{}.max_halvings, member, "guard");
  }
  require_default(o.flow.feature_angle, flow.feature_angle, "flow.feature_angle", "feature_angle");
  require_default(o.smooth.surface.feature_angle, smooth.surface.feature_angle, "smooth.surface.feature_angle",
                  "feature_angle");
  require_default(o.flow.refuse_non_manifold, flow.refuse_non_manifold, "flow.refuse_non_manifold",
                  "refuse_non_manifold");
  require_default(o.unsharp.refuse_non_manifold, unsharp.refuse_non_manifold, "unsharp.refuse_non_manifold",
                  "refuse_non_manifold");
  require_default(o.fit.max_rounds, fit.max_rounds, "fit.max_rounds", "max_rounds");
  require_default(o.smooth.fit.max_rounds, smooth.fit.max_rounds, "smooth.fit.max_rounds", "max_rounds");
  require_default(o.smooth.max_poor_face_fraction, smooth.max_poor_face_fraction, "smooth.max_poor_face_fraction",
                  "assume_on_surface");
  require_default(o.smooth.max_sharp_edge_fraction, smooth.max_sharp_edge_fraction, "smooth.max_sharp_edge_fraction",
                  "assume_on_surface");
  require_default(o.smooth.already_fitted, smooth.already_fitted, "smooth.already_fitted",
                  "assume_on_surface (the engine reads the input's provenance)");
}

EnhanceMode mode_of(const EnhanceOptions& o, bool has_reference, OptionNaming naming) {
  const bool unsharp = o.method == EnhanceMethod::Unsharp, smooth = o.surface == EnhanceSurface::Smooth;
  if (unsharp && smooth)
    refuse(name_of("surface", naming) + " smooth and " + mode_display(EnhanceMode::Unsharp, naming) +
           " exclude each other");
  if (!has_reference) {
    if (o.reference_method != ReferenceMethod::Fit)
      refuse(name_of("reference_method", naming) + " applies to a reference only");
    return unsharp ? EnhanceMode::Unsharp : smooth ? EnhanceMode::Smooth : EnhanceMode::Flow;
  }
  const std::string reference = naming == OptionNaming::Cli ? "--reference" : "reference";
  if (unsharp) refuse(reference + " and " + mode_display(EnhanceMode::Unsharp, naming) + " exclude each other");
  if (smooth) refuse(reference + " and " + mode_display(EnhanceMode::Smooth, naming) + " exclude each other");
  return o.reference_method == ReferenceMethod::Flow ? EnhanceMode::ReferenceFlow : EnhanceMode::ReferenceFit;
}

using Callback = std::function<void(const std::string&)>;

void tell(const Callback& callback, const std::string& line) {
  if (callback) callback(line);
}

// Collects warnings for the result and passes them on.
struct Warnings {
  const EnhanceCallbacks& callbacks;
  std::vector<std::string>& lines;
  void operator()(std::string line) const {
    tell(callbacks.warning, line);
    lines.push_back(std::move(line));
  }
};

void warn_about_split(Index held, Index reoriented, Index cut, const Warnings& warn) {
  if (held + reoriented + cut > 0)
    warn(fmt::format(
        "the mesh is not manifold or not consistently oriented: {} vertices held (their faces form more than one fan), "
        "{} faces reoriented, {} edges treated as boundaries; --strict refuses such meshes",
        held, reoriented, cut));
}

struct MethodRun {
  Vertices V;
  nlohmann::json report;
};

// `topology`: as enhance_clean's.
MethodRun run_flow(const Mesh& mesh, const ReferenceSurface* reference, const FlowOptions& options,
                   const EnhanceCallbacks& callbacks, const Warnings& warn, Topology* topology,
                   bool topology_is_spare) {
  const auto start = Clock::now();
  FlowResult result = reference
                          ? vertex_flow_on_reference(mesh.V, mesh.F, reference->vertices(), reference->faces(), options)
                      : !topology ? vertex_flow(mesh.V, mesh.F, build_topology(mesh.F, mesh.num_vertices()), options)
                      : topology_is_spare ? vertex_flow(mesh.V, mesh.F, std::move(*topology), options)
                                          : vertex_flow(mesh.V, mesh.F, std::as_const(*topology), options);
  const double flow_seconds = seconds_since(start);  // before the phase lines, which a terminal may slow
  const FlowReport& r = result.report;
  tell(callbacks.phase, fmt::format("curvature {:.3f} s, assembly {:.3f} s, solve {:.3f} s, projection {:.3f} s, "
                                    "guard {:.3f} s; {} vertices limited by the guard",
                                    r.seconds_curvature, r.seconds_assembly, r.seconds_solve, r.seconds_projection,
                                    r.seconds_guard, r.limited_vertices));
  if (r.flat)
    tell(callbacks.phase, fmt::format("the {} has no curvature radius below {} times its bounding-box diagonal: "
                                      "nothing to enhance, no solve ran (flow.h)",
                                      reference ? "reference" : "surface", 1 / kFlatCurvature));
  if (options.density.passes > 0)
    tell(callbacks.phase, fmt::format("{} density passes {:.3f} s; {} vertices limited by their guard",
                                      options.density.passes, r.seconds_density, r.density_limited_vertices));
  warn_about_split(r.held_non_manifold_vertices, r.reoriented_faces, r.cut_edges, warn);
  MethodRun run;
  run.report = r;
  // What none of FlowReport's phases times, so that the report names the whole flow: its set-up
  // (features, normalisation, slivers, the guard's floors, the solver's numbering; on S, S's tree
  // and curvature), the topology when none was given, and the density passes' own set-up. At
  // 10M vertices it was 22 s of a 200 s run (docs/benchmarks.md, "Memory by phase").
  const double timed = r.seconds_curvature + r.seconds_assembly + r.seconds_solve + r.seconds_factorization +
                       r.seconds_projection + r.seconds_guard + r.seconds_density;
  run.report["seconds"]["set_up"] = std::max(0.0, flow_seconds - timed);
  run.report["options"] = options;
  run.V = std::move(result.V);
  return run;
}

MethodRun run_fit(const Mesh& mesh, const ReferenceSurface& reference, const FitOptions& options,
                  const EnhanceCallbacks& callbacks) {
  FitResult result = fit_to_reference(mesh.V, mesh.F, reference, options);
  const FitReport& r = result.report;
  tell(callbacks.phase,
       fmt::format("fitted in {} rounds{}: RMS distance {:.6g} -> {:.6g}; tree {:.3f} s, queries {:.3f} s, solve "
                   "{:.3f} s, guard {:.3f} s; {} vertices limited by the guard",
                   r.rounds, r.converged ? "" : " (max-rounds reached)", r.rms_distance.front(), r.rms_distance.back(),
                   r.seconds_tree, r.seconds_queries, r.seconds_solve, r.seconds_guard, r.limited_vertices));
  MethodRun run;
  run.report = r;
  run.report["options"] = options;
  run.V = std::move(result.V);
  return run;
}

// The input check of issue 30 (input_check.h) for the methods that assume the vertices on the
// true surface: the check's verdict (with the default thresholds, also under assume_on_surface,
// so the report says what the flag overrode), whether the input is held, and the warning.
struct Hold {
  HoldReason reason = HoldReason::None;
  bool held = false;
  double poor_face_fraction = 0, sharp_edge_fraction = 0;
};

Hold decide_hold(double poor_face_fraction, double sharp_edge_fraction, bool already_fitted, bool assume_on_surface) {
  Hold hold;
  hold.poor_face_fraction = poor_face_fraction;
  hold.sharp_edge_fraction = sharp_edge_fraction;
  hold.reason = already_fitted                                ? HoldReason::AlreadyFitted
                : poor_face_fraction > kMaxPoorFaceFraction   ? HoldReason::Decimated
                : sharp_edge_fraction > kMaxSharpEdgeFraction ? HoldReason::ControlMesh
                                                              : HoldReason::None;
  hold.held = hold.reason != HoldReason::None && !assume_on_surface;
  return hold;
}

// The one warning line of a held input: the measured reason, what was held, and the two ways on.
void warn_about_hold(const Hold& hold, EnhanceMode mode, const std::string* fitted_by, const Warnings& warn) {
  std::string why;
  switch (hold.reason) {
    case HoldReason::AlreadyFitted:
      why = fmt::format(
          "its provenance comment '{}' records an earlier fit, which left the vertices off the surface "
          "the faces inscribe",
          fitted_by ? *fitted_by : std::string());
      break;
    case HoldReason::Decimated:
      why = fmt::format(
          "{:.1f}% of the interior faces are below quality 0.3 (over {:g}%): a decimated mesh, whose vertices lie "
          "off the surface",
          100 * hold.poor_face_fraction, 100 * kMaxPoorFaceFraction);
      break;
    case HoldReason::ControlMesh:
      why = fmt::format(
          "{:.1f}% of the edges turn by more than {:g} degrees (over {:g}%): a subdivision control mesh, "
          "whose vertices lie off its limit surface",
          100 * hold.sharp_edge_fraction, kSharpEdgeAngle, 100 * kMaxSharpEdgeFraction);
      break;
    case HoldReason::None:
      return;
  }
  const bool smooth = mode == EnhanceMode::Smooth;
  warn(
      fmt::format("{}: {}, which assumes them on it, held every vertex; --reference DENSE fits it to a dense mesh "
                  "of the surface, --assume-on-surface {} anyway",
                  why, smooth ? "smooth mode" : "the paper's flow", smooth ? "fits" : "flows"));
}

// The report's "hold" section.
nlohmann::json hold_json(const Hold& hold, bool assume_on_surface) {
  return {
      {"held", hold.held},
      {"reason", hold.reason == HoldReason::None ? nlohmann::json() : nlohmann::json(hold_reason_name(hold.reason))},
      {"poor_face_fraction", hold.poor_face_fraction},
      {"sharp_edge_fraction", hold.sharp_edge_fraction},
      {"thresholds",
       {{"poor_face_fraction", kMaxPoorFaceFraction},
        {"sharp_edge_fraction", kMaxSharpEdgeFraction},
        {"sharp_edge_angle", kSharpEdgeAngle}}},
      {"assume_on_surface", assume_on_surface}};
}

MethodRun run_smooth(const Mesh& mesh, const SmoothFitOptions& options, const std::string* fitted_by,
                     bool assume_on_surface, const EnhanceCallbacks& callbacks, const Warnings& warn) {
  FitResult result = fit_to_smooth_surface(mesh.V, mesh.F, options);
  const FitReport& r = result.report;
  const Hold hold = decide_hold(r.poor_face_fraction, r.sharp_edge_fraction, fitted_by != nullptr, assume_on_surface);
  if (hold.held)
    warn_about_hold(hold, EnhanceMode::Smooth, fitted_by, warn);
  else
    tell(callbacks.phase,
         fmt::format("patches {:.3f} s; fitted in {} round{}: RMS distance to them {:.6g} -> {:.6g}; {} vertices "
                     "limited by the guard",
                     r.seconds_surface, r.rounds, r.rounds == 1 ? "" : "s", r.rms_distance.front(),
                     r.rms_distance.back(), r.limited_vertices));
  MethodRun run;
  run.report = r;
  run.report["fit"]["poor_face_fraction"] = r.poor_face_fraction;
  run.report["fit"]["held_as_decimated"] = r.held_as_decimated;
  run.report["fit"]["sharp_edge_fraction"] = r.sharp_edge_fraction;
  run.report["fit"]["held_as_control_mesh"] = r.held_as_control_mesh;
  run.report["fit"]["held_as_fitted"] = r.held_as_fitted;
  run.report["fit"]["fitted_by"] = r.held_as_fitted && fitted_by ? nlohmann::json(*fitted_by) : nlohmann::json();
  run.report["options"] = options.fit;
  for (const char* unused : {"samples_per_vertex", "mesh_to_reference_weight", "seed"})
    run.report["options"].erase(unused);
  run.report["options"]["surface"] = options.surface;
  run.report["options"]["max_poor_face_fraction"] = options.max_poor_face_fraction;
  run.report["options"]["max_sharp_edge_fraction"] = options.max_sharp_edge_fraction;
  run.report["hold"] = hold_json(hold, assume_on_surface);
  run.V = std::move(result.V);
  return run;
}

MethodRun run_unsharp(const Mesh& mesh, const UnsharpOptions& options, const Warnings& warn) {
  const auto start = Clock::now();
  UnsharpResult result = unsharp_mask(mesh.V, mesh.F, options);
  const double seconds = seconds_since(start);
  warn_about_split(result.non_manifold.held_vertices, result.non_manifold.reversed_faces, result.non_manifold.cut_edges,
                   warn);
  MethodRun run;
  run.report = result;
  run.report["options"] = options;
  run.report["seconds"] = {{"unsharp", seconds}};
  run.V = std::move(result.V);
  return run;
}

// Edge flips towards the reference, or towards the smooth estimate of the input. Reference mode
// alternates them with a refit of the vertices on the new faces, for flip_cycles cycles. The
// other modes flip once: the paper's flow keeps the vertices on the input surface, and smooth
// mode's fit pairs each face with its own patch, which new faces do not have (a closest-point
// refit to the estimate, tried instead, lost 1 point of mean distance on the 6k remeshes).
nlohmann::json flip_and_refit(const Mesh& input, const ReferenceSurface* reference, const EnhanceOptions& o, Mesh& out,
                              const EnhanceCallbacks& callbacks) {
  const bool fit = reference != nullptr;
  const auto start = Clock::now();
  std::optional<DistanceQuery> estimate;
  if (!fit) {
    const Mesh target = smooth_surface_estimate(input.V, input.F, effective_smooth_options(o).surface);
    estimate.emplace(target.V, target.F);
  }
  const DistanceQuery& to_target = fit ? reference->distance_query() : *estimate;
  EdgeFlipOptions flips;
  flips.min_quality = o.guard.min_quality;
  flips.fixed_edges = o.constraints.crease_edges;  // chart boundaries (enhance() sets them)
  // No face may end against the input face whose index it takes (faces_turned_over, the
  // report's flip count).
  Vertices slot_normals(input.F.rows(), 3);
  for (Index f = 0; f < input.F.rows(); ++f) slot_normals.row(f) = face_normal(input.V, input.F, f).transpose();
  const FitOptions refit = effective_fit_options(o);
  nlohmann::json cycles = nlohmann::json::array();
  Index total = 0;
  for (int cycle = 0; cycle < o.flip_cycles; ++cycle) {
    // Progress (progress.h): each cycle a part, its flips and its refit half each.
    const int cycles_run = fit ? o.flip_cycles : 1;
    const ProgressPart cycle_part("", static_cast<double>(cycle) / cycles_run,
                                  static_cast<double>(cycle + 1) / cycles_run);
    report_progress("edge flips", 0, fit ? 0.5 : 1);
    EdgeFlipResult flipped = flip_edges_toward(out.V, out.F, to_target, flips, &slot_normals);
    const EdgeFlipReport& r = flipped.report;
    nlohmann::json entry = {
        {"flips", r.flips}, {"passes", r.passes}, {"rms_before", r.rms_before}, {"rms_after_flips", r.rms_after}};
    total += r.flips;
    bool refit_refused = false;
    if (r.flips > 0) {
      out.F = std::move(flipped.F);
      if (fit) {
        const ProgressPart refit_part("refit", 0.5, 1);
        Vertices refitted = fit_to_reference(out.V, out.F, *reference, refit).V;
        // The refit's guard keeps each face from turning against its own start, the flipped
        // mesh, not against the input face whose index it took: a steep new face could still
        // end past 90 degrees from that one (one face at a level of horse-48k and of rocker-arm
        // in bench/lod_peers). Such a refit is not taken, and the cycles stop.
        const Index turned = faces_turned_over(input.V, input.F, refitted, out.F);
        refit_refused = turned > 0;
        if (refit_refused)
          entry["refit_refused_turned_faces"] = turned;
        else
          out.V = std::move(refitted);
        entry["refitted"] = !refit_refused;
      }
    }
    tell(callbacks.phase,
         fmt::format("edge flips, cycle {}: {} flips in {} passes, RMS distance to the {} {:.6g} -> {:.6g}", cycle + 1,
                     r.flips, r.passes, fit ? "reference" : "smooth estimate", r.rms_before, r.rms_after));
    cycles.push_back(std::move(entry));
    if (r.flips == 0 || !fit || refit_refused) break;
  }
  return {{"cycles", cycles},
          {"flips", total},
          {"target", fit ? "reference" : "smooth estimate"},
          {"seconds", seconds_since(start)}};
}

}  // namespace

void check_reference_fits(const Mesh& mesh, const ReferenceSurface& reference) {
  const BoundingBox input = bounding_box(mesh.V), dense = bounding_box(reference.vertices());
  const double input_size = input.diagonal(), size = dense.diagonal();
  if (!(input_size > 0)) return;  // the methods refuse a mesh without extent, in their words
  const std::string name = reference.name().empty() ? "the reference" : "the reference " + reference.name();
  const std::string rule = fmt::format(
      "a reference must be the input's surface in the input's units (bounding boxes overlapping over at least {:g}% "
      "of the input's extent along each axis, diagonals within a factor {:g})",
      100 * kReferenceCoverage, kReferenceSizeFactor);
  const double grow = 0.01 * input_size;  // boxes of flat inputs and references have no thickness
  double worst = 1;
  int worst_axis = 0;
  for (int a = 0; a < 3; ++a) {
    const double overlap = std::min(input.max[a], dense.max[a]) - std::max(input.min[a], dense.min[a]);
    if (overlap < -2 * grow)
      throw std::invalid_argument(
          fmt::format("{} does not overlap the input: their bounding boxes are {:.6g} apart "
                      "along {} (the input's diagonal is {:.6g}); {}",
                      name, -overlap, "xyz"[a], input_size, rule));
    const double covered = (overlap + 2 * grow) / (input.max[a] - input.min[a] + 2 * grow);
    if (covered < worst) worst = covered, worst_axis = a;
  }
  if (!(size * kReferenceSizeFactor >= input_size && size <= kReferenceSizeFactor * input_size))
    throw std::invalid_argument(
        fmt::format("{} is {:.3g} times the input's size (bounding-box diagonals {:.6g} and "
                    "{:.6g}); {}",
                    name, size / input_size, size, input_size, rule));
  if (worst < kReferenceCoverage)
    throw std::invalid_argument(fmt::format("{} overlaps the input over only {:.1f}% of its extent along {}; {}", name,
                                            100 * worst, "xyz"[worst_axis], rule));
}

EnhanceMode enhance_mode(const EnhanceOptions& options, bool has_reference) {
  return mode_of(options, has_reference, OptionNaming::Cpp);
}

const char* enhance_mode_name(EnhanceMode mode) {
  switch (mode) {
    case EnhanceMode::Flow:
      return "flow";
    case EnhanceMode::ReferenceFit:
      return "reference";
    case EnhanceMode::ReferenceFlow:
      return "reference-flow";
    case EnhanceMode::Smooth:
      return "smooth";
    case EnhanceMode::Unsharp:
      return "unsharp";
  }
  return "?";
}

FlowOptions effective_flow_options(const EnhanceOptions& o) {
  FlowOptions flow = o.flow;
  flow.constraints = o.constraints;
  flow.guard = o.guard;
  flow.refuse_non_manifold = o.refuse_non_manifold;
  flow.feature_angle = o.feature_angle;
  return flow;
}

FitOptions effective_fit_options(const EnhanceOptions& o) {
  FitOptions fit = o.fit;
  fit.constraints = o.constraints;
  fit.guard = o.guard;
  if (o.max_rounds) fit.max_rounds = *o.max_rounds;
  return fit;
}

SmoothFitOptions effective_smooth_options(const EnhanceOptions& o, bool already_fitted) {
  SmoothFitOptions smooth = o.smooth;
  smooth.surface.feature_angle = o.feature_angle;
  smooth.fit.constraints = o.constraints;
  smooth.fit.guard = o.guard;
  // The solver is one choice for both fits (the option table's fit_solver).
  smooth.fit.solver = o.fit.solver;
  if (o.max_rounds) smooth.fit.max_rounds = *o.max_rounds;
  if (o.assume_on_surface) smooth.max_poor_face_fraction = smooth.max_sharp_edge_fraction = 1.0;
  smooth.already_fitted = already_fitted && !o.assume_on_surface;
  return smooth;
}

UnsharpOptions effective_unsharp_options(const EnhanceOptions& o) {
  UnsharpOptions unsharp = o.unsharp;
  unsharp.constraints = o.constraints;
  unsharp.refuse_non_manifold = o.refuse_non_manifold;
  return unsharp;
}

void validate_enhance_options(const EnhanceOptions& options, bool has_reference, Index num_vertices,
                              OptionNaming naming) {
  const EnhanceMode mode = mode_of(options, has_reference, naming);
  // Every option that does not apply to the mode keeps its default. (A default given
  // explicitly is accepted: it changes nothing.)
  static const EnhanceOptions defaults;
  for (const EnhanceOptionSpec& spec : enhance_option_specs()) {
    if (spec.modes & mode_bit(mode)) continue;
    if (spec.get(options) != spec.get(defaults))
      refuse(fmt::format("{} does not apply to {}", option_display_name(spec, naming), mode_display(mode, naming)));
  }
  if (!options.edge_flips && options.flip_cycles != defaults.flip_cycles)
    refuse(name_of("flip_cycles", naming) + " applies to " + name_of("edge_flips", naming) + " only");
  require_shared_untouched(options);
  // The ranges, in the table's words first (the front ends' names), then the methods' own
  // checks of what the table does not hold.
  for (const EnhanceOptionSpec& spec : enhance_option_specs()) check_option_value(spec, spec.get(options), naming);
  switch (mode) {
    case EnhanceMode::Flow:
    case EnhanceMode::ReferenceFlow:
      validate_flow_options(effective_flow_options(options), num_vertices);
      break;
    case EnhanceMode::ReferenceFit:
      validate_fit_options(effective_fit_options(options), num_vertices, "fit to reference");
      break;
    case EnhanceMode::Smooth:
      validate_fit_options(effective_smooth_options(options).fit, num_vertices, "fit to smooth surface");
      break;
    case EnhanceMode::Unsharp:  // the table checked its two numbers; its pins here
      validate_vertex_constraints(options.constraints, num_vertices, "unsharp mask");
      break;
  }
}

namespace {

// How progress (progress.h) names a mode's method until the method names its own phases.
const char* progress_phase(EnhanceMode mode) {
  switch (mode) {
    case EnhanceMode::Flow:
      return "flow";
    case EnhanceMode::ReferenceFit:
      return "fit to reference";
    case EnhanceMode::ReferenceFlow:
      return "flow on reference";
    case EnhanceMode::Smooth:
      return "fit to smooth surface";
    case EnhanceMode::Unsharp:
      return "unsharp mask";
  }
  return "enhance";
}

// The engine on a mesh whose faces all have three distinct vertices, positive area and no
// duplicate, and whose vertices all have faces; attributes are left to enhance(). `topology`, when
// given, is the mesh's (build_topology), for the flow; if `topology_is_spare` the caller needs it
// no more, and the flow frees the parts only its set-up reads (flow.h).
EnhanceResult enhance_clean(const Mesh& mesh, const ReferenceSurface* reference, const EnhanceOptions& options,
                            const EnhanceCallbacks& callbacks, Topology* topology = nullptr,
                            bool topology_is_spare = false) {
  // Trees over the reference's faces this run builds (its own, or any step's copy): one is the
  // promise of reference_surface.h, the flow on S's own tree a second (flow.h).
  const std::uint64_t trees_before = reference ? distance_trees_built(reference->faces().rows()) : 0;
  EnhanceResult result;
  const EnhanceMode mode = enhance_mode(options, reference != nullptr);
  result.mode = mode;
  const Warnings warn{callbacks, result.warnings};
  const FlowOptions flow = effective_flow_options(options);
  switch (mode) {
    case EnhanceMode::ReferenceFit:
      tell(callbacks.phase,
           fmt::format("fitting {} vertices to {} ({} faces)", mesh.num_vertices(),
                       reference->name().empty() ? "the reference" : reference->name(), reference->faces().rows()));
      break;
    case EnhanceMode::Smooth:
      tell(callbacks.phase,
           fmt::format("fitting {} vertices to the smooth-surface estimate through them", mesh.num_vertices()));
      break;
    case EnhanceMode::ReferenceFlow:
      tell(callbacks.phase, fmt::format("flowing {} vertices over {} (lambda {}, mu {})", mesh.num_vertices(),
                                        reference->name().empty() ? "the reference" : reference->name(),
                                        flow.weights.lambda, flow.weights.mu));
      break;
    case EnhanceMode::Unsharp:
      tell(callbacks.phase,
           fmt::format("unsharp mask on {} vertices (weight {}, {} smoothing iterations)", mesh.num_vertices(),
                       options.unsharp.weight, options.unsharp.smoothing_iterations));
      break;
    case EnhanceMode::Flow:
      tell(callbacks.phase, fmt::format("flowing {} vertices (lambda {}, mu {})", mesh.num_vertices(),
                                        flow.weights.lambda, flow.weights.mu));
      break;
  }

  // Smooth mode holds an input that an earlier fit already moved off the inscribed surface
  // (provenance.h).
  const std::string* fitted_by = find_fit_provenance(mesh.comments);
  const SmoothFitOptions smooth = effective_smooth_options(options, fitted_by != nullptr);
  MethodRun run;
  // Progress (progress.h): the method, then the flips (their cost guessed equal: no figures).
  std::optional<ProgressPart> method_part;
  method_part.emplace(progress_phase(mode), 0, options.edge_flips ? 0.5 : 1);
  switch (mode) {
    case EnhanceMode::ReferenceFit:
      run = run_fit(mesh, *reference, effective_fit_options(options), callbacks);
      break;
    case EnhanceMode::Smooth:
      run = run_smooth(mesh, smooth, fitted_by, options.assume_on_surface, callbacks, warn);
      break;
    case EnhanceMode::Unsharp:
      run = run_unsharp(mesh, effective_unsharp_options(options), warn);
      break;
    case EnhanceMode::ReferenceFlow:
      run = run_flow(mesh, reference, flow, callbacks, warn, nullptr, false);
      break;
    case EnhanceMode::Flow: {
      // The flow and its density passes slide the vertices over the input's facets: an input
      // whose vertices look off the true surface is held (input_check.h).
      const InputCheck check = check_input(mesh.V, mesh.F, {}, topology);
      const Hold hold =
          decide_hold(check.poor_face_fraction, check.sharp_edge_fraction, false, options.assume_on_surface);
      if (hold.held) {
        warn_about_hold(hold, EnhanceMode::Flow, nullptr, warn);
        run.report = FlowReport{};
        run.report["options"] = flow;
        run.V = mesh.V;
      } else {
        run = run_flow(mesh, nullptr, flow, callbacks, warn, topology, topology_is_spare);
      }
      run.report["hold"] = hold_json(hold, options.assume_on_surface);
      break;
    }
  }
  // A held input comes back unchanged: no edge flips either.
  const bool held = run.report.contains("hold") && run.report["hold"]["held"].get<bool>();

  // Same connectivity (unless edge flips); enhance() carries the attributes.
  Mesh& out = result.mesh;
  out.V = std::move(run.V);
  out.F = mesh.F;
  method_part.reset();
  if (options.edge_flips && !held) {
    const ProgressPart flips_part("edge flips", 0.5, 1);
    run.report["edge_flips"] =
        flip_and_refit(mesh, mode == EnhanceMode::ReferenceFit ? reference : nullptr, options, out, callbacks);
  }

  // The input's provenance and a line for this run, so a chain of runs stays visible and a
  // later smooth-mode run can tell a fitted input (provenance.h).
  ProvenanceRun provenance;
  provenance.mode = mode;
  if (reference) provenance.reference = reference->name();
  provenance.edge_flips = options.edge_flips;
  provenance.assume_on_surface = options.assume_on_surface;
  if (held) provenance.held = run.report["hold"]["reason"].get<std::string>();
  result.provenance = provenance_line(provenance);
  out.comments = mesh.comments;
  append_provenance(out.comments, result.provenance);
  run.report["provenance"] = result.provenance;
  run.report["method"] = enhance_mode_name(mode);
  if (reference) {
    run.report["reference_trees_built"] = distance_trees_built(reference->faces().rows()) - trees_before;
    // What S holds after the run: V, F, its tree and samples (reference_surface.h).
    run.report["reference_memory_bytes"] = reference->memory_bytes();
  }
  result.report = std::move(run.report);
  return result;
}

}  // namespace

namespace enhance_detail {

std::vector<Index> workable_faces(const Mesh& mesh, std::optional<Topology>* topology) {
  const auto m = static_cast<std::size_t>(mesh.num_faces());
  // Zero area, a repeated vertex, or a repeat of an earlier face (the reader's test,
  // mesh/duplicate_faces.h).
  std::vector<char> out(m, 0);
  bool held = false;
  for (const Index f : degenerate_faces(mesh.V, mesh.F)) out[static_cast<std::size_t>(f)] = 1, held = true;
  for (Index f = 0; f < mesh.num_faces(); ++f)
    if (mesh.F(f, 0) == mesh.F(f, 1) || mesh.F(f, 1) == mesh.F(f, 2) || mesh.F(f, 2) == mesh.F(f, 0))
      out[static_cast<std::size_t>(f)] = 1, held = true;
  bool repeats_found = false;
  if (topology && !held) {
    // With no edge of more than two faces, a face with another's vertex set is adjacent to it
    // across all three edges (0.7 s of sorting at 10M vertices saved; the topology is the run's).
    *topology = build_topology(mesh.F, mesh.num_vertices());
    const Topology& t = **topology;
    if (t.non_manifold_edges.empty()) {
      for (Index f = 0; f < mesh.num_faces(); ++f) {
        const Index g = t.face_adjacency(f, 0);
        if (g >= 0 && g < f && t.face_adjacency(f, 1) == g && t.face_adjacency(f, 2) == g)
          out[static_cast<std::size_t>(f)] = 1;
      }
      repeats_found = true;
    }
  }
  if (!repeats_found) {
    const std::vector<char> repeats = find_duplicate_faces(mesh.F.data(), m, mesh.num_vertices());
    for (std::size_t f = 0; f < m; ++f) out[f] |= repeats[f];
  }
  std::vector<Index> faces;
  faces.reserve(m);
  for (std::size_t f = 0; f < m; ++f)
    if (!out[f]) faces.push_back(static_cast<Index>(f));
  return faces;
}

Faces face_rows(const Faces& F, const std::vector<Index>& faces) {
  Faces rows(static_cast<Eigen::Index>(faces.size()), 3);
  for (std::size_t i = 0; i < faces.size(); ++i) rows.row(static_cast<Eigen::Index>(i)) = F.row(faces[i]);
  return rows;
}

std::uint64_t faces_fingerprint(const Faces& F) {
  // FNV-1a's offset and prime over whole indices: a check that the metrics measure the mesh the
  // run kept its topology for, not a defence against a crafted collision.
  std::uint64_t h = 14695981039346656037ull ^ static_cast<std::uint64_t>(F.rows());
  const Index* data = F.data();
  for (Eigen::Index i = 0; i < F.size(); ++i) h = (h ^ static_cast<std::uint32_t>(data[i])) * 1099511628211ull;
  return h;
}

}  // namespace enhance_detail

namespace {

// Where edge flips changed faces around a vertex that welds several input vertices (a cut-open
// seam, mesh/cut_seams.h), which copy each changed face takes: the copy on its side of the seam,
// from the first face around the vertex that is unchanged or holds a seam half-edge
// (mesh/fan_walk.h).
class SeamSides {
 public:
  // `work_F` are the methods' faces (rows `faces` of `input_F` through `to_work`), `output_F`
  // the same after the flips; `copies` counts the input vertices of each work vertex.
  SeamSides(const Faces& input_F, const std::vector<Index>& faces, const std::vector<Index>& to_work,
            const std::vector<Index>& copies, const std::vector<std::array<Index, 2>>& seam_edges, const Faces& work_F,
            const Faces& output_F)
      : input_F_(input_F), faces_(faces), work_F_(work_F), output_F_(output_F), index_(output_F, welded(copies)) {
    for (const auto& [a, b] : seam_edges) seam_.insert(half_edge_key(std::min(a, b), std::max(a, b)));
    for (std::size_t i = 0; i < faces.size(); ++i)
      for (int k = 0; k < 3; ++k) {
        const Index v = input_F(faces[i], k), u = input_F(faces[i], (k + 1) % 3);
        const Index w = to_work[static_cast<std::size_t>(v)], x = to_work[static_cast<std::size_t>(u)];
        if (is_seam(w, x)) seam_side_[half_edge_key(w, x)] = {v, u};
      }
  }

  // The input copy of work vertex w for output face f, or -1 if the walk finds none.
  Index copy_for(Index f, Index w) const {
    return index_.walk_around(
        f, w,
        [&](Index g, Index next, Index prev) -> Index {
          if (output_F_.row(g) == work_F_.row(g))
            for (int k = 0; k < 3; ++k)
              if (work_F_(g, k) == w) return input_F_(faces_[static_cast<std::size_t>(g)], k);
          if (const auto it = seam_side_.find(half_edge_key(w, next)); it != seam_side_.end()) return it->second[0];
          if (const auto it = seam_side_.find(half_edge_key(prev, w)); it != seam_side_.end()) return it->second[1];
          return -1;
        },
        [&](Index a, Index b) { return !is_seam(a, b); });
  }

 private:
  static std::vector<char> welded(const std::vector<Index>& copies) {
    std::vector<char> at(copies.size());
    for (std::size_t w = 0; w < copies.size(); ++w) at[w] = copies[w] > 1;
    return at;
  }
  bool is_seam(Index a, Index b) const { return seam_.count(half_edge_key(std::min(a, b), std::max(a, b))) > 0; }

  const Faces& input_F_;
  const std::vector<Index>& faces_;
  const Faces& work_F_;
  const Faces& output_F_;
  HalfEdgeFaces index_;
  std::unordered_set<std::uint64_t> seam_;
  std::unordered_map<std::uint64_t, std::array<Index, 2>> seam_side_;  // directed -> input (from, to)
};

}  // namespace

namespace {

// enhance(), keeping in `reuse` (when given) what the metrics can take.
EnhanceResult enhance_keeping(const Mesh& mesh, const ReferenceSurface* reference, const EnhanceOptions& options,
                              const EnhanceCallbacks& callbacks, EnhanceMetricsReuse* reuse) {
  if (reuse) reuse->clear();
  validate_enhance_options(options, reference != nullptr, mesh.num_vertices());
  if (reference) check_reference_fits(mesh, *reference);
  // Progress (progress.h): this preparation took 0.2-2.6 s of 16-200 s runs at 1M-10M
  // (docs/benchmarks.md); re-sampling attributes is a guess (no figures at that size).
  constexpr double kPrepared = 0.02, kMethodEnds = 0.95;
  const double method_ends = mesh.attributes.empty() ? 1 : kMethodEnds;
  report_progress("preparing", 0, kPrepared);
  try {
    mesh.attributes.validate(mesh.num_vertices(), mesh.num_faces());
  } catch (const std::invalid_argument& e) {
    throw EnhanceOptionError(std::string("enhance: ") + e.what());
  }
  const Index n = mesh.num_vertices();
  std::optional<Topology> topology;  // of all faces, when workable_faces built it
  std::vector<Index> faces = enhance_detail::workable_faces(mesh, &topology);
  const bool all_faces = faces.size() == static_cast<std::size_t>(mesh.num_faces());
  const Faces workable_F = all_faces ? Faces() : enhance_detail::face_rows(mesh.F, faces);
  const Faces& input_F = all_faces ? mesh.F : workable_F;
  if (!all_faces || !topology) {
    topology.reset();
    topology = build_topology(input_F, n);
  }
  // Seams stored cut open are welded for the methods and held as creases.
  const CutSeams cut = find_cut_seams(mesh.V, input_F, *topology);
  auto representative = [&](Index v) { return cut.empty() ? v : cut.representative[static_cast<std::size_t>(v)]; };

  // Work vertices: the input vertices of workable faces, copies on a cut seam as one. Vertices
  // of the faces kept out are held; vertices with no workable face are left out.
  std::vector<Index> to_work(static_cast<std::size_t>(n), -1);
  for (const Index f : faces)
    for (int k = 0; k < 3; ++k) to_work[static_cast<std::size_t>(mesh.F(f, k))] = 0;
  std::vector<Index> to_input;  // the lowest input vertex of each work vertex
  Index used = 0;
  for (Index v = 0; v < n; ++v) {
    Index& w = to_work[static_cast<std::size_t>(v)];
    if (w < 0) continue;
    ++used;
    const Index r = representative(v);  // r <= v, and used
    if (r != v) {
      w = to_work[static_cast<std::size_t>(r)];
    } else {
      w = static_cast<Index>(to_input.size());
      to_input.push_back(v);
    }
  }
  std::vector<char> held(static_cast<std::size_t>(n), 0);
  {
    std::vector<char> in_workable(static_cast<std::size_t>(mesh.num_faces()), 0);
    for (const Index f : faces) in_workable[static_cast<std::size_t>(f)] = 1;
    for (Index f = 0; f < mesh.num_faces(); ++f)
      if (!in_workable[static_cast<std::size_t>(f)])
        for (int k = 0; k < 3; ++k) held[static_cast<std::size_t>(mesh.F(f, k))] = 1;
  }
  const bool whole = all_faces && used == n && cut.empty();
  if (whole && mesh.attributes.empty()) {
    // The flow takes the topology; the other modes build what they need, so it goes now.
    if (enhance_mode(options, reference != nullptr) != EnhanceMode::Flow) topology.reset();
    // So do the maps of the partial paths: 21 bytes per vertex at the flow's peak.
    std::vector<Index>().swap(faces);
    std::vector<Index>().swap(to_work);
    std::vector<Index>().swap(to_input);
    std::vector<char>().swap(held);
    const ProgressPart part("", kPrepared, method_ends);
    EnhanceResult result = enhance_clean(mesh, reference, options, callbacks, topology ? &*topology : nullptr, true);
    if (reuse && topology) {
      auto kept = std::make_unique<EnhanceMetricsReuse::Kept>();
      kept->topology = std::move(*topology);
      kept->faces = enhance_detail::faces_fingerprint(mesh.F);
      reuse->keep(std::move(kept));
    }
    return result;
  }

  // Chart boundaries (seams, material boundaries) are creases for the flow and never flipped.
  const attributes_detail::ChartBoundaries charts = attributes_detail::chart_boundaries(mesh, faces, *topology);
  const std::vector<std::array<Index, 2>>& seams = charts.edges;

  // The methods' mesh: the input itself when every face and vertex is workable and nothing is
  // welded, else the workable faces on the work vertices.
  Mesh work;
  if (!whole) work.comments = mesh.comments;
  const Mesh& methods_mesh = whole ? mesh : work;
  auto work_of = [&](Index v) { return to_work[static_cast<std::size_t>(v)]; };
  EnhanceOptions o = options;
  o.constraints.pinned.clear();
  o.constraints.crease_edges.clear();
  if (!whole) {
    work.V.resize(static_cast<Eigen::Index>(to_input.size()), 3);
    for (std::size_t w = 0; w < to_input.size(); ++w)
      work.V.row(static_cast<Eigen::Index>(w)) = mesh.V.row(to_input[w]);
    work.F.resize(input_F.rows(), 3);
    for (Eigen::Index i = 0; i < input_F.rows(); ++i)
      for (int k = 0; k < 3; ++k) work.F(i, k) = work_of(input_F(i, k));
  }
  // The caller's pins as given (the report counts them), then the held vertices.
  for (const Index p : options.constraints.pinned)
    if (work_of(p) >= 0) o.constraints.pinned.push_back(work_of(p));
  Index vertices_held = 0;
  for (Index v = 0; v < n; ++v)
    if (held[static_cast<std::size_t>(v)] && work_of(v) >= 0) {
      o.constraints.pinned.push_back(work_of(v));
      ++vertices_held;
    }
  for (const auto& [a, b] : options.constraints.crease_edges)
    if (a >= 0 && b >= 0 && a < n && b < n && work_of(a) >= 0 && work_of(b) >= 0)
      o.constraints.crease_edges.push_back({work_of(a), work_of(b)});
  for (const auto& [a, b] : seams) o.constraints.crease_edges.push_back({work_of(a), work_of(b)});
  std::vector<std::array<Index, 2>> cut_edges;  // in work vertices
  for (const auto& [a, b] : cut.edges) cut_edges.push_back({work_of(a), work_of(b)});
  o.constraints.crease_edges.insert(o.constraints.crease_edges.end(), cut_edges.begin(), cut_edges.end());
  if (!cut.empty())
    tell(callbacks.phase, fmt::format("{} seam edges are stored cut open: their {} vertex copies move as one, the "
                                      "seams as creases",
                                      cut.edges.size(), cut.vertices_welded));

  // The topology built for the seams is the flow's too when the methods work on the input.
  EnhanceResult result = [&] {
    const ProgressPart part("", kPrepared, method_ends);
    return enhance_clean(methods_mesh, reference, o, callbacks, whole ? &*topology : nullptr);
  }();
  Mesh out;
  if (whole) {
    out.V = std::move(result.mesh.V);
    out.F = std::move(result.mesh.F);
  } else {
    out.V = mesh.V;
    for (Index v = 0; v < n; ++v)
      if (work_of(v) >= 0) out.V.row(v) = result.mesh.V.row(work_of(v));
    out.F = mesh.F;
    // Faces the edge flips left alone keep their input rows; changed ones take, at a welded
    // vertex, the copy on their side of the seam.
    std::vector<Index> copies(to_input.size(), 0);
    for (Index v = 0; v < n; ++v)
      if (work_of(v) >= 0) ++copies[static_cast<std::size_t>(work_of(v))];
    std::optional<SeamSides> sides;
    for (std::size_t i = 0; i < faces.size(); ++i) {
      const auto row = static_cast<Eigen::Index>(i);
      if (result.mesh.F.row(row) == work.F.row(row)) continue;
      for (int k = 0; k < 3; ++k) {
        const Index w = result.mesh.F(row, k);
        Index v = to_input[static_cast<std::size_t>(w)];
        if (copies[static_cast<std::size_t>(w)] > 1) {
          if (!sides) sides.emplace(mesh.F, faces, to_work, copies, cut_edges, work.F, result.mesh.F);
          if (const Index side = sides->copy_for(static_cast<Index>(i), w); side >= 0) v = side;
        }
        out.F(faces[i], k) = v;
      }
    }
  }
  out.comments = std::move(result.mesh.comments);
  const Index faces_held = mesh.num_faces() - static_cast<Index>(faces.size());
  if (faces_held > 0) {
    const std::string line = fmt::format(
        "{} zero-area, repeated-vertex or duplicate faces stay in the face list; their {} vertices are held",
        faces_held, vertices_held);
    result.warnings.push_back(line);
    if (callbacks.warning) callbacks.warning(line);
  }
  result.report["face_list"] = {{"faces", mesh.num_faces()},
                                {"faces_held", faces_held},
                                {"vertices_held", vertices_held},
                                {"vertices_without_faces", n - used}};
  if (!cut.empty())
    result.report["cut_seams"] = {{"edges", cut.edges.size()}, {"vertices_welded", cut.vertices_welded}};
  if (!mesh.attributes.empty()) {
    report_progress("attributes", kMethodEnds, 1);
    const auto start = Clock::now();
    attributes_detail::TransportReport t;
    out.attributes = attributes_detail::transport_attributes(mesh, faces, *topology, charts, out.V, out.F, t);
    result.report["attributes"] = {
        {"chart_boundary_edges", seams.size()}, {"vertices_moved", t.vertices_moved},
        {"wedges_located", t.wedges_located},   {"max_location_distance_edges", t.max_location_distance},
        {"rows_added", t.rows_added},           {"normal_channels_recomputed", t.normal_channels},
        {"seconds", seconds_since(start)}};
  }
  result.mesh = std::move(out);
  return result;
}

}  // namespace

EnhanceResult enhance(const Mesh& mesh, const ReferenceSurface* reference, const EnhanceOptions& options,
                      const EnhanceCallbacks& callbacks) {
  return enhance_keeping(mesh, reference, options, callbacks, nullptr);
}

EnhanceResult enhance(const Mesh& mesh, const ReferenceSurface* reference, const EnhanceOptions& options,
                      const EnhanceCallbacks& callbacks, EnhanceMetricsReuse& reuse) {
  return enhance_keeping(mesh, reference, options, callbacks, &reuse);
}

EnhanceMetricsReuse::EnhanceMetricsReuse() = default;
EnhanceMetricsReuse::~EnhanceMetricsReuse() = default;
EnhanceMetricsReuse::EnhanceMetricsReuse(EnhanceMetricsReuse&&) noexcept = default;
EnhanceMetricsReuse& EnhanceMetricsReuse::operator=(EnhanceMetricsReuse&&) noexcept = default;

bool EnhanceMetricsReuse::empty() const {
  return kept_ == nullptr;
}

void EnhanceMetricsReuse::clear() {
  kept_.reset();
}

void EnhanceMetricsReuse::keep(std::unique_ptr<Kept> kept) {
  kept_ = std::move(kept);
}

}  // namespace vertexflow
