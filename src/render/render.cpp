// Off-screen rendering with OSMesa (Mesa's software OpenGL, llvmpipe), legacy fixed-function
// GL: the compatibility profile has lighting, colour material and client-side vertex arrays,
// which is all a shaded mesh with a wireframe needs. Multisampling goes through a framebuffer
// object resolved into OSMesa's buffer. The legend's text is drawn with FreeType; the colour
// bar itself is a few filled rectangles written straight into the image. PNG via libpng.
// About 800 lines in one file: the scene, its checker texture, the legend and the output share
// one OSMesa context and its GL state, whose set-up and tear-down order matters.
#include "vertexflow/render.h"

#include "vertexflow/colormap.h"
#include "vertexflow/curvature.h"
#include "vertexflow/exaggerated_shading.h"
#include "vertexflow/io.h"
#include "vertexflow/quality.h"
#include "vertexflow/timing.h"
#include "vertexflow/topology.h"

#define GL_GLEXT_PROTOTYPES
#include <GL/osmesa.h>  // includes GL/gl.h, which glext.h needs first

#include <GL/glext.h>

#include <ft2build.h>
#include FT_FREETYPE_H

#include <png.h>

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string_view>

namespace vertexflow {
namespace {

// How a quantity becomes a colour: diverging_colors((value - offset) * sign, limit), shown on
// the bar for values in [lo, hi]. Quality uses offset 1, sign -1 so that q = 1 is white, 0 red.
struct ColorScale {
  double offset = 0;
  double sign = 1;
  double limit = 1;
  double lo = 0;
  double hi = 1;
  std::string quantity;

