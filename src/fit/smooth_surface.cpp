// The smooth-surface estimate of fit.h: PN triangles (Vlachos, Peters, Boyd and Mitchell,
// "Curved PN triangles", I3D 2001) over the input, with creases kept straight.
#include "vertexflow/fit.h"

#include "fit_rounds.h"
#include "numerics/parallel.h"
#include "vertexflow/progress.h"
#include "vertexflow/quality.h"
#include "vertexflow/timing.h"
#include "vertexflow/topology.h"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace vertexflow {
namespace {

Eigen::Vector3d row3(const Vertices& M, Index i) {
  return M.row(i).transpose();
}

// The interior angle of face f at its corner k.
double corner_angle(const Vertices& V, const Faces& F, Index f, int k) {
  const Eigen::Vector3d a = row3(V, F(f, (k + 1) % 3)) - row3(V, F(f, k)),
                        b = row3(V, F(f, (k + 2) % 3)) - row3(V, F(f, k));
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

// The cubic Bezier triangle of one face: b the corners, e[k][0], e[k][1] the control points of
// edge k -> k + 1 (next to k and to k + 1), c the centre.
struct PnPatch {
  Eigen::Vector3d b[3], e[3][2], c;
  /// The point at barycentric (u, v, w) for corners 0, 1, 2.
  Eigen::Vector3d at(double u, double v, double w) const {
    return u * u * u * b[0] + v * v * v * b[1] + w * w * w * b[2] +
           3.0 * (u * u * v * e[0][0] + u * v * v * e[0][1] + v * v * w * e[1][0] + v * w * w * e[1][1] +
                  w * w * u * e[2][0] + w * u * u * e[2][1]) +
           6.0 * u * v * w * c;
  }
};

std::vector<PnPatch> pn_patches(const Vertices& V, const Faces& F, const Topology& topology,
                                const SmoothSurfaceOptions& options) {
  if (!(options.feature_angle >= 0)) throw std::invalid_argument("smooth surface: feature_angle must be >= 0");
  const Index m = F.rows();
  const double cos_crease = std::cos(options.feature_angle * std::numbers::pi / 180.0);
  Vertices face_normals(m, 3);
  Vertices corner_angles(m, 3);
  parallel_for_index(m, [&](Index f) {
    const Eigen::Vector3d normal = face_normal(V, F, f);  // mesh.h: length twice the area
    face_normals.row(f) =
        normal.norm() > 0 ? Eigen::RowVector3d(normal.normalized().transpose()) : Eigen::RowVector3d::Zero();
    for (int k = 0; k < 3; ++k) corner_angles(f, k) = corner_angle(V, F, f, k);
  });

  // Corner normals: per corner (f, k), the angle-weighted mean of the normals of the faces
  // around its vertex that are within the feature angle of f's, so that a crease's two sides
  // get their own normals. Edges: straight where the two faces meet at more than the feature
  // angle, or at a boundary or non-manifold edge (one face, or more than two).
  std::vector<Eigen::Vector3d> corner_normal(static_cast<std::size_t>(3 * m));
  std::vector<char> straight(static_cast<std::size_t>(3 * m), 0);  // edge k -> k + 1 of face f
  parallel_for_index(m, [&](Index f) {
    const Eigen::Vector3d nf = face_normals.row(f).transpose();
    for (int k = 0; k < 3; ++k) {
      const Index v = F(f, k);
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (Index s = topology.face_offsets[static_cast<std::size_t>(v)];
           s < topology.face_offsets[static_cast<std::size_t>(v) + 1]; ++s) {
        const Index g = topology.vertex_faces[static_cast<std::size_t>(s)];
        const Eigen::Vector3d ng = face_normals.row(g).transpose();
        if (g != f && ng.dot(nf) < cos_crease) continue;
        int corner = 0;
        while (F(g, corner) != v) ++corner;
        sum += corner_angles(g, corner) * ng;
      }
      corner_normal[static_cast<std::size_t>(3 * f + k)] = sum.norm() > 0 ? Eigen::Vector3d(sum.normalized()) : nf;
      // The faces on the other side of edge (v, w).
      const Index w = F(f, (k + 1) % 3);
      int others = 0;
      bool crease = false;
      for (Index s = topology.face_offsets[static_cast<std::size_t>(v)];
           s < topology.face_offsets[static_cast<std::size_t>(v) + 1]; ++s) {
        const Index g = topology.vertex_faces[static_cast<std::size_t>(s)];
        if (g == f || (F(g, 0) != w && F(g, 1) != w && F(g, 2) != w)) continue;
        ++others;
        if (face_normals.row(g).dot(nf) < cos_crease) crease = true;
      }
      straight[static_cast<std::size_t>(3 * f + k)] = others != 1 || crease;
    }
  });

  std::vector<PnPatch> patches(static_cast<std::size_t>(m));
  parallel_for_index(m, [&](Index f) {
    PnPatch& patch = patches[static_cast<std::size_t>(f)];
    const Eigen::Vector3d* P = patch.b;
    for (int k = 0; k < 3; ++k) patch.b[k] = row3(V, F(f, k));
    auto& e = patch.e;
    for (int k = 0; k < 3; ++k) {
      const int l = (k + 1) % 3;
      const Eigen::Vector3d d = P[l] - P[k];
      if (straight[static_cast<std::size_t>(3 * f + k)]) {
        e[k][0] = P[k] + d / 3.0;
        e[k][1] = P[l] - d / 3.0;
      } else {
        const Eigen::Vector3d& nk = corner_normal[static_cast<std::size_t>(3 * f + k)];
        const Eigen::Vector3d& nl = corner_normal[static_cast<std::size_t>(3 * f + l)];
        e[k][0] = (2.0 * P[k] + P[l] - d.dot(nk) * nk) / 3.0;
        e[k][1] = (2.0 * P[l] + P[k] + d.dot(nl) * nl) / 3.0;
      }
    }
    Eigen::Vector3d edge_mean = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) edge_mean += e[k][0] + e[k][1];
    edge_mean /= 6.0;
    const Eigen::Vector3d corner_mean = (P[0] + P[1] + P[2]) / 3.0;
    patch.c = edge_mean + (edge_mean - corner_mean) / 2.0;
  });
  return patches;
}

}  // namespace

