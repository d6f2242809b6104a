// The table of enhance_options.h: every option of EnhanceOptions, once.
#include "vertexflow/enhance_options.h"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <type_traits>
#include <utility>

namespace vertexflow {
namespace {

constexpr ModeMask kFlow = mode_bit(EnhanceMode::Flow), kReferenceFlow = mode_bit(EnhanceMode::ReferenceFlow),
                   kFit = mode_bit(EnhanceMode::ReferenceFit), kSmooth = mode_bit(EnhanceMode::Smooth),
                   kUnsharp = mode_bit(EnhanceMode::Unsharp);
constexpr ModeMask kFlowModes = kFlow | kReferenceFlow;
constexpr ModeMask kGuarded = kFlowModes | kFit | kSmooth;
constexpr ModeMask kAll = kGuarded | kUnsharp;
constexpr double kInf = std::numeric_limits<double>::infinity();

// The members are reached through generic lambdas `[](auto& o) -> auto& { return o.x; }`, which
// serve the const getter and the setter alike.
template <typename Member>
EnhanceOptionSpec member_spec(std::string_view name, std::string_view cpp, std::string_view flag, OptionKind kind,
                              ModeMask modes, std::string_view help, Member member) {
  EnhanceOptionSpec s;
  s.name = name;
  s.cpp = cpp;
  s.flag = flag;
  s.kind = kind;
  s.modes = modes;
  s.help = help;
  s.get = [member](const EnhanceOptions& o) -> OptionValue {
    const auto& v = member(o);
    using T = std::decay_t<decltype(v)>;
    if constexpr (std::is_same_v<T, bool> || std::is_same_v<T, double> || std::is_same_v<T, std::vector<Index>>)
      return v;
    else if constexpr (std::is_same_v<T, std::optional<int>>)
      return v ? OptionValue(static_cast<long long>(*v)) : OptionValue();
    else
      return static_cast<long long>(v);  // an integer, or an enum's value (choice() names it)
  };
  s.set = [member](EnhanceOptions& o, const OptionValue& value) {
    auto& v = member(o);
    using T = std::decay_t<decltype(v)>;
    if constexpr (std::is_same_v<T, bool>)
      v = std::get<bool>(value);
    else if constexpr (std::is_same_v<T, double>)
      v = std::holds_alternative<long long>(value) ? static_cast<double>(std::get<long long>(value))
                                                   : std::get<double>(value);
    else if constexpr (std::is_same_v<T, std::vector<Index>>)
      v = std::get<std::vector<Index>>(value);
    else if constexpr (std::is_same_v<T, std::optional<int>>) {
      if (std::holds_alternative<std::monostate>(value))
        v.reset();
      else
        v = static_cast<int>(std::get<long long>(value));
    } else {
      v = static_cast<T>(std::get<long long>(value));  // an integer, or an enum from its value
    }
  };
  return s;
}

EnhanceOptionSpec ranged(EnhanceOptionSpec s, double min, double max, bool min_open = false, bool max_open = false) {
  s.min = min;
  s.max = max;
  s.min_open = min_open;
  s.max_open = max_open;
  return s;
}

// A Choice: the member holds an enum, set and read by name; `values` pairs each name with its
// enumerator (the table's order is the help's, not necessarily the enum's).
template <typename Enum>
EnhanceOptionSpec choice(EnhanceOptionSpec s, std::vector<std::pair<std::string_view, Enum>> values) {
  for (const auto& [name, value] : values) {
    s.choices.push_back(name);
    s.choice_values.push_back(static_cast<long long>(value));
  }
  auto get_value = s.get;
  auto set_value = s.set;
  s.get = [get_value, values](const EnhanceOptions& o) -> OptionValue {
    const auto current = static_cast<Enum>(std::get<long long>(get_value(o)));
    for (const auto& [name, value] : values)
      if (value == current) return std::string(name);
    return std::string("?");
  };
  s.set = [set_value, values](EnhanceOptions& o, const OptionValue& v) {
    const auto& name = std::get<std::string>(v);
    for (const auto& [choice_name, value] : values)
      if (choice_name == name) return set_value(o, static_cast<long long>(value));
    throw std::invalid_argument("'" + name + "' is not a choice");
  };
  return s;
}

EnhanceOptionSpec negated_flag(EnhanceOptionSpec s) {
  s.flag_negates = true;
  return s;
}

std::vector<EnhanceOptionSpec> make_specs() {
  using K = OptionKind;
  std::vector<EnhanceOptionSpec> t;
  // Which mode (enhance.h's table).
  t.push_back(choice<EnhanceMethod>(
      member_spec(
          "method", "method", "--method", K::Choice, kAll,
          "flow (Ji et al.) or unsharp (geometric unsharp mask baseline)", [](auto& o) -> auto& { return o.method; }),
      {{"flow", EnhanceMethod::Flow}, {"unsharp", EnhanceMethod::Unsharp}}));
  t.push_back(
      choice<EnhanceSurface>(member_spec(
                                 "surface", "surface", "--surface", K::Choice, kAll,
                                 "What the vertices approximate without a reference: input (the paper's flow over the "
                                 "input surface) or smooth (fit to a PN-triangle estimate of the smooth surface "
                                 "through the vertices; fit.h)",
                                 [](auto& o) -> auto& { return o.surface; }),
                             {{"input", EnhanceSurface::Input}, {"smooth", EnhanceSurface::Smooth}}));
  t.push_back(
      choice<ReferenceMethod>(member_spec(
                                  "reference_method", "reference_method", "--reference-method", K::Choice, kAll,
                                  "With a reference: fit (the vertices fitted to it, leaving the input surface; fit.h) "
                                  "or flow (the paper's flow with its foot points, frames and curvature from the "
                                  "reference, the vertices on it; flow.h)",
                                  [](auto& o) -> auto& { return o.reference_method; }),
                              {{"fit", ReferenceMethod::Fit}, {"flow", ReferenceMethod::Flow}}));

  // The flow's own (flow.h, flow_energy.h).
  t.push_back(ranged(member_spec(
                         "lam", "flow.weights.lambda", "--lambda", K::Double, kFlowModes,
                         "Weight of the distance to the input: smaller moves vertices further (0.2 strong .. "
                         "50 faint)",
                         [](auto& o) -> auto& { return o.flow.weights.lambda; }),
                     0, kInf, true, true));
  t.push_back(ranged(member_spec(
                         "mu", "flow.weights.mu", "--mu", K::Double, kFlowModes, "Weight of the fairness term",
                         [](auto& o) -> auto& { return o.flow.weights.mu; }),
                     0, kInf, false, true));
  t.push_back(ranged(member_spec(
                         "epsilon", "flow.weights.epsilon", "--epsilon", K::Double, kFlowModes,
                         "Weight of the tangential edge term that keeps flat regions well posed (flow_energy.h)",
                         [](auto& o) -> auto& { return o.flow.weights.epsilon; }),
                     0, kInf, true, true));
  t.push_back(ranged(member_spec(
                         "sliver", "flow.weights.sliver", "--sliver-stiffness", K::Double, kFlowModes,
                         "Weight of the solve's term that keeps corners of faces below the min quality from "
                         "their opposite edges (0: the guard alone)",
                         [](auto& o) -> auto& { return o.flow.weights.sliver; }),
                     0, kInf, false, true));
  t.push_back(
      choice<FairnessTarget>(member_spec(
                                 "fairness_target", "flow.weights.fairness_target", "--fairness", K::Choice, kFlowModes,
                                 "Target of the fairness term: input-normal (keeps the shape) or zero (the paper's)",
                                 [](auto& o) -> auto& { return o.flow.weights.fairness_target; }),
                             {{"input-normal", FairnessTarget::InputNormal}, {"zero", FairnessTarget::Zero}}));
  t.push_back(ranged(member_spec(
                         "d_percentile", "flow.d_percentile", "--d-percentile", K::Double, kFlowModes,
                         "d of Eq. 6 is the curvature radius at this percentile of |k| (100: the paper's "
                         "minimum radius)",
                         [](auto& o) -> auto& { return o.flow.d_percentile; }),
                     0, 100));
  t.push_back(ranged(member_spec(
                         "iterations", "flow.iterations", "--iterations", K::Int, kFlowModes,
                         "Solves, curvature recomputed in between", [](auto& o) -> auto& { return o.flow.iterations; }),
                     1, 20));
  t.push_back(negated_flag(member_spec(
      "project_to_input", "flow.project_to_input", "--no-projection", K::Bool, kFlowModes,
      "Leave vertices where the solve puts them instead of moving them onto the "
      "input surface",
      [](auto& o) -> auto& { return o.flow.project_to_input; })));
  t.push_back(choice<LinearSolver>(member_spec(
                                       "solver", "flow.solver", "--solver", K::Choice, kFlowModes,
                                       "Linear solver: automatic (flow.h says how it chooses), direct, iterative or "
                                       "multilevel",
                                       [](auto& o) -> auto& { return o.flow.solver; }),
                                   {{"automatic", LinearSolver::Automatic},
                                    {"direct", LinearSolver::Direct},
                                    {"iterative", LinearSolver::Iterative},
                                    {"multilevel", LinearSolver::Multilevel}}));
  t.push_back(ranged(member_spec(
                         "solver_tolerance", "flow.solver_tolerance", "--solver-tolerance", K::Double, kFlowModes,
                         "Iterative solvers: the relative residual at which they stop",
                         [](auto& o) -> auto& { return o.flow.solver_tolerance; }),
                     0, 1, true, true));
  t.push_back(
      ranged(member_spec(
                 "curvature_smoothing_rounds", "flow.curvature.smoothing_rounds", "--curvature-smoothing", K::Int,
                 kFlowModes, "Rounds of smoothing of the curvature tensors the flow uses (curvature.h; 0: none)",
                 [](auto& o) -> auto& { return o.flow.curvature.smoothing_rounds; }),
             0, 1000));
  t.push_back(choice<NormalWeighting>(
      member_spec(
          "normal_weighting", "flow.curvature.normal_weighting", "--normal-weighting", K::Choice, kFlowModes,
          "Vertex normals of the curvature estimate (curvature.h)",
          [](auto& o) -> auto& { return o.flow.curvature.normal_weighting; }),
      {{"max1999", NormalWeighting::Max1999}, {"area", NormalWeighting::Area}, {"angle", NormalWeighting::Angle}}));
  t.push_back(ranged(member_spec(
                         "density_passes", "flow.density.passes", "--density-passes", K::Int, kFlowModes,
                         "Density-weighted centroidal passes after the solve, which move vertices towards "
                         "curvature where the mesh's connectivity holds the flow back (vertex-clustered "
                         "scans); 0: the paper's flow alone (flow.h, DensityRelaxation)",
                         [](auto& o) -> auto& { return o.flow.density.passes; }),
                     0, 1000));
  t.push_back(ranged(member_spec(
                         "density_exponent", "flow.density.exponent", "--density-exponent", K::Double, kFlowModes,
                         "Density passes: sizing density (0.1 + (|k1| + |k2|) * mean edge length)^this; 0 "
                         "equalises areas; at most 10, where the density stays finite (flow.h)",
                         [](auto& o) -> auto& { return o.flow.density.exponent; }),
                     0, DensityRelaxation::max_exponent));
  t.push_back(ranged(member_spec(
                         "density_epsilon", "flow.density.epsilon", "--density-epsilon", K::Double, kFlowModes,
                         "Density passes: the density of a flat region, per mean edge length",
                         [](auto& o) -> auto& { return o.flow.density.epsilon; }),
                     0, kInf, true, true));
  t.push_back(ranged(member_spec(
                         "density_step", "flow.density.step", "--density-step", K::Double, kFlowModes,
                         "Density passes: the fraction of the way to the centroid per pass",
                         [](auto& o) -> auto& { return o.flow.density.step; }),
                     0, 1, true, false));

  // Shared by several modes (enhance.h).
  t.push_back(negated_flag(member_spec(
      "fix_boundary", "constraints.fix_boundary", "--free-boundary", K::Bool, kAll,
      "Let boundary vertices move (default: fixed)", [](auto& o) -> auto& { return o.constraints.fix_boundary; })));
  t.push_back(member_spec(
      "pins", "constraints.pinned", "", K::Indices, kAll, "Vertex indices (0-based) held in place",
      [](auto& o) -> auto& { return o.constraints.pinned; }));
  t.push_back(member_spec(
      "refuse_non_manifold", "refuse_non_manifold", "--strict", K::Bool, kFlowModes | kUnsharp,
      "Refuse a non-manifold or inconsistently oriented mesh (default: hold its non-manifold "
      "vertices and move the rest)",
      [](auto& o) -> auto& { return o.refuse_non_manifold; }));
  t.push_back(ranged(member_spec(
                         "feature_angle", "feature_angle", "--feature-angle", K::Double, kFlowModes | kSmooth,
                         "Dihedral angle (degrees) above which an edge is a crease vertices slide along, not "
                         "across (smooth mode: which the estimate keeps straight)",
                         [](auto& o) -> auto& { return o.feature_angle; }),
                     0, kInf, false, true));
  t.push_back(ranged(member_spec(
                         "min_quality", "guard.min_quality", "--min-quality", K::Double, kGuarded,
                         "Guard: no face ends below min(this, the worst input radius ratio 2r/R around its "
                         "corners); 0 repairs only flips",
                         [](auto& o) -> auto& { return o.guard.min_quality; }),
                     0, 1));
  t.push_back(ranged(member_spec(
                         "sliver_floor", "guard.sliver_floor", "--sliver-floor", K::Double, kGuarded,
                         "Guard: a face starting below the min quality may not fall below this fraction of its "
                         "input ratio",
                         [](auto& o) -> auto& { return o.guard.sliver_floor; }),
                     0, 1));
  t.push_back(ranged(member_spec(
                         "max_halvings", "guard.max_halvings", "--max-halvings", K::Int, kGuarded,
                         "Guard: halvings of a vertex's move before it is set back to its start",
                         [](auto& o) -> auto& { return o.guard.max_halvings; }),
                     1, 1000));
  t.push_back(ranged(member_spec(
                         "max_rounds", "max_rounds", "--max-rounds", K::OptionalInt, kFit | kSmooth,
                         "Reference and smooth modes: rounds of solve and guard at most (default 10 with a "
                         "reference, 1 in smooth mode)",
                         [](auto& o) -> auto& { return o.max_rounds; }),
                     1, 100));
  t.push_back(member_spec(
      "assume_on_surface", "assume_on_surface", "--assume-on-surface", K::Bool, kFlow | kSmooth,
      "The paper's flow (density passes too) and smooth mode: the vertices lie on the true surface; "
      "run even on inputs that look decimated (over 2.5% of the faces below quality 0.3) or like a "
      "subdivision control mesh (over 8% of the edges sharper than 40 degrees), or, in smooth mode, "
      "whose provenance records a fit, which are otherwise held unchanged (input_check.h)",
      [](auto& o) -> auto& { return o.assume_on_surface; }));

  // The fit's and smooth mode's own (fit.h).
  t.push_back(ranged(member_spec(
                         "samples_per_vertex", "fit.samples_per_vertex", "--samples-per-vertex", K::Double, kFit,
                         "Reference mode: area-uniform samples of the reference per vertex of the mesh",
                         [](auto& o) -> auto& { return o.fit.samples_per_vertex; }),
                     0, kInf, true, true));
  t.push_back(choice<FitSolver>(member_spec(
                                    "fit_solver", "fit.solver", "--fit-solver", K::Choice, kFit | kSmooth,
                                    "Reference and smooth modes: how each round's linear system is "
                                    "solved: iterative (conjugate gradients) or direct (CHOLMOD); fit.h",
                                    [](auto& o) -> auto& { return o.fit.solver; }),
                                {{"iterative", FitSolver::Iterative}, {"direct", FitSolver::Direct}}));
  t.push_back(ranged(member_spec(
                         "smooth_segments", "smooth.surface.segments", "--smooth-segments", K::Int, kSmooth,
                         "Smooth mode: each face of the estimate is tessellated into this squared triangles",
                         [](auto& o) -> auto& { return o.smooth.surface.segments; }),
                     1, 64));

  // The unsharp baseline's own (unsharp.h).
  t.push_back(
      ranged(member_spec(
                 "weight", "unsharp.weight", "--weight", K::Double, kUnsharp,
                 "Unsharp mask: weight w of the detail added back", [](auto& o) -> auto& { return o.unsharp.weight; }),
             -kInf, kInf, true, true));
  t.push_back(ranged(member_spec(
                         "smoothing_iterations", "unsharp.smoothing_iterations", "--smoothing-iterations", K::Int,
                         kUnsharp, "Unsharp mask: rounds of uniform Laplacian smoothing",
                         [](auto& o) -> auto& { return o.unsharp.smoothing_iterations; }),
                     0, 1000));

  // Edge flips (edge_flips.h).
  t.push_back(member_spec(
      "edge_flips", "edge_flips", "--edge-flips", K::Bool, kFlow | kFit | kSmooth,
      "After the method, flip edges where that brings the faces closer to the reference (or, "
      "without one, to the smooth estimate of the input), then refit; changes connectivity, keeps "
      "the vertex count (edge_flips.h)",
      [](auto& o) -> auto& { return o.edge_flips; }));
  t.push_back(ranged(member_spec(
                         "flip_cycles", "flip_cycles", "--flip-cycles", K::Int, kFlow | kFit | kSmooth,
                         "Edge flips with a reference fit: cycles of flips and refit (other modes flip once)",
                         [](auto& o) -> auto& { return o.flip_cycles; }),
                     1, 20));
  return t;
}

}  // namespace

const std::vector<EnhanceOptionSpec>& enhance_option_specs() {
  static const std::vector<EnhanceOptionSpec> specs = make_specs();
  return specs;
}

const EnhanceOptionSpec* find_enhance_option(std::string_view name) {
  for (const auto& spec : enhance_option_specs())
    if (spec.name == name) return &spec;
  return nullptr;
}

std::string_view choice_name(std::string_view option, long long value) {
  if (const EnhanceOptionSpec* spec = find_enhance_option(option))
    for (std::size_t i = 0; i < spec->choice_values.size(); ++i)
      if (spec->choice_values[i] == value) return spec->choices[i];
  return "?";
}

std::string option_display_name(const EnhanceOptionSpec& spec, OptionNaming naming) {
  switch (naming) {
    case OptionNaming::Cli:
      return spec.flag.empty() ? (spec.name == "pins" ? std::string("--pin") : std::string(spec.name))
                               : std::string(spec.flag);
    case OptionNaming::Python:
      return std::string(spec.name);
    case OptionNaming::Cpp:
      return std::string(spec.cpp);
  }
  return std::string(spec.name);
}

namespace {

std::string range_text(const EnhanceOptionSpec& s) {
  const bool low = std::isfinite(s.min), high = std::isfinite(s.max);
  if (low && high) return fmt::format("{}{}, {}{}", s.min_open ? '(' : '[', s.min, s.max, s.max_open ? ')' : ']');
  if (low) return fmt::format("{} {}", s.min_open ? ">" : ">=", s.min);
  if (high) return fmt::format("{} {}", s.max_open ? "<" : "<=", s.max);
  return "finite";
}

}  // namespace

void check_option_value(const EnhanceOptionSpec& spec, const OptionValue& value, OptionNaming naming) {
  const std::string name = option_display_name(spec, naming);
  auto fail = [&](const std::string& what) { throw std::invalid_argument(name + ": " + what); };
  switch (spec.kind) {
    case OptionKind::Bool:
      if (!std::holds_alternative<bool>(value)) fail("must be a boolean");
      return;
    case OptionKind::Indices:
      if (!std::holds_alternative<std::vector<Index>>(value)) fail("must be vertex indices");
      return;
    case OptionKind::Choice: {
      std::string allowed;
      for (const auto c : spec.choices) allowed += (allowed.empty() ? "" : ", ") + std::string(c);
      if (!std::holds_alternative<std::string>(value)) fail("must be one of " + allowed);
      for (const auto c : spec.choices)
        if (c == std::get<std::string>(value)) return;
      fail("'" + std::get<std::string>(value) + "' is not one of " + allowed);
      return;
    }
    case OptionKind::OptionalInt:
      if (std::holds_alternative<std::monostate>(value)) return;
      [[fallthrough]];
    case OptionKind::Int:
      if (!std::holds_alternative<long long>(value)) fail("must be an integer");
      break;
    case OptionKind::Double:
      if (!std::holds_alternative<double>(value) && !std::holds_alternative<long long>(value)) fail("must be a number");
      break;
  }
  const double x = std::holds_alternative<long long>(value) ? static_cast<double>(std::get<long long>(value))
                                                            : std::get<double>(value);
  const bool ok = std::isfinite(x) && (spec.min_open ? x > spec.min : x >= spec.min) &&
                  (spec.max_open ? x < spec.max : x <= spec.max);
  // An unbounded option's only range is "finite": say so rather than "the allowed range (finite)".
  if (!ok && !std::isfinite(spec.min) && !std::isfinite(spec.max)) fail(fmt::format("{} is not a finite number", x));
  if (!ok) fail(fmt::format("{} is not in the allowed range ({})", x, range_text(spec)));
}

nlohmann::json enhance_options_json(const EnhanceOptions& options) {
  nlohmann::json j = nlohmann::json::object();
  for (const EnhanceOptionSpec& spec : enhance_option_specs()) {
    const OptionValue value = spec.get(options);
    std::visit(
        [&](const auto& v) {
          using T = std::decay_t<decltype(v)>;
          if constexpr (std::is_same_v<T, std::monostate>)
            j[std::string(spec.name)] = nullptr;
          else if constexpr (std::is_same_v<T, std::vector<Index>>)
            j[std::string(spec.name)] = v.size();
          else
            j[std::string(spec.name)] = v;
        },
        value);
  }
  return j;
}

std::string python_literal(const OptionValue& value) {
  return std::visit(
      [](const auto& v) -> std::string {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, std::monostate>)
          return "None";
        else if constexpr (std::is_same_v<T, bool>)
          return v ? "True" : "False";
        else if constexpr (std::is_same_v<T, long long>)
          return std::to_string(v);
        else if constexpr (std::is_same_v<T, double>) {
          std::string s = fmt::format("{}", v);  // the shortest round trip, as Python's repr
          if (s.find_first_of(".en") == std::string::npos) s += ".0";
          return s;
        } else if constexpr (std::is_same_v<T, std::string>)
          return "'" + v + "'";
        else
          return "None";  // indices: no literal default but None
      },
      value);
}

}  // namespace vertexflow