  [[nodiscard]] Colors colors(const Eigen::VectorXd& values) const {
    return diverging_colors(((values.array() - offset) * sign).matrix(), limit);
  }
};

// The quantity to colour by, per vertex or (quality) per face, and its scale.
struct ScalarField {
  Eigen::VectorXd values;
  bool per_face = false;
  ColorScale scale;
};

ScalarField scalar_field(const Mesh& mesh, const RenderOptions& options, const Topology* topology) {
  ScalarField field;
  switch (options.color) {
    case RenderColor::None:
      return field;
    case RenderColor::Mean:
    case RenderColor::Gauss: {
      const Curvature c = principal_curvatures(mesh.V, mesh.F, *topology);
      const bool mean = options.color == RenderColor::Mean;
      field.values = mean ? c.mean() : c.gaussian();
      field.scale.quantity = mean ? "mean curvature" : "Gaussian curvature";
      field.scale.limit = options.color_limit ? *options.color_limit : robust_color_limit(field.values);
      field.scale.lo = -field.scale.limit;
      field.scale.hi = field.scale.limit;
      return field;
    }
    case RenderColor::Quality:
      field.values = triangle_quality(mesh.V, mesh.F);
      field.per_face = true;
      field.scale = {1, -1, 1, 0, 1, "quality 2r/R"};
      return field;
    case RenderColor::Displacement: {
      const Vertices& before = options.displacement_reference;
      if (before.rows() != mesh.V.rows())
        throw std::invalid_argument(
            fmt::format("displacement colouring needs the mesh before the flow with the same {} vertices, got {}",
                        mesh.V.rows(), before.rows()));
      field.values = (mesh.V - before).rowwise().norm();
      field.scale.quantity = "displacement";
      field.scale.limit = options.color_limit ? *options.color_limit : robust_color_limit(field.values);
      field.scale.hi = field.scale.limit;
      return field;
    }
  }
  return field;
}

// The orthonormal basis of the view (RenderCamera's right, up, back; render.h's conventions).
RenderCamera camera_for(const RenderOptions& options) {
  double azimuth = 0, elevation = 0;
  switch (options.view) {
    case RenderView::Front:
      break;
    case RenderView::Side:
      azimuth = 90;
      break;
    case RenderView::Top:
      elevation = 90;
      break;
    // The classic isometric direction (1, 1, 1): azimuth 45, elevation atan(1 / sqrt 2).
    case RenderView::Iso:
      azimuth = 45, elevation = std::atan(1 / std::sqrt(2.0)) * 180 / std::numbers::pi;
      break;
    case RenderView::Custom:
      azimuth = options.azimuth_degrees, elevation = options.elevation_degrees;
      break;
  }
  const double a = azimuth * std::numbers::pi / 180, e = elevation * std::numbers::pi / 180;
  RenderCamera c;
  c.back = Eigen::Vector3d(std::cos(e) * std::sin(a), std::sin(e), std::cos(e) * std::cos(a));
  // Up is +y projected into the image plane. Looking straight down (or up) that is undefined;
  // then up is the horizontal direction away from the camera's azimuth, as if the camera had
  // tilted down from the front: "top" has -z up.
  Eigen::Vector3d up = Eigen::Vector3d::UnitY() - c.back.y() * c.back;
  if (up.norm() < 1e-6) up = -Eigen::Vector3d(std::sin(a), 0, std::cos(a)) * (c.back.y() > 0 ? 1 : -1);
  c.up = up.normalized();
  c.right = c.up.cross(c.back);
  return c;
}

// Arrays for glDrawArrays / glDrawElements. Positions are relative to the frame centre, so
// float precision is spent on the visible range, not on a far-away origin.
struct DrawArrays {
  std::vector<float> positions;       // 3 per render vertex
  std::vector<float> normals;         // 3 per render vertex
  std::vector<std::uint8_t> rgba;     // 4 per render vertex
  std::vector<float> uvs;             // 2 per render vertex, in checker texture periods; empty: no texture
  bool indexed = false;               // true: render vertices are mesh vertices, draw F
  std::vector<float> mesh_positions;  // 3 per mesh vertex, for the wireframe
};

void put3(std::vector<float>& out, std::size_t slot, const Eigen::Vector3d& v) {
  for (int k = 0; k < 3; ++k) out[3 * slot + k] = static_cast<float>(v[k]);
}

// The texture coordinates a checker render uses: the first TexCoord corner channel with two
// or more components, else the first such vertex channel (render.h).
struct TexCoords {
  const CornerChannel* corner = nullptr;
  const AttributeChannel* vertex = nullptr;
  [[nodiscard]] bool empty() const { return !corner && !vertex; }
};

TexCoords find_texcoords(const Mesh& mesh) {
  TexCoords t;
  for (const CornerChannel& c : mesh.attributes.corner)
    if (c.channel.role == AttributeRole::TexCoord && c.channel.width() >= 2 && c.corners.rows() == mesh.F.rows()) {
      t.corner = &c;
      return t;
    }
  for (const AttributeChannel& c : mesh.attributes.vertex)
    if (c.role == AttributeRole::TexCoord && c.width() >= 2 && c.rows() == mesh.V.rows()) {
      t.vertex = &c;
      return t;
    }
  return t;
}

// The checker texture holds 2 x 2 squares (one period), so texture coordinates are scaled by
// squares / 2. A corner without a value (-1) gets the centre of a light square, so a face
// without texture coordinates shows plain rather than a stretched pattern.
Eigen::Vector2d corner_uv(const TexCoords& t, Index f, int k, Index v, int squares) {
  const double scale = squares / 2.0;
  if (t.vertex) return scale * Eigen::Vector2d(t.vertex->values(v, 0), t.vertex->values(v, 1));
  const std::int32_t row = t.corner->corners(f, k);
  if (row < 0) return {0.25, 0.25};
  if (row >= t.corner->channel.rows())
    throw std::invalid_argument(
        fmt::format("texture coordinate channel '{}': corner {} of face {} indexes row {} of {}",
                    t.corner->channel.name, k, f, row, t.corner->channel.rows()));
  return scale * Eigen::Vector2d(t.corner->channel.values(row, 0), t.corner->channel.values(row, 1));
}

// `shades`: exaggerated shading's per-vertex shades (empty for the lit modes), which scale the
// vertex colours from white (or the colour map's colour) down to black.
// `texcoords`: empty unless a texture is drawn.
DrawArrays build_arrays(const Mesh& mesh, const RenderOptions& options, const ScalarField& field,
                        const Eigen::VectorXd& shades, const Eigen::Vector3d& centre, const TexCoords& texcoords) {
  const auto nv = static_cast<std::size_t>(mesh.V.rows());
  const auto nf = static_cast<std::size_t>(mesh.F.rows());
  const bool flat = options.shading == RenderShading::Flat;
  const bool textured = !texcoords.empty();
  DrawArrays a;
  // Per-corner texture coordinates differ between a vertex's faces at a seam: 3 render
  // vertices per face.
  a.indexed = !flat && !field.per_face && !textured;
  a.mesh_positions.resize(3 * nv);
  for (std::size_t v = 0; v < nv; ++v)
    put3(a.mesh_positions, v, mesh.V.row(static_cast<Index>(v)).transpose() - centre);

  const bool shaded = shades.size() > 0;
  const std::uint8_t plain[3] = {205, 205, 210}, white[3] = {255, 255, 255};
  const std::uint8_t* base = shaded ? white : plain;
  const Colors colors = field.values.size() ? field.scale.colors(field.values) : Colors();
  // i: the index of the colour (a face for per-face fields), v: the mesh vertex of the slot.
  const auto color_of = [&](std::size_t i, std::size_t v, std::size_t slot) {
    for (int k = 0; k < 3; ++k) {
      const std::uint8_t c = colors.rows() ? colors(static_cast<Index>(i), k) : base[k];
      a.rgba[4 * slot + k] = shaded ? static_cast<std::uint8_t>(std::lround(c * shades[static_cast<Index>(v)])) : c;
    }
    a.rgba[4 * slot + 3] = 255;
  };

  if (a.indexed) {
    a.positions = a.mesh_positions;
    const Vertices N = vertex_normals(mesh.V, mesh.F);
    a.normals.resize(3 * nv);
    a.rgba.resize(4 * nv);
    for (std::size_t v = 0; v < nv; ++v) {
      put3(a.normals, v, N.row(static_cast<Index>(v)).transpose());
      color_of(v, v, v);
    }
    return a;
  }
  // Three render vertices per face: per-face normals (flat), per-face colours (quality) or
  // per-corner texture coordinates.
  const Vertices N = flat ? Vertices() : vertex_normals(mesh.V, mesh.F);
  a.positions.resize(9 * nf);
  a.normals.resize(9 * nf);
  a.rgba.resize(12 * nf);
  if (textured) a.uvs.resize(6 * nf);
  for (std::size_t f = 0; f < nf; ++f) {
    const auto fi = static_cast<Index>(f);
    Eigen::Vector3d face_n = flat ? face_normal(mesh.V, mesh.F, fi) : Eigen::Vector3d::UnitZ();
    face_n = face_n.norm() > 0 ? Eigen::Vector3d(face_n.normalized()) : Eigen::Vector3d::UnitZ();
    for (int k = 0; k < 3; ++k) {
      const Index v = mesh.F(fi, k);
      const std::size_t slot = 3 * f + static_cast<std::size_t>(k);
      std::copy_n(&a.mesh_positions[3 * static_cast<std::size_t>(v)], 3, &a.positions[3 * slot]);
      put3(a.normals, slot, flat ? face_n : Eigen::Vector3d(N.row(v).transpose()));
      color_of(field.per_face ? f : static_cast<std::size_t>(v), static_cast<std::size_t>(v), slot);
      if (textured) {
        const Eigen::Vector2d uv = corner_uv(texcoords, fi, k, v, options.checker_squares);
        a.uvs[2 * slot] = static_cast<float>(uv.x());
        a.uvs[2 * slot + 1] = static_cast<float>(uv.y());
      }
    }
  }
  return a;
}

// OSMesa context and the buffer it renders into, destroyed together.
class OffscreenContext {
 public:
  OffscreenContext(int width, int height) {
    const int attributes[] = {OSMESA_FORMAT,
                              OSMESA_RGBA,
                              OSMESA_DEPTH_BITS,
                              24,
                              OSMESA_PROFILE,
                              OSMESA_COMPAT_PROFILE,
                              OSMESA_CONTEXT_MAJOR_VERSION,
                              2,
                              0};
    context_ = OSMesaCreateContextAttribs(attributes, nullptr);
    if (!context_) throw std::runtime_error("cannot create an off-screen OpenGL context (OSMesa)");
    buffer_.resize(4 * static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
    if (!OSMesaMakeCurrent(context_, buffer_.data(), GL_UNSIGNED_BYTE, width, height)) {
      OSMesaDestroyContext(context_);
      throw std::runtime_error(fmt::format("cannot make a {}x{} off-screen OpenGL context current", width, height));
    }
  }
  OffscreenContext(const OffscreenContext&) = delete;
  OffscreenContext& operator=(const OffscreenContext&) = delete;
  ~OffscreenContext() { OSMesaDestroyContext(context_); }

  /// The rendered pixels, bottom row first (OSMesa's default).
  [[nodiscard]] const std::vector<std::uint8_t>& buffer() const { return buffer_; }

 private:
  OSMesaContext context_ = nullptr;
  std::vector<std::uint8_t> buffer_;
};

// A multisampled colour + depth framebuffer object; the default framebuffer when samples <= 1.
class MultisampleTarget {
 public:
  MultisampleTarget(int width, int height, int samples) : width_(width), height_(height) {
    GLint max_samples = 0;
    glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
    samples = std::min(samples, static_cast<int>(max_samples));
    if (samples <= 1) return;
    glGenFramebuffers(1, &fbo_);
    glGenRenderbuffers(2, renderbuffers_);
    glBindRenderbuffer(GL_RENDERBUFFER, renderbuffers_[0]);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, width, height);
    glBindRenderbuffer(GL_RENDERBUFFER, renderbuffers_[1]);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH_COMPONENT24, width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, renderbuffers_[0]);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, renderbuffers_[1]);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      // Fall back to the single-sampled default framebuffer rather than failing.
      glBindFramebuffer(GL_FRAMEBUFFER, 0);
      release();
    }
  }
  MultisampleTarget(const MultisampleTarget&) = delete;
  MultisampleTarget& operator=(const MultisampleTarget&) = delete;
  ~MultisampleTarget() { release(); }

  /// Averages the samples into the default framebuffer (OSMesa's buffer).
  void resolve() const {
    if (!fbo_) return;
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    glBlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
  }

 private:
  void release() {
    if (fbo_) glDeleteFramebuffers(1, &fbo_);
    if (renderbuffers_[0]) glDeleteRenderbuffers(2, renderbuffers_);
    fbo_ = 0;
    renderbuffers_[0] = renderbuffers_[1] = 0;
  }
  int width_, height_;
  GLuint fbo_ = 0;
  GLuint renderbuffers_[2] = {0, 0};
};

