// Principal curvatures against analytic surfaces (sphere, cylinder, torus, saddle), under
// refinement, rigid motion, scaling and orientation reversal, and on every bundled mesh.
#include "shapes.h"
#include "test_support.h"

#include "vertexflow/curvature.h"
#include "vertexflow/io.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace vertexflow {
namespace {

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0;
  const auto rank = static_cast<std::size_t>(std::ceil(p / 100.0 * static_cast<double>(values.size()))) - 1;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(rank), values.end());
  return values[rank];
}

// Angle in degrees between two directions, ignoring sign (principal directions are lines).
double line_angle_degrees(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::min(1.0, std::abs(a.normalized().dot(b.normalized())))) * 180.0 / M_PI;
}

struct TorusErrors {
  double k1_median, k1_p95, k2_median, k2_p95, direction_median;
};

// Errors on a torus (R, r): k1 = 1/r along the tube, k2 = cos(theta) / (R + r cos(theta))
// along the big circle. Relative errors of k2 are taken where |k2| is at least a tenth of its
// maximum (near theta = +-90 degrees k2 crosses zero and a relative error is meaningless).
TorusErrors torus_errors(double R, double r, int around, int tube) {
  const Mesh mesh = test::torus(R, r, around, tube);
  const Curvature c = principal_curvatures(mesh.V, mesh.F);
  std::vector<double> e1, e2, angles;
  const double k2_max = 1.0 / (R + r);
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    const Eigen::Vector3d p = mesh.V.row(v).transpose();
    const double rho = std::hypot(p.x(), p.y());
    const double cos_theta = (rho - R) / r;
    const double k1 = 1.0 / r, k2 = cos_theta / (R + r * cos_theta);
    e1.push_back(std::abs(c.k1[v] - k1) / k1);
    if (std::abs(k2) >= 0.1 * k2_max) e2.push_back(std::abs(c.k2[v] - k2) / std::abs(k2));
    // T2 (the smaller curvature) runs along the big circle: the azimuthal direction.
    const Eigen::Vector3d azimuthal(-p.y() / rho, p.x() / rho, 0);
    angles.push_back(line_angle_degrees(c.T2.row(v).transpose(), azimuthal));
  }
  return {percentile(e1, 50), percentile(e1, 95), percentile(e2, 50), percentile(e2, 95), percentile(angles, 50)};
}

TEST(Curvature, TorusMatchesAnalyticValues) {
  // 400 x 100 = 40,000 vertices; R = 3, r = 1 keeps the triangles well shaped.
  const TorusErrors e = torus_errors(3.0, 1.0, 400, 100);
  EXPECT_LE(e.k1_median, 0.01);
  EXPECT_LE(e.k1_p95, 0.05);
  EXPECT_LE(e.k2_median, 0.01);
  EXPECT_LE(e.k2_p95, 0.05);
  EXPECT_LE(e.direction_median, 5.0);
  std::printf("torus 40k: k1 median %.4f%% p95 %.4f%%, k2 median %.4f%% p95 %.4f%%, direction median %.3f deg\n",
              100 * e.k1_median, 100 * e.k1_p95, 100 * e.k2_median, 100 * e.k2_p95, e.direction_median);
}

TEST(Curvature, ErrorDecreasesUnderRefinement) {
  const TorusErrors coarse = torus_errors(3.0, 1.0, 100, 25);
  const TorusErrors medium = torus_errors(3.0, 1.0, 200, 50);
  const TorusErrors fine = torus_errors(3.0, 1.0, 400, 100);
  EXPECT_LT(medium.k1_median, coarse.k1_median);
  EXPECT_LT(fine.k1_median, medium.k1_median);
  EXPECT_LT(medium.k2_median, coarse.k2_median);
  EXPECT_LT(fine.k2_median, medium.k2_median);
}

