// Off-screen rendering: the camera against analytic projections of a sphere (area, centre,
// shifts by a known translation in every view), colour maps by their hue, the colour bar by its
// end colours, the wireframe by its exact line colour (hidden edges stay hidden), flat shading
// by its number of distinct shades, the checker texture by its squares and greys, determinism,
// and the PNG read back with libpng.
#include "shapes.h"
#include "test_support.h"

#include "vertexflow/io.h"
#include "vertexflow/render.h"
#include "vertexflow/topology.h"

#include <gtest/gtest.h>
#include <png.h>

#include <cmath>
#include <numbers>
#include <set>

namespace vertexflow {
namespace {

// A PNG decoded by libpng's simplified API into 8-bit RGBA.
Image read_png(const std::filesystem::path& path) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, path.c_str())) throw std::runtime_error(png.message);
  png.format = PNG_FORMAT_RGBA;
  Image image;
  image.width = static_cast<int>(png.width);
  image.height = static_cast<int>(png.height);
  image.pixels.resize(PNG_IMAGE_SIZE(png));
  if (!png_image_finish_read(&png, nullptr, image.pixels.data(), 0, nullptr)) throw std::runtime_error(png.message);
  return image;
}

bool is_background(const std::uint8_t* p) {
  return p[0] == 255 && p[1] == 255 && p[2] == 255;
}

// Pixels that are not the (white) background, and their centroid.
struct Footprint {
  long count = 0;
  double x = 0, y = 0;
};

Footprint footprint(const Image& image) {
  Footprint f;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      if (!is_background(image.pixel(x, y))) {
        ++f.count;
        f.x += x + 0.5;
        f.y += y + 0.5;
      }
  if (f.count) f.x /= f.count, f.y /= f.count;
  return f;
}

long count_color(const Image& image, std::array<std::uint8_t, 3> rgb, int x0 = 0) {
  long n = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = x0; x < image.width; ++x) {
      const std::uint8_t* p = image.pixel(x, y);
      n += p[0] == rgb[0] && p[1] == rgb[1] && p[2] == rgb[2];
    }
  return n;
}

// Mean colour of the non-background pixels left of the legend strip.
Eigen::Vector3d mean_foreground_color(const Image& image) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  long n = 0;
  const int strip = static_cast<int>(image.width * (1 - kLegendWidthFraction));
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < strip; ++x)
      if (const std::uint8_t* p = image.pixel(x, y); !is_background(p)) {
        sum += Eigen::Vector3d(p[0], p[1], p[2]);
        ++n;
      }
  return n ? Eigen::Vector3d(sum / n) : sum;
}

RenderOptions small(RenderView view = RenderView::Front) {
  RenderOptions o;
  o.width = 320;
  o.height = 240;
  o.view = view;
  return o;
}

Mesh translated(Mesh mesh, const Eigen::Vector3d& t) {
  mesh.V.rowwise() += t.transpose();
  return mesh;
}

// Pixels per unit length when the frame `box` is seen with `right` and `up` as image axes
// (front, side and top views, where they are coordinate axes): the box's projection fills 92%
// of the 320x240 image minus the legend strip in its limiting direction.
double pixels_per_unit(const BoundingBox& box, int right, int up) {
  const Eigen::Vector3d extent = box.max - box.min;
  return 0.92 * std::min(320 * (1 - kLegendWidthFraction) / extent[right], 240 / extent[up]);
}

TEST(Render, SphereProjectsToTheFittedDisk) {
  // Without anti-aliasing, so that every covered pixel is fully the sphere's.
  const Mesh sphere = test::icosphere(1.0, 4);
  const BoundingBox box = bounding_box(sphere.V);
  struct Case {
    RenderView view;
    int right, up;  // axes along the image's x and y
  };
  for (const Case& c : {Case{RenderView::Front, 0, 1}, Case{RenderView::Side, 2, 1}, Case{RenderView::Top, 0, 2},
                        Case{RenderView::Iso, -1, -1}}) {
    RenderOptions options = small(c.view);
    options.samples = 1;
    const Image image = render_mesh(sphere, options);
    ASSERT_EQ(image.width, 320);
    ASSERT_EQ(image.height, 240);
    const Footprint f = footprint(image);
    EXPECT_NEAR(f.x, 320 * (1 - kLegendWidthFraction) / 2, 0.5);
    EXPECT_NEAR(f.y, 120, 0.5);
    if (c.right < 0) continue;  // iso: the box's projection is a hexagon; centre only
    const double radius = pixels_per_unit(box, c.right, c.up);
    EXPECT_NEAR(f.count, std::numbers::pi * radius * radius, 0.02 * std::numbers::pi * radius * radius);
  }
}