Mesh smooth_surface_estimate(const Vertices& V, const Faces& F, const SmoothSurfaceOptions& options) {
  if (options.segments < 1) throw std::invalid_argument("smooth surface: segments must be at least 1");
  const std::vector<PnPatch> patches = pn_patches(V, F, build_topology(F, V.rows()), options);
  const Index m = F.rows();
  const int s = options.segments;
  const Index points_per_face = (s + 1) * (s + 2) / 2;
  Mesh out;
  out.V.resize(m * points_per_face, 3);
  out.F.resize(m * s * s, 3);
  parallel_for_index(m, [&](Index f) {
    const PnPatch& patch = patches[static_cast<std::size_t>(f)];
    const Index base = f * points_per_face;
    auto index = [&](int i, int j) {  // row i (0..s), column j (0..s - i)
      return base + i * (s + 1) - i * (i - 1) / 2 + j;
    };
    for (int i = 0; i <= s; ++i)
      for (int j = 0; j <= s - i; ++j) {
        const double v = static_cast<double>(i) / s, w = static_cast<double>(j) / s;
        out.V.row(index(i, j)) = patch.at(1.0 - v - w, v, w).transpose();
      }
    Index t = f * s * s;
    for (int i = 0; i < s; ++i)
      for (int j = 0; j < s - i; ++j) {
        out.F.row(t++) << index(i, j), index(i + 1, j), index(i, j + 1);
        if (j + 1 < s - i) out.F.row(t++) << index(i + 1, j), index(i + 1, j + 1), index(i, j + 1);
      }
  });
  return out;
}

