// Fitting to a reference surface (fit.h): Hoppe et al.'s distance energy over the vertex
// positions, with foot points iterated and the flow's guard after every solve.
#include "vertexflow/fit.h"

#include "fit_rounds.h"
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

// The data rows of one round, first direction: the reference's samples at their foot points on
// the mesh X. Returns their mean squared distance.
double rows_to_mesh(const Vertices& X, const Faces& F, const Vertices& samples, std::vector<DataRow>& to_mesh) {
  const DistanceQuery mesh(X, F);
  const std::vector<ClosestPoint> feet = mesh.closest_points(samples);
  to_mesh.resize(feet.size());
  double sum_to_mesh = 0;
  for (std::size_t j = 0; j < feet.size(); ++j) {
    to_mesh[j] = {feet[j].face, F.row(feet[j].face).transpose(), feet[j].barycentric,
                  samples.row(static_cast<Index>(j)).transpose()};
    sum_to_mesh += feet[j].squared_distance;
  }
  return sum_to_mesh / static_cast<double>(feet.size());
}

// Second direction: the mesh's vertices and face centroids at their closest points on the
// reference. Returns their mean squared distance.
double rows_to_reference(const Vertices& X, const Faces& F, const DistanceQuery& reference,
                         std::vector<DataRow>& to_reference) {
  const Index n = X.rows(), m = F.rows();
  Vertices points(n + m, 3);
  points.topRows(n) = X;
  for (Index f = 0; f < m; ++f) points.row(n + f) = (X.row(F(f, 0)) + X.row(F(f, 1)) + X.row(F(f, 2))) / 3.0;
  const std::vector<ClosestPoint> closest = reference.closest_points(points);
  to_reference.resize(closest.size());
  double sum_to_reference = 0;
  for (Index s = 0; s < n + m; ++s) {
    const ClosestPoint& c = closest[static_cast<std::size_t>(s)];
    to_reference[static_cast<std::size_t>(s)] =
        s < n ? DataRow{-1, {static_cast<int>(s), static_cast<int>(s), static_cast<int>(s)}, {1.0, 0.0, 0.0}, c.point}
              : DataRow{s - n, F.row(s - n).transpose(), Eigen::Vector3d::Constant(1.0 / 3.0), c.point};
    sum_to_reference += c.squared_distance;
  }
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
  tbb::parallel_invoke([&] { (void)reference.distance_query(); },
                       [&] {
                         SamplingOptions sampling;
                         sampling.samples =
                             static_cast<Index>(std::ceil(options.samples_per_vertex * static_cast<double>(n)));
                         sampling.seed = fit_sample_seed(options.seed);
                         sampling.vertices = false;
                         sampling.edge_midpoints = false;
                         samples_pointer = &reference.samples(sampling).points;
                         rounds.emplace(V, F, options);
                       });
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
    const double to_mesh_ms = rows_to_mesh(X, F, samples, to_mesh);
    const double to_reference_ms = rows_to_reference(X, F, tree, to_reference);
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