// Curvature smoothing (CurvatureOptions::smoothing_rounds, the CLI's `curvature --smooth`) on a
// noisy torus: every vertex of a 200 x 50 torus (R = 3, r = 1) displaced along the surface
// normal by Gaussian noise of 5% of an edge. The error against the analytic curvature at the
// unperturbed point must fall with smoothing; on the clean torus smoothing must cost little.
double median_curvature_error(const Mesh& clean, const Mesh& mesh, double R, double r, int rounds) {
  CurvatureOptions options;
  options.smoothing_rounds = rounds;
  const Curvature c = principal_curvatures(mesh.V, mesh.F, options);
  std::vector<double> errors;
  for (Index v = 0; v < clean.num_vertices(); ++v) {
    const Eigen::Vector3d p = clean.V.row(v).transpose();
    const double cos_theta = (std::hypot(p.x(), p.y()) - R) / r;
    const double k1 = 1.0 / r, k2 = cos_theta / (R + r * cos_theta);
    // Absolute errors in units of k1 (k2 crosses zero): both principal curvatures.
    errors.push_back(std::hypot(c.k1[v] - k1, c.k2[v] - k2) / k1);
  }
  return percentile(errors, 50);
}

TEST(Curvature, SmoothingLowersTheErrorOfANoisySurface) {
  const double R = 3.0, r = 1.0;
  const Mesh clean = test::torus(R, r, 200, 50);
  Mesh noisy = clean;
  std::mt19937 random(11);
  std::normal_distribution<double> noise(0.0, 0.05 * 2 * M_PI * r / 50);
  for (Index v = 0; v < clean.num_vertices(); ++v) {
    const Eigen::Vector3d p = clean.V.row(v).transpose();
    const Eigen::Vector3d centre = R * Eigen::Vector3d(p.x(), p.y(), 0).normalized();
    noisy.V.row(v) += noise(random) * (p - centre).normalized().transpose();
  }
  double previous = std::numeric_limits<double>::infinity();
  for (const int rounds : {0, 1, 3}) {
    const double e = median_curvature_error(clean, noisy, R, r, rounds);
    std::printf("noisy torus, %d smoothing rounds: median error %.4f k1\n", rounds, e);
    EXPECT_LT(e, 0.8 * previous) << rounds << " rounds";
    previous = e;
  }
  const double plain = median_curvature_error(clean, clean, R, r, 0),
               smoothed = median_curvature_error(clean, clean, R, r, 3);
  std::printf("clean torus: median error %.4f k1 plain, %.4f smoothed 3 rounds\n", plain, smoothed);
  EXPECT_LT(smoothed, plain + 0.01);
}

// A non-manifold mesh (curvature.h): two spheres of radius R that share one vertex, and one of
// them with a few faces reversed. Every vertex, the shared one included, gets about 1/R with an
// outward normal, as on a sphere of its own.
TEST(Curvature, NonManifoldAndMisorientedMeshesAreEstimatedPerFan) {
  const double R = 2.0;
  const Mesh sphere = test::icosphere(R, 3);
  const Index n = sphere.num_vertices();
  // The second sphere: translated by 2R along the direction of vertex 0, its antipode shared.
  Index antipode = 0;
  (sphere.V * sphere.V.row(0).transpose()).minCoeff(&antipode);
  Mesh two;
  two.V.resize(2 * n - 1, 3);
  two.V.topRows(n) = sphere.V;
  std::vector<Index> index(static_cast<std::size_t>(n));
  const Eigen::RowVector3d shift = 2 * sphere.V.row(0);
  for (Index v = 0, next = n; v < n; ++v) index[static_cast<std::size_t>(v)] = v == antipode ? 0 : next++;
  for (Index v = 0; v < n; ++v)
    if (v != antipode) two.V.row(index[static_cast<std::size_t>(v)]) = sphere.V.row(v) + shift;
  two.F.resize(2 * sphere.num_faces(), 3);
  two.F.topRows(sphere.num_faces()) = sphere.F;
  for (Index f = 0; f < sphere.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) two.F(sphere.num_faces() + f, k) = index[static_cast<std::size_t>(sphere.F(f, k))];
  for (const Index f : {Index{5}, Index{77}, Index{300}}) std::swap(two.F(f, 1), two.F(f, 2));
  const Topology topology = build_topology(two.F, two.num_vertices());
  ASSERT_EQ(topology.non_manifold_vertices, std::vector<Index>{0});
  ASSERT_FALSE(topology.is_oriented);
  const Curvature c = principal_curvatures(two.V, two.F);
  std::vector<double> errors;
  for (Index v = 0; v < two.num_vertices(); ++v) {
    errors.push_back(std::max(std::abs(c.k1[v] * R - 1), std::abs(c.k2[v] * R - 1)));
    const Eigen::RowVector3d centre = v < n ? Eigen::RowVector3d::Zero() : shift;
    if (v != 0) {
      EXPECT_GT(c.N.row(v).dot(two.V.row(v) - centre), 0) << v;
    }
  }
  EXPECT_LT(std::abs(c.k1[0] * R - 1), 0.05);  // the shared vertex: one fan's values
  EXPECT_LE(percentile(errors, 50), 0.02);
  EXPECT_NEAR(c.area.sum(), 2 * 4 * M_PI * R * R, 0.02 * 8 * M_PI * R * R);
}