TEST(Render, SharedFrameShowsATranslationInEveryView) {
  // Camera frame fixed to twice the untranslated sphere's box (so the moved copy stays in the
  // picture); the translated copy must move by translation * pixels-per-unit in the direction
  // each view puts that axis.
  const Mesh sphere = test::icosphere(1.0, 3);
  const BoundingBox box{2 * bounding_box(sphere.V).min, 2 * bounding_box(sphere.V).max};
  struct Case {
    RenderView view;
    Eigen::Vector3d translation;
    double dx, dy;  // expected shift in pixels per unit of translation (y down)
    int right, up;
  };
  const Case cases[] = {
      {RenderView::Front, {0.3, 0, 0}, 1, 0, 0, 1},   // +x to the right
      {RenderView::Front, {0, 0.3, 0}, 0, -1, 0, 1},  // +y up
      {RenderView::Side, {0, 0, -0.3}, 1, 0, 2, 1},   // seen from +x, -z is to the right
      {RenderView::Top, {0, 0, -0.3}, 0, -1, 0, 2},   // seen from +y, -z is up
  };
  for (const Case& c : cases) {
    RenderOptions options = small(c.view);
    options.frame = box;
    const Footprint before = footprint(render_mesh(sphere, options));
    const Footprint after = footprint(render_mesh(translated(sphere, c.translation), options));
    const double amount = c.translation.norm() * pixels_per_unit(box, c.right, c.up);
    EXPECT_NEAR(after.x - before.x, c.dx * amount, 0.5);
    EXPECT_NEAR(after.y - before.y, c.dy * amount, 0.5);
  }
}

TEST(Render, FrameFromTheMeshItselfIsTheDefault) {
  const Mesh bunny = read_mesh(test::data_path("bunny_adaptive.off"));
  RenderOptions options = small(RenderView::Iso);
  options.wireframe = true;
  RenderInfo info;
  const Image a = render_mesh(bunny, options, &info);
  EXPECT_EQ(info.frame.min, bounding_box(bunny.V).min);
  EXPECT_EQ(info.frame.max, bounding_box(bunny.V).max);
  options.frame = bounding_box(bunny.V);
  EXPECT_EQ(render_mesh(bunny, options).pixels, a.pixels);
}

TEST(Render, SameInputGivesByteIdenticalPng) {
  const Mesh bunny = read_mesh(test::data_path("bunny_adaptive.off"));
  RenderOptions options = small(RenderView::Iso);
  options.color = RenderColor::Mean;
  options.wireframe = true;
  const std::string first = encode_png(render_mesh(bunny, options));
  const std::string second = encode_png(render_mesh(bunny, options));
  EXPECT_EQ(first, second);
  // A real PNG: the signature, then libpng reads back exactly the rendered pixels.
  ASSERT_GT(first.size(), 8u);
  EXPECT_EQ(first.substr(1, 3), "PNG");
  test::ScratchDir dir("render_png");
  const Image image = render_mesh(bunny, options);
  write_png(dir.file("bunny.png"), image);
  const Image back = read_png(dir.file("bunny.png"));
  EXPECT_EQ(back.width, image.width);
  EXPECT_EQ(back.height, image.height);
  EXPECT_EQ(back.pixels, image.pixels);
  const double foreground = static_cast<double>(footprint(back).count) / (back.width * back.height);
  EXPECT_GT(foreground, 0.10);
  EXPECT_LT(foreground, 0.60);
}

