// Levels of detail fitted to their dense mesh (issue 30, `vertexflow lod`): a chain of coarser
// and coarser meshes of one dense mesh D, each made by quadric-error simplification (QEM,
// simplify.h) and then reference mode's fit against D (fit.h, through enhance.h), optionally
// followed by edge flips towards D and refits (edge_flips.h).
//
// The chain: level 1 is simplified from D, level i from level i - 1 as it was kept (fitted, or
// QEM alone, see below), and every level is fitted against D itself, never against the level
// before it, so the errors of one level do not carry into the next one's target. D's closest-
// point tree and samples are built once (ReferenceSurface) and shared by every level's fit,
// flips and measurements.
//
// Measured at each level, against D, in D's units (docs/metrics.md's two-sided figures, as
// `enhance --report` gives them): the mean of both one-sided mean distances, the RMS over both
// directions, and the Hausdorff distance, for QEM alone (the level's simplification, before the
// fit) and for the fitted level; the minimum triangle quality 2r/R; the faces whose normal
// turned over from QEM to the fitted level (faces_turned_over, edge_flips.h: 0 by the guard).
//
// Never worse than QEM alone: where the fitted level measures a larger two-sided mean distance
// than its QEM alone (keep_better_of_two), the level is QEM alone, and the level's report says
// so (LodLevelReport::kept_qem). The fit minimises a squared-distance energy with a guard, so it
// may lose on the mean at a level where it gains on the RMS. A level that QEM alone puts on D up
// to rounding (RMS distance at most kLodExactRelative of D's bounding-box diagonal: a decimation
// of a flat subdivision, or of D's planar parts) is not fitted at all: the fit could only add
// rounding (on such a 1M-vertex armadillo it measured 1.3-1.5 times QEM's 3e-13 mean distance,
// after 2-27 rounds and 100-240 s a level).
//
// Input: as simplify.h takes it (a non-manifold or inconsistently oriented D is simplified
// through its manifold split; boundary loops kept exactly unless keep_boundary is false, and the
// fit holds boundary vertices). Output: each level as simplify.h returns it (manifold,
// consistently oriented), its vertices moved by the fit, its faces those of QEM or, with edge
// flips, flipped (same count). Deterministic: identical bytes for any thread count.
#pragma once

#include "vertexflow/distance.h"
#include "vertexflow/enhance.h"
#include "vertexflow/mesh.h"
#include "vertexflow/reference_surface.h"
#include "vertexflow/simplify.h"

#include <nlohmann/json.hpp>

#include <functional>
#include <optional>
#include <vector>

