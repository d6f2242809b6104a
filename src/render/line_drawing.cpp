// Line drawings in an image (line_drawing.h): feature lines, hidden-line removal against the
// renderer's depth buffer, SVG and PNG output, and line-drawing fidelity.
#include "vertexflow/line_drawing.h"

#include "vertexflow/io.h"
#include "vertexflow/timing.h"

#include <cairo.h>
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <stdexcept>

namespace vertexflow {
namespace {

struct Style {
  std::array<std::uint8_t, 3> rgb;
  double width;  // times the line width
  [[nodiscard]] std::string svg_color() const { return fmt::format("#{:02x}{:02x}{:02x}", rgb[0], rgb[1], rgb[2]); }
  [[nodiscard]] double channel(int c) const { return rgb[static_cast<std::size_t>(c)] / 255.0; }  // cairo's
};

Style style_of(LineType type) {
  switch (type) {
    case LineType::Contour:
      return {{0, 0, 0}, 1.0};
    case LineType::SuggestiveContour:
      return {{0, 0, 0}, 0.75};
    case LineType::Ridge:
      return {{0xa0, 0x28, 0x18}, 0.75};
    case LineType::Valley:
      return {{0x18, 0x40, 0xa0}, 0.75};
  }
  return {{0, 0, 0}, 1.0};
}

// The farthest surface depth among the 3 x 3 pixels around (x, y) (line_drawing.h says why);
// +inf beyond the image or where a pixel has no surface.
float farthest_around(const DepthImage& depth, double x, double y) {
  const int cx = static_cast<int>(std::floor(x)), cy = static_cast<int>(std::floor(y));
  float far = -std::numeric_limits<float>::infinity();
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const int px = cx + dx, py = cy + dy;
      if (px < 0 || py < 0 || px >= depth.width || py >= depth.height) return std::numeric_limits<float>::infinity();
      far = std::max(far, depth.at(px, py));
    }
  return far;
}

// Splits `line` (3D) into its visible pieces in the image, sampled every half pixel.
void visible_pieces(const Polyline& line, const RenderCamera& camera, const DepthImage* depth, double slack,
                    std::vector<ImagePolyline>& out) {
  const Index n = line.points.rows();
  if (n < 2) return;
  ImagePolyline piece;
  piece.type = line.type;
  const auto flush = [&] {
    if (piece.points.size() >= 2) out.push_back(piece);
    piece.points.clear();
  };
  const auto visible = [&](const Eigen::Vector3d& q) {
    return !depth || q.z() <= static_cast<double>(farthest_around(*depth, q.x(), q.y())) + slack;
  };
  const Index segments = line.closed ? n : n - 1;
  Eigen::Vector3d a = camera.project(line.points.row(0).transpose());
  bool a_visible = visible(a);
  if (a_visible) piece.points.emplace_back(a.head<2>());
  for (Index i = 0; i < segments; ++i) {
    const Eigen::Vector3d b = camera.project(line.points.row((i + 1) % n).transpose());
    const int steps = std::max(1, static_cast<int>(std::ceil(2 * (b - a).head<2>().norm())));
    for (int k = 1; k <= steps; ++k) {
      const Eigen::Vector3d q = a + (b - a) * (static_cast<double>(k) / steps);
      const bool q_visible = visible(q);
      if (q_visible && !a_visible) piece.points.emplace_back(q.head<2>());  // a piece starts
      if (!q_visible && a_visible) flush();                                 // a piece ends
      a_visible = q_visible;
    }
    if (a_visible) piece.points.emplace_back(b.head<2>());
    a = b;
  }
  flush();
}

// Owning handles of cairo objects.
using Surface = std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)>;
using Context = std::unique_ptr<cairo_t, decltype(&cairo_destroy)>;

void check_fidelity_options(const LineFidelityOptions& o) {
  if (o.views < 1) throw std::invalid_argument("line fidelity: at least one view is needed");
  if (!(o.elevation_degrees >= -90 && o.elevation_degrees <= 90))
    throw std::invalid_argument("line fidelity: the elevation must be in [-90, 90] degrees");
  if (!(o.match_pixels >= 0)) throw std::invalid_argument("line fidelity: the match radius must be >= 0");
}

// The share of `a`'s pixels with a pixel of `b` within `radius`.
double matched_share(const std::vector<char>& a, const std::vector<char>& b, int width, int height, double radius,
                     Index& count) {
  const int r = static_cast<int>(std::floor(radius));
  std::vector<std::pair<int, int>> disk;
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx)
      if (dx * dx + dy * dy <= radius * radius) disk.emplace_back(dx, dy);
  Index total = 0, matched = 0;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      if (!a[static_cast<std::size_t>(y) * width + x]) continue;
      ++total;
      for (const auto& [dx, dy] : disk) {
        const int px = x + dx, py = y + dy;
        if (px >= 0 && py >= 0 && px < width && py < height && b[static_cast<std::size_t>(py) * width + px]) {
          ++matched;
          break;
        }
      }
    }
  count = total;
  return total > 0 ? static_cast<double>(matched) / static_cast<double>(total) : 0.0;
}

}  // namespace