// The checkerboard: one period of 2 x 2 squares, light where the square indices have an even
// sum, with its mipmaps built here by 2 x 2 box filtering (exact and the same on every
// driver) rather than by glGenerateMipmap. Trilinear filtering keeps small or receding squares
// from aliasing into moire; the 128 texels per square keep magnified edges sharp.
class CheckerTexture {
 public:
  static constexpr int kSize = 256;
  static constexpr std::uint8_t kDark = 89, kLight = 230;  // 0.35 and 0.9 of full intensity

  CheckerTexture() {
    std::vector<std::uint8_t> level(static_cast<std::size_t>(kSize) * kSize);
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x)
        level[static_cast<std::size_t>(y) * kSize + x] = ((2 * x / kSize + 2 * y / kSize) % 2) ? kDark : kLight;
    glGenTextures(1, &id_);
    glBindTexture(GL_TEXTURE_2D, id_);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    int n = kSize;
    for (int lod = 0;; ++lod) {
      glTexImage2D(GL_TEXTURE_2D, lod, GL_LUMINANCE8, n, n, 0, GL_LUMINANCE, GL_UNSIGNED_BYTE, level.data());
      if (n == 1) break;
      const int half = n / 2;
      std::vector<std::uint8_t> next(static_cast<std::size_t>(half) * half);
      for (int y = 0; y < half; ++y)
        for (int x = 0; x < half; ++x) {
          const auto at = [&](int dx, int dy) {
            return unsigned{level[static_cast<std::size_t>(2 * y + dy) * n + 2 * x + dx]};
          };
          next[static_cast<std::size_t>(y) * half + x] =
              static_cast<std::uint8_t>((at(0, 0) + at(1, 0) + at(0, 1) + at(1, 1) + 2) / 4);
        }
      level = std::move(next);
      n = half;
    }
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    // Lit (or exaggerated-shading) colour times the texel: the squares darken the shading.
    glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
  }
  CheckerTexture(const CheckerTexture&) = delete;
  CheckerTexture& operator=(const CheckerTexture&) = delete;
  ~CheckerTexture() { glDeleteTextures(1, &id_); }

 private:
  GLuint id_ = 0;
};