TEST(Render, WireframeDrawsVisibleEdgesOnly) {
  // Without anti-aliasing a line pixel has exactly the wire colour, which lighting never
  // produces (its ambient floor is brighter). A closed sphere must show about as many wire
  // pixels as its front half alone: edges behind the surface stay hidden. The view is oblique
  // because the icosphere is mirror-symmetric in the coordinate planes: seen along an axis
  // its back edges would project exactly onto its front edges.
  const Mesh sphere = test::icosphere(1.0, 3);
  RenderOptions options = small(RenderView::Custom);
  options.azimuth_degrees = 20;
  options.elevation_degrees = 15;
  const double a = 20 * std::numbers::pi / 180, e = 15 * std::numbers::pi / 180;
  const Eigen::Vector3d towards_camera(std::cos(e) * std::sin(a), std::sin(e), std::cos(e) * std::cos(a));
  Mesh front = sphere;
  std::vector<Index> kept;
  for (Index f = 0; f < sphere.num_faces(); ++f) {
    bool visible = true;
    for (int k = 0; k < 3; ++k) visible = visible && sphere.V.row(sphere.F(f, k)).dot(towards_camera) > 0;
    if (visible) kept.push_back(f);
  }
  front.F.resize(static_cast<Eigen::Index>(kept.size()), 3);
  for (std::size_t i = 0; i < kept.size(); ++i) front.F.row(static_cast<Index>(i)) = sphere.F.row(kept[i]);

  options.samples = 1;
  options.frame = bounding_box(sphere.V);
  const std::array<std::uint8_t, 3> wire{25, 25, 30};
  EXPECT_EQ(count_color(render_mesh(sphere, options), wire), 0);
  options.wireframe = true;
  const long full = count_color(render_mesh(sphere, options), wire);
  const long half = count_color(render_mesh(front, options), wire);
  EXPECT_LT(std::abs(full - half), 0.1 * half);

  // A one-pixel line covers about max(|dx|, |dy|) pixels: the front half's edges, projected
  // with the documented camera, predict the count. Lines lost in the surface (no polygon
  // offset) or drawn over it would miss this.
  const Eigen::Vector3d up = (Eigen::Vector3d::UnitY() - towards_camera.y() * towards_camera).normalized();
  const Eigen::Vector3d right = up.cross(towards_camera);
  const BoundingBox box = *options.frame;
  const Eigen::Vector3d centre = 0.5 * (box.min + box.max);
  double half_x = 0, half_y = 0;
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3d p((c & 1 ? box.max : box.min).x(), (c & 2 ? box.max : box.min).y(),
                            (c & 4 ? box.max : box.min).z());
    half_x = std::max(half_x, std::abs((p - centre).dot(right)));
    half_y = std::max(half_y, std::abs((p - centre).dot(up)));
  }
  const double scale = 0.92 * std::min(320 * (1 - kLegendWidthFraction) / (2 * half_x), 240 / (2 * half_y));
  double predicted = 0;
  const Topology topology = build_topology(front.F, front.num_vertices());
  for (Index edge = 0; edge < topology.num_edges(); ++edge) {
    const Eigen::Vector3d d = front.V.row(topology.edges(edge, 1)) - front.V.row(topology.edges(edge, 0));
    predicted += scale * std::max(std::abs(d.dot(right)), std::abs(d.dot(up)));
  }
  EXPECT_GT(half, 0.8 * predicted);
  EXPECT_LT(half, 1.05 * predicted);
  std::printf("wire pixels: closed sphere %ld, front half %ld, predicted %.0f\n", full, half, predicted);
}

TEST(Render, FlatShadingShowsOneShadePerFace) {
  const Mesh sphere = test::icosphere(1.0, 1);  // 80 faces
  RenderOptions options = small(RenderView::Iso);
  options.samples = 1;
  const auto shades = [&](RenderShading shading) {
    options.shading = shading;
    const Image image = render_mesh(sphere, options);
    std::set<std::array<std::uint8_t, 3>> colors;
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x)
        if (const std::uint8_t* p = image.pixel(x, y); !is_background(p)) colors.insert({p[0], p[1], p[2]});
    return colors.size();
  };
  const std::size_t flat = shades(RenderShading::Flat), smooth = shades(RenderShading::Smooth);
  EXPECT_LE(flat, 80u);
  EXPECT_GT(smooth, 3 * flat);
}

