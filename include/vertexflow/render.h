// Headless rendering of a mesh to an image, for before/after figures and visual checks.
//
// Rendering runs on the CPU through Mesa's off-screen OpenGL (OSMesa, llvmpipe rasteriser):
// no display and no GPU are needed. llvmpipe rasterises with LP_NUM_THREADS threads (default:
// one per core); the pixels do not depend on the thread count. Mesa may keep compiled shaders
// in its on-disk cache (~/.cache/mesa_shader_cache; MESA_SHADER_CACHE_DISABLE=true turns it
// off).
//
// Conventions
// - Camera: orthographic, so sizes compare across the image. The "camera frame" is a bounding
//   box in mesh coordinates; the camera looks at its centre and scales the box's projection in
//   the chosen view to fill 92% of the image (in the limiting direction). Two renders with the
//   same frame, view and size use the same camera, so before/after images line up pixel for
//   pixel. Without a frame the mesh's own bounding box is used, so the mesh is always wholly
//   in the picture; a mesh larger than a given frame may be cut off.
// - The box is fitted into the image minus a legend strip at the right (kLegendWidthFraction
//   of the width), with or without a colour bar, so coloured and plain renders line up too.
// - Views assume +y is up (the convention of most scanned models, e.g. the Stanford bunny):
//   front looks along -z (camera on +z), side along -x (camera on +x), top along -y (camera on
//   +y, -z pointing up in the image), iso from the (+x, +y, +z) octant. Custom uses azimuth
//   (degrees about +y, from +z towards +x) and elevation (degrees above the xz plane).
// - Faces are lit on both sides (open meshes show their inside), by a light at the camera
//   plus a weaker fill light from the upper left. Exaggerated shading replaces that lighting
//   by its own per-vertex shades (exaggerated_shading.h), from a light given in camera
//   coordinates (RenderOptions::exaggerated_light).
// - Image: RGBA8, rows top to bottom, 4 bytes per pixel; pixel (x, y) with y = 0 the top row.
#pragma once