TEST(Curvature, SphereIsUmbilicWithCurvatureOneOverR) {
  for (const double R : {0.5, 1.0, 20.0}) {
    const Mesh mesh = test::icosphere(R, 5);
    const Curvature c = principal_curvatures(mesh.V, mesh.F);
    std::vector<double> e1, e2;
    for (Index v = 0; v < mesh.num_vertices(); ++v) {
      e1.push_back(std::abs(c.k1[v] * R - 1));
      e2.push_back(std::abs(c.k2[v] * R - 1));
      // Outward normals.
      ASSERT_GT(c.N.row(v).dot(mesh.V.row(v)), 0);
    }
    EXPECT_LE(percentile(e1, 50), 0.01) << "R = " << R;
    EXPECT_LE(percentile(e2, 50), 0.01) << "R = " << R;
  }
}

TEST(Curvature, IrregularUnitSphere) {
  // sphere.off: an irregular (remeshed, not subdivided) triangulation of the unit sphere.
  const Mesh mesh = read_mesh(test::data_path("sphere.off"));
  const Curvature c = principal_curvatures(mesh.V, mesh.F);
  std::vector<double> e1, e2;
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    const double R = mesh.V.row(v).norm();
    e1.push_back(std::abs(c.k1[v] * R - 1));
    e2.push_back(std::abs(c.k2[v] * R - 1));
  }
  EXPECT_LE(percentile(e1, 50), 0.01);
  EXPECT_LE(percentile(e2, 50), 0.01);
  EXPECT_LE(percentile(e1, 95), 0.05);
  EXPECT_LE(percentile(e2, 95), 0.05);
}

TEST(Curvature, CylinderOneOverRAndZero) {
  // Catches the biased reference 3x3 LDLT (k1 = 0.93 on R = 1).
  const double R = 1.0;
  const Mesh mesh = test::cylinder(R, 4.0, 120, 80);
  const Topology topology = build_topology(mesh.F, mesh.num_vertices());
  const Curvature c = principal_curvatures(mesh.V, mesh.F, topology);
  std::vector<double> e1, e2, angles;
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    if (topology.is_boundary_vertex[static_cast<std::size_t>(v)]) continue;
    e1.push_back(std::abs(c.k1[v] - 1 / R) * R);
    e2.push_back(std::abs(c.k2[v]) * R);
    const Eigen::Vector3d p = mesh.V.row(v).transpose();
    angles.push_back(line_angle_degrees(c.T1.row(v).transpose(), Eigen::Vector3d(-p.y(), p.x(), 0)));
  }
  EXPECT_LE(percentile(e1, 50), 0.01);
  EXPECT_LE(percentile(e1, 95), 0.05);
  EXPECT_LE(percentile(e2, 50), 0.01);
  EXPECT_LE(percentile(angles, 50), 1.0);
}

TEST(Curvature, SaddleAtTheOrigin) {
  const Mesh mesh = test::saddle(0.5, 40);  // vertex (20, 20) is the origin
  const Curvature c = principal_curvatures(mesh.V, mesh.F);
  const Index origin = 20 * 41 + 20;
  ASSERT_EQ(mesh.V.row(origin).norm(), 0.0);
  // Normals up: the surface bends away from the normal along y (k = +1), towards it along x.
  EXPECT_NEAR(c.k1[origin], 1.0, 0.01);
  EXPECT_NEAR(c.k2[origin], -1.0, 0.01);
  EXPECT_LE(line_angle_degrees(c.T1.row(origin).transpose(), Eigen::Vector3d::UnitY()), 2.0);
  EXPECT_NEAR(c.gaussian()[origin], -1.0, 0.02);
  EXPECT_NEAR(c.mean()[origin], 0.0, 0.01);
}

