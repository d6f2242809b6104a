// Exaggerated shading (exaggerated_shading.h): what tells it from plain shading and from doing
// nothing. A sphere has no detail at any scale, so the detail terms vanish and only the overall
// shape is shaded; a plane with small bumps lit obliquely shows them with far more contrast
// than Lambertian shading does; the shades do not change under rigid motions and scaling of
// mesh and light, follow a renumbering of the vertices, and do not depend on the thread count.
// Renders: grey per-vertex shades, a picture unlike the smooth render; the CLI's --shading.
#include "shapes.h"
#include "test_support.h"

#include "vertexflow/curvature.h"
#include "vertexflow/exaggerated_shading.h"
#include "vertexflow/io.h"
#include "vertexflow/render.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <numeric>
#include <random>

namespace vertexflow {
namespace {

// The grid [-1, 1]^2 of n x n quads lifted to z = amplitude sin(k x) sin(k y), normals up.
Mesh bumpy_plane(int n, double amplitude, double k) {
  Mesh mesh;
  mesh.V.resize((n + 1) * (n + 1), 3);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double x = -1 + 2.0 * i / n, y = -1 + 2.0 * j / n;
      mesh.V.row(j * (n + 1) + i) << x, y, amplitude * std::sin(k * x) * std::sin(k * y);
    }
  mesh.F.resize(2 * n * n, 3);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const Index a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      mesh.F.row(2 * (j * n + i)) << a, b, d;
      mesh.F.row(2 * (j * n + i) + 1) << a, d, c;
    }
  return mesh;
}

// Standard deviation of `values` over the vertices with |x|, |y| <= 0.8 (away from the rim,
// where the one-ring averages are one-sided); two passes, so a constant gives exactly 0.
double interior_spread(const Mesh& mesh, const Eigen::VectorXd& values) {
  std::vector<double> inside;
  for (Index v = 0; v < mesh.num_vertices(); ++v)
    if (std::abs(mesh.V(v, 0)) <= 0.8 && std::abs(mesh.V(v, 1)) <= 0.8) inside.push_back(values[v]);
  const double mean = std::accumulate(inside.begin(), inside.end(), 0.0) / static_cast<double>(inside.size());
  double sum2 = 0;
  for (const double x : inside) sum2 += (x - mean) * (x - mean);
  return std::sqrt(sum2 / static_cast<double>(inside.size()));
}

// Lambertian shading max(0, n . l) of the vertex normals: what the smooth render shows.
Eigen::VectorXd lambertian(const Mesh& mesh, const Eigen::Vector3d& light) {
  return (vertex_normals(mesh.V, mesh.F) * light.normalized()).cwiseMax(0.0);
}

TEST(ExaggeratedShading, SphereHasNoDetailAtAnyScale) {
  const Mesh sphere = test::icosphere(1.0, 4);  // 2562 vertices
  const Eigen::Vector3d light(0.3, 0.5, 0.8);
  // Detail terms only: every one is ~0 on a sphere, so the shade is ~1/2 everywhere.
  ExaggeratedShadingOptions detail;
  detail.weights = {1, 1, 1, 1, 0};
  const Eigen::VectorXd shade = exaggerated_shading(sphere.V, sphere.F, light, detail);
  const double deviation = (shade.array() - 0.5).abs().maxCoeff();
  // Lambertian shading spans [0, 1] on the sphere: not uniform at all.
  const Eigen::VectorXd plain = lambertian(sphere, light);
  // With detail (the same sphere as a noisy scan) the detail terms are far from 0.
  const Mesh noisy = test::noisy_scan(sphere, 0.2, 0.0, 11);
  const double noisy_deviation = (exaggerated_shading(noisy.V, noisy.F, light, detail).array() - 0.5).abs().maxCoeff();
  std::printf("sphere: detail-only shade max |s - 1/2| = %.3g (noisy sphere %.3g, Lambertian range %.3g)\n", deviation,
              noisy_deviation, plain.maxCoeff() - plain.minCoeff());
  // Measured 0.043 (the icosphere's uneven triangles tilt the smoothed normals by ~2 degrees,
  // and a = 10 exaggerates that too), noisy sphere 0.26.
  EXPECT_LT(deviation, 0.1);
  EXPECT_GT(noisy_deviation, 0.13);
  EXPECT_GT(plain.maxCoeff() - plain.minCoeff(), 0.9);

  // Default weights: what remains is the overall-shape term 1/2 + 1/2 k_b clamp(a n . l) with
  // the sphere's exact normals n = p (k_b = 2/6), up to the smoothing's rounding of n.
  const Eigen::VectorXd full = exaggerated_shading(sphere.V, sphere.F, light);
  const double a = ExaggeratedShadingOptions{}.exaggeration;
  double off = 0;
  for (Index v = 0; v < sphere.num_vertices(); ++v) {
    const double expected =
        0.5 + 0.5 * (2.0 / 6.0) * std::clamp(a * sphere.V.row(v).normalized().dot(light.normalized()), -1.0, 1.0);
    off = std::max(off, std::abs(full[v] - expected));
  }
  std::printf("sphere: default shade against the overall-shape term alone: max off %.3g\n", off);
  EXPECT_LT(off, 0.06);  // measured 0.029
}