TEST(Render, ColorBarShowsTheMapsEndColours) {
  // Gaussian curvature of a torus is positive outside and negative inside: a diverging bar
  // from blue (bottom) to red (top) in the legend strip, absent without colouring.
  const Mesh torus = test::torus(3.0, 1.0, 60, 20);
  RenderOptions options = small(RenderView::Iso);
  const int strip = static_cast<int>(320 * (1 - kLegendWidthFraction));
  const std::array<std::uint8_t, 3> red{180, 4, 38}, blue{59, 76, 192};
  const Image plain = render_mesh(torus, options);
  EXPECT_EQ(count_color(plain, red, strip) + count_color(plain, blue, strip), 0);
  options.color = RenderColor::Gauss;
  RenderInfo info;
  const Image colored = render_mesh(torus, options, &info);
  // The bar's end rows carry exactly the end colours, red at the top, blue at the bottom.
  // Rows of the legend strip with at least 4 pixels of exactly `rgb` (the bar is >= 4 wide).
  const auto rows_of = [&](const Image& image, const std::array<std::uint8_t, 3>& rgb) {
    std::vector<int> rows;
    for (int y = 0; y < image.height; ++y) {
      long n = 0;
      for (int x = strip; x < image.width; ++x) {
        const std::uint8_t* p = image.pixel(x, y);
        n += p[0] == rgb[0] && p[1] == rgb[1] && p[2] == rgb[2];
      }
      if (n >= 4) rows.push_back(y);
    }
    return rows;
  };
  const std::vector<int> red_rows = rows_of(colored, red), blue_rows = rows_of(colored, blue);
  ASSERT_FALSE(red_rows.empty());
  ASSERT_FALSE(blue_rows.empty());
  EXPECT_LT(red_rows.back(), blue_rows.front());
  EXPECT_EQ(info.color_quantity, "Gaussian curvature");
  EXPECT_LT(info.color_min, 0);
  EXPECT_DOUBLE_EQ(info.color_max, -info.color_min);
  // Labels are drawn in dark ink above and below the bar.
  long ink = 0;
  for (int y = 0; y < 240 / 4 - 2; ++y)
    for (int x = strip; x < 320; ++x) ink += colored.pixel(x, y)[0] < 100;
  EXPECT_GT(ink, 10);
  options.color_bar = false;
  const Image no_bar = render_mesh(torus, options);
  EXPECT_EQ(count_color(no_bar, red, strip) + count_color(no_bar, blue, strip), 0);
}

TEST(Render, ColorMapsColourByTheirQuantity) {
  // Mean curvature of a sphere is +1/R everywhere: all red; with the faces turned inside out
  // it is -1/R: all blue. A saddle z = (x^2 - y^2)/2 has K < 0 everywhere: bluish, from
  // saturated at the centre to light at the corners. Red and blue are told apart by which
  // channel dominates.
  RenderOptions options = small(RenderView::Iso);
  options.color = RenderColor::Mean;
  const Mesh sphere = test::icosphere(1.0, 3);
  const Eigen::Vector3d outward = mean_foreground_color(render_mesh(sphere, options));
  EXPECT_GT(outward[0], 2 * outward[1]);
  EXPECT_GT(outward[0], 2 * outward[2]);
  Mesh inward = sphere;
  inward.F.col(1).swap(inward.F.col(2));
  const Eigen::Vector3d inverted = mean_foreground_color(render_mesh(inward, options));
  EXPECT_GT(inverted[2], 2 * inverted[0]);
  options.color = RenderColor::Gauss;
  const Eigen::Vector3d saddle_gauss = mean_foreground_color(render_mesh(test::saddle(1.0, 30), options));
  EXPECT_GT(saddle_gauss[2], saddle_gauss[0] + 20);

  // Quality: near-equilateral triangles are white, triangles stretched 20:1 red.
  options.color = RenderColor::Quality;
  RenderInfo info;
  const Eigen::Vector3d good = mean_foreground_color(render_mesh(test::saddle(1.0, 20), options, &info));
  EXPECT_EQ(info.color_min, 0);
  EXPECT_EQ(info.color_max, 1);
  Mesh stretched = test::saddle(1.0, 20);
  stretched.V.col(0) *= 20;
  const Eigen::Vector3d bad = mean_foreground_color(render_mesh(stretched, options));
  EXPECT_LT(std::abs(good[0] - good[2]), 40);
  EXPECT_GT(bad[0], 2 * bad[2]);
}