FitResult fit_to_smooth_surface(const Vertices& V, const Faces& F, const SmoothFitOptions& options) {
  validate_fit(V, F, options.fit, "smooth fit");
  if (!(options.max_poor_face_fraction >= 0 && options.max_poor_face_fraction <= 1))
    throw std::invalid_argument("smooth fit: max_poor_face_fraction must be in [0, 1]");
  if (!(options.max_sharp_edge_fraction >= 0 && options.max_sharp_edge_fraction <= 1))
    throw std::invalid_argument("smooth fit: max_sharp_edge_fraction must be in [0, 1]");
  FitResult result;
  FitReport& report = result.report;
  const InputCheck check = check_input(V, F, {options.max_poor_face_fraction, options.max_sharp_edge_fraction});
  report.poor_face_fraction = check.poor_face_fraction;
  report.sharp_edge_fraction = check.sharp_edge_fraction;
  if (options.already_fitted || check.reason != HoldReason::None) {
    // One reason: the provenance, when there is one, says more than the mesh's shape.
    report.held_as_fitted = options.already_fitted;
    report.held_as_decimated = !options.already_fitted && check.reason == HoldReason::Decimated;
    report.held_as_control_mesh = !options.already_fitted && check.reason == HoldReason::ControlMesh;
    result.V = V;
    return result;
  }
  // Progress (progress.h): the patches, then at most max_rounds rounds (one by default).
  constexpr double kPatchesEnd = 0.3;
  report_progress("smooth patches", 0, kPatchesEnd);
  auto start = Clock::now();
  Topology topology = build_topology(F, V.rows());
  const std::vector<PnPatch> patches = pn_patches(V, F, topology, options.surface);
  report.seconds_surface = seconds_since(start);
  start = Clock::now();
  FitRounds rounds(V, F, std::move(topology), options.fit);
  report.seconds_tree = seconds_since(start);
  // The data rows: the centroid of each of the segments^2 triangles of a face's subdivision,
  // as the point of the face at those barycentric coordinates and its target on the face's
  // patch, weighted by the face's area (the midpoint rule of the squared distance's integral
  // over the face; corners are left out, where face and patch always agree).
  const int s = options.surface.segments;
  const Index points_per_face = s * s, m = F.rows();
  std::vector<DataRow> rows(static_cast<std::size_t>(m * points_per_face));
  parallel_for_index(m, [&](Index f) {
    const PnPatch& patch = patches[static_cast<std::size_t>(f)];
    const double area = 0.5 * face_normal(V, F, f).norm();
    Index at = f * points_per_face;
    auto add = [&](double i, double j) {
      const double v = i / s, w = j / s, u = 1.0 - v - w;
      rows[static_cast<std::size_t>(at++)] = {f, F.row(f).transpose(), {u, v, w}, patch.at(u, v, w), area};
    };
    for (int i = 0; i < s; ++i)
      for (int j = 0; j < s - i; ++j) {
        add(i + 1.0 / 3.0, j + 1.0 / 3.0);
        if (j + 1 < s - i) add(i + 2.0 / 3.0, j + 2.0 / 3.0);
      }
  });
  report.reference_samples = static_cast<Index>(rows.size());
  auto mean_squared_distance = [&](const Vertices& X) {
    double sum = 0, weights = 0;
    for (const DataRow& row : rows) {
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      for (int k = 0; k < 3; ++k) p += row.weights[k] * X.row(row.corners[k]).transpose();
      sum += row.weight * (p - row.target).squaredNorm();
      weights += row.weight;
    }
    return weights > 0 ? sum / weights : 0.0;
  };
  Vertices X = V;
  double previous = mean_squared_distance(X);
  report.rms_distance.push_back(std::sqrt(previous));
  for (int round = 0; round < options.fit.max_rounds; ++round) {
    const double width = (1 - kPatchesEnd) / options.fit.max_rounds;
    report_progress(fmt::format("fit round {}", round + 1), kPatchesEnd + round * width,
                    kPatchesEnd + (round + 1) * width);
    Vertices Y = rounds.step(X, rows, {}, report);
    const double energy = mean_squared_distance(Y);
    if (energy > previous) break;  // the guard held the round back so far it lost ground
    X = std::move(Y);
    report.rms_distance.push_back(std::sqrt(energy));
    report.rounds = round + 1;
    if (!(previous - energy > options.fit.tolerance * previous)) {
      report.converged = true;
      break;
    }
    previous = energy;
  }
  result.V = rounds.finish(std::move(X), report);
  return result;
}

}  // namespace vertexflow
