// The enhance engine (enhance.h) and its option table (enhance_options.h): each mode is the
// method it names, run with the shared options written in; every option that does not apply to
// a mode is refused by name; the reference's tree is built once per run; results do not depend
// on the thread count.
#include "shapes.h"
#include "test_support.h"

#include "vertexflow/distance.h"
#include "vertexflow/enhance.h"
#include "vertexflow/enhance_options.h"
#include "vertexflow/io.h"
#include "vertexflow/provenance.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>

namespace vertexflow {
namespace {

// A coarse sphere and a dense mesh of the same (unit) sphere: the reference of the reference modes.
struct SpherePair {
  Mesh coarse = test::icosphere(1.0, 2);
  ReferenceSurface dense{test::icosphere(1.0, 5).V, test::icosphere(1.0, 5).F, "dense.off"};
};

EnhanceOptions with_mode(EnhanceMode mode) {
  EnhanceOptions o;
  if (mode == EnhanceMode::Smooth) o.surface = EnhanceSurface::Smooth;
  if (mode == EnhanceMode::Unsharp) o.method = EnhanceMethod::Unsharp;
  if (mode == EnhanceMode::ReferenceFlow) o.reference_method = ReferenceMethod::Flow;
  return o;
}

bool needs_reference(EnhanceMode mode) {
  return mode == EnhanceMode::ReferenceFit || mode == EnhanceMode::ReferenceFlow;
}

constexpr EnhanceMode kModes[] = {EnhanceMode::Flow, EnhanceMode::ReferenceFit, EnhanceMode::ReferenceFlow,
                                  EnhanceMode::Smooth, EnhanceMode::Unsharp};

// Each mode runs its method with the shared options written in (the CLI and Python call only
// this), and moves the vertices.
TEST(Enhance, EachModeIsItsMethodWithTheSharedOptions) {
  const Mesh bunny = read_mesh(test::data_path("bunny_uniform.off"));
  const Mesh dense = read_mesh(test::data_path("bunny.off"));
  const ReferenceSurface reference(dense.V, dense.F, "bunny.off");
  // What the engine must run the flow with: its own lambda, the shared guard and pins.
  FlowOptions flow;
  flow.weights.lambda = 2;
  flow.guard.min_quality = 0.25;
  flow.constraints.pinned = {0, 7};
  for (const EnhanceMode mode : kModes) {
    EnhanceOptions o = with_mode(mode);
    o.guard.min_quality = 0.25;     // shared: the flow's, the fit's and smooth mode's guard
    o.constraints.pinned = {0, 7};  // shared by every mode
    if (mode == EnhanceMode::Flow || mode == EnhanceMode::ReferenceFlow) o.flow.weights.lambda = 2;
    if (mode == EnhanceMode::Unsharp) o.guard = {};
    const EnhanceResult r = enhance(bunny, needs_reference(mode) ? &reference : nullptr, o);
    Vertices expected;
    switch (mode) {
      case EnhanceMode::Flow:
        expected = vertex_flow(bunny.V, bunny.F, flow).V;
        break;
      case EnhanceMode::ReferenceFlow:
        expected = vertex_flow_on_reference(bunny.V, bunny.F, dense.V, dense.F, flow).V;
        break;
      case EnhanceMode::ReferenceFit: {
        FitOptions f;
        f.guard.min_quality = 0.25;
        f.constraints.pinned = {0, 7};
        expected = fit_to_reference(bunny.V, bunny.F, dense.V, dense.F, f).V;
        break;
      }
      case EnhanceMode::Smooth: {
        SmoothFitOptions s;
        s.fit.guard.min_quality = 0.25;
        s.fit.constraints.pinned = {0, 7};
        expected = fit_to_smooth_surface(bunny.V, bunny.F, s).V;
        break;
      }
      case EnhanceMode::Unsharp: {
        UnsharpOptions u;
        u.constraints.pinned = {0, 7};
        expected = unsharp_mask(bunny.V, bunny.F, u).V;
        break;
      }
    }
    const std::string name = enhance_mode_name(mode);
    EXPECT_EQ(r.mode, mode) << name;
    EXPECT_EQ(r.mesh.V, expected) << name;
    EXPECT_NE(r.mesh.V, bunny.V) << name;
    EXPECT_EQ(r.mesh.F, bunny.F) << name;
    EXPECT_EQ(r.mesh.V.row(7), bunny.V.row(7)) << name;
    EXPECT_EQ(r.report["method"], name);
    // The run's provenance line closes the comments, and records the mode.
    ASSERT_FALSE(r.mesh.comments.empty()) << name;
    EXPECT_EQ(r.mesh.comments.back(), r.provenance) << name;
    EXPECT_EQ(r.report["provenance"], r.provenance) << name;
    EXPECT_EQ(records_fit(r.provenance), mode == EnhanceMode::ReferenceFit || mode == EnhanceMode::Smooth) << name;
  }
}

// A value of the spec's kind that is not `value` and lies in the spec's range.
OptionValue another_value(const EnhanceOptionSpec& spec, const OptionValue& value) {
  switch (spec.kind) {
    case OptionKind::Bool:
      return !std::get<bool>(value);
    case OptionKind::Int:
      return std::get<long long>(value) + 1 <= spec.max ? std::get<long long>(value) + 1
                                                        : std::get<long long>(value) - 1;
    case OptionKind::OptionalInt:
      return 2LL;
    case OptionKind::Double: {
      const double x = std::get<double>(value);
      const double y = x == 0 ? 0.5 : 0.5 * x;
      return y > spec.min || (!spec.min_open && y >= spec.min) ? y : 0.5 * (x + std::min(spec.max, x + 1));
    }
    case OptionKind::Choice:
      for (const auto c : spec.choices)
        if (c != std::get<std::string>(value)) return std::string(c);
      return value;
    case OptionKind::Indices:
      return std::vector<Index>{0};
  }
  return value;
}

// The table decides which options apply where, once: every option of every mode it does not
// apply to is refused, naming it in each front end's words; every option of a mode it applies
// to is accepted.
TEST(EnhanceOptions, EveryOptionThatDoesNotApplyIsRefusedByName) {
  int refused = 0, accepted = 0;
  for (const EnhanceMode mode : kModes) {
    const EnhanceOptions base = with_mode(mode);
    for (const EnhanceOptionSpec& spec : enhance_option_specs()) {
      if (spec.name == "method" || spec.name == "surface" || spec.name == "reference_method") continue;
      if (spec.name == "flip_cycles") continue;  // needs edge_flips: its own test
      EnhanceOptions o = base;
      const OptionValue value = another_value(spec, spec.get(o));
      ASSERT_NE(value, spec.get(o)) << spec.name;
      spec.set(o, value);
      EXPECT_EQ(spec.get(o), value) << spec.name << ": set and get disagree";
      const bool applies = (spec.modes & mode_bit(mode)) != 0;
      for (const OptionNaming naming : {OptionNaming::Cli, OptionNaming::Python, OptionNaming::Cpp}) {
        if (applies) {
          EXPECT_NO_THROW(validate_enhance_options(o, needs_reference(mode), 100, naming))
              << spec.name << " in " << enhance_mode_name(mode);
          ++accepted;
          continue;
        }
        try {
          validate_enhance_options(o, needs_reference(mode), 100, naming);
          ADD_FAILURE() << spec.name << " was accepted in " << enhance_mode_name(mode);
        } catch (const EnhanceOptionError& e) {
          EXPECT_NE(std::string(e.what()).find(option_display_name(spec, naming)), std::string::npos) << e.what();
          EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
          ++refused;
        }
      }
    }
  }
  // Measured: 34 options x 5 modes x 3 namings; a table whose masks were all-modes would refuse none.
  EXPECT_GT(refused, 100);
  EXPECT_GT(accepted, 100);
}

TEST(EnhanceOptions, ModesThatDoNotGoTogetherAreRefused) {
  const auto refuses = [](EnhanceOptions o, bool reference, const std::string& words) {
    try {
      validate_enhance_options(o, reference, -1, OptionNaming::Cli);
      ADD_FAILURE() << "accepted: " << words;
    } catch (const EnhanceOptionError& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  EnhanceOptions smooth;
  smooth.surface = EnhanceSurface::Smooth;
  refuses(smooth, true, "--reference and --surface smooth exclude each other");
  EnhanceOptions unsharp;
  unsharp.method = EnhanceMethod::Unsharp;
  refuses(unsharp, true, "--reference and --method unsharp exclude each other");
  EnhanceOptions both = smooth;
  both.method = EnhanceMethod::Unsharp;
  refuses(both, false, "exclude each other");
  EnhanceOptions flow_on_reference;
  flow_on_reference.reference_method = ReferenceMethod::Flow;
  refuses(flow_on_reference, false, "--reference-method applies to a reference only");
  EnhanceOptions cycles;
  cycles.flip_cycles = 3;
  refuses(cycles, false, "--flip-cycles applies to --edge-flips only");
  cycles.edge_flips = true;
  EXPECT_NO_THROW(validate_enhance_options(cycles, true));
  // The methods' own copies of the shared options would be overwritten: refused.
  EnhanceOptions copy;
  copy.flow.guard.min_quality = 0.1;
  refuses(copy, false, "flow.guard is set by EnhanceOptions::guard");
  // Ranges, in the front end's words.
  EnhanceOptions range;
  range.flow.weights.lambda = -1;
  try {
    validate_enhance_options(range, false, -1, OptionNaming::Python);
    ADD_FAILURE() << "lambda -1 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("lam: -1 is not in the allowed range"), std::string::npos) << e.what();
  }
  range.flow.weights.lambda = std::nan("");
  EXPECT_THROW(validate_enhance_options(range, false), std::invalid_argument);
}

// Reference mode with edge flips and two refit cycles, then the report's distances: one tree of
// the reference for all of it (the fit, the flips, every refit and the metrics).
TEST(Enhance, TheReferenceTreeIsBuiltOncePerRun) {
  const Mesh input = test::roof(8, true);
  const Mesh exact = test::roof(32, false);
  const ReferenceSurface reference(exact.V, exact.F, "roof.off");
  EnhanceOptions o;
  o.edge_flips = true;
  o.flip_cycles = 3;
  const std::uint64_t before = distance_trees_built(exact.num_faces());
  const EnhanceResult r = enhance(input, &reference, o);
  const nlohmann::json metrics = enhance_metrics(input, r.mesh, &reference);
  EXPECT_GE(r.report["edge_flips"]["flips"].get<Index>(), 6);  // measured 8: the flips ran, with refits
  EXPECT_TRUE(r.report["edge_flips"]["cycles"][0].value("refitted", false));
  EXPECT_EQ(distance_trees_built(exact.num_faces()) - before, 1u);
  EXPECT_EQ(reference.trees_built(), 1);
  EXPECT_EQ(metrics["flipped_faces"], 0);
  EXPECT_LT(metrics["distance_to_reference"]["result"]["mean"].get<double>(),
            metrics["distance_to_reference"]["input"]["mean"].get<double>());
}

// Byte-identical results for any thread count, in every mode.
TEST(Enhance, ResultsDoNotDependOnTheThreadCount) {
  const SpherePair pair;
  for (const EnhanceMode mode : kModes) {
    const EnhanceOptions o = with_mode(mode);
    const ReferenceSurface* reference = needs_reference(mode) ? &pair.dense : nullptr;
    const Vertices one = test::with_threads(1, [&] { return enhance(pair.coarse, reference, o).mesh.V; });
    const Vertices two = test::with_threads(2, [&] { return enhance(pair.coarse, reference, o).mesh.V; });
    EXPECT_EQ(one, two) << enhance_mode_name(mode);
  }
}

// What a flow run keeps for its metrics (EnhanceMetricsReuse): the same figures as without it,
// and ignored for another face list or a run that held faces out.
TEST(EnhanceMetrics, WhatTheRunKeptGivesTheSameFiguresForItsOwnInputOnly) {
  const Mesh mesh = read_mesh(test::data_path("bunny_uniform.off"));
  EnhanceMetricsReuse reuse;
  const EnhanceResult run = enhance(mesh, nullptr, EnhanceOptions{}, {}, reuse);
  ASSERT_FALSE(reuse.empty());  // the flow ran on all of the input's faces
  EXPECT_EQ(enhance_metrics(mesh, run.mesh, nullptr, nullptr, &reuse), enhance_metrics(mesh, run.mesh));

  // The same vertices and faces in another order: the kept face lists no longer fit, so they
  // must not be read.
  Mesh reordered = mesh;
  Mesh reordered_result = run.mesh;
  for (Eigen::Index f = 0; f + 1 < mesh.F.rows(); f += 2) {
    reordered.F.row(f).swap(reordered.F.row(f + 1));
    reordered_result.F.row(f).swap(reordered_result.F.row(f + 1));
  }
  EXPECT_EQ(enhance_metrics(reordered, reordered_result, nullptr, nullptr, &reuse),
            enhance_metrics(reordered, reordered_result));

  // A duplicate face is held out of the methods (enhance.h): nothing is kept.
  Mesh with_duplicate = mesh;
  with_duplicate.F.conservativeResize(mesh.F.rows() + 1, 3);
  with_duplicate.F.row(mesh.F.rows()) = mesh.F.row(0);
  enhance(with_duplicate, nullptr, EnhanceOptions{}, {}, reuse);
  EXPECT_TRUE(reuse.empty());
}

// Smooth mode holds an input whose comments record a fit (provenance.h), with one warning in
// the result; assume_on_surface fits it anyway.
TEST(Enhance, SmoothModeReadsTheInputsProvenance) {
  Mesh fitted = read_mesh(test::data_path("sphere_low.off"));
  ProvenanceRun smooth_fit;
  smooth_fit.mode = EnhanceMode::Smooth;
  fitted.comments = {provenance_line(smooth_fit)};
  EnhanceOptions o;
  o.surface = EnhanceSurface::Smooth;
  const EnhanceResult held = enhance(fitted, nullptr, o);
  EXPECT_EQ(held.mesh.V, fitted.V);
  ASSERT_EQ(held.warnings.size(), 1u);
  EXPECT_NE(held.warnings[0].find("records an earlier fit"), std::string::npos) << held.warnings[0];
  EXPECT_NE(held.provenance.find("held: already fitted"), std::string::npos) << held.provenance;
  o.assume_on_surface = true;
  EXPECT_NE(enhance(fitted, nullptr, o).mesh.V, fitted.V);
}

// The analytic check of the fit through the engine: a coarse inscribed sphere moves out towards
// the unit sphere, and the report's two-sided mean distance falls.
TEST(Enhance, ReferenceFitBringsAnInscribedSphereToTheSphere) {
  const SpherePair pair;
  const EnhanceResult r = enhance(pair.coarse, &pair.dense, EnhanceOptions{});
  const nlohmann::json m = enhance_metrics(pair.coarse, r.mesh, &pair.dense);
  const double before = m["distance_to_reference"]["input"]["mean"].get<double>();
  const double after = m["distance_to_reference"]["result"]["mean"].get<double>();
  std::cout << "[measured] icosphere(2) to the unit sphere: mean distance " << before << " -> " << after << "\n";
  EXPECT_LT(after, 0.6 * before);  // measured 0.24x; an engine that did nothing gives 1x
  // Vertices off the sphere's inscribed polyhedron: radii above 1 where the faces sag inside.
  EXPECT_GT(r.mesh.V.rowwise().norm().maxCoeff(), 1.0);
}

// Issue 32 item 2: a reference that is not the input's surface in its units is refused, in both
// reference methods, with one line naming it (check_reference_fits). Before, each was fitted or
// flowed to with no word, moving vertices by 6-8 edge lengths.
TEST(Enhance, AReferenceThatIsNotTheInputsSurfaceIsRefused) {
  const SpherePair pair;  // a bumpy input would do as well: only the boxes matter
  const Mesh dense = test::icosphere(1.0, 5);
  auto moved = [&](double scale, const Eigen::RowVector3d& shift) {
    Vertices V = dense.V * scale;
    V.rowwise() += shift;
    return V;
  };
  struct Case {
    const char* what;
    Vertices V;
    Faces F;
    const char* message;
  };
  const Case cases[] = {
      {"shifted by 1e6", moved(1, {1e6, 0, 0}), dense.F, "does not overlap the input"},
      {"scaled by 1e-9", moved(1e-9, {0, 0, 0}), dense.F, "1e-09 times the input's size"},
      {"scaled by 11", moved(11, {0, 0, 0}), dense.F, "11 times the input's size"},
      {"one triangle", (Vertices(3, 3) << -1, -1, 0, 1, -1, 0, 0, 1, 0).finished(), (Faces(1, 3) << 0, 1, 2).finished(),
       "over only 3.3% of its extent along z"},
      {"shifted by 1.2 radii", moved(1, {0, 0, 1.2}), dense.F, "over only 42.0% of its extent along z"}};
  for (const Case& c : cases) {
    const ReferenceSurface reference(c.V, c.F, "R.off");
    for (const ReferenceMethod method : {ReferenceMethod::Fit, ReferenceMethod::Flow}) {
      SCOPED_TRACE(::testing::Message() << c.what << (method == ReferenceMethod::Fit ? ", fit" : ", flow"));
      EnhanceOptions o;
      o.reference_method = method;
      try {
        enhance(pair.coarse, &reference, o);
        ADD_FAILURE() << "accepted";
      } catch (const std::invalid_argument& e) {
        const std::string line = e.what();
        EXPECT_EQ(line.rfind("the reference R.off ", 0), 0u) << line;
        EXPECT_NE(line.find(c.message), std::string::npos) << line;
        EXPECT_EQ(line.find('\n'), std::string::npos) << line;
      }
    }
  }
  // Within the bounds: 9 times the size (the input inside it), and a flat reference under a flat
  // input 1e-12 above it (the boxes are grown by 1% of the input's diagonal).
  EXPECT_NO_THROW(check_reference_fits(pair.coarse, ReferenceSurface(moved(9, {0, 0, 0}), dense.F)));
  Mesh square;
  square.V = (Vertices(4, 3) << 0, 0, 1e-12, 1, 0, 1e-12, 1, 1, 1e-12, 0, 1, 1e-12).finished();
  square.F = (Faces(2, 3) << 0, 1, 2, 0, 2, 3).finished();
  EXPECT_NO_THROW(check_reference_fits(square, ReferenceSurface(square.V.array() - 1e-12, square.F)));
}

// The bundled pairs stand for their inputs' surfaces: diagonals within 0.2%, boxes overlapping
// fully (measured: bunny_uniform and bunny_adaptive on bunny, amo_adaptive on amo).
TEST(Enhance, TheBundledReferencePairsFit) {
  for (const auto& [coarse, fine] :
       {std::pair{"bunny_uniform.off", "bunny.off"}, std::pair{"bunny_adaptive.off", "bunny.off"},
        std::pair{"amo_adaptive.off", "amo.off"}}) {
    SCOPED_TRACE(coarse);
    const Mesh dense = read_mesh(test::data_path(fine));
    EXPECT_NO_THROW(check_reference_fits(read_mesh(test::data_path(coarse)), ReferenceSurface(dense.V, dense.F, fine)));
  }
}

}  // namespace
}  // namespace vertexflow