TEST(Render, DisplacementColoursMovedVerticesRed) {
  // The right half (x > 0) is pushed out along +z by 0.1, the left half stays: right red,
  // left white-grey.
  const Mesh before = test::saddle(1.0, 30);
  Mesh after = before;
  for (Index v = 0; v < after.num_vertices(); ++v)
    if (after.V(v, 0) > 0) after.V(v, 2) += 0.1;
  RenderOptions options = small(RenderView::Front);
  options.color = RenderColor::Displacement;
  options.displacement_reference = before.V;
  RenderInfo info;
  const Image image = render_mesh(after, options, &info);
  EXPECT_EQ(info.color_min, 0);
  EXPECT_NEAR(info.color_max, 0.1, 1e-12);
  const auto redness = [&](int x0, int x1) {
    double sum = 0;
    long n = 0;
    for (int y = 0; y < image.height; ++y)
      for (int x = x0; x < x1; ++x)
        if (const std::uint8_t* p = image.pixel(x, y); !is_background(p)) sum += p[0] - p[2], ++n;
    return sum / std::max(n, 1L);
  };
  const int centre = static_cast<int>(320 * (1 - kLegendWidthFraction) / 2);
  const double full_red = redness(centre + 10, centre + 80);
  EXPECT_GT(full_red, 60);
  EXPECT_LT(std::abs(redness(centre - 80, centre - 10)), 15);

  // A fixed limit twice the displacement: the moved half is only half-way to red.
  options.color_limit = 0.2;
  const Image fixed = render_mesh(after, options, &info);
  EXPECT_EQ(info.color_max, 0.2);
  const auto half_red = [&](int x0, int x1) {
    double sum = 0;
    long n = 0;
    for (int y = 0; y < fixed.height; ++y)
      for (int x = x0; x < x1; ++x)
        if (const std::uint8_t* p = fixed.pixel(x, y); !is_background(p)) sum += p[0] - p[2], ++n;
    return sum / std::max(n, 1L);
  }(centre + 10, centre + 80);
  EXPECT_GT(half_red, 0.3 * full_red);
  EXPECT_LT(half_red, 0.7 * full_red);
  options.color_limit = 0.0;
  EXPECT_THROW(render_mesh(after, options), std::invalid_argument);
  options.color_limit.reset();

  options.displacement_reference = before.V.topRows(10);
  EXPECT_THROW(render_mesh(after, options), std::invalid_argument);
}

TEST(Render, RejectsBadOptions) {
  const Mesh sphere = test::icosphere(1.0, 1);
  RenderOptions options = small();
  options.width = 8;
  EXPECT_THROW(render_mesh(sphere, options), std::invalid_argument);
  options = small();
  options.frame = BoundingBox{Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 1)};
  EXPECT_THROW(render_mesh(sphere, options), std::invalid_argument);
  options = small();
  options.color = RenderColor::Mean;
  options.font_path = "/nonexistent/font.ttf";
  EXPECT_THROW(render_mesh(sphere, options), std::runtime_error);
  options.color_bar = false;
  EXPECT_NO_THROW(render_mesh(sphere, options));
}

// ---- Checker texture -----------------------------------------------------------------------

// The unit square [-0.5, 0.5]^2 in z = 0 (facing the front view's camera), n x n quads, with
// texture coordinates (x + 0.5, y + 0.5) as a vertex channel or, equally, a corner channel.
Mesh uv_square(int n, bool per_corner) {
  Mesh square = test::height_field(0.5, n, [](double, double) { return 0.0; });
  AttributeChannel uv;
  uv.name = "uv";
  uv.components = {"u", "v"};
  uv.role = AttributeRole::TexCoord;
  uv.values.resize(square.V.rows(), 2);
  for (Index v = 0; v < square.V.rows(); ++v) uv.values.row(v) << square.V(v, 0) + 0.5, square.V(v, 1) + 0.5;
  if (!per_corner) {
    square.attributes.vertex.push_back(std::move(uv));
    return square;
  }
  CornerChannel corners;
  corners.channel = std::move(uv);
  corners.corners = square.F;  // one table row per vertex: the same coordinates per corner
  square.attributes.corner.push_back(std::move(corners));
  return square;
}

double luminance(const std::uint8_t* p) {
  return (p[0] + p[1] + p[2]) / 3.0;
}

// Dark and light runs of the foreground along image row y (threshold halfway between the row's
// darkest and lightest foreground pixel), and the mean of the darkest and of the lightest.
struct Runs {
  int count = 0;
  double dark = 0, light = 0;
};

