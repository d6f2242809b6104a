// Fitting to a reference surface (fit.h): Hoppe et al.'s distance energy over the vertex
// positions, with foot points iterated and the flow's guard after every solve.
#include "vertexflow/fit.h"

#include "fit_rounds.h"
#include "numerics/parallel.h"
#include "numerics/vertex_ordering.h"
#include "vertexflow/distance.h"
#include "vertexflow/features.h"
#include "vertexflow/progress.h"
#include "vertexflow/timing.h"
#include "vertexflow/topology.h"

#include <fmt/format.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

namespace vertexflow {

std::uint64_t fit_sample_seed(std::uint64_t seed) {
  // SplitMix64's output function (Steele, Lea, Flood 2014) on the seed with a tag: well mixed,
  // so no small seed a user gives compare or a report lands on the fit's stream.
  std::uint64_t z = (seed ^ 0x6669745f73616d70ULL) + 0x9e3779b97f4a7c15ULL;  // tag: "fit_samp"
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

namespace {

// What the rounds' queries reuse from one round to the next: every round has the same sizes, so
// these are allocated, and their pages first touched, once per fit. (Made anew each round, the
// answers alone were 64 bytes a point; page faults were about a tenth of the fit's time on lod's
// first level of a 1M-vertex mesh, 5M samples.)
struct QueryBuffers {
  std::vector<Index> near;      // rows_to_mesh's guesses, one per sample
  std::vector<double> squared;  // each point's squared distance, summed in the points' order
  Vertices sorted;              // rows_to_reference's points along the curve
  std::vector<Index> guesses;   // and their guesses
};

// The data rows of one round, first direction: the reference's samples at their foot points on
// the mesh X. Returns their mean squared distance. The searches start from the faces of the
// previous round's rows, when there are any: the vertices have moved little since, so most feet
// stay on their face, and that first guess prunes more of the tree (lod's first level of a
// 692k-vertex mesh: 3.5M samples in 2.2 s a round instead of 2.8 s).
double rows_to_mesh(const Vertices& X, const Faces& F, const Vertices& samples, std::vector<DataRow>& to_mesh,
                    QueryBuffers& buffers) {
  const DistanceQuery mesh(X, F, DistanceQuery::Borrow{});
  const Index count = samples.rows();
  // No guesses (an empty list) in the first round, as in rows_to_reference.
  const bool guessed = to_mesh.size() == static_cast<std::size_t>(count);
  buffers.near.resize(guessed ? to_mesh.size() : 0);
  if (guessed)
    parallel_for_index(
        count, [&](Index j) { buffers.near[static_cast<std::size_t>(j)] = to_mesh[static_cast<std::size_t>(j)].face; });
  to_mesh.resize(static_cast<std::size_t>(count));
  buffers.squared.resize(static_cast<std::size_t>(count));
  mesh.for_each_closest_point(samples, buffers.near, [&](Index j, const ClosestPoint& foot) {
    to_mesh[static_cast<std::size_t>(j)] = {foot.face, F.row(foot.face).transpose(), foot.barycentric,
                                            samples.row(j).transpose()};
    buffers.squared[static_cast<std::size_t>(j)] = foot.squared_distance;
  });
  const double sum_to_mesh =
      sum_over_vertices(count, 0.0, [&](Index j) { return buffers.squared[static_cast<std::size_t>(j)]; });
  return sum_to_mesh / static_cast<double>(count);
}

// Second direction: the mesh's vertices and face centroids at their closest points on the
// reference. Returns their mean squared distance. The points are queried along a Morton curve
// (`order`, computed in the first round: the vertices move little), since the mesh's own order
// need not be coherent in space: a QEM simplification of a Loop-subdivided mesh took 2.4-3.1 s
// a round for its 1.5M points in their order, 1.7-1.9 s along the curve. The previous round's
// closest faces of the reference are the first guesses, as in rows_to_mesh (1.0M points in
// 1.3 s instead of 2.0 s); they are kept in a list of their own, since a row names the mesh's
// face.
double rows_to_reference(const Vertices& X, const Faces& F, const DistanceQuery& reference,
                         std::vector<DataRow>& to_reference, std::vector<Index>& reference_faces,
                         std::vector<Index>& order, QueryBuffers& buffers) {
  const Index n = X.rows(), m = F.rows();
  auto point = [&](Index s) -> Eigen::RowVector3d {
    return s < n ? Eigen::RowVector3d(X.row(s))
                 : Eigen::RowVector3d((X.row(F(s - n, 0)) + X.row(F(s - n, 1)) + X.row(F(s - n, 2))) / 3.0);
  };
  if (order.empty()) {
    Vertices points(n + m, 3);
    parallel_for_index(n + m, [&](Index s) { points.row(s) = point(s); });
    order = space_filling_order(points);
  }
  const bool guessed = !reference_faces.empty();
  buffers.sorted.resize(n + m, 3);
  buffers.guesses.resize(guessed ? order.size() : 0);
  parallel_for_index(n + m, [&](Index k) {
    const Index s = order[static_cast<std::size_t>(k)];
    buffers.sorted.row(k) = point(s);
    if (guessed) buffers.guesses[static_cast<std::size_t>(k)] = reference_faces[static_cast<std::size_t>(s)];
  });
  to_reference.resize(order.size());
  reference_faces.resize(order.size());
  buffers.squared.resize(order.size());
  // Each answer goes straight to its point's row (the guesses were copied above, so a point's
  // guess is never overwritten before it is read); the rows are summed in their own order.
  reference.for_each_closest_point(buffers.sorted, buffers.guesses, [&](Index k, const ClosestPoint& c) {
    const Index s = order[static_cast<std::size_t>(k)];
    to_reference[static_cast<std::size_t>(s)] =
        s < n ? DataRow{-1, {static_cast<int>(s), static_cast<int>(s), static_cast<int>(s)}, {1.0, 0.0, 0.0}, c.point}
              : DataRow{s - n, F.row(s - n).transpose(), Eigen::Vector3d::Constant(1.0 / 3.0), c.point};
    reference_faces[static_cast<std::size_t>(s)] = c.face;
    buffers.squared[static_cast<std::size_t>(s)] = c.squared_distance;
  });
  const double sum_to_reference =
      sum_over_vertices(n + m, 0.0, [&](Index s) { return buffers.squared[static_cast<std::size_t>(s)]; });
  return sum_to_reference / static_cast<double>(n + m);
}

}  // namespace

FitResult fit_to_reference(const Vertices& V, const Faces& F, const Vertices& VR, const Faces& FR,
                           const FitOptions& options) {
  validate_fit(V, F, options, "fit to reference");
  if (VR.rows() == 0 || FR.rows() == 0) throw std::invalid_argument("fit to reference: the reference is empty");
  if (!VR.allFinite()) throw std::invalid_argument("fit to reference: a coordinate is not finite");
  return fit_to_reference(V, F, ReferenceSurface(VR, FR), options);
}

FitResult fit_to_reference(const Vertices& V, const Faces& F, const ReferenceSurface& reference,
                           const FitOptions& options) {
  validate_fit(V, F, options, "fit to reference");
  FitResult result;
  FitReport& report = result.report;
  const Index n = V.rows();
  // The reference's tree (built once per ReferenceSurface; CGAL builds it on one thread per
  // half, distance.cpp) alongside its samples and the system's ordering and analysis.
  // Progress (progress.h): the tree and samples, then max_rounds rounds (a converged fit ends
  // early); the tree was about a third of a 10-round fit against a 557k-vertex reference.
  constexpr double kTreeEnds = 0.3;
  const double round_width = (1 - kTreeEnds) / options.max_rounds;
  report_progress("reference tree", 0, kTreeEnds);
  auto start = Clock::now();
  std::optional<FitRounds> rounds;
  const Vertices* samples_pointer = nullptr;
  std::vector<DataRow> to_mesh, to_reference;
  std::vector<Index> reference_faces;  // the closest face of the reference to each mesh point
  std::vector<Index> point_order;      // the mesh points' Morton order (rows_to_reference)
  QueryBuffers buffers;
  // Three branches: where the tree is already built (lod's levels), the samples and the set-up
  // still overlap (lod's first level of a 1M-vertex mesh: 5M samples and a 500k-vertex set-up).
  tbb::parallel_invoke([&] { (void)reference.distance_query(); },
                       [&] {
                         SamplingOptions sampling;
                         sampling.samples =
                             static_cast<Index>(std::ceil(options.samples_per_vertex * static_cast<double>(n)));
                         sampling.seed = fit_sample_seed(options.seed);
                         sampling.vertices = false;
                         sampling.edge_midpoints = false;
                         samples_pointer = &reference.samples(sampling).points;
                       },
                       [&] { rounds.emplace(V, F, options); });
  const Vertices& samples = *samples_pointer;
  const DistanceQuery& tree = reference.distance_query();
  report.reference_samples = samples.rows();
  report.seconds_tree += seconds_since(start);

  Vertices X = V, last = V;
  double previous = 0;
  for (int round = 0;; ++round) {
    report_progress(fmt::format("fit round {}", round + 1), kTreeEnds + round * round_width,
                    kTreeEnds + (round + 1) * round_width);
    start = Clock::now();
    const double to_mesh_ms = rows_to_mesh(X, F, samples, to_mesh, buffers);
    const double to_reference_ms = rows_to_reference(X, F, tree, to_reference, reference_faces, point_order, buffers);
    report.seconds_queries += seconds_since(start);
    const double energy = 0.5 * (to_mesh_ms + to_reference_ms);
    report.rms_distance.push_back(std::sqrt(energy));
    if (round > 0 && !(previous - energy > options.tolerance * previous)) {
      report.converged = true;
      if (energy > previous) {  // the round made it worse (the guard held it back): undo it
        X = std::move(last);
        report.rms_distance.pop_back();
        --report.rounds;
      }
      break;
    }
    if (round == options.max_rounds) break;
    previous = energy;
    Vertices Y = rounds->step(X, to_mesh, to_reference, report);
    last = std::move(X);
    X = std::move(Y);
    report.rounds = round + 1;
  }
  result.V = rounds->finish(std::move(X), report);
  return result;
}

}  // namespace vertexflow