#include "vertexflow/exaggerated_shading.h"
#include "vertexflow/mesh.h"

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace vertexflow {

/// An 8-bit RGBA image, rows top to bottom.
struct Image {
  int width = 0;
  int height = 0;
  /// width * height * 4 bytes: R, G, B, A of pixel (x, y) at 4 * (y * width + x).
  std::vector<std::uint8_t> pixels;

  [[nodiscard]] const std::uint8_t* pixel(int x, int y) const {
    return &pixels[4 * (static_cast<std::size_t>(y) * width + x)];
  }
  [[nodiscard]] std::uint8_t* pixel(int x, int y) { return &pixels[4 * (static_cast<std::size_t>(y) * width + x)]; }
};

enum class RenderView { Front, Side, Top, Iso, Custom };

/// What the surface colour shows.
enum class RenderColor {
  /// A uniform light grey.
  None,
  /// Mean curvature H = (k1 + k2) / 2 (curvature.h), diverging map (colormap.h), symmetric
  /// range [-L, L] with L = robust_color_limit(H) unless RenderOptions::color_limit is set.
  Mean,
  /// Gaussian curvature K = k1 k2, as Mean.
  Gauss,
  /// Triangle quality 2r/R (quality.h) per face, fixed range [0, 1] so renders compare:
  /// 1 (equilateral) white, 0 (degenerate) red.
  Quality,
  /// Per-vertex displacement length |V - reference| (RenderOptions::displacement_reference),
  /// range [0, L] with L = robust_color_limit (or RenderOptions::color_limit), white (0) to
  /// red (L).
  Displacement,
};

/// A texture laid over the surface through its texture coordinates (the first TexCoord corner
/// or vertex channel, attributes.h), to show how a method moved them.
enum class RenderTexture {
  None,
  /// A procedural checkerboard in UV space, RenderOptions::checker_squares squares per unit,
  /// dark and light grey, multiplied into the surface colour: a texture that swims or stretches
  /// shows as bent or uneven squares.
  Checker,
};

enum class RenderShading {
  /// Vertex normals (curvature.h's vertex_normals, Max 1999 weights), lit per vertex and
  /// interpolated across each triangle (Gouraud).
  Smooth,
  /// One normal per face: every triangle visible.
  Flat,
  /// Exaggerated shading (Rusinkiewicz, Burns and DeCarlo 2006; exaggerated_shading.h): the
  /// per-vertex shade s in [0, 1] of RenderOptions::exaggerated, lit from
  /// RenderOptions::exaggerated_light, drawn with OpenGL lighting off as the grey 255 s (times
  /// the colour map's colour when colouring by a quantity), interpolated across each triangle.
  Exaggerated,
};

/// Fraction of the image width kept for the legend (colour bar and labels) at the right.
inline constexpr double kLegendWidthFraction = 0.12;

/// The default font for the legend labels (Debian package fonts-dejavu-core).
inline constexpr const char* kDefaultRenderFont = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

struct RenderOptions {
  /// Image size in pixels; each in [16, 8192].
  int width = 1600;
  int height = 1200;
  RenderView view = RenderView::Iso;
  /// Used when view == Custom, in degrees (see the conventions above).
  double azimuth_degrees = 30;
  double elevation_degrees = 20;
  RenderColor color = RenderColor::None;
  /// RenderTexture::Checker needs texture coordinates (render_mesh throws without them).
  RenderTexture texture = RenderTexture::None;
  /// Checker squares per unit of texture coordinate, in [1, 256].
  int checker_squares = 16;
  RenderShading shading = RenderShading::Smooth;
  /// Draw every edge on top of the surface (hidden edges stay hidden), to show the vertex
  /// distribution.
  bool wireframe = false;
  /// Wireframe line width in pixels.
  double wireframe_width = 1.0;
  std::array<std::uint8_t, 4> background{255, 255, 255, 255};
  /// Camera frame in mesh coordinates (see above); the mesh's bounding box when empty.
  std::optional<BoundingBox> frame;
  /// Fixed colour-map limit L for Mean, Gauss (range [-L, L]) and Displacement ([0, L]),
  /// instead of robust_color_limit of the data: give the same L to a before and an after
  /// render so equal colours mean equal values. Must be > 0; ignored for None and Quality.
  std::optional<double> color_limit;
  /// Positions before the flow, same vertex count and order as the mesh: required by
  /// RenderColor::Displacement, ignored otherwise.
  Vertices displacement_reference;
  /// Draw the colour bar with its range labels when colouring by a quantity.
  bool color_bar = true;
  /// TrueType font for the colour bar's labels. Rendering a labelled bar throws if it cannot
  /// be loaded.
  std::string font_path = kDefaultRenderFont;
  /// Multisample anti-aliasing samples per pixel (1 = off; llvmpipe supports 4).
  int samples = 4;
  /// RenderShading::Exaggerated: scales, smoothing, exaggeration and weights (the defaults are
  /// documented in exaggerated_shading.h).
  ExaggeratedShadingOptions exaggerated;
  /// RenderShading::Exaggerated: the direction towards the light in camera coordinates, x to the
  /// image's right, y up, z towards the viewer; need not be unit, must be finite and non-zero.
  /// The default, from the upper left and in front, is the cartographers' convention for relief
  /// (light from the top of the image) turned towards the viewer so most visible surface is lit.
  Eigen::Vector3d exaggerated_light{-1, 1, 1};
};

/// The orthographic camera of a render (conventions above), to place mesh points in its image.
struct RenderCamera {
  /// Orthonormal basis: `back` points from the scene towards the camera (the viewing direction
  /// is -back), `up` is the image's up, right = up x back.
  Eigen::Vector3d right = Eigen::Vector3d::UnitX(), up = Eigen::Vector3d::UnitY(), back = Eigen::Vector3d::UnitZ();
  BoundingBox frame;                                 ///< the camera frame (options.frame or V's box)
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  ///< the frame's centre
  double pixels_per_unit = 1;                        ///< image scale
  double centre_x = 0, centre_y = 0;                 ///< where the centre lands, in pixels
  double depth_range = 1;  ///< the GL depth range is [-depth_range, depth_range] around the centre
  int width = 0, height = 0;

  /// (x, y, depth) of mesh point p: x from the image's left edge and y from its top edge in
  /// pixels (pixel (i, j) covers [i, i + 1) x [j, j + 1)), depth along the viewing direction
  /// from the centre's plane in mesh units (larger is farther).
  [[nodiscard]] Eigen::Vector3d project(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d d = p - centre;
    return {centre_x + pixels_per_unit * d.dot(right), centre_y - pixels_per_unit * d.dot(up), -d.dot(back)};
  }
};

/// The camera render_mesh uses for `V` (its bounding box when options.frame is empty) and
/// `options` (view, size, frame). Throws as render_mesh for a bad size or frame.
RenderCamera render_camera(const Vertices& V, const RenderOptions& options);

/// A depth buffer: per pixel the depth (RenderCamera::project's third coordinate) of the nearest
/// surface at the pixel's centre, +infinity where there is none. Rows top to bottom.
struct DepthImage {
  int width = 0, height = 0;
  std::vector<float> depth;  ///< width * height
  RenderCamera camera;
  [[nodiscard]] float at(int x, int y) const { return depth[static_cast<std::size_t>(y) * width + x]; }
};

/// Rasterises `mesh`'s faces with render_mesh's camera for the same options, single-sampled,
/// into a depth buffer (both sides of every face; colours and lights unused): what hidden-line
/// removal tests lines against. Throws as render_mesh.
DepthImage render_depth(const Mesh& mesh, const RenderOptions& options = {});

/// What a render measured, for the caller's legend text and for benchmarks.
struct RenderInfo {
  /// The quantity's name ("mean curvature", ...), empty for RenderColor::None.
  std::string color_quantity;
  /// The colour map's value range: values at or beyond these ends get the end colours.
  double color_min = 0;
  double color_max = 0;
  /// The camera frame actually used.
  BoundingBox frame;
  /// The camera actually used.
  RenderCamera camera;
  /// Wall-clock seconds: preparing arrays (normals, colours, edges), OpenGL drawing up to
  /// glFinish, and getting the pixels into the Image (multisample resolve and copy).
  double prepare_seconds = 0;
  double draw_seconds = 0;
  double readback_seconds = 0;
};

/// Renders `mesh` off-screen. Throws std::invalid_argument for bad options (size out of range,
/// a displacement reference of the wrong size, exaggerated shading's options or light out of
/// range, checker_squares outside [1, 256], RenderTexture::Checker on a mesh without texture
/// coordinates) and
/// std::runtime_error when OSMesa cannot create a context or the legend font cannot be loaded.
/// Deterministic: the same mesh and options give the same pixels.
Image render_mesh(const Mesh& mesh, const RenderOptions& options = {}, RenderInfo* info = nullptr);

/// Encodes `image` as an 8-bit RGBA PNG (libpng) in memory.
std::string encode_png(const Image& image);

/// Writes `image` as PNG, atomically (temporary file beside `path`, then rename; see
/// write_text_file in io.h). Throws IoError.
void write_png(const std::filesystem::path& path, const Image& image);

}  // namespace vertexflow