Runs checker_runs(const Image& image, int y) {
  double lo = 255, hi = 0;
  for (int x = 0; x < image.width; ++x)
    if (!is_background(image.pixel(x, y)))
      lo = std::min(lo, luminance(image.pixel(x, y))), hi = std::max(hi, luminance(image.pixel(x, y)));
  Runs r;
  r.dark = lo, r.light = hi;
  int previous = -1;  // 0 dark, 1 light, -1 background
  for (int x = 0; x < image.width; ++x) {
    const std::uint8_t* p = image.pixel(x, y);
    const int now = is_background(p) ? -1 : luminance(p) > 0.5 * (lo + hi);
    if (now >= 0 && now != previous) ++r.count;
    previous = now;
  }
  return r;
}

TEST(RenderChecker, SquaresAlongARowAndTheirTwoGreys) {
  const Mesh square = uv_square(8, false);
  RenderOptions options = small(RenderView::Front);
  options.samples = 1;
  options.texture = RenderTexture::Checker;
  options.checker_squares = 4;
  RenderInfo info;
  const Image image = render_mesh(square, options, &info);
  // Rows through the middle of the second and third rows of squares (v = 0.375 and 0.625),
  // and a square's column: 4 squares each way, alternating.
  for (const double v : {0.375, 0.625}) {
    const int y = static_cast<int>(info.camera.project(Eigen::Vector3d(0, v - 0.5, 0)).y());
    const Runs runs = checker_runs(image, y);
    EXPECT_EQ(runs.count, 4) << "row " << y;
    // Lit colour times 0.35 and 0.9: flat square, one lit colour, so the greys' ratio.
    EXPECT_NEAR(runs.dark / runs.light, 0.35 / 0.9, 0.02) << runs.dark << " " << runs.light;
  }
  // 16 squares per unit: 16 runs.
  options.checker_squares = 16;
  const Image fine = render_mesh(square, options, &info);
  const int y = static_cast<int>(info.camera.project(Eigen::Vector3d(0, 0.5 / 16 - 0.5 + 1.0 / 16, 0)).y());
  EXPECT_EQ(checker_runs(fine, y).count, 16);
  // The untextured square is one uniform colour.
  options.texture = RenderTexture::None;
  EXPECT_EQ(checker_runs(render_mesh(square, options), y).count, 1);
}

TEST(RenderChecker, CornerAndVertexCoordinatesGiveTheSamePicture) {
  RenderOptions options = small(RenderView::Iso);
  options.texture = RenderTexture::Checker;
  options.checker_squares = 5;
  EXPECT_EQ(render_mesh(uv_square(6, true), options).pixels, render_mesh(uv_square(6, false), options).pixels);
  // Corners without coordinates (-1) draw; a corner past its table is an error.
  Mesh partial = uv_square(6, true);
  partial.attributes.corner[0].corners.row(0).setConstant(-1);
  EXPECT_NO_THROW(render_mesh(partial, options));
  partial.attributes.corner[0].corners(0, 0) = 1000;
  EXPECT_THROW(render_mesh(partial, options), std::invalid_argument);
}

// Per pixel checker / plain: the texel, 0.35 or 0.9 (the lit colour is the same in both).
struct TexelRatios {
  double near_dark = 0, near_light = 0;  // fractions of the lit foreground
};

TexelRatios texel_ratios(const Image& plain, const Image& checker) {
  long dark = 0, light = 0, n = 0;
  for (int y = 0; y < plain.height; ++y)
    for (int x = 0; x < plain.width; ++x) {
      const std::uint8_t *p = plain.pixel(x, y), *c = checker.pixel(x, y);
      if (is_background(p) || luminance(p) < 60) continue;
      const double ratio = luminance(c) / luminance(p);
      ++n;
      dark += std::abs(ratio - 0.35) < 0.04;
      light += std::abs(ratio - 0.9) < 0.04;
    }
  return {double(dark) / std::max(1L, n), double(light) / std::max(1L, n)};
}