namespace vertexflow {

/// Relative RMS distance of QEM alone to D at and below which a level is not fitted (above).
inline constexpr double kLodExactRelative = 1e-9;

struct LodOptions {
  /// The levels' face budgets in percent of D's faces, in (0, 100), strictly decreasing; used
  /// when `faces` is empty. Each budget is round(percent / 100 * #F(D)), at least 1.
  std::vector<double> percent = {50, 25, 10, 5, 2, 1};
  /// The levels' face budgets as counts, strictly decreasing, each below #F(D); overrides
  /// `percent` when not empty.
  std::vector<Index> faces;
  /// Edge flips towards D after each level's fit, with refits (EnhanceOptions::edge_flips and
  /// flip_cycles).
  bool edge_flips = false;
  /// simplify.h's keep_boundary; false also lets the fit move boundary vertices.
  bool keep_boundary = true;
  /// The QEM of every level (simplify.h). Native by default: its area-weighted quadrics keep
  /// the chain closer to D (a fitted level's faces differ in size), at a fraction of CGAL's
  /// time (docs/lod.md).
  SimplifyMethod simplify_method = SimplifyMethod::Native;
  /// Keep QEM alone at a level where the fit measures a larger two-sided mean distance (above).
  bool keep_better_of_two = true;
  /// Reference mode's own options (fit.h: samples, weights, rounds, tolerance, seed); its
  /// constraints and guard are left at their defaults (keep_boundary sets the boundary's).
  /// FitOptions's defaults but for the stopping rule: a QEM level starts further from D than a
  /// remesh, and the fit keeps gaining after FitOptions's 5% (which stops it after 2 rounds).
  /// Measured on bunny.off's levels 50-2% against CGAL's QEM alone (bench/lod_peers): mean
  /// distance -13.2% with 5% and 10 rounds, -16.1% with 0.5% and 30 rounds (the chain 1.6x
  /// slower), -20.1% with 0.1% and 60 rounds (5x slower); measured while the fit's samples were
  /// the measurement's first points (fit.h, FitOptions::seed), so each about a point too good.
  FitOptions fit = [] {
    FitOptions f;
    f.tolerance = 0.005;
    f.max_rounds = 30;
    return f;
  }();
  /// The sampling of every distance measured against D (distance.h). The fit draws its own.
  SamplingOptions sampling;
};

/// Two-sided distances of one mesh to D, in D's units (see above).
struct LodDistance {
  double mean = 0;       ///< (mean A->D + mean D->A) / 2
  double rms = 0;        ///< sqrt((ms A->D + ms D->A) / 2)
  double hausdorff = 0;  ///< max over both directions' points
};

struct LodLevelReport {
  int level = 0;             ///< 1 for the first (finest) level
  Index target_faces = 0;    ///< the level's face budget
  Index input_faces = 0;     ///< faces of the mesh it was simplified from
  Index faces = 0;           ///< faces of the level (target_faces or target_faces + 1, see simplify.h)
  Index vertices = 0;        ///< vertices of the level
  LodDistance qem;           ///< QEM alone, against D
  LodDistance fitted;        ///< the fit (and flips), against D
  bool kept_qem = false;     ///< the level is QEM alone: the fit measured a larger mean, or was skipped
  bool fit_skipped = false;  ///< QEM alone is on D up to rounding: not fitted (fitted = qem)
  double min_quality = 0;    ///< the smallest 2r/R of the level as kept
  Index flipped_faces = 0;   ///< faces turned over from QEM to the fitted level
  Index edge_flips = 0;      ///< edges flipped towards D (0 without LodOptions::edge_flips)
  /// QEM. From the second level of a chain on, QEM runs in the previous level's call, alongside
  /// its measurement (lod_level): the phases' seconds overlap, and `seconds` does not count it.
  double simplify_seconds = 0;
  double fit_seconds = 0;      ///< the fit, flips and refits (enhance())
  double measure_seconds = 0;  ///< both measurements against D
  double seconds = 0;          ///< the lod_level call in all
  SimplifyReport simplify;     ///< QEM's own report
  nlohmann::json enhance;      ///< the fit's report (EnhanceResult::report)
};

struct LodLevel {
  /// The level as kept: the fitted mesh (faces flipped when edge_flips) with the fit's provenance
  /// line in its comments, or QEM alone (kept_qem) without comments.
  Mesh mesh;
  LodLevelReport report;
  /// `mesh` simplified to the next level's budget (lod_level's `next_target_faces`), for the next
  /// lod_level to take as its `simplified`; empty when none was asked for, when the level was not
  /// fitted or is QEM alone, or when that simplification failed (the next lod_level then
  /// simplifies as usual).
  std::optional<SimplifyResult> next_simplified;
};

/// The two-sided distances of `mesh` to D as every level's are measured (above), with
/// `sampling`. Throws std::invalid_argument for a mesh without faces.
LodDistance lod_distance(const Mesh& mesh, const ReferenceSurface& dense, const SamplingOptions& sampling = {});

/// The face budgets `options` give for a D of `dense_faces` faces, finest first. Throws
/// std::invalid_argument (one line, naming LodOptions's member) for no level, a percent outside
/// (0, 100) or not finite, a count below 1 or not below `dense_faces`, or budgets that do not
/// strictly decrease (two percents that round to one count included).
std::vector<Index> lod_face_budgets(Index dense_faces, const LodOptions& options);

/// One level: simplifies `previous` (D itself for level 1, the kept previous level otherwise) to
/// `target_faces`, fits it to `dense` (and flips, with edge_flips), measures both against
/// `dense` and keeps the better (above). `level` is only recorded.
///
/// The chain's steps overlap where they can, and the results are the same bytes as one step
/// after another. QEM runs on one thread, so the second core does other work meanwhile:
/// - without `simplified`, D's tree and the measurements' samples of D (ReferenceSurface) are
///   built alongside QEM;
/// - with `next_target_faces` > 0, the fitted level is simplified to that budget alongside its
///   measurement, and returned as LodLevel::next_simplified. Where the measurement then keeps
///   QEM alone (keep_better_of_two), or that simplification fails, next_simplified is left
///   empty, and the next lod_level simplifies the level as kept itself (and throws there).
/// `simplified`, when given, is `previous` simplified to `target_faces` with `options` (the
/// previous level's next_simplified) and takes the place of this level's QEM.
///
/// Throws std::invalid_argument as simplify() and enhance() do (a `previous` without faces, a
/// `dense` that is not its surface in its units: check_reference_fits), for `target_faces` below
/// 1, or for a `simplified` whose report names another input or budget.
LodLevel lod_level(const Mesh& previous, const ReferenceSurface& dense, Index target_faces, int level,
                   const LodOptions& options = {}, const EnhanceCallbacks& callbacks = {}, Index next_target_faces = 0,
                   std::optional<SimplifyResult> simplified = std::nullopt);

/// `mesh` with its vertices sorted along a Morton curve in their bounding box, then its faces
/// by their centroids along one in the centroids' box, ties by index; each face keeps its
/// corners' cyclic order, so its orientation. Comments are kept, attributes dropped (lod drops
/// them). The order the chain runs in (lod() and `vertexflow lod`): the levels inherit D's
/// order, and in a scattered order every tree query, tree build and solve of the chain misses
/// the cache. Measured on the smooth 1M-vertex mesh of docs/lod.md (Loop-subdivided, so
/// scattered), whole process, 3 runs each: 56.0-58.2 s in file order, 45.2-47.8 s in this one.
/// The chain is then another one, as QEM breaks ties by vertex index and D's samples follow its
/// face order: that mesh's gains per level moved by at most 0.3 points, both ways;
/// docs/results_lod.md's averages by at most 0.4.
Mesh in_morton_order(const Mesh& mesh);

/// The whole chain on D = in_morton_order(`dense`), whose ReferenceSurface it builds once.
/// `on_level` (may be empty) is called as each level is finished, in order. Reports progress
/// (progress.h): level i is the part [i - 1, i] / #levels of the task. Throws as
/// lod_face_budgets and lod_level.
std::vector<LodLevel> lod(const Mesh& dense, const LodOptions& options = {}, const EnhanceCallbacks& callbacks = {},
                          const std::function<void(const LodLevel&)>& on_level = {});
/// The same with D's ReferenceSurface given (a front end that reads D once and names it), in the
/// order D has there: give it in_morton_order's for the speed above.
std::vector<LodLevel> lod(const ReferenceSurface& dense, const LodOptions& options = {},
                          const EnhanceCallbacks& callbacks = {},
                          const std::function<void(const LodLevel&)>& on_level = {});

/// The options as the summary records them (the per-level budgets, edge flips, boundary, keep
/// rule, sampling).
nlohmann::json lod_options_json(const LodOptions& options);

/// A level's report as JSON: the fields above by name ("qem" and "fitted" as {mean, rms,
/// hausdorff}, "kept": "fitted" or "qem"; "simplify" and "enhance" as their reports), and
/// "mean_gain": 1 - fitted.mean / qem.mean (above 0: the fit is closer).
nlohmann::json to_json(const LodLevelReport& report);

}  // namespace vertexflow