void set_light(GLenum light, const Eigen::Vector3d& direction, float diffuse, float specular) {
  const Eigen::Vector3d d = direction.normalized();
  const GLfloat position[] = {static_cast<GLfloat>(d.x()), static_cast<GLfloat>(d.y()), static_cast<GLfloat>(d.z()),
                              0};  // w = 0: directional, in eye coordinates (identity modelview)
  const GLfloat diffuse4[] = {diffuse, diffuse, diffuse, 1}, specular4[] = {specular, specular, specular, 1};
  const GLfloat black[] = {0, 0, 0, 1};
  glLightfv(light, GL_POSITION, position);
  glLightfv(light, GL_AMBIENT, black);
  glLightfv(light, GL_DIFFUSE, diffuse4);
  glLightfv(light, GL_SPECULAR, specular4);
  glEnable(light);
}

// The 4x4 column-major modelview: rows of the rotation are the camera's right, up, back.
std::array<GLfloat, 16> modelview_matrix(const RenderCamera& c) {
  std::array<GLfloat, 16> m{};
  for (int k = 0; k < 3; ++k) {
    m[4 * k + 0] = static_cast<GLfloat>(c.right[k]);
    m[4 * k + 1] = static_cast<GLfloat>(c.up[k]);
    m[4 * k + 2] = static_cast<GLfloat>(c.back[k]);
  }
  m[15] = 1;
  return m;
}

// glOrtho for `camera`: the camera's centre_x/centre_y pixel is the frame centre, the depth
// range symmetric around it.
void load_projection(const RenderCamera& c) {
  glMatrixMode(GL_PROJECTION);
  glLoadIdentity();
  glOrtho(-c.centre_x / c.pixels_per_unit, (c.width - c.centre_x) / c.pixels_per_unit,
          -(c.height - c.centre_y) / c.pixels_per_unit, c.centre_y / c.pixels_per_unit, -c.depth_range, c.depth_range);
}

// ---- Legend --------------------------------------------------------------------------------

class Font {
 public:
  explicit Font(const std::string& path) {
    if (FT_Init_FreeType(&library_) != 0) throw std::runtime_error("cannot initialise FreeType");
    if (FT_New_Face(library_, path.c_str(), 0, &face_) != 0) {
      FT_Done_FreeType(library_);
      throw std::runtime_error(path +
                               ": cannot load the legend font (install fonts-dejavu-core, or render without "
                               "the colour bar)");
    }
  }
  Font(const Font&) = delete;
  Font& operator=(const Font&) = delete;
  ~Font() {
    FT_Done_Face(face_);
    FT_Done_FreeType(library_);
  }