TEST(ExaggeratedShading, BumpsShowWhateverTheLightsElevation) {
  // 96 x 96 quads, bumps of period 2 pi / k = 0.5 = 24 edge lengths and slope at most 0.1:
  // the coarsest scale (8 edge lengths) smooths them out, the finer ones follow them.
  const Mesh plane = bumpy_plane(96, 0.1 / (4 * std::numbers::pi), 4 * std::numbers::pi);
  // Lambertian contrast falls with the cosine of the light's elevation (the light's component
  // along the surface); exaggerated shading makes the light grazing for every scale, so the
  // bumps keep their contrast when the light is raised.
  std::vector<double> exaggerated, plain;
  for (const double elevation : {20.0, 45.0, 70.0}) {
    const double e = elevation * std::numbers::pi / 180;
    const Eigen::Vector3d light(std::cos(e) * 0.96, std::cos(e) * 0.28, std::sin(e));
    exaggerated.push_back(interior_spread(plane, exaggerated_shading(plane.V, plane.F, light)));
    plain.push_back(interior_spread(plane, lambertian(plane, light)));
    std::printf("bumps, light elevation %g: spread exaggerated %.4f, Lambertian %.4f, ratio %.2f\n", elevation,
                exaggerated.back(), plain.back(), exaggerated.back() / plain.back());
  }
  // Measured: exaggerated 0.0400, 0.0400, 0.0399; Lambertian 0.0456, 0.0344, 0.0167, so
  // ratios 0.88, 1.16, 2.40.
  EXPECT_NEAR(exaggerated[2] / exaggerated[0], 1.0, 0.1);
  EXPECT_LT(plain[2] / plain[0], 0.5);
  EXPECT_GT(exaggerated[2] / plain[2], 1.6);
  // A larger exaggeration a raises the contrast in proportion while no term saturates; plain
  // shading has no such knob. Measured at 45 degrees with a = 30: 0.118, 3.44 x Lambertian.
  ExaggeratedShadingOptions strong;
  strong.exaggeration = 30;
  const double e45 = 45 * std::numbers::pi / 180;
  const Eigen::Vector3d light45(std::cos(e45) * 0.96, std::cos(e45) * 0.28, std::sin(e45));
  const double strong_spread = interior_spread(plane, exaggerated_shading(plane.V, plane.F, light45, strong));
  std::printf("bumps, a = 30, elevation 45: spread %.4f, %.2f x Lambertian\n", strong_spread, strong_spread / plain[1]);
  EXPECT_GT(strong_spread / plain[1], 2.3);

  // Doing nothing (a flat plane) has nothing to show: every detail term is 0.
  const Mesh flat = bumpy_plane(96, 0.0, 1.0);
  const Eigen::VectorXd shade = exaggerated_shading(flat.V, flat.F, Eigen::Vector3d(1, 0.3, 0.6));
  EXPECT_LT(interior_spread(flat, shade), 1e-12);
}

TEST(ExaggeratedShading, NoScalesIsToonShadingOfTheVertexNormals) {
  const Mesh bunny = read_mesh(test::data_path("bunny_adaptive.off"));
  const Eigen::Vector3d light(-1, 2, 0.5);
  ExaggeratedShadingOptions options;
  options.scales = 0;
  options.exaggeration = 3;
  const Eigen::VectorXd shade = exaggerated_shading(bunny.V, bunny.F, light, options);
  const Vertices N = vertex_normals(bunny.V, bunny.F);
  for (Index v = 0; v < bunny.num_vertices(); ++v)
    ASSERT_NEAR(shade[v], 0.5 + 0.5 * std::clamp(3 * N.row(v).dot(light.normalized()), -1.0, 1.0), 1e-15);
}