TEST(Curvature, FramesAreOrthonormalAndRightHanded) {
  const Mesh mesh = read_mesh(test::data_path("fandisk.off"));
  const Curvature c = principal_curvatures(mesh.V, mesh.F);
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    const Eigen::Vector3d t1 = c.T1.row(v).transpose(), t2 = c.T2.row(v).transpose(), n = c.N.row(v).transpose();
    ASSERT_NEAR(t1.norm(), 1.0, 1e-12);
    ASSERT_NEAR(t2.norm(), 1.0, 1e-12);
    ASSERT_NEAR(t1.dot(n), 0.0, 1e-12);
    ASSERT_LE((t1.cross(t2) - n).norm(), 1e-12);
    ASSERT_GE(c.k1[v], c.k2[v]);
  }
}

TEST(Curvature, RigidMotionAndScaling) {
  const Mesh mesh = read_mesh(test::data_path("spot.obj"));
  const Curvature c = principal_curvatures(mesh.V, mesh.F);
  const double s = 7.25;
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()).toRotationMatrix();
  const Eigen::RowVector3d translation(10, -3, 2.5);
  Mesh moved = mesh;
  moved.V = (s * (mesh.V * rotation.transpose())).rowwise() + translation;
  const Curvature m = principal_curvatures(moved.V, moved.F);
  const double scale = c.k1.cwiseAbs().maxCoeff();
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    ASSERT_NEAR(m.k1[v] * s, c.k1[v], 1e-9 * scale) << v;
    ASSERT_NEAR(m.k2[v] * s, c.k2[v], 1e-9 * scale) << v;
    ASSERT_LE((m.N.row(v).transpose() - rotation * c.N.row(v).transpose()).norm(), 1e-9);
    // Directions are defined where the curvatures differ.
    if (c.k1[v] - c.k2[v] > 1e-3 * scale) {
      ASSERT_LE(line_angle_degrees(m.T1.row(v).transpose(), rotation * c.T1.row(v).transpose()), 1e-5) << v;
    }
  }
}

TEST(Curvature, ReversedOrientationFlipsTheSign) {
  const Mesh mesh = read_mesh(test::data_path("bunny_uniform.off"));
  Mesh reversed = mesh;
  reversed.F.col(1).swap(reversed.F.col(2));
  const Curvature c = principal_curvatures(mesh.V, mesh.F);
  const Curvature r = principal_curvatures(reversed.V, reversed.F);
  const double scale = c.k1.cwiseAbs().maxCoeff();
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    ASSERT_NEAR(r.k1[v], -c.k2[v], 1e-9 * scale);
    ASSERT_NEAR(r.k2[v], -c.k1[v], 1e-9 * scale);
    ASSERT_LE((r.N.row(v) + c.N.row(v)).norm(), 1e-12);
  }
}

TEST(Curvature, SameResultForOneAndTwoThreads) {
  const Mesh mesh = read_mesh(test::data_path("armadillo-43k.obj"));
  Curvature one, two;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = principal_curvatures(mesh.V, mesh.F, CurvatureOptions{NormalWeighting::Max1999, 1});
  }
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
    two = principal_curvatures(mesh.V, mesh.F, CurvatureOptions{NormalWeighting::Max1999, 1});
  }
  EXPECT_EQ(one.k1, two.k1);
  EXPECT_EQ(one.k2, two.k2);
  EXPECT_EQ(one.T1, two.T1);
  EXPECT_EQ(one.N, two.N);
}

// A plain reference of the whole estimator, written from Rusinkiewicz (2004) with Eigen only
// and none of the library's shortcuts (no blocks, SIMD, cofactor solve, reduced rotation or
// special frames): Max (1999) normals, Meyer et al. mixed areas, per-face fit by Eigen's LLT
// of the 6 x 3 least-squares problem, the face frame rotated onto each vertex's tangent plane
// by Eigen's Quaternion::FromTwoVectors, area-weighted sums, Eigen's 2x2 eigensolver.
struct ReferenceCurvature {
  Eigen::VectorXd k1, k2;
  Vertices T1;
};