  void set_pixel_size(int pixels) { FT_Set_Pixel_Sizes(face_, 0, static_cast<FT_UInt>(pixels)); }

  /// Advance width of `text` in pixels at the current size.
  int width(std::string_view text) {
    long advance = 0;
    for (char ch : text) {
      if (FT_Load_Char(face_, static_cast<unsigned char>(ch), FT_LOAD_DEFAULT) == 0) advance += face_->glyph->advance.x;
    }
    return static_cast<int>(advance >> 6);
  }

  /// Blends `text` in `color` into the image with its baseline starting at (x, baseline).
  void draw(Image& image, std::string_view text, int x, int baseline, const std::array<std::uint8_t, 3>& color) {
    long pen = static_cast<long>(x) << 6;
    for (char ch : text) {
      if (FT_Load_Char(face_, static_cast<unsigned char>(ch), FT_LOAD_RENDER) != 0) continue;
      const FT_GlyphSlot g = face_->glyph;
      const int left = static_cast<int>(pen >> 6) + g->bitmap_left, top = baseline - g->bitmap_top;
      for (unsigned r = 0; r < g->bitmap.rows; ++r) {
        for (unsigned c = 0; c < g->bitmap.width; ++c) {
          const int px = left + static_cast<int>(c), py = top + static_cast<int>(r);
          if (px < 0 || py < 0 || px >= image.width || py >= image.height) continue;
          const unsigned coverage = g->bitmap.buffer[r * static_cast<unsigned>(g->bitmap.pitch) + c];
          std::uint8_t* p = image.pixel(px, py);
          for (int k = 0; k < 3; ++k)
            p[k] = static_cast<std::uint8_t>((color[k] * coverage + p[k] * (255 - coverage) + 127) / 255);
          p[3] = std::max<std::uint8_t>(p[3], static_cast<std::uint8_t>(coverage));
        }
      }
      pen += g->advance.x;
    }
  }

 private:
  FT_Library library_ = nullptr;
  FT_Face face_ = nullptr;
};

void fill_rect(Image& image, int x0, int y0, int x1, int y1, const std::uint8_t* rgb) {
  for (int y = std::max(0, y0); y < std::min(image.height, y1); ++y)
    for (int x = std::max(0, x0); x < std::min(image.width, x1); ++x) {
      std::uint8_t* p = image.pixel(x, y);
      std::copy_n(rgb, 3, p);
      p[3] = 255;
    }
}

std::string label(double value) {
  return value == 0 ? std::string("0") : fmt::format("{:.3g}", value);
}

// The colour bar in the legend strip: top = scale.hi, bottom = scale.lo (the end rows carry
// exactly the end colours), labels above and below, "0" beside the middle of a diverging bar.
void draw_legend(Image& image, const ColorScale& scale, const RenderOptions& options) {
  const int strip_x = static_cast<int>(std::lround(image.width * (1 - kLegendWidthFraction)));
  const int strip_w = image.width - strip_x;
  const int bar_w = std::max(4, strip_w / 5);
  const int bar_x = strip_x + (strip_w - bar_w) / 2;
  const int bar_top = image.height / 4, bar_bottom = image.height - image.height / 4;
  const int bar_h = std::max(2, bar_bottom - bar_top);

  Eigen::VectorXd samples(bar_h);
  for (int i = 0; i < bar_h; ++i) samples[i] = scale.hi - (scale.hi - scale.lo) * i / (bar_h - 1);
  const Colors colors = scale.colors(samples);
  const std::uint8_t* bg = options.background.data();
  const bool dark_background = 0.299 * bg[0] + 0.587 * bg[1] + 0.114 * bg[2] < 128;
  const std::array<std::uint8_t, 3> ink =
      dark_background ? std::array<std::uint8_t, 3>{240, 240, 240} : std::array<std::uint8_t, 3>{20, 20, 20};
  fill_rect(image, bar_x - 1, bar_top - 1, bar_x + bar_w + 1, bar_top + bar_h + 1, ink.data());  // frame
  for (int i = 0; i < bar_h; ++i) fill_rect(image, bar_x, bar_top + i, bar_x + bar_w, bar_top + i + 1, &colors(i, 0));

  Font font(options.font_path);
  const std::string top = label(scale.hi), bottom = label(scale.lo);
  // The largest size (at most 1/50 of the height) at which every text fits the strip.
  int size = std::max(8, image.height / 50);
  for (; size > 6; --size) {
    font.set_pixel_size(size);
    const int widest = std::max({font.width(scale.quantity), font.width(top), font.width(bottom)});
    if (widest <= strip_w - strip_w / 8) break;
  }
  const auto centred = [&](const std::string& text, int baseline) {
    font.draw(image, text, strip_x + (strip_w - font.width(text)) / 2, baseline, ink);
  };
  centred(scale.quantity, bar_top - 2 * size);
  centred(top, bar_top - size / 2);
  centred(bottom, bar_top + bar_h + size + size / 4);
  if (scale.lo < 0 && scale.hi > 0) {
    const int mid = bar_top + static_cast<int>(std::lround((bar_h - 1) * scale.hi / (scale.hi - scale.lo)));
    fill_rect(image, bar_x + bar_w, mid, bar_x + bar_w + std::max(2, size / 3), mid + 1, ink.data());
    font.draw(image, "0", bar_x + bar_w + size / 2, mid + size / 3, ink);
  }
}