TEST(ExaggeratedShading, RigidMotionScalingAndRenumberingLeaveTheShades) {
  const Mesh mesh = test::noisy_scan(test::icosphere(1.0, 4), 0.2, 0.2, 7);
  const Eigen::Vector3d light(0.3, 0.5, 0.8);
  const Eigen::VectorXd shade = exaggerated_shading(mesh.V, mesh.F, light);
  ASSERT_EQ(shade.size(), mesh.V.rows());
  EXPECT_GE(shade.minCoeff(), 0.0);
  EXPECT_LE(shade.maxCoeff(), 1.0);

  // Rotated, scaled by 3.7 and translated, the light rotated with it.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  Mesh moved = mesh;
  moved.V = ((3.7 * mesh.V * R.transpose()).rowwise() + Eigen::RowVector3d(5, -2, 11)).eval();
  const Eigen::VectorXd moved_shade = exaggerated_shading(moved.V, moved.F, R * light);
  const double motion = (moved_shade - shade).cwiseAbs().maxCoeff();
  std::printf("rigid motion + scaling: max shade change %.3g\n", motion);
  EXPECT_LT(motion, 1e-9);

  // Vertices renumbered by a random permutation: the shades are renumbered with them.
  std::vector<Index> order(static_cast<std::size_t>(mesh.num_vertices()));
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937(3));  // new vertex i is old order[i]
  std::vector<Index> new_index(order.size());
  for (std::size_t i = 0; i < order.size(); ++i) new_index[static_cast<std::size_t>(order[i])] = static_cast<Index>(i);
  Mesh renumbered = mesh;
  for (Index v = 0; v < mesh.num_vertices(); ++v) renumbered.V.row(v) = mesh.V.row(order[static_cast<std::size_t>(v)]);
  for (Index f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) renumbered.F(f, k) = new_index[static_cast<std::size_t>(mesh.F(f, k))];
  const Eigen::VectorXd renumbered_shade = exaggerated_shading(renumbered.V, renumbered.F, light);
  double permutation = 0;
  for (Index v = 0; v < mesh.num_vertices(); ++v)
    permutation = std::max(permutation, std::abs(renumbered_shade[v] - shade[order[static_cast<std::size_t>(v)]]));
  std::printf("renumbering: max shade change %.3g\n", permutation);
  EXPECT_LT(permutation, 1e-9);
}

TEST(ExaggeratedShading, SameShadesForAnyThreadCount) {
  const Mesh bunny = read_mesh(test::data_path("bunny.off"));
  const Eigen::Vector3d light(-1, 1, 1);
  const Eigen::VectorXd one = test::with_threads(1, [&] { return exaggerated_shading(bunny.V, bunny.F, light); });
  const Eigen::VectorXd two = test::with_threads(2, [&] { return exaggerated_shading(bunny.V, bunny.F, light); });
  const Eigen::VectorXd four = test::with_threads(4, [&] { return exaggerated_shading(bunny.V, bunny.F, light); });
  ASSERT_EQ(one.size(), bunny.V.rows());
  EXPECT_TRUE(one == two);
  EXPECT_TRUE(one == four);
}

TEST(ExaggeratedShading, RejectsBadOptions) {
  const Mesh sphere = test::icosphere(1.0, 1);
  const Eigen::Vector3d light(0, 0, 1);
  EXPECT_THROW(exaggerated_shading(sphere.V, sphere.F, Eigen::Vector3d::Zero()), std::invalid_argument);
  EXPECT_THROW(exaggerated_shading(sphere.V, sphere.F, Eigen::Vector3d(NAN, 0, 1)), std::invalid_argument);
  const auto throws = [&](auto change) {
    ExaggeratedShadingOptions options;
    change(options);
    EXPECT_THROW(exaggerated_shading(sphere.V, sphere.F, light, options), std::invalid_argument);
  };
  throws([](ExaggeratedShadingOptions& o) { o.scales = -1; });
  throws([](ExaggeratedShadingOptions& o) { o.scales = 9; });
  throws([](ExaggeratedShadingOptions& o) { o.sigma = 0; });
  throws([](ExaggeratedShadingOptions& o) { o.exaggeration = -1; });
  throws([](ExaggeratedShadingOptions& o) { o.weights = {1, 1}; });
  throws([](ExaggeratedShadingOptions& o) { o.weights = {1, 1, 1, 1, -1}; });
  throws([](ExaggeratedShadingOptions& o) { o.weights = {0, 0, 0, 0, 0}; });
  Faces bad = sphere.F;
  bad(0, 0) = 1000;
  EXPECT_THROW(exaggerated_shading(sphere.V, bad, light), std::invalid_argument);
  EXPECT_EQ(exaggerated_shading(Vertices(0, 3), Faces(0, 3), light).size(), 0);
}

// ---- Rendering -----------------------------------------------------------------------------

RenderOptions small_render(RenderShading shading) {
  RenderOptions o;
  o.width = 320;
  o.height = 240;
  o.view = RenderView::Front;
  o.shading = shading;
  return o;
}