ReferenceCurvature reference_curvature(const Mesh& mesh) {
  const Index nv = mesh.num_vertices(), nf = mesh.num_faces();
  auto p = [&](Index f, int k) -> Eigen::Vector3d { return mesh.V.row(mesh.F(f, k % 3)).transpose(); };
  Vertices N = Vertices::Zero(nv, 3);
  Eigen::VectorXd area = Eigen::VectorXd::Zero(nv);
  std::vector<Eigen::Vector3d> corner_area(static_cast<std::size_t>(nf));
  for (Index f = 0; f < nf; ++f) {
    const double face_area = 0.5 * (p(f, 1) - p(f, 0)).cross(p(f, 2) - p(f, 0)).norm();
    Eigen::Vector3d angle_cos;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d a = p(f, k + 1) - p(f, k), b = p(f, k + 2) - p(f, k);
      N.row(mesh.F(f, k)) += a.cross(b).transpose() / (a.squaredNorm() * b.squaredNorm());
      angle_cos[k] = a.dot(b);
    }
    Eigen::Vector3d& ca = corner_area[static_cast<std::size_t>(f)];
    const int obtuse = angle_cos[0] < 0 ? 0 : angle_cos[1] < 0 ? 1 : angle_cos[2] < 0 ? 2 : -1;
    for (int k = 0; k < 3; ++k) {
      if (obtuse >= 0) {
        ca[k] = (k == obtuse ? 0.5 : 0.25) * face_area;
      } else {  // (|p_k p_k+1|^2 cot(angle at k+2) + |p_k p_k+2|^2 cot(angle at k+1)) / 8
        auto cot = [&](int m) {
          const Eigen::Vector3d a = p(f, m + 1) - p(f, m), b = p(f, m + 2) - p(f, m);
          return a.dot(b) / a.cross(b).norm();
        };
        ca[k] =
            ((p(f, k + 1) - p(f, k)).squaredNorm() * cot(k + 2) + (p(f, k + 2) - p(f, k)).squaredNorm() * cot(k + 1)) /
            8;
      }
      area[mesh.F(f, k)] += ca[k];
    }
  }
  N.rowwise().normalize();

  std::vector<Eigen::Matrix2d> tensor(static_cast<std::size_t>(nv), Eigen::Matrix2d::Zero());
  std::vector<Eigen::Vector3d> frame_u(static_cast<std::size_t>(nv));
  for (Index v = 0; v < nv; ++v) frame_u[static_cast<std::size_t>(v)] = N.row(v).transpose().unitOrthogonal();
  for (Index f = 0; f < nf; ++f) {
    const Eigen::Vector3d t = (p(f, 2) - p(f, 1)).normalized();
    const Eigen::Vector3d n = (p(f, 1) - p(f, 0)).cross(p(f, 2) - p(f, 0)).normalized();
    const Eigen::Vector3d b = n.cross(t);
    Eigen::Matrix<double, 6, 3> A = Eigen::Matrix<double, 6, 3>::Zero();
    Eigen::Matrix<double, 6, 1> r;
    for (int k = 0; k < 3; ++k) {  // edge from corner k+1 to corner k+2
      const Eigen::Vector3d e = p(f, k + 2) - p(f, k + 1);
      const Eigen::Vector3d dn = (N.row(mesh.F(f, (k + 2) % 3)) - N.row(mesh.F(f, (k + 1) % 3))).transpose();
      A.row(2 * k) << e.dot(t), e.dot(b), 0;
      A.row(2 * k + 1) << 0, e.dot(t), e.dot(b);
      r[2 * k] = dn.dot(t);
      r[2 * k + 1] = dn.dot(b);
    }
    const Eigen::Vector3d efg = (A.transpose() * A).llt().solve(A.transpose() * r);
    Eigen::Matrix2d II;
    II << efg[0], efg[1], efg[1], efg[2];
    for (int k = 0; k < 3; ++k) {
      const Index v = mesh.F(f, k);
      const Eigen::Vector3d nv_ = N.row(v).transpose();
      const Eigen::Quaterniond rotation = Eigen::Quaterniond::FromTwoVectors(n, nv_);
      const Eigen::Vector3d t_rot = rotation * t, b_rot = rotation * b;
      const Eigen::Vector3d u = frame_u[static_cast<std::size_t>(v)], w = nv_.cross(u);
      Eigen::Matrix2d R;  // columns: u and w in the rotated face frame
      R << u.dot(t_rot), w.dot(t_rot), u.dot(b_rot), w.dot(b_rot);
      tensor[static_cast<std::size_t>(v)] += corner_area[static_cast<std::size_t>(f)][k] * R.transpose() * II * R;
    }
  }
  ReferenceCurvature out{Eigen::VectorXd(nv), Eigen::VectorXd(nv), Vertices(nv, 3)};
  for (Index v = 0; v < nv; ++v) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(tensor[static_cast<std::size_t>(v)] / area[v]);
    out.k2[v] = eigen.eigenvalues()[0];
    out.k1[v] = eigen.eigenvalues()[1];
    const Eigen::Vector2d d = eigen.eigenvectors().col(1);
    const Eigen::Vector3d u = frame_u[static_cast<std::size_t>(v)], w = N.row(v).transpose().cross(u);
    out.T1.row(v) = (d[0] * u + d[1] * w).transpose();
  }
  return out;
}