// What render_camera needs: the size and the frame.
void check_camera_options(const RenderOptions& options) {
  if (options.width < 16 || options.width > 8192 || options.height < 16 || options.height > 8192)
    throw std::invalid_argument(fmt::format("image size {}x{} is outside 16..8192", options.width, options.height));
  if (options.frame && !(options.frame->min.allFinite() && options.frame->max.allFinite() &&
                         (options.frame->max.array() >= options.frame->min.array()).all()))
    throw std::invalid_argument("the camera frame is not a finite box with min <= max");
}

void check_options(const Mesh& mesh, const RenderOptions& options) {
  check_camera_options(options);
  if (mesh.F.rows() > 0 && (mesh.F.minCoeff() < 0 || mesh.F.maxCoeff() >= mesh.V.rows()))
    throw std::invalid_argument("a face references a vertex that does not exist");
  if (!mesh.V.allFinite()) throw std::invalid_argument("the mesh has non-finite vertex coordinates");
  if (options.color_limit && !(*options.color_limit > 0 && std::isfinite(*options.color_limit)))
    throw std::invalid_argument("the colour limit must be a positive finite number");
  if (!(options.wireframe_width > 0 && options.wireframe_width <= 16))
    throw std::invalid_argument("wireframe width must be in (0, 16] pixels");
  if (options.shading == RenderShading::Exaggerated &&
      !(options.exaggerated_light.allFinite() && options.exaggerated_light.norm() > 0))
    throw std::invalid_argument("the exaggerated shading light must be a finite non-zero direction");
  if (options.checker_squares < 1 || options.checker_squares > 256)
    throw std::invalid_argument(fmt::format("checker squares {} is outside 1..256", options.checker_squares));
}

}  // namespace

RenderCamera render_camera(const Vertices& V, const RenderOptions& options) {
  check_camera_options(options);
  RenderCamera c = camera_for(options);
  c.frame = options.frame ? *options.frame : bounding_box(V);
  const BoundingBox& frame = c.frame;
  c.width = options.width, c.height = options.height;
  c.centre = 0.5 * (frame.min + frame.max);
  double radius = 0.5 * frame.diagonal();
  if (!(radius > 0)) radius = 1;  // a single point or an empty mesh: any scale will do
  // Depth range: everything in the mesh, even parts outside a frame taken from another mesh.
  double depth = radius;
  for (Index v = 0; v < V.rows(); ++v) depth = std::max(depth, (V.row(v).transpose() - c.centre).norm());
  c.depth_range = 1.05 * depth;
  // The frame box as seen in this view fills 92% of the image minus the legend strip in its
  // limiting direction, centred in that region.
  const double region_w = options.width * (1 - kLegendWidthFraction);
  double half_x = 0, half_y = 0;  // half-extents of the projected box
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d p((corner & 1 ? frame.max : frame.min).x(), (corner & 2 ? frame.max : frame.min).y(),
                            (corner & 4 ? frame.max : frame.min).z());
    half_x = std::max(half_x, std::abs((p - c.centre).dot(c.right)));
    half_y = std::max(half_y, std::abs((p - c.centre).dot(c.up)));
  }
  // A box seen edge-on (a flat mesh) has no extent in one direction: the other one decides.
  half_x = std::max(half_x, 1e-9 * radius);
  half_y = std::max(half_y, 1e-9 * radius);
  c.pixels_per_unit = 0.92 * std::min(region_w / (2 * half_x), options.height / (2 * half_y));
  c.centre_x = 0.5 * region_w;
  c.centre_y = 0.5 * options.height;
  return c;
}