LineDrawing draw_lines(const Mesh& mesh, const LineDrawingOptions& options) {
  if (!(options.depth_tolerance_pixels >= 0))
    throw std::invalid_argument("line drawing: the depth tolerance must be >= 0 pixels");
  LineDrawing drawing;
  drawing.width = options.render.width;
  drawing.height = options.render.height;
  // The depth pass computes the camera; without it, the camera alone.
  auto start = Clock::now();
  std::optional<DepthImage> depth;
  if (options.hidden_line_removal) depth = render_depth(mesh, options.render);
  drawing.depth_seconds = seconds_since(start);
  drawing.camera = depth ? depth->camera : render_camera(mesh.V, options.render);
  start = Clock::now();
  View view;
  view.orthographic = true;
  view.direction = -drawing.camera.back;
  const std::vector<Polyline> lines = feature_lines(mesh.V, mesh.F, view, options.lines);
  drawing.lines_seconds = seconds_since(start);
  start = Clock::now();
  const double slack = options.depth_tolerance_pixels / drawing.camera.pixels_per_unit;
  for (const Polyline& line : lines) {
    ++drawing.extracted[static_cast<std::size_t>(line.type)];
    const std::size_t before = drawing.lines.size();
    visible_pieces(line, drawing.camera, depth ? &*depth : nullptr, slack, drawing.lines);
    drawing.drawn[static_cast<std::size_t>(line.type)] += static_cast<int>(drawing.lines.size() - before);
  }
  drawing.visibility_seconds = seconds_since(start);
  return drawing;
}

std::string svg_document(const LineDrawing& drawing, double line_width) {
  std::string svg = fmt::format(
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\">\n"
      "<rect width=\"{0}\" height=\"{1}\" fill=\"#ffffff\"/>\n",
      drawing.width, drawing.height);
  for (const LineType type : {LineType::Contour, LineType::SuggestiveContour, LineType::Ridge, LineType::Valley}) {
    const Style style = style_of(type);
    svg += fmt::format(
        "<g id=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"{:.3g}\" stroke-linecap=\"round\" "
        "stroke-linejoin=\"round\">\n",
        line_type_name(type), style.svg_color(), style.width * line_width);
    for (const ImagePolyline& line : drawing.lines) {
      if (line.type != type) continue;
      svg += "<polyline points=\"";
      for (std::size_t i = 0; i < line.points.size(); ++i)
        svg += fmt::format("{}{:.2f},{:.2f}", i ? " " : "", line.points[i].x(), line.points[i].y());
      svg += "\"/>\n";
    }
    svg += "</g>\n";
  }
  svg += "</svg>\n";
  return svg;
}

void write_svg(const std::filesystem::path& path, const LineDrawing& drawing, double line_width) {
  write_text_file(path, svg_document(drawing, line_width));
}

Image line_image(const LineDrawing& drawing, double line_width, const Image& underlay) {
  const int w = drawing.width, h = drawing.height;
  if (!underlay.pixels.empty() && (underlay.width != w || underlay.height != h))
    throw std::invalid_argument(
        fmt::format("line image: the underlay is {}x{}, the drawing {}x{}", underlay.width, underlay.height, w, h));
  Surface surface(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, w, h), &cairo_surface_destroy);
  if (cairo_surface_status(surface.get()) != CAIRO_STATUS_SUCCESS)
    throw std::runtime_error(fmt::format("cannot create a {}x{} cairo image", w, h));
  unsigned char* data = cairo_image_surface_get_data(surface.get());
  const int stride = cairo_image_surface_get_stride(surface.get());
  // Cairo's ARGB32 is premultiplied, one native-endian 32-bit word per pixel.
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      std::uint32_t argb = 0xffffffffu;
      if (!underlay.pixels.empty()) {
        const std::uint8_t* p = underlay.pixel(x, y);
        const std::uint32_t a = p[3];
        const auto pre = [&](std::uint8_t c) { return (static_cast<std::uint32_t>(c) * a + 127) / 255; };
        argb = (a << 24) | (pre(p[0]) << 16) | (pre(p[1]) << 8) | pre(p[2]);
      }
      std::memcpy(data + static_cast<std::size_t>(y) * stride + 4 * static_cast<std::size_t>(x), &argb, 4);
    }
  cairo_surface_mark_dirty(surface.get());
  Context cr(cairo_create(surface.get()), &cairo_destroy);
  cairo_set_line_cap(cr.get(), CAIRO_LINE_CAP_ROUND);
  cairo_set_line_join(cr.get(), CAIRO_LINE_JOIN_ROUND);
  for (const ImagePolyline& line : drawing.lines) {
    const Style style = style_of(line.type);
    cairo_set_source_rgb(cr.get(), style.channel(0), style.channel(1), style.channel(2));
    cairo_set_line_width(cr.get(), style.width * line_width);
    cairo_move_to(cr.get(), line.points[0].x(), line.points[0].y());
    for (std::size_t i = 1; i < line.points.size(); ++i)
      cairo_line_to(cr.get(), line.points[i].x(), line.points[i].y());
    cairo_stroke(cr.get());
  }
  cairo_surface_flush(surface.get());
  Image image;
  image.width = w;
  image.height = h;
  image.pixels.resize(4 * static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      std::uint32_t argb;
      std::memcpy(&argb, data + static_cast<std::size_t>(y) * stride + 4 * static_cast<std::size_t>(x), 4);
      const std::uint32_t a = argb >> 24;
      const auto un = [&](int shift) {
        const std::uint32_t c = (argb >> shift) & 0xffu;
        return static_cast<std::uint8_t>(a ? std::min<std::uint32_t>(255, (c * 255 + a / 2) / a) : 0);
      };
      std::uint8_t* p = image.pixel(x, y);
      p[0] = un(16), p[1] = un(8), p[2] = un(0), p[3] = static_cast<std::uint8_t>(a);
    }
  return image;
}

