// Levels of detail fitted to their dense mesh (lod.h): QEM, then reference mode's fit, per level.
#include "vertexflow/lod.h"

#include "numerics/parallel.h"
#include "numerics/vertex_ordering.h"
#include "vertexflow/edge_flips.h"
#include "vertexflow/progress.h"
#include "vertexflow/quality.h"
#include "vertexflow/report_json.h"
#include "vertexflow/timing.h"

#include <fmt/format.h>
#include <tbb/parallel_invoke.h>

#include <cmath>
#include <stdexcept>
#include <utility>

namespace vertexflow {
namespace {

// Two-sided distances to D as enhance_metrics measures them (docs/metrics.md): D's tree and
// samples are the ReferenceSurface's, built once for every level; the level's own tree borrows
// its V and F for its one query.
}  // namespace

LodDistance lod_distance(const Mesh& m, const ReferenceSurface& dense, const SamplingOptions& sampling) {
  const DistanceStats to_dense = one_sided_distance(sample_surface(m.V, m.F, sampling), dense.distance_query());
  const DistanceStats from_dense =
      one_sided_distance(dense.samples(sampling), DistanceQuery(m.V, m.F, DistanceQuery::Borrow{}));
  const SymmetricDistance d = symmetric_distance(to_dense, from_dense);
  return {d.mean(), d.rms(), d.hausdorff};
}

namespace {

nlohmann::json to_json(const LodDistance& d) {
  return {{"mean", d.mean}, {"rms", d.rms}, {"hausdorff", d.hausdorff}};
}

SimplifyOptions simplify_options(Index target_faces, const LodOptions& options) {
  SimplifyOptions o;
  o.target_faces = target_faces;
  o.keep_boundary = options.keep_boundary;
  o.method = options.simplify_method;
  return o;
}

// Reference mode's fit (and flips) with everything else at enhance's defaults: the same run as
// `vertexflow enhance LEVEL OUT --reference D [--edge-flips]`.
EnhanceOptions fit_options(const LodOptions& options) {
  EnhanceOptions o;
  o.reference_method = ReferenceMethod::Fit;
  o.edge_flips = options.edge_flips;
  o.constraints.fix_boundary = options.keep_boundary;
  o.fit = options.fit;
  // The engine takes the shared options from EnhanceOptions (enhance.h) and refuses them in
  // the method's copy.
  o.fit.constraints = {};
  o.fit.guard = {};
  if (o.fit.max_rounds != FitOptions{}.max_rounds) o.max_rounds = o.fit.max_rounds;
  o.fit.max_rounds = FitOptions{}.max_rounds;
  return o;
}

}  // namespace

std::vector<Index> lod_face_budgets(Index dense_faces, const LodOptions& options) {
  std::vector<Index> budgets;
  if (!options.faces.empty()) {
    for (const Index f : options.faces) {
      if (f < 1 || f >= dense_faces)
        throw std::invalid_argument(fmt::format(
            "lod: a level of {} faces is not in [1, {}) (the dense mesh has {} faces)", f, dense_faces, dense_faces));
      budgets.push_back(f);
    }
  } else {
    for (const double p : options.percent) {
      if (!(std::isfinite(p) && p > 0 && p < 100))
        throw std::invalid_argument(fmt::format("lod: a level of {:g}% is not in (0, 100)", p));
      budgets.push_back(std::max<Index>(1, std::llround(p / 100 * static_cast<double>(dense_faces))));
    }
  }
  if (budgets.empty()) throw std::invalid_argument("lod: no level given");
  for (std::size_t i = 1; i < budgets.size(); ++i)
    if (budgets[i] >= budgets[i - 1])
      throw std::invalid_argument(fmt::format(
          "lod: the levels must have strictly fewer faces each ({} faces, then {}); give them coarser and coarser",
          budgets[i - 1], budgets[i]));
  return budgets;
}

LodLevel lod_level(const Mesh& previous, const ReferenceSurface& dense, Index target_faces, int level,
                   const LodOptions& options, const EnhanceCallbacks& callbacks, Index next_target_faces,
                   std::optional<SimplifyResult> simplified) {
  if (target_faces < 1) throw std::invalid_argument("lod: a level's face budget must be at least 1");
  if (simplified &&
      (simplified->report.input_faces != previous.num_faces() || simplified->report.target_faces != target_faces))
    throw std::invalid_argument(fmt::format(
        "lod: the simplification given for level {} is of {} faces to {}, not of the previous level's {} to {}", level,
        simplified->report.input_faces, simplified->report.target_faces, previous.num_faces(), target_faces));
  const auto start = Clock::now();
  LodLevel out;
  LodLevelReport& r = out.report;
  r.level = level;
  r.target_faces = target_faces;
  r.input_faces = previous.num_faces();

  // Progress (progress.h): costs guessed from the bunny's levels (simplify 1.3 s, fit 0.9 s,
  // measurements 0.4 s at 50%), flips doubling the fit.
  const double fit_end = options.edge_flips ? 0.8 : 0.65;
  report_progress("simplify", 0, 0.35);
  SimplifyResult qem;
  if (simplified) {
    qem = std::move(*simplified);
  } else {
    // QEM is serial (quadric_collapse.cpp); D's tree and samples, built on first use, take the
    // other core meanwhile (on a 1M-vertex D, QEM is 8 s, the tree and samples about 1.5 s).
    tbb::parallel_invoke([&] { qem = simplify(previous.V, previous.F, simplify_options(target_faces, options)); },
                         [&] {
                           const ProgressScope silent{ProgressSink{}};
                           (void)dense.distance_query();
                           (void)dense.samples(options.sampling);
                         });
  }
  r.simplify = qem.report;
  r.simplify_seconds = qem.report.seconds;

  auto t = Clock::now();
  report_progress("measure", 0.35, 0.42);
  r.qem = lod_distance(qem.mesh, dense, options.sampling);
  r.measure_seconds = seconds_since(t);
  if (r.qem.rms <= kLodExactRelative * bounding_box(dense.vertices()).diagonal()) {
    r.fit_skipped = true;
    r.kept_qem = true;
    r.fitted = r.qem;
    out.mesh = std::move(qem.mesh);
  } else {
    t = Clock::now();
    EnhanceResult fitted;
    {
      const ProgressPart fit_part("fit", 0.42, fit_end);
      fitted = enhance(qem.mesh, &dense, fit_options(options), callbacks);
    }
    r.fit_seconds = seconds_since(t);
    r.enhance = std::move(fitted.report);
    if (r.enhance.contains("edge_flips")) r.edge_flips = r.enhance["edge_flips"].value("flips", Index{0});
    r.flipped_faces = faces_turned_over(qem.mesh.V, qem.mesh.F, fitted.mesh.V, fitted.mesh.F);

    t = Clock::now();
    report_progress("measure", fit_end, 1);
    // The next level's QEM alongside the measurement, from the fitted level: the level kept
    // unless the measurement says otherwise (then it is dropped below). The measurement's
    // seconds are its own, though they overlap QEM's.
    double measure_seconds = 0;
    tbb::parallel_invoke(
        [&] {
          r.fitted = lod_distance(fitted.mesh, dense, options.sampling);
          measure_seconds = seconds_since(t);
        },
        [&] {
          if (next_target_faces <= 0) return;
          const ProgressScope silent{ProgressSink{}};
          // A failure here is the next level's, not this one's: it is left to the next
          // lod_level, which simplifies as usual and throws there.
          try {
            out.next_simplified = simplify(fitted.mesh.V, fitted.mesh.F, simplify_options(next_target_faces, options));
          } catch (const std::exception&) {
            out.next_simplified.reset();
          }
        });
    r.measure_seconds += measure_seconds;

    r.kept_qem = options.keep_better_of_two && r.fitted.mean > r.qem.mean;
    // Made from the fitted level, which is not the one kept: the next lod_level simplifies QEM
    // alone itself.
    if (r.kept_qem) out.next_simplified.reset();
    out.mesh = r.kept_qem ? std::move(qem.mesh) : std::move(fitted.mesh);
  }
  r.faces = out.mesh.num_faces();
  r.vertices = out.mesh.num_vertices();
  r.min_quality = summarize_quality(triangle_quality(out.mesh.V, out.mesh.F)).min;
  r.seconds = seconds_since(start);
  return out;
}

std::vector<LodLevel> lod(const ReferenceSurface& dense, const LodOptions& options, const EnhanceCallbacks& callbacks,
                          const std::function<void(const LodLevel&)>& on_level) {
  const std::vector<Index> budgets = lod_face_budgets(static_cast<Index>(dense.faces().rows()), options);
  std::vector<LodLevel> levels;
  levels.reserve(budgets.size());
  const double n = static_cast<double>(budgets.size());
  for (std::size_t i = 0; i < budgets.size(); ++i) {
    const ProgressPart part(fmt::format("level {}", i + 1), static_cast<double>(i) / n, static_cast<double>(i + 1) / n);
    Mesh dense_mesh;
    if (i == 0) {
      dense_mesh.V = dense.vertices();
      dense_mesh.F = dense.faces();
    }
    const Index next = i + 1 < budgets.size() ? budgets[i + 1] : 0;
    std::optional<SimplifyResult> simplified;
    if (i > 0) simplified = std::exchange(levels.back().next_simplified, std::nullopt);
    levels.push_back(lod_level(i == 0 ? dense_mesh : levels.back().mesh, dense, budgets[i], static_cast<int>(i + 1),
                               options, callbacks, next, std::move(simplified)));
    if (on_level) on_level(levels.back());
  }
  return levels;
}

Mesh in_morton_order(const Mesh& mesh) {
  const Index nv = mesh.num_vertices(), nf = mesh.num_faces();
  if (nf > 0 && (mesh.F.minCoeff() < 0 || mesh.F.maxCoeff() >= nv))
    throw std::invalid_argument(fmt::format("lod: a face index is outside the {} vertices", nv));
  const std::vector<Index> vertex_order = space_filling_order(mesh.V);  // new index -> old
  std::vector<Index> new_index(static_cast<std::size_t>(nv));
  for (Index k = 0; k < nv; ++k) new_index[static_cast<std::size_t>(vertex_order[static_cast<std::size_t>(k)])] = k;
  Vertices centroids(nf, 3);
  parallel_for_index(nf, [&](Index f) {
    centroids.row(f) = (mesh.V.row(mesh.F(f, 0)) + mesh.V.row(mesh.F(f, 1)) + mesh.V.row(mesh.F(f, 2))) / 3.0;
  });
  const std::vector<Index> face_order = space_filling_order(centroids);
  Mesh out;
  out.V.resize(nv, 3);
  parallel_for_index(nv, [&](Index k) { out.V.row(k) = mesh.V.row(vertex_order[static_cast<std::size_t>(k)]); });
  out.F.resize(nf, 3);
  parallel_for_index(nf, [&](Index k) {
    for (int c = 0; c < 3; ++c)
      out.F(k, c) = new_index[static_cast<std::size_t>(mesh.F(face_order[static_cast<std::size_t>(k)], c))];
  });
  out.comments = mesh.comments;
  return out;
}

std::vector<LodLevel> lod(const Mesh& dense, const LodOptions& options, const EnhanceCallbacks& callbacks,
                          const std::function<void(const LodLevel&)>& on_level) {
  Mesh ordered = in_morton_order(dense);
  const ReferenceSurface reference(std::move(ordered.V), std::move(ordered.F));
  return lod(reference, options, callbacks, on_level);
}

nlohmann::json lod_options_json(const LodOptions& options) {
  nlohmann::json j;
  if (options.faces.empty())
    j["percent"] = options.percent;
  else
    j["faces"] = options.faces;
  j["edge_flips"] = options.edge_flips;
  j["keep_boundary"] = options.keep_boundary;
  j["simplify_method"] = simplify_method_name(options.simplify_method);
  j["keep_better_of_two"] = options.keep_better_of_two;
  j["sampling"] = {{"samples", options.sampling.samples},
                   {"seed", options.sampling.seed},
                   {"max_vertices_and_midpoints", options.sampling.max_vertices_and_midpoints}};
  return j;
}

nlohmann::json to_json(const LodLevelReport& r) {
  nlohmann::json simplify = {{"input_faces", r.simplify.input_faces},       {"target_faces", r.simplify.target_faces},
                             {"output_faces", r.simplify.output_faces},     {"collapses", r.simplify.collapses},
                             {"reached_target", r.simplify.reached_target}, {"seconds", r.simplify.seconds}};
  return {{"level", r.level},
          {"target_faces", r.target_faces},
          {"input_faces", r.input_faces},
          {"faces", r.faces},
          {"vertices", r.vertices},
          {"qem", to_json(r.qem)},
          {"fitted", to_json(r.fitted)},
          {"kept", r.kept_qem ? "qem" : "fitted"},
          {"fit_skipped", r.fit_skipped},
          {"mean_gain", r.qem.mean > 0 ? 1 - r.fitted.mean / r.qem.mean : 0.0},
          {"min_quality", r.min_quality},
          {"flipped_faces", r.flipped_faces},
          {"edge_flips", r.edge_flips},
          {"seconds",
           {{"simplify", r.simplify_seconds},
            {"fit", r.fit_seconds},
            {"measure", r.measure_seconds},
            {"total", r.seconds}}},
          {"simplify", std::move(simplify)},
          {"enhance", r.enhance}};
}

}  // namespace vertexflow