TEST(ExaggeratedShadingRender, GreyShadesUnlikeTheSmoothRender) {
  const Mesh bunny = read_mesh(test::data_path("bunny_adaptive.off"));
  const Image smooth = render_mesh(bunny, small_render(RenderShading::Smooth));
  const Image exaggerated = render_mesh(bunny, small_render(RenderShading::Exaggerated));
  long foreground = 0, grey = 0, differing = 0;
  double sum = 0, sum2 = 0;
  for (int y = 0; y < exaggerated.height; ++y)
    for (int x = 0; x < exaggerated.width; ++x) {
      const std::uint8_t* p = exaggerated.pixel(x, y);
      const std::uint8_t* q = smooth.pixel(x, y);
      const bool background = p[0] == 255 && p[1] == 255 && p[2] == 255;
      const bool smooth_background = q[0] == 255 && q[1] == 255 && q[2] == 255;
      if (background && smooth_background) continue;
      differing += std::abs(p[0] - q[0]) > 8;
      if (background) continue;
      ++foreground;
      grey += p[0] == p[1] && p[1] == p[2];
      sum += p[0], sum2 += double(p[0]) * p[0];
    }
  const double mean = sum / foreground, spread = std::sqrt(sum2 / foreground - mean * mean);
  std::printf("bunny render: %ld foreground pixels, %ld grey, %ld differ from smooth by > 8, grey mean %.1f sd %.1f\n",
              foreground, grey, differing, mean, spread);
  EXPECT_GT(foreground, 0.1 * exaggerated.width * exaggerated.height);  // not blank
  EXPECT_EQ(grey, foreground);                                          // lighting off, colour none: greys
  EXPECT_GT(differing, foreground / 2);                                 // measured 86%
  EXPECT_GT(spread, 30);                                                // measured 42.3 (of 255)

  // With a colour map its colours are scaled by the shades: coloured, not grey.
  RenderOptions colored = small_render(RenderShading::Exaggerated);
  colored.color = RenderColor::Mean;
  colored.color_bar = false;
  const Image tinted_image = render_mesh(bunny, colored);
  long tinted = 0;
  for (int y = 0; y < tinted_image.height; ++y)
    for (int x = 0; x < tinted_image.width; ++x)
      tinted += std::abs(tinted_image.pixel(x, y)[0] - tinted_image.pixel(x, y)[2]) > 20;
  std::printf("mean curvature colours under exaggerated shading: %ld tinted pixels\n", tinted);
  EXPECT_GT(tinted, foreground / 10);  // measured 35%
}

TEST(ExaggeratedShadingCli, ShadingOptionAndAliases) {
  test::ScratchDir dir("render_cli_exaggerated");
  const std::string in = test::quoted_data_path("bunny_adaptive.off");
  const auto run = [&](const std::string& out, const std::string& args) {
    return test::run_cli("render " + in + " " + test::shell_quote(dir.file(out).string()) + " --size 200x150 " + args);
  };
  ASSERT_EQ(run("x.png", "--shading exaggerated --exaggeration 6 --scales 3 --sigma 1.5 --light 0,1,1").exit_code, 0);
  ASSERT_EQ(run("flat.png", "--flat").exit_code, 0);
  ASSERT_EQ(run("flat2.png", "--shading flat").exit_code, 0);
  ASSERT_EQ(run("smooth.png", "--smooth").exit_code, 0);
  ASSERT_EQ(run("smooth2.png", "--shading smooth").exit_code, 0);
  EXPECT_EQ(test::read_text(dir.file("flat.png")), test::read_text(dir.file("flat2.png")));
  EXPECT_EQ(test::read_text(dir.file("smooth.png")), test::read_text(dir.file("smooth2.png")));
  EXPECT_NE(test::read_text(dir.file("x.png")), test::read_text(dir.file("smooth.png")));
  EXPECT_NE(test::read_text(dir.file("flat.png")), test::read_text(dir.file("smooth.png")));
  // Conflicting or bad options: an error and no file.
  EXPECT_NE(run("bad1.png", "--shading exaggerated --flat").exit_code, 0);
  EXPECT_NE(run("bad2.png", "--shading glossy").exit_code, 0);
  EXPECT_NE(run("bad3.png", "--shading exaggerated --weights 1,2").exit_code, 0);
  for (const char* bad : {"bad1.png", "bad2.png", "bad3.png"}) EXPECT_FALSE(std::filesystem::exists(dir.file(bad)));
  // Exaggerated-shading options without the mode: a warning, the smooth picture.
  const test::CommandResult r = run("warned.png", "--exaggeration 4");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.err.find("only used with --shading exaggerated"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace vertexflow