// The optimised estimator agrees with the plain reference above on real meshes, to rounding.
// This also guards the shortcuts the reference does not take (the vectorised cofactor solve
// among them) against the class of error of the widely copied hand-written 3x3 LDLT.
TEST(Curvature, MatchesAPlainEigenReference) {
  for (const char* name : {"bunny_uniform.off", "fandisk.off", "spot.obj"}) {
    const Mesh mesh = read_mesh(test::data_path(name));
    const Curvature c = principal_curvatures(mesh.V, mesh.F);
    const ReferenceCurvature r = reference_curvature(mesh);
    const double scale = c.k1.cwiseAbs().maxCoeff();
    for (Index v = 0; v < mesh.num_vertices(); ++v) {
      ASSERT_NEAR(c.k1[v], r.k1[v], 1e-9 * scale) << name << " vertex " << v;
      ASSERT_NEAR(c.k2[v], r.k2[v], 1e-9 * scale) << name << " vertex " << v;
      if (c.k1[v] - c.k2[v] > 1e-3 * scale) {
        ASSERT_LE(line_angle_degrees(c.T1.row(v).transpose(), r.T1.row(v).transpose()), 1e-4)
            << name << " vertex " << v;
      }
    }
  }
}

// Vertex and face order, and which corner a face lists first, change only the order of
// floating-point additions (and which SIMD lane and block computes a face), not the result.
TEST(Curvature, IndependentOfVertexAndFaceOrder) {
  const Mesh mesh = read_mesh(test::data_path("armadillo-43k.obj"));
  const auto [shuffled, new_index] = test::renumbered(mesh, 7, true);
  const Curvature c = principal_curvatures(mesh.V, mesh.F);
  const Curvature s = principal_curvatures(shuffled.V, shuffled.F);
  const double scale = c.k1.cwiseAbs().maxCoeff();
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    const Index w = new_index[static_cast<std::size_t>(v)];
    ASSERT_NEAR(s.k1[w], c.k1[v], 1e-9 * scale) << v;
    ASSERT_NEAR(s.k2[w], c.k2[v], 1e-9 * scale) << v;
    ASSERT_NEAR(s.area[w], c.area[v], 1e-12 * c.area.maxCoeff()) << v;
    ASSERT_LE((s.N.row(w) - c.N.row(v)).norm(), 1e-12) << v;
    if (c.k1[v] - c.k2[v] > 1e-3 * scale) {
      ASSERT_LE(line_angle_degrees(s.T1.row(w).transpose(), c.T1.row(v).transpose()), 1e-5) << v;
    }
  }
}