std::vector<char> line_pixels(const LineDrawing& drawing) {
  const int w = drawing.width, h = drawing.height;
  std::vector<char> mask(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), 0);
  const auto mark = [&](const Eigen::Vector2d& p) {
    const int x = static_cast<int>(std::floor(p.x())), y = static_cast<int>(std::floor(p.y()));
    if (x >= 0 && y >= 0 && x < w && y < h) mask[static_cast<std::size_t>(y) * w + x] = 1;
  };
  for (const ImagePolyline& line : drawing.lines) {
    mark(line.points[0]);
    for (std::size_t i = 1; i < line.points.size(); ++i) {
      const Eigen::Vector2d a = line.points[i - 1], b = line.points[i];
      const int steps = std::max(1, static_cast<int>(std::ceil(2 * (b - a).norm())));  // every half pixel
      for (int k = 1; k <= steps; ++k) mark(a + (b - a) * (static_cast<double>(k) / steps));
    }
  }
  return mask;
}

LineFidelity line_drawing_fidelity(const Mesh& coarse, const Mesh& dense, const LineFidelityOptions& options) {
  check_fidelity_options(options);
  if (coarse.F.rows() == 0 || dense.F.rows() == 0) throw std::invalid_argument("line fidelity: a mesh has no faces");
  LineDrawingOptions drawing = options.drawing;
  drawing.render.width = options.width;
  drawing.render.height = options.height;
  const BoundingBox dense_box = bounding_box(dense.V);
  drawing.render.frame = dense_box;
  drawing.render.view = RenderView::Custom;
  drawing.render.elevation_degrees = options.elevation_degrees;
  if (drawing.lines.length_scale == 0) drawing.lines.length_scale = dense_box.diagonal();
  LineFidelity result;
  int with_lines = 0;  // views where either drawing has a line pixel: the means' count
  for (int v = 0; v < options.views; ++v) {
    drawing.render.azimuth_degrees = 360.0 * v / options.views;
    const std::vector<char> a = line_pixels(draw_lines(coarse, drawing));
    const std::vector<char> b = line_pixels(draw_lines(dense, drawing));
    LineFidelityView view;
    view.azimuth_degrees = drawing.render.azimuth_degrees;
    view.precision = matched_share(a, b, options.width, options.height, options.match_pixels, view.coarse_pixels);
    view.recall = matched_share(b, a, options.width, options.height, options.match_pixels, view.dense_pixels);
    if (view.coarse_pixels == 0 && view.dense_pixels == 0) {
      // Nothing drawn on either side: no agreement to measure (a flat mesh, one triangle), not
      // a score of 0 for a mesh against itself.
      view.precision = view.recall = view.f1 = std::numeric_limits<double>::quiet_NaN();
      result.views.push_back(view);
      continue;
    }
    const double sum = view.precision + view.recall;
    view.f1 = sum > 0 ? 2 * view.precision * view.recall / sum : 0.0;
    result.precision += view.precision;  // sums here, means after the loop
    result.recall += view.recall;
    result.f1 += view.f1;
    ++with_lines;
    result.views.push_back(view);
  }
  if (with_lines == 0) {
    result.precision = result.recall = result.f1 = std::numeric_limits<double>::quiet_NaN();
  } else {
    result.precision /= with_lines;
    result.recall /= with_lines;
    result.f1 /= with_lines;
  }
  return result;
}

}  // namespace vertexflow