DepthImage render_depth(const Mesh& mesh, const RenderOptions& options) {
  check_options(mesh, options);
  DepthImage out;
  out.camera = render_camera(mesh.V, options);
  out.width = options.width;
  out.height = options.height;
  const std::size_t pixels = static_cast<std::size_t>(out.width) * static_cast<std::size_t>(out.height);
  out.depth.assign(pixels, std::numeric_limits<float>::infinity());
  if (mesh.F.rows() == 0) return out;
  std::vector<float> positions(3 * static_cast<std::size_t>(mesh.V.rows()));
  for (Index v = 0; v < mesh.V.rows(); ++v)
    for (int k = 0; k < 3; ++k)
      positions[3 * static_cast<std::size_t>(v) + k] = static_cast<float>(mesh.V(v, k) - out.camera.centre[k]);
  OffscreenContext context(out.width, out.height);
  glViewport(0, 0, out.width, out.height);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  load_projection(out.camera);
  glMatrixMode(GL_MODELVIEW);
  const std::array<GLfloat, 16> modelview = modelview_matrix(out.camera);
  glLoadMatrixf(modelview.data());
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glEnableClientState(GL_VERTEX_ARRAY);
  glVertexPointer(3, GL_FLOAT, 0, positions.data());
  glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(3 * mesh.F.rows()), GL_UNSIGNED_INT, mesh.F.data());
  glDisableClientState(GL_VERTEX_ARRAY);
  std::vector<float> window(pixels);
  glReadPixels(0, 0, out.width, out.height, GL_DEPTH_COMPONENT, GL_FLOAT, window.data());
  if (const GLenum error = glGetError(); error != GL_NO_ERROR)
    throw std::runtime_error(fmt::format("OpenGL error 0x{:x} while rendering depth", error));
  // Window depth w in [0, 1] is (1 + depth / range) / 2 for glOrtho(..., -range, range); rows
  // bottom to top. 1 is the cleared far plane: no surface.
  const double range = out.camera.depth_range;
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x) {
      const float w = window[static_cast<std::size_t>(out.height - 1 - y) * out.width + x];
      if (w < 1.0f)
        out.depth[static_cast<std::size_t>(y) * out.width + x] = static_cast<float>((2.0 * w - 1.0) * range);
    }
  return out;
}

Image render_mesh(const Mesh& mesh, const RenderOptions& options, RenderInfo* info) {
  check_options(mesh, options);
  const int width = options.width, height = options.height;
  auto start = Clock::now();

  // Topology only when something needs it: curvature, or the unique edges of the wireframe.
  const bool curvature = options.color == RenderColor::Mean || options.color == RenderColor::Gauss;
  std::optional<Topology> topology;
  if ((curvature || options.wireframe) && mesh.F.rows() > 0) topology = build_topology(mesh.F, mesh.num_vertices());
  const ScalarField field =
      mesh.F.rows() > 0 ? scalar_field(mesh, options, topology ? &*topology : nullptr) : ScalarField{};

  const RenderCamera view = render_camera(mesh.V, options);
  const Eigen::Vector3d centre = view.centre;
  const bool exaggerated = options.shading == RenderShading::Exaggerated;
  Eigen::VectorXd shades;
  if (exaggerated && mesh.F.rows() > 0) {
    const Eigen::Vector3d& l = options.exaggerated_light;  // camera coordinates
    shades = exaggerated_shading(mesh.V, mesh.F, l.x() * view.right + l.y() * view.up + l.z() * view.back,
                                 options.exaggerated);
  }
  TexCoords texcoords;
  if (options.texture == RenderTexture::Checker) {
    texcoords = find_texcoords(mesh);
    if (texcoords.empty()) throw std::invalid_argument("render: --texture checker needs texture coordinates");
  }
  const DrawArrays arrays = build_arrays(mesh, options, field, shades, centre, texcoords);
  const double prepare_seconds = seconds_since(start);

  start = Clock::now();
  OffscreenContext context(width, height);
  MultisampleTarget target(width, height, options.samples);
  std::optional<CheckerTexture> checker;
  if (!arrays.uvs.empty()) checker.emplace();
  glViewport(0, 0, width, height);
  const auto& bg = options.background;
  glClearColor(bg[0] / 255.f, bg[1] / 255.f, bg[2] / 255.f, bg[3] / 255.f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);

  load_projection(view);
  glMatrixMode(GL_MODELVIEW);
  glLoadIdentity();

  // Lights in eye coordinates: a headlight and a weaker fill from the upper left. Both sides
  // of every face are lit, so the inside of an open mesh is not black.
  const GLfloat ambient[] = {0.22f, 0.22f, 0.22f, 1};
  glLightModelfv(GL_LIGHT_MODEL_AMBIENT, ambient);
  glLightModeli(GL_LIGHT_MODEL_TWO_SIDE, GL_TRUE);
  set_light(GL_LIGHT0, {0.1, 0.15, 1}, 0.68f, 0.18f);
  set_light(GL_LIGHT1, {-1, 1, 0.5}, 0.25f, 0.0f);
  const GLfloat specular[] = {1, 1, 1, 1};
  glMaterialfv(GL_FRONT_AND_BACK, GL_SPECULAR, specular);
  glMaterialf(GL_FRONT_AND_BACK, GL_SHININESS, 40);
  glColorMaterial(GL_FRONT_AND_BACK, GL_AMBIENT_AND_DIFFUSE);
  glEnable(GL_COLOR_MATERIAL);
  // Exaggerated shading is already in the vertex colours.
  if (!exaggerated) glEnable(GL_LIGHTING);
  glEnable(GL_NORMALIZE);  // normals are unit, but float rounding is not
  glShadeModel(GL_SMOOTH);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LEQUAL);
  const std::array<GLfloat, 16> modelview = modelview_matrix(view);
  glLoadMatrixf(modelview.data());

  if (mesh.F.rows() > 0) {
    // The surface is pushed back in depth so that the wireframe's lines, drawn at the true
    // depth, win the depth test on visible faces but are still hidden behind nearer faces.
    if (options.wireframe) {
      glEnable(GL_POLYGON_OFFSET_FILL);
      glPolygonOffset(1.0f, 1.0f);
    }
    glEnableClientState(GL_VERTEX_ARRAY);
    glEnableClientState(GL_NORMAL_ARRAY);
    glEnableClientState(GL_COLOR_ARRAY);
    glVertexPointer(3, GL_FLOAT, 0, arrays.positions.data());
    glNormalPointer(GL_FLOAT, 0, arrays.normals.data());
    glColorPointer(4, GL_UNSIGNED_BYTE, 0, arrays.rgba.data());
    if (checker) {
      glEnable(GL_TEXTURE_2D);
      glEnableClientState(GL_TEXTURE_COORD_ARRAY);
      glTexCoordPointer(2, GL_FLOAT, 0, arrays.uvs.data());
    }
    if (arrays.indexed)
      glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(3 * mesh.F.rows()), GL_UNSIGNED_INT, mesh.F.data());
    else
      glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(3 * mesh.F.rows()));
    glDisableClientState(GL_NORMAL_ARRAY);
    glDisableClientState(GL_COLOR_ARRAY);
    glDisableClientState(GL_TEXTURE_COORD_ARRAY);
    glDisable(GL_TEXTURE_2D);  // the wireframe is not textured
    glDisable(GL_POLYGON_OFFSET_FILL);

    if (options.wireframe) {
      glDisable(GL_LIGHTING);
      glColor3ub(25, 25, 30);
      glLineWidth(static_cast<GLfloat>(options.wireframe_width));
      glVertexPointer(3, GL_FLOAT, 0, arrays.mesh_positions.data());
      glDrawElements(GL_LINES, static_cast<GLsizei>(2 * topology->edges.rows()), GL_UNSIGNED_INT,
                     topology->edges.data());
    }
    glDisableClientState(GL_VERTEX_ARRAY);
  }
  glFinish();
  const double draw_seconds = seconds_since(start);

  start = Clock::now();
  target.resolve();
  glFinish();
  if (const GLenum error = glGetError(); error != GL_NO_ERROR)
    throw std::runtime_error(fmt::format("OpenGL error 0x{:x} while rendering", error));
  Image image;
  image.width = width;
  image.height = height;
  image.pixels.resize(4 * static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  const std::size_t row = 4 * static_cast<std::size_t>(width);
  for (int y = 0; y < height; ++y)  // OSMesa's rows run bottom to top
    std::copy_n(&context.buffer()[row * static_cast<std::size_t>(height - 1 - y)], row, &image.pixels[row * y]);
  const double readback_seconds = seconds_since(start);

  if (field.values.size() && options.color_bar) draw_legend(image, field.scale, options);
  if (info) {
    info->color_quantity = field.scale.quantity;
    info->color_min = field.values.size() ? field.scale.lo : 0;
    info->color_max = field.values.size() ? field.scale.hi : 0;
    info->frame = view.frame;
    info->camera = view;
    info->prepare_seconds = prepare_seconds;
    info->draw_seconds = draw_seconds;
    info->readback_seconds = readback_seconds;
  }
  return image;
}