TEST(Curvature, HemisphereBoundaryIsFiniteAndItsBiasIsBounded) {
  // hemisphere.off is half of a unit sphere: interior k = 1; the boundary ring sees only one
  // side of its neighbourhood.
  const Mesh mesh = read_mesh(test::data_path("hemisphere.off"));
  const Topology topology = build_topology(mesh.F, mesh.num_vertices());
  const Curvature c = principal_curvatures(mesh.V, mesh.F, topology);
  const double R = mesh.V.rowwise().norm().mean();
  std::vector<double> interior, boundary;
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    ASSERT_TRUE(std::isfinite(c.k1[v]) && std::isfinite(c.k2[v]));
    const double mean_error = std::abs(c.mean()[v] * R - 1);
    (topology.is_boundary_vertex[static_cast<std::size_t>(v)] ? boundary : interior).push_back(mean_error);
  }
  EXPECT_LE(percentile(interior, 50), 0.01);
  // Documented in curvature.h: the boundary is biased but bounded.
  EXPECT_LE(percentile(boundary, 50), 0.25);
  std::printf("hemisphere: interior median |H R - 1| %.4f, boundary median %.4f\n", percentile(interior, 50),
              percentile(boundary, 50));
}

TEST(Curvature, AreasSumToSurfaceArea) {
  const Mesh mesh = read_mesh(test::data_path("camelhead.off"));  // has obtuse triangles
  const Eigen::VectorXd areas = vertex_areas(mesh.V, mesh.F);
  double total = 0;
  for (Index f = 0; f < mesh.num_faces(); ++f) total += face_area(mesh.V, mesh.F, f);
  EXPECT_NEAR(areas.sum(), total, 1e-12 * total);
  EXPECT_GE(areas.minCoeff(), 0.0);
}

TEST(Curvature, NormalsOfASphereAreRadial) {
  const Mesh mesh = test::icosphere(2.0, 3);
  for (const auto weighting : {NormalWeighting::Max1999, NormalWeighting::Area, NormalWeighting::Angle}) {
    const Vertices N = vertex_normals(mesh.V, mesh.F, weighting);
    double worst = 0;
    for (Index v = 0; v < mesh.num_vertices(); ++v) worst = std::max(worst, (N.row(v) - mesh.V.row(v) / 2.0).norm());
    // Max's weighting is exact for vertices on a sphere; the others are close.
    EXPECT_LE(worst, weighting == NormalWeighting::Max1999 ? 1e-12 : 2e-2);
  }
}

TEST(Curvature, DegenerateInputStaysFinite) {
  Mesh mesh;
  mesh.V.resize(5, 3);
  mesh.V << 0, 0, 0, 1, 0, 0, 2, 0, 0, 0, 1, 0, 5, 5, 5;  // a collinear face and an isolated vertex
  mesh.F.resize(2, 3);
  mesh.F << 0, 1, 2, 0, 1, 3;
  const Curvature c = principal_curvatures(mesh.V, mesh.F);
  EXPECT_TRUE(c.k1.allFinite() && c.k2.allFinite() && c.T1.allFinite() && c.T2.allFinite() && c.N.allFinite());
  EXPECT_EQ(c.k1[4], 0.0);
}

class BundledCurvature : public ::testing::TestWithParam<const char*> {};

TEST_P(BundledCurvature, NoNanOrInf) {
  const Mesh mesh = read_mesh(test::data_path(GetParam()));
  const Curvature c = principal_curvatures(mesh.V, mesh.F);
  EXPECT_TRUE(c.k1.allFinite());
  EXPECT_TRUE(c.k2.allFinite());
  EXPECT_TRUE(c.T1.allFinite());
  EXPECT_TRUE(c.T2.allFinite());
  EXPECT_TRUE(c.N.allFinite());
}

INSTANTIATE_TEST_SUITE_P(Data, BundledCurvature,
                         ::testing::Values("bunny.off", "bunny_uniform.off", "bunny_adaptive.off", "amo.off",
                                           "amo_adaptive.off", "fandisk.off", "fandisk_quads.off", "chamfer-cube.off",
                                           "hemisphere.off", "sphere.off", "sphere_low.off", "icosahedron_ascii.stl",
                                           "suzanne.obj", "max-planck-5k.obj", "armadillo-43k.obj", "camelhead.off",
                                           "fertility.off", "torus.obj", "horse-48k.ply", "rocker-arm.obj", "spot.obj"),
                         [](const auto& param_info) { return test::test_name(param_info.param); });

}  // namespace
}  // namespace vertexflow