TEST(RenderChecker, ModulatesEveryShadingAndColour) {
  const Mesh spot = read_mesh(test::data_path("spot.obj"));
  ASSERT_FALSE(spot.attributes.corner.empty());
  RenderOptions options = small(RenderView::Front);
  options.width = 640;
  options.height = 480;
  options.samples = 1;
  options.checker_squares = 8;
  for (const RenderShading shading : {RenderShading::Smooth, RenderShading::Flat, RenderShading::Exaggerated})
    for (const RenderColor color : {RenderColor::None, RenderColor::Mean, RenderColor::Quality}) {
      options.shading = shading;
      options.color = color;
      options.texture = RenderTexture::None;
      const Image plain = render_mesh(spot, options);
      options.texture = RenderTexture::Checker;
      const Image checker = render_mesh(spot, options);
      ASSERT_NE(plain.pixels, checker.pixels);
      // The same coverage (a white highlight of the plain render counts as background there).
      EXPECT_NEAR(footprint(checker).count, footprint(plain).count, 0.01 * footprint(plain).count);
      const TexelRatios r = texel_ratios(plain, checker);
      EXPECT_GT(r.near_dark, 0.3) << static_cast<int>(shading) << " " << static_cast<int>(color);
      EXPECT_GT(r.near_light, 0.3) << static_cast<int>(shading) << " " << static_cast<int>(color);
      EXPECT_GT(r.near_dark + r.near_light, 0.85) << static_cast<int>(shading) << " " << static_cast<int>(color);
      // Deterministic: the same bytes again.
      EXPECT_EQ(encode_png(render_mesh(spot, options)), encode_png(checker));
    }
}

TEST(RenderChecker, NeedsTextureCoordinatesAndASquareCountInRange) {
  const Mesh sphere = test::icosphere(1.0, 2);
  RenderOptions options = small();
  options.texture = RenderTexture::Checker;
  try {
    render_mesh(sphere, options);
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "render: --texture checker needs texture coordinates");
  }
  // A vertex channel of another role is not texture coordinates.
  Mesh labelled = sphere;
  labelled.set_vertex_property("u", Eigen::VectorXd::Zero(sphere.V.rows()));
  EXPECT_THROW(render_mesh(labelled, options), std::invalid_argument);
  const Mesh square = uv_square(2, false);
  for (const int squares : {0, 257, -3}) {
    options.checker_squares = squares;
    EXPECT_THROW(render_mesh(square, options), std::invalid_argument) << squares;
  }
  options.checker_squares = 256;
  EXPECT_NO_THROW(render_mesh(square, options));
  options.checker_squares = 1;
  EXPECT_NO_THROW(render_mesh(square, options));
}

// ---- CLI -----------------------------------------------------------------------------------

TEST(RenderCli, WritesAPngAndPrintsTheRange) {
  test::ScratchDir dir("render_cli");
  const std::string in = test::data_path("bunny_adaptive.off").string();
  const std::string out = dir.file("bunny.png").string();
  const test::CommandResult r = test::run_cli("render " + test::shell_quote(in) + " " + test::shell_quote(out) +
                                              " --wireframe --color mean --size 320x240 --flat");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("colour range (mean curvature): [-"), std::string::npos) << r.out;
  const Image image = read_png(out);
  EXPECT_EQ(image.width, 320);
  EXPECT_EQ(image.height, 240);

  // Same command again: byte-identical file. --frame-from the input itself: same picture.
  const std::string again = dir.file("again.png").string(), framed = dir.file("framed.png").string();
  ASSERT_EQ(test::run_cli("render " + test::shell_quote(in) + " " + test::shell_quote(again) +
                          " --wireframe --color mean --size 320x240 --flat")
                .exit_code,
            0);
  EXPECT_EQ(test::read_text(again), test::read_text(out));
  ASSERT_EQ(test::run_cli("render " + test::shell_quote(in) + " " + test::shell_quote(framed) +
                          " --wireframe --color mean --size 320x240 --flat --frame-from " + test::shell_quote(in))
                .exit_code,
            0);
  EXPECT_EQ(test::read_text(framed), test::read_text(out));

  // llvmpipe on one rasteriser thread (instead of one per core): the same bytes.
  const std::string one_thread = dir.file("one_thread.png").string();
  ASSERT_EQ(
      test::run_command("LP_NUM_THREADS=1 " + test::shell_quote(VERTEXFLOW_CLI) + " render " + test::shell_quote(in) +
                        " " + test::shell_quote(one_thread) + " --wireframe --color mean --size 320x240 --flat")
          .exit_code,
      0);
  EXPECT_EQ(test::read_text(one_thread), test::read_text(out));
}