std::string encode_png(const Image& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.pixels.size() != 4 * static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height))
    throw std::invalid_argument("encode_png: the image's pixel buffer does not match its size");
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  if (!png) throw std::runtime_error("cannot initialise libpng");
  png_infop png_info = png_create_info_struct(png);
  std::string out;
  // libpng reports errors by longjmp; nothing with a destructor is created between here and
  // the end of the block that could be skipped except `out`, which is declared before it.
  if (!png_info || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &png_info);
    throw std::runtime_error("PNG encoding failed");
  }
  png_set_write_fn(
      png, &out,
      [](png_structp p, png_bytep data, png_size_t size) {
        static_cast<std::string*>(png_get_io_ptr(p))->append(reinterpret_cast<const char*>(data), size);
      },
      nullptr);
  png_set_IHDR(png, png_info, static_cast<png_uint_32>(image.width), static_cast<png_uint_32>(image.height), 8,
               PNG_COLOR_TYPE_RGBA, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  // Renders are mostly flat background: a fast zlib level compresses them nearly as well.
  png_set_compression_level(png, 3);
  png_write_info(png, png_info);
  for (int y = 0; y < image.height; ++y)
    png_write_row(png, const_cast<png_bytep>(image.pixel(0, y)));  // libpng's API is not const-correct
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &png_info);
  return out;
}

void write_png(const std::filesystem::path& path, const Image& image) {
  write_text_file(path, encode_png(image));
}

}  // namespace vertexflow
