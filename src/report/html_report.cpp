#include "vertexflow/html_report.h"

#include "html_assets.h"
#include "vertexflow/colormap.h"
#include "vertexflow/curvature.h"
#include "vertexflow/io.h"
#include "vertexflow/quality.h"
#include "vertexflow/topology.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <unordered_map>
#include <vector>

namespace vertexflow {
namespace {

using Json = nlohmann::ordered_json;

// Checker squares per unit of texture coordinate in the page's texture view at first (the page
// can change it); render.h's default.
constexpr int kCheckerSquares = 16;

// The page reads the arrays with Float32Array / Uint32Array views, which use the browser's byte
// order: little-endian on every platform a browser runs on. Bytes are copied as they are.
static_assert(std::endian::native == std::endian::little, "the report's typed arrays are little-endian");

// RFC 4648 base64. Written here because it is a dozen lines and none of the project's
// dependencies has a public encoder (Boost's is in a detail namespace).
std::string base64(const void* data, std::size_t size) {
  static constexpr char alphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* bytes = static_cast<const unsigned char*>(data);
  std::string out;
  out.reserve((size + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < size; i += 3) {
    const std::uint32_t v = (std::uint32_t{bytes[i]} << 16) | (std::uint32_t{bytes[i + 1]} << 8) | bytes[i + 2];
    out += alphabet[(v >> 18) & 63];
    out += alphabet[(v >> 12) & 63];
    out += alphabet[(v >> 6) & 63];
    out += alphabet[v & 63];
  }
  if (i < size) {
    const bool two = i + 1 < size;
    const std::uint32_t v = (std::uint32_t{bytes[i]} << 16) | (two ? std::uint32_t{bytes[i + 1]} << 8 : 0u);
    out += alphabet[(v >> 18) & 63];
    out += alphabet[(v >> 12) & 63];
    out += two ? alphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

template <class T>
std::string base64(const std::vector<T>& values) {
  return base64(values.data(), values.size() * sizeof(T));
}

std::string base64(const Colors& colors) {
  return base64(colors.data(), static_cast<std::size_t>(colors.size()));
}

// Which display face each face of one mesh becomes.
struct DisplayFaces {
  std::vector<Index> face_of;          // #F; -1 for a face that collapsed
  std::vector<std::uint32_t> indices;  // 3 per display face
  [[nodiscard]] Index size() const { return static_cast<Index>(indices.size() / 3); }
};

// Which display vertex each mesh vertex becomes (one map for both meshes, so displacement
// stays per vertex), and the display faces of the input and, when it has its own (edge flips),
// of the result.
struct DisplayMesh {
  std::vector<Index> vertex_of;  // #V
  Index num_vertices = 0;
  DisplayFaces faces;
  std::optional<DisplayFaces> result_faces;
};

DisplayFaces all_faces(const Faces& F) {
  DisplayFaces d;
  d.face_of.resize(static_cast<std::size_t>(F.rows()));
  std::iota(d.face_of.begin(), d.face_of.end(), 0);
  d.indices.assign(F.data(), F.data() + F.size());
  return d;
}

DisplayMesh full_display(const Faces& F, const Faces* result_F, Index num_vertices) {
  DisplayMesh d;
  d.vertex_of.resize(static_cast<std::size_t>(num_vertices));
  std::iota(d.vertex_of.begin(), d.vertex_of.end(), 0);
  d.num_vertices = num_vertices;
  d.faces = all_faces(F);
  if (result_F) d.result_faces = all_faces(*result_F);
  return d;
}

struct TripleHash {
  std::size_t operator()(const std::array<Index, 3>& t) const {
    std::uint64_t h = static_cast<std::uint32_t>(t[0]);
    h = h * 0x9E3779B97F4A7C15ull ^ static_cast<std::uint32_t>(t[1]);
    h = h * 0x9E3779B97F4A7C15ull ^ static_cast<std::uint32_t>(t[2]);
    return static_cast<std::size_t>(h ^ (h >> 29));
  }
};

// Vertex clustering (Rossignac and Borrel 1993) on a grid of cubic cells: the vertices in a
// cell become one, faces with two corners in one cell vanish and faces over the same three
// cells are kept once. Written here rather than taken from CGAL because it is for display only
// and must (a) run in linear time on millions of faces, (b) give one vertex map that applies to
// the input and the result alike, so both keep shared vertices and per-vertex displacement
// (and a result with its own faces has them mapped through the same clusters); CGAL's
// edge-collapse simplification is neither linear nor shareable between two meshes. Cluster and
// face order follow the mesh's order, so the output is deterministic.

// Cluster of every vertex for cells of side `cell`; returns the number of clusters.
Index cluster_once(const Vertices& V, const Eigen::Vector3d& origin, double cell, std::vector<Index>& cluster_of) {
  constexpr std::int64_t kCellsPerAxis = std::int64_t{1} << 21;  // three axes in a 64-bit key
  cluster_of.resize(static_cast<std::size_t>(V.rows()));
  std::unordered_map<std::uint64_t, Index> cluster_of_cell;
  cluster_of_cell.reserve(static_cast<std::size_t>(V.rows()));
  Index clusters = 0;
  for (Index v = 0; v < V.rows(); ++v) {
    std::uint64_t key = 0;
    for (int k = 0; k < 3; ++k) {
      const auto c = static_cast<std::int64_t>(std::floor((V(v, k) - origin[k]) / cell));
      key |= static_cast<std::uint64_t>(std::clamp<std::int64_t>(c, 0, kCellsPerAxis - 1)) << (21 * k);
    }
    const auto [it, inserted] = cluster_of_cell.try_emplace(key, clusters);
    if (inserted) ++clusters;
    cluster_of[static_cast<std::size_t>(v)] = it->second;
  }
  return clusters;
}

// Faces whose corners lie in three different clusters: an upper bound of the display's faces.
Index surviving_faces(const Faces& F, const std::vector<Index>& cluster_of) {
  Index n = 0;
  for (Index f = 0; f < F.rows(); ++f) {
    const Index a = cluster_of[static_cast<std::size_t>(F(f, 0))], b = cluster_of[static_cast<std::size_t>(F(f, 1))],
                c = cluster_of[static_cast<std::size_t>(F(f, 2))];
    n += a != b && b != c && a != c;
  }
  return n;
}

// F's faces over the clusters: collapsed faces dropped, faces over the same three clusters kept
// once.
DisplayFaces clustered_faces(const Faces& F, const std::vector<Index>& vertex_of, Index max_faces) {
  DisplayFaces d;
  d.face_of.assign(static_cast<std::size_t>(F.rows()), -1);
  std::unordered_map<std::array<Index, 3>, Index, TripleHash> face_of_triple;
  face_of_triple.reserve(static_cast<std::size_t>(max_faces));
  for (Index f = 0; f < F.rows(); ++f) {
    const std::array<Index, 3> c{vertex_of[static_cast<std::size_t>(F(f, 0))],
                                 vertex_of[static_cast<std::size_t>(F(f, 1))],
                                 vertex_of[static_cast<std::size_t>(F(f, 2))]};
    if (c[0] == c[1] || c[1] == c[2] || c[0] == c[2]) continue;
    std::array<Index, 3> sorted = c;
    std::sort(sorted.begin(), sorted.end());
    const auto [it, inserted] = face_of_triple.try_emplace(sorted, d.size());
    if (inserted)
      d.indices.insert(d.indices.end(), {static_cast<std::uint32_t>(c[0]), static_cast<std::uint32_t>(c[1]),
                                         static_cast<std::uint32_t>(c[2])});
    d.face_of[static_cast<std::size_t>(f)] = it->second;
  }
  return d;
}

// Grows the cell until at most max_faces faces of each mesh survive. The first guess assumes
// about two faces per cluster and one occupied cell per cell-sized patch of surface.
DisplayMesh cluster_vertices(const Vertices& V, const Faces& F, const Faces* result_F, Index max_faces) {
  const BoundingBox box = bounding_box(V);
  double area = 0;
  for (Index f = 0; f < F.rows(); ++f) area += face_area(V, F, f);
  const double diagonal = std::max(box.diagonal(), 1e-300);
  double cell = area > 0 ? std::sqrt(area / std::max<double>(1.0, max_faces / 2.0)) : diagonal / 1000;
  // Cells of at least diagonal / 2^20 keep every coordinate inside the key's 21 bits.
  cell = std::max(cell, diagonal / double(1 << 20));
  DisplayMesh d;
  for (;;) {
    d.num_vertices = cluster_once(V, box.min, cell, d.vertex_of);
    Index faces = surviving_faces(F, d.vertex_of);
    if (result_F) faces = std::max(faces, surviving_faces(*result_F, d.vertex_of));
    if (faces <= max_faces) break;
    // Face count falls roughly with the square of the cell size; at least 10% larger per try,
    // so a cell beyond the diagonal (one cluster, no faces) is reached in a few dozen tries.
    cell *= std::max(1.1, 1.02 * std::sqrt(static_cast<double>(faces) / max_faces));
  }
  d.faces = clustered_faces(F, d.vertex_of, max_faces);
  if (result_F) d.result_faces = clustered_faces(*result_F, d.vertex_of, max_faces);
  return d;
}

// Per display vertex mean of per-vertex rows or values.
Vertices average_rows(const DisplayMesh& d, const Vertices& P) {
  Vertices sum = Vertices::Zero(d.num_vertices, 3);
  Eigen::VectorXd count = Eigen::VectorXd::Zero(d.num_vertices);
  for (Index v = 0; v < P.rows(); ++v) {
    sum.row(d.vertex_of[static_cast<std::size_t>(v)]) += P.row(v);
    count[d.vertex_of[static_cast<std::size_t>(v)]] += 1;
  }
  for (Index c = 0; c < d.num_vertices; ++c) sum.row(c) /= std::max(1.0, count[c]);
  return sum;
}

Eigen::VectorXd average(const std::vector<Index>& target_of, Index targets, const Eigen::VectorXd& values) {
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(targets), count = Eigen::VectorXd::Zero(targets);
  for (Eigen::Index i = 0; i < values.size(); ++i) {
    const Index t = target_of[static_cast<std::size_t>(i)];
    if (t < 0) continue;
    sum[t] += values[i];
    count[t] += 1;
  }
  return sum.cwiseQuotient(count.cwiseMax(1.0));
}

std::vector<float> float_positions(const Vertices& P, const Eigen::Vector3d& offset) {
  std::vector<float> out(static_cast<std::size_t>(P.size()));
  for (Index v = 0; v < P.rows(); ++v)
    for (int k = 0; k < 3; ++k) out[static_cast<std::size_t>(3 * v + k)] = static_cast<float>(P(v, k) - offset[k]);
  return out;
}

// A mesh's texture coordinates as the render's checker uses them (render.h): the first TexCoord
// corner channel with two components, else the first such vertex channel; nullopt without.
// Returned per face corner (#F x 6: u, v of corners 0, 1, 2); a corner without a value (-1)
// gets the centre of the first (light) square at the default count, as the render does.
std::optional<Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor>> corner_texcoords(const Mesh& mesh) {
  Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor> uv(mesh.F.rows(), 6);
  for (const CornerChannel& c : mesh.attributes.corner) {
    if (c.channel.role != AttributeRole::TexCoord || c.channel.width() < 2 || c.corners.rows() != mesh.F.rows())
      continue;
    for (Index f = 0; f < mesh.F.rows(); ++f)
      for (int k = 0; k < 3; ++k) {
        const std::int32_t row = c.corners(f, k);
        const bool valid = row >= 0 && row < c.channel.rows();
        uv(f, 2 * k) = valid ? c.channel.values(row, 0) : 0.5 / kCheckerSquares;
        uv(f, 2 * k + 1) = valid ? c.channel.values(row, 1) : 0.5 / kCheckerSquares;
      }
    return uv;
  }
  for (const AttributeChannel& c : mesh.attributes.vertex) {
    if (c.role != AttributeRole::TexCoord || c.width() < 2 || c.rows() != mesh.V.rows()) continue;
    for (Index f = 0; f < mesh.F.rows(); ++f)
      for (int k = 0; k < 3; ++k) {
        uv(f, 2 * k) = c.values(mesh.F(f, k), 0);
        uv(f, 2 * k + 1) = c.values(mesh.F(f, k), 1);
      }
    return uv;
  }
  return std::nullopt;
}

// Texture coordinates per corner of the display faces: a display face takes those of the first
// mesh face mapped to it, whose corners lie in its clusters in the same order (clustered_faces
// keeps the first face's corner order), so a decimated view still shows the pattern.
std::vector<float> display_texcoords(const Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor>& uv,
                                     const DisplayFaces& faces) {
  std::vector<float> out(6 * static_cast<std::size_t>(faces.size()));
  std::vector<char> done(static_cast<std::size_t>(faces.size()), 0);
  for (std::size_t f = 0; f < faces.face_of.size(); ++f) {
    const Index d = faces.face_of[f];
    if (d < 0 || done[static_cast<std::size_t>(d)]) continue;
    done[static_cast<std::size_t>(d)] = 1;
    for (int k = 0; k < 6; ++k)
      out[6 * static_cast<std::size_t>(d) + static_cast<std::size_t>(k)] =
          static_cast<float>(uv(static_cast<Index>(f), k));
  }
  return out;
}

// Colour stops and end labels of one map, for the page's legend.
Json legend(const Eigen::VectorXd& stops, double limit, std::string low, std::string high, std::string unit) {
  const Colors c = diverging_colors(stops, limit);
  Json colors = Json::array();
  for (Index i = 0; i < c.rows(); ++i) colors.push_back({c(i, 0), c(i, 1), c(i, 2)});
  return {{"colors", colors}, {"labels", {std::move(low), std::move(high)}}, {"unit", std::move(unit)}};
}

std::string escape_html(std::string_view text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// JSON that is safe inside <script>: ASCII only, and every '<' (only possible inside strings)
// as \u003c, so no "</script>" or "<!--" in a file name can end or confuse the element.
std::string script_safe_json(const Json& json) {
  // File names need not be UTF-8: invalid bytes become U+FFFD rather than an exception.
  const std::string text = json.dump(-1, ' ', /*ensure_ascii=*/true, Json::error_handler_t::replace);
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    if (c == '<')
      out += "\\u003c";
    else
      out += c;
  }
  return out;
}

// The template with its three markers replaced; each must occur exactly once.
std::string fill_template(std::string_view title, std::string_view data, std::string_view script) {
  const std::string_view page = html_assets::page_template();
  std::string out;
  out.reserve(page.size() + data.size() + script.size() + title.size());
  std::size_t from = 0;
  for (const auto& [marker, text] : {std::pair<std::string_view, std::string_view>{"@VF_TITLE@", title},
                                     {"@VF_DATA@", data},
                                     {"@VF_SCRIPT@", script}}) {
    const std::size_t at = page.find(marker, from);
    if (at == std::string_view::npos) throw std::logic_error(fmt::format("report template: marker {} missing", marker));
    out.append(page.substr(from, at - from));
    out.append(text);
    from = at + marker.size();
  }
  out.append(page.substr(from));
  return out;
}

// The checks both html_report overloads make before anything else, and the metrics parsed.
Json checked_metrics(const Mesh& input, const Mesh& result, std::string_view metrics_json,
                     const HtmlReportOptions& options) {
  if (result.V.rows() != input.V.rows() || result.F.rows() != input.F.rows())
    throw std::invalid_argument(
        fmt::format("the result ({} vertices, {} faces) does not have the input's vertex and face counts ({} vertices, "
                    "{} faces): a report compares a result with its own input",
                    result.num_vertices(), result.num_faces(), input.num_vertices(), input.num_faces()));
  // The result's own faces (edge flips) index the shared vertices; the input's are its own.
  if (result.F != input.F && result.F.size() > 0 &&
      (result.F.minCoeff() < 0 || result.F.maxCoeff() >= result.num_vertices()))
    throw std::invalid_argument("the result has a face corner that is not one of its vertices");
  if (options.max_display_faces < 1) throw std::invalid_argument("max_display_faces must be at least 1");
  Json metrics = Json::object();
  if (!metrics_json.empty()) {
    metrics = Json::parse(metrics_json, nullptr, /*allow_exceptions=*/false);
    if (!metrics.is_object()) throw std::invalid_argument("the metrics are not a JSON object");
  }
  return metrics;
}

// The page, given each mesh's mean curvature H.
std::string report_page(const Mesh& input, const Mesh& result, const Eigen::VectorXd& H_input,
                        const Eigen::VectorXd& H_result, Json metrics, const HtmlReportOptions& options) {
  const Faces& F = input.F;
  // A result with faces of its own (edge flips) is shown, coloured and measured on them.
  const Faces* result_F = result.F != F ? &result.F : nullptr;
  const Eigen::VectorXd q_input = triangle_quality(input.V, F);
  const Eigen::VectorXd q_result = triangle_quality(result.V, result.F);
  const Eigen::VectorXd moved = (result.V - input.V).rowwise().norm();
  // Limits from the full meshes, so a decimated view keeps the scale of the real data.
  const double H_limit = robust_color_limit(H_input);
  const double moved_limit = robust_color_limit(moved);

  const bool decimate = input.num_faces() > options.max_display_faces;
  const DisplayMesh d = decimate ? cluster_vertices(input.V, F, result_F, options.max_display_faces)
                                 : full_display(F, result_F, input.num_vertices());
  const DisplayFaces& result_faces = d.result_faces ? *d.result_faces : d.faces;
  const BoundingBox box = bounding_box(input.V);
  // float32 relative to the box centre keeps ~7 significant digits of the shape itself even
  // for meshes far from the origin.
  const Eigen::Vector3d offset = 0.5 * (box.min + box.max);

  const auto mesh_data = [&](const Vertices& V, const Eigen::VectorXd& H, const DisplayFaces& faces,
                             const Eigen::VectorXd& q) {
    const Eigen::VectorXd H_shown = average(d.vertex_of, d.num_vertices, H);
    const Eigen::VectorXd q_shown = average(faces.face_of, faces.size(), q);
    return Json{{"positions", base64(float_positions(decimate ? average_rows(d, V) : V, offset))},
                {"mean_curvature", base64(diverging_colors(H_shown, H_limit))},
                {"quality", base64(diverging_colors(Eigen::VectorXd(0.5 - q_shown.array()), 0.5))}};
  };

  std::string note;
  if (decimate)
    note = fmt::format(
        "Large mesh: the views show a decimation for display only ({} of {} faces{}, {} of {} vertices, by vertex "
        "clustering). Histograms and metrics describe the full meshes.",
        d.faces.size(), input.num_faces(),
        d.result_faces ? fmt::format(", {} of the result's own faces", d.result_faces->size()) : "", d.num_vertices,
        input.num_vertices());

  Json data;
  data["format"] = 1;
  data["title"] = options.title;
  data["labels"] = {{"input", options.input_label}, {"result", options.result_label}};
  data["counts"] = {{"vertices", input.num_vertices()}, {"faces", input.num_faces()}};
  data["offset"] = {offset.x(), offset.y(), offset.z()};
  data["display"] = {{"vertices", d.num_vertices},
                     {"faces", d.faces.size()},
                     {"decimated", decimate},
                     {"note", note},
                     {"indices", base64(d.faces.indices)}};
  // Only when they differ, so a result with the input's faces gives the same page as before.
  if (d.result_faces) {
    data["display"]["result_faces"] = d.result_faces->size();
    data["display"]["result_indices"] = base64(d.result_faces->indices);
  }
  data["input"] = mesh_data(input.V, H_input, d.faces, q_input);
  data["result"] = mesh_data(result.V, H_result, result_faces, q_result);
  // The checker view needs texture coordinates on both sides; absent otherwise, so a page
  // without them is the same as before.
  const auto input_uv = corner_texcoords(input), result_uv = corner_texcoords(result);
  if (input_uv && result_uv) {
    data["input"]["uv"] = base64(display_texcoords(*input_uv, d.faces));
    data["result"]["uv"] = base64(display_texcoords(*result_uv, result_faces));
    data["texture"] = {{"squares", kCheckerSquares}};
  }
  data["displacement"] = base64(diverging_colors(average(d.vertex_of, d.num_vertices, moved), moved_limit));
  data["legend"] = {
      {"mean_curvature", legend(Eigen::Vector3d(-H_limit, 0, H_limit), H_limit, fmt::format("{:.3g}", -H_limit),
                                fmt::format("+{:.3g}", H_limit), "(1/length; red convex)")},
      {"quality", legend(Eigen::Vector3d(0.5, 0, -0.5), 0.5, "0", "1", "(2r/R; red = sliver)")},
      {"displacement",
       legend(Eigen::Vector2d(0, moved_limit), moved_limit, "0", fmt::format("{:.3g}", moved_limit), "(mesh units)")}};
  data["histograms"] = {{"input", summarize_quality(q_input).histogram},
                        {"result", summarize_quality(q_result).histogram}};
  data["metrics"] = std::move(metrics);

  return fill_template(escape_html(options.title), script_safe_json(data), html_assets::viewer_script());
}

}  // namespace

std::string html_report(const Mesh& input, const Mesh& result, std::string_view metrics_json,
                        const HtmlReportOptions& options) {
  Json metrics = checked_metrics(input, result, metrics_json, options);
  const Topology topology = build_topology(input.F, input.num_vertices());
  const Eigen::VectorXd H_input = principal_curvatures(input.V, input.F, topology).mean();
  // Each mesh's curvature on its own faces (a result of edge flips has its own).
  const Eigen::VectorXd H_result = result.F == input.F ? principal_curvatures(result.V, input.F, topology).mean()
                                                       : principal_curvatures(result.V, result.F).mean();
  return report_page(input, result, H_input, H_result, std::move(metrics), options);
}

std::string html_report(const Mesh& input, const Mesh& result, const Curvature& input_curvature,
                        const Curvature& result_curvature, std::string_view metrics_json,
                        const HtmlReportOptions& options) {
  Json metrics = checked_metrics(input, result, metrics_json, options);
  const auto check = [&](const Curvature& curvature, const char* name) {
    if (curvature.k1.size() != input.num_vertices() || curvature.k2.size() != input.num_vertices())
      throw std::invalid_argument(fmt::format("the {} curvature has {} vertices, the mesh {}", name,
                                              curvature.k1.size(), input.num_vertices()));
  };
  check(input_curvature, "input");
  check(result_curvature, "result");
  return report_page(input, result, input_curvature.mean(), result_curvature.mean(), std::move(metrics), options);
}

void write_html_report(const std::filesystem::path& path, const Mesh& input, const Mesh& result,
                       std::string_view metrics_json, const HtmlReportOptions& options) {
  write_text_file(path, html_report(input, result, metrics_json, options));
}

void write_html_report(const std::filesystem::path& path, const Mesh& input, const Mesh& result,
                       const Curvature& input_curvature, const Curvature& result_curvature,
                       std::string_view metrics_json, const HtmlReportOptions& options) {
  write_text_file(path, html_report(input, result, input_curvature, result_curvature, metrics_json, options));
}

}  // namespace vertexflow