TEST(RenderCli, DisplacementAgainstTheMeshBefore) {
  test::ScratchDir dir("render_cli_disp");
  const std::string before = test::data_path("bunny_adaptive.off").string();
  Mesh moved = read_mesh(before);
  moved.V.col(1) *= 1.1;
  const std::string after = dir.file("after.ply").string();
  write_mesh(after, moved);
  const std::string out = dir.file("disp.png").string();
  const test::CommandResult r = test::run_cli("render " + test::shell_quote(after) + " " + test::shell_quote(out) +
                                              " --color displacement --before " + test::shell_quote(before) +
                                              " --size 200x150 --json --range 0.01");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\"quantity\": \"displacement\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"max\": 0.01"), std::string::npos) << r.out;
  EXPECT_EQ(read_png(out).width, 200);

  // A different vertex count: one clear error naming the file, and no output.
  const std::string other = test::data_path("bunny_uniform.off").string();
  const std::string bad = dir.file("bad.png").string();
  const test::CommandResult e = test::run_cli("render " + test::shell_quote(after) + " " + test::shell_quote(bad) +
                                              " --color displacement --before " + test::shell_quote(other));
  EXPECT_EQ(e.exit_code, 1);
  EXPECT_NE(e.err.find("bunny_uniform.off"), std::string::npos) << e.err;
  EXPECT_FALSE(std::filesystem::exists(bad));
}

TEST(RenderCli, CheckerTexture) {
  test::ScratchDir dir("render_cli_checker");
  const std::string spot = test::quoted_data_path("spot.obj");
  const std::string out = dir.file("spot.png").string(), plain = dir.file("plain.png").string();
  const test::CommandResult r =
      test::run_cli("render " + spot + " " + test::shell_quote(out) + " --texture checker --size 320x240");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  ASSERT_EQ(test::run_cli("render " + spot + " " + test::shell_quote(plain) + " --size 320x240").exit_code, 0);
  EXPECT_NE(read_png(out).pixels, read_png(plain).pixels);
  const std::string coarse = dir.file("coarse.png").string();
  ASSERT_EQ(test::run_cli("render " + spot + " " + test::shell_quote(coarse) +
                          " --texture checker --checker-squares 4 --size 320x240")
                .exit_code,
            0);
  EXPECT_NE(read_png(coarse).pixels, read_png(out).pixels);

  // No texture coordinates, a square count out of range, an unknown texture: one line each.
  const std::string bad = test::shell_quote(dir.file("bad.png").string());
  for (const std::string& args :
       {test::quoted_data_path("sphere_low.off") + " " + bad + " --texture checker",
        spot + " " + bad + " --texture checker --checker-squares 0",
        spot + " " + bad + " --texture checker --checker-squares 300", spot + " " + bad + " --texture marble"}) {
    const test::CommandResult e = test::run_cli("render " + args);
    EXPECT_NE(e.exit_code, 0) << args;
    EXPECT_EQ(std::count(e.err.begin(), e.err.end(), '\n'), 1) << e.err;
    EXPECT_TRUE(e.err.find("--texture") != std::string::npos || e.err.find("--checker-squares") != std::string::npos)
        << e.err;
  }
  EXPECT_FALSE(std::filesystem::exists(dir.file("bad.png")));
}

TEST(RenderCli, BadArgumentsGiveOneLineErrors) {
  test::ScratchDir dir("render_cli_bad");
  const std::string in = test::quoted_data_path("sphere_low.off");
  const auto run = [&](const std::string& args) { return test::run_cli("render " + in + " " + args); };
  for (const std::string& args :
       {test::shell_quote(dir.file("a.jpg").string()), test::shell_quote(dir.file("a.png").string()) + " --size 12",
        test::shell_quote(dir.file("a.png").string()) + " --color displacement"}) {
    const test::CommandResult r = run(args);
    EXPECT_EQ(r.exit_code, 1) << args;
    EXPECT_NE(r.err.find("vertexflow: error:"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  EXPECT_FALSE(std::filesystem::exists(dir.file("a.png")));
  EXPECT_NE(run(test::shell_quote(dir.file("a.png").string()) + " --color curvy").exit_code, 0);
}

}  // namespace
}  // namespace vertexflow
