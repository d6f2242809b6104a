// Pictures: render (render.h), feature_lines (lines.h), line_drawing and compare_lines
// (line_drawing.h).
#include "convert.h"

#include "vertexflow/line_drawing.h"
#include "vertexflow/lines.h"
#include "vertexflow/render.h"

#include <pybind11/stl.h>

#include <cmath>
#include <cstring>

namespace vertexflow::python {
namespace {

RenderView render_view(const std::string& view) {
  return enum_option<RenderView>("view", view,
                                 {{"front", RenderView::Front},
                                  {"side", RenderView::Side},
                                  {"top", RenderView::Top},
                                  {"iso", RenderView::Iso},
                                  {"custom", RenderView::Custom}});
}

py::array py_render(const py::handle& V, const py::handle& F, int width, int height, const std::string& view,
                    const std::string& color, const std::string& shading, bool wireframe, double azimuth,
                    double elevation, const py::object& displacement_reference, bool color_bar, int samples,
                    int threads) {
  const Mesh mesh = to_mesh(V, F);
  RenderOptions options;
  options.width = width;
  options.height = height;
  options.view = render_view(view);
  options.color = enum_option<RenderColor>("color", color,
                                           {{"none", RenderColor::None},
                                            {"mean", RenderColor::Mean},
                                            {"gauss", RenderColor::Gauss},
                                            {"quality", RenderColor::Quality},
                                            {"displacement", RenderColor::Displacement}});
  options.shading = enum_option<RenderShading>(
      "shading", shading,
      {{"smooth", RenderShading::Smooth}, {"flat", RenderShading::Flat}, {"exaggerated", RenderShading::Exaggerated}});
  options.wireframe = wireframe;
  options.azimuth_degrees = azimuth;
  options.elevation_degrees = elevation;
  options.color_bar = color_bar;
  options.samples = samples;
  if (!displacement_reference.is_none())
    options.displacement_reference = to_vertices(as_vertices(displacement_reference, "displacement_reference"));
  // threads limits the TBB part (arrays, colours); llvmpipe rasterises with LP_NUM_THREADS.
  const Image image = without_gil(threads, [&] { return render_mesh(mesh, options); });
  py::array_t<std::uint8_t> rgb(
      {static_cast<py::ssize_t>(image.height), static_cast<py::ssize_t>(image.width), static_cast<py::ssize_t>(3)});
  std::uint8_t* out = rgb.mutable_data();
  const std::size_t pixels = static_cast<std::size_t>(image.width) * image.height;
  for (std::size_t i = 0; i < pixels; ++i) std::memcpy(out + 3 * i, image.pixels.data() + 4 * i, 3);
  return rgb;
}

// Line options from keyword values (lines.h); the same names as the CLI's, with underscores.
LineOptions line_options(bool contours, bool suggestive_contours, bool ridges, bool valleys,
                         double suggestive_threshold, double ridge_threshold, double smoothing_scale,
                         double length_scale) {
  LineOptions o;
  o.contours = contours;
  o.suggestive_contours = suggestive_contours;
  o.ridges = ridges;
  o.valleys = valleys;
  o.suggestive_threshold = suggestive_threshold;
  o.ridge_threshold = ridge_threshold;
  o.smoothing_scale = smoothing_scale;
  o.length_scale = length_scale;
  return o;
}

py::array_t<double> points_array(const std::vector<Eigen::Vector2d>& points) {
  py::array_t<double> out({static_cast<py::ssize_t>(points.size()), static_cast<py::ssize_t>(2)});
  double* data = out.mutable_data();
  for (std::size_t i = 0; i < points.size(); ++i) data[2 * i] = points[i].x(), data[2 * i + 1] = points[i].y();
  return out;
}

py::list py_feature_lines(const py::handle& V, const py::handle& F, const py::object& direction, const py::object& eye,
                          bool contours, bool suggestive_contours, bool ridges, bool valleys,
                          double suggestive_threshold, double ridge_threshold, double smoothing_scale,
                          double length_scale, int threads) {
  const Mesh mesh = to_mesh(V, F);
  if (!direction.is_none() && !eye.is_none())
    throw std::invalid_argument("feature_lines: give direction (orthographic) or eye (perspective), not both");
  View view;
  view.orthographic = eye.is_none();
  const auto vec3 = [](const py::object& o, const char* name) {
    const std::vector<double> v = o.cast<std::vector<double>>();
    if (v.size() != 3) throw std::invalid_argument(std::string("feature_lines: ") + name + " needs 3 values");
    return Eigen::Vector3d(v[0], v[1], v[2]);
  };
  if (!direction.is_none()) view.direction = vec3(direction, "direction");
  if (!eye.is_none()) view.eye = vec3(eye, "eye");
  const LineOptions options = line_options(contours, suggestive_contours, ridges, valleys, suggestive_threshold,
                                           ridge_threshold, smoothing_scale, length_scale);
  const std::vector<Polyline> lines =
      without_gil(threads, [&] { return feature_lines(mesh.V, mesh.F, view, options); });
  py::list out;
  for (const Polyline& line : lines) {
    py::array_t<double> points({static_cast<py::ssize_t>(line.points.rows()), static_cast<py::ssize_t>(3)});
    std::memcpy(points.mutable_data(), line.points.data(), sizeof(double) * 3 * line.points.rows());
    out.append(py::dict(py::arg("type") = std::string(line_type_name(line.type)), py::arg("points") = points,
                        py::arg("closed") = line.closed));
  }
  return out;
}

LineDrawingOptions drawing_options(int width, int height, const std::string& view, double azimuth, double elevation,
                                   const LineOptions& lines, bool hidden_line_removal) {
  LineDrawingOptions o;
  o.render.width = width;
  o.render.height = height;
  o.render.view = render_view(view);
  o.render.azimuth_degrees = azimuth;
  o.render.elevation_degrees = elevation;
  o.lines = lines;
  o.hidden_line_removal = hidden_line_removal;
  return o;
}

py::dict py_line_drawing(const py::handle& V, const py::handle& F, int width, int height, const std::string& view,
                         double azimuth, double elevation, bool contours, bool suggestive_contours, bool ridges,
                         bool valleys, double suggestive_threshold, double ridge_threshold, double smoothing_scale,
                         double length_scale, bool hidden_line_removal, double line_width, int threads) {
  const Mesh mesh = to_mesh(V, F);
  const LineDrawingOptions options =
      drawing_options(width, height, view, azimuth, elevation,
                      line_options(contours, suggestive_contours, ridges, valleys, suggestive_threshold,
                                   ridge_threshold, smoothing_scale, length_scale),
                      hidden_line_removal);
  const LineDrawing drawing = without_gil(threads, [&] { return draw_lines(mesh, options); });
  py::list lines;
  for (const ImagePolyline& line : drawing.lines)
    lines.append(py::dict(py::arg("type") = std::string(line_type_name(line.type)),
                          py::arg("points") = points_array(line.points)));
  return py::dict(py::arg("lines") = lines, py::arg("svg") = svg_document(drawing, line_width),
                  py::arg("width") = drawing.width, py::arg("height") = drawing.height);
}

py::dict py_compare_lines(const py::handle& Vc, const py::handle& Fc, const py::handle& Vd, const py::handle& Fd,
                          int views, double elevation, int width, int height, double match_pixels, int threads) {
  const Mesh coarse = to_mesh(Vc, Fc, "V_coarse", "F_coarse");
  const Mesh dense = to_mesh(Vd, Fd, "V_dense", "F_dense");
  LineFidelityOptions options;
  options.views = views;
  options.elevation_degrees = elevation;
  options.width = width;
  options.height = height;
  options.match_pixels = match_pixels;
  const BoundingBox coarse_box = bounding_box(coarse.V), dense_box = bounding_box(dense.V);
  if ((coarse_box.max.array() < dense_box.min.array()).any() || (dense_box.max.array() < coarse_box.min.array()).any())
    if (PyErr_WarnEx(PyExc_UserWarning,
                     "compare_lines: the bounding boxes do not overlap, so the drawings cannot match (both are "
                     "framed on the dense mesh)",
                     1) != 0)
      throw py::error_already_set();
  const LineFidelity fidelity = without_gil(threads, [&] { return line_drawing_fidelity(coarse, dense, options); });
  // Undefined (neither drawing has a line pixel) is None, as the CLI's JSON has null.
  const auto value = [](double x) -> py::object {
    if (std::isnan(x)) return py::none();
    return py::float_(x);
  };
  py::list per_view;
  for (const LineFidelityView& v : fidelity.views)
    per_view.append(py::dict(py::arg("azimuth") = v.azimuth_degrees, py::arg("precision") = value(v.precision),
                             py::arg("recall") = value(v.recall), py::arg("f1") = value(v.f1),
                             py::arg("coarse_pixels") = v.coarse_pixels, py::arg("dense_pixels") = v.dense_pixels));
  return py::dict(py::arg("precision") = value(fidelity.precision), py::arg("recall") = value(fidelity.recall),
                  py::arg("f1") = value(fidelity.f1), py::arg("views") = per_view);
}

}  // namespace

void register_render_lines(py::module_& m) {
  m.def("render", &py_render, py::arg("V"), py::arg("F"), py::kw_only(), py::arg("width") = 800,
        py::arg("height") = 600, py::arg("view") = "iso", py::arg("color") = "none", py::arg("shading") = "smooth",
        py::arg("wireframe") = false, py::arg("azimuth") = 30.0, py::arg("elevation") = 20.0,
        py::arg("displacement_reference") = py::none(), py::arg("color_bar") = true, py::arg("samples") = 4,
        py::arg("threads") = 0,
        R"doc(Renders the mesh off-screen (OSMesa) -> (height, width, 3) uint8 RGB array, rows top to bottom.
view: front, side, top, iso, custom (azimuth, elevation); color: none, mean, gauss, quality,
displacement (needs displacement_reference, the positions before); shading: smooth, flat,
exaggerated (Rusinkiewicz et al. 2006, render.h's default options).
threads limits the TBB part; llvmpipe rasterises with LP_NUM_THREADS threads.)doc");
  m.def("feature_lines", &py_feature_lines, py::arg("V"), py::arg("F"), py::kw_only(),
        py::arg("direction") = py::none(), py::arg("eye") = py::none(), py::arg("contours") = true,
        py::arg("suggestive_contours") = true, py::arg("ridges") = true, py::arg("valleys") = true,
        py::arg("suggestive_threshold") = LineOptions{}.suggestive_threshold,
        py::arg("ridge_threshold") = LineOptions{}.ridge_threshold, py::arg("smoothing_scale") = 0.0,
        py::arg("length_scale") = 0.0, py::arg("threads") = 0,
        R"doc(The feature lines as 3D polylines (lines.h) -> [{"type", "points" (N, 3), "closed"}].
Orthographic along direction (default (0, 0, -1)) or perspective from eye. type is contours,
suggestive-contours, ridges or valleys; thresholds in units of L (length_scale, default the
bounding-box diagonal). Hidden lines are not removed: line_drawing does that.)doc");
  m.def("line_drawing", &py_line_drawing, py::arg("V"), py::arg("F"), py::kw_only(), py::arg("width") = 800,
        py::arg("height") = 600, py::arg("view") = "iso", py::arg("azimuth") = 30.0, py::arg("elevation") = 20.0,
        py::arg("contours") = true, py::arg("suggestive_contours") = true, py::arg("ridges") = true,
        py::arg("valleys") = true, py::arg("suggestive_threshold") = LineOptions{}.suggestive_threshold,
        py::arg("ridge_threshold") = LineOptions{}.ridge_threshold, py::arg("smoothing_scale") = 0.0,
        py::arg("length_scale") = 0.0, py::arg("hidden_line_removal") = true, py::arg("line_width") = 1.5,
        py::arg("threads") = 0,
        R"doc(`vertexflow lines` in memory (line_drawing.h) -> {"lines": [{"type", "points" (N, 2) pixels}],
"svg": str, "width", "height"}: render's camera, hidden lines removed with its depth buffer.)doc");
  m.def("compare_lines", &py_compare_lines, py::arg("V_coarse"), py::arg("F_coarse"), py::arg("V_dense"),
        py::arg("F_dense"), py::kw_only(), py::arg("views") = LineFidelityOptions{}.views,
        py::arg("elevation") = LineFidelityOptions{}.elevation_degrees, py::arg("width") = LineFidelityOptions{}.width,
        py::arg("height") = LineFidelityOptions{}.height, py::arg("match_pixels") = LineFidelityOptions{}.match_pixels,
        py::arg("threads") = 0,
        R"doc(`vertexflow compare-lines`: line-drawing fidelity of the coarse mesh against the dense one
(line_drawing.h) -> {"precision", "recall", "f1", "views": [per view]}; each None where neither drawing has a
line pixel (a flat mesh), and a UserWarning when the two bounding boxes do not overlap.)doc");
}

}  // namespace vertexflow::python
