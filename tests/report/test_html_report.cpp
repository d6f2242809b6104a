// The HTML report page: self-contained, both meshes' data decoded back and compared with the
// meshes, colours wired to the right quantities, deterministic bytes, display decimation of
// large meshes, results with faces of their own (edge flips), each mesh's own texture
// coordinates for the checker view. The page in a real browser is tested by
// web/tests/report_browser.mjs.
#include "page_data.h"
#include "shapes.h"
#include "test_support.h"

#include "vertexflow/curvature.h"
#include "vertexflow/html_report.h"
#include "vertexflow/io.h"
#include "vertexflow/quality.h"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace vertexflow {
namespace {

// A torus and a copy whose vertices moved by a smooth, known field (same connectivity).
struct Pair {
  Mesh input, result;
};

Pair torus_pair() {
  Pair p;
  // r > R / 2: the inner equator has negative mean curvature.
  p.input = test::torus(1.0, 0.6, 48, 24);
  p.result = p.input;
  for (Index v = 0; v < p.input.num_vertices(); ++v) {
    const double x = p.input.V(v, 0), y = p.input.V(v, 1);
    p.result.V(v, 2) += 0.02 * std::sin(3 * x) * std::cos(2 * y);
  }
  return p;
}

// Faces with interior edges flipped as edge_flips.h flips them: (a, b, c) and (b, a, d) become
// (a, d, c) and (d, b, c), each keeping its face index. No vertex takes part in two flips and no
// new diagonal is an edge already, so the faces stay a closed manifold surface.
Faces with_flipped_edges(const Faces& F, Index num_vertices) {
  std::map<std::pair<Index, Index>, Index> face_of_edge;  // directed edge -> face
  std::set<std::pair<Index, Index>> edges;
  for (Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const Index a = F(f, k), b = F(f, (k + 1) % 3);
      face_of_edge[{a, b}] = f;
      edges.insert(std::minmax(a, b));
    }
  Faces out = F;
  std::vector<char> used(static_cast<std::size_t>(num_vertices), 0);
  const auto free = [&](Index v) { return !used[static_cast<std::size_t>(v)]; };
  for (Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const Index a = F(f, k), b = F(f, (k + 1) % 3), c = F(f, (k + 2) % 3);
      const auto twin = face_of_edge.find({b, a});
      if (twin == face_of_edge.end()) continue;
      const Index g = twin->second;
      const Index d = F(g, 0) + F(g, 1) + F(g, 2) - a - b;
      if (!free(a) || !free(b) || !free(c) || !free(d) || edges.count(std::minmax(c, d))) continue;
      out.row(f) << a, d, c;
      out.row(g) << d, b, c;
      for (const Index v : {a, b, c, d}) used[static_cast<std::size_t>(v)] = 1;
      edges.insert(std::minmax(c, d));
      break;
    }
  return out;
}

// An ellipsoid (so mean curvature varies and its colours do not saturate) and a result with a
// bump and its own faces: near-equilateral pairs flipped into thin ones.
Pair flipped_ellipsoid_pair(int levels) {
  Pair p;
  p.input = test::icosphere(1.0, levels);
  p.input.V.col(0) *= 1.6;
  p.input.V.col(2) *= 0.7;
  p.result = p.input;
  for (Index v = 0; v < p.input.num_vertices(); ++v)
    p.result.V.row(v) *= 1.0 + 0.05 * std::sin(3 * p.input.V(v, 0)) * std::cos(2 * p.input.V(v, 1));
  p.result.F = with_flipped_edges(p.input.F, p.input.num_vertices());
  return p;
}

Index changed_faces(const Pair& p) {
  Index n = 0;
  for (Index f = 0; f < p.input.num_faces(); ++f) n += p.result.F.row(f) != p.input.F.row(f);
  return n;
}

std::vector<std::int64_t> histogram(const Vertices& V, const Faces& F) {
  const auto counts = summarize_quality(triangle_quality(V, F)).histogram;
  return {counts.begin(), counts.end()};
}

// The display's faces as sets of three display vertices, each checked: in range, three
// different corners, none twice.
std::set<std::array<std::uint32_t, 3>> display_triples(const std::vector<std::uint32_t>& indices, Index vertices) {
  std::set<std::array<std::uint32_t, 3>> distinct;
  for (std::size_t f = 0; f + 2 < indices.size(); f += 3) {
    std::array<std::uint32_t, 3> t{indices[f], indices[f + 1], indices[f + 2]};
    for (const auto i : t) EXPECT_LT(i, static_cast<std::uint32_t>(vertices));
    EXPECT_TRUE(t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) << "collapsed face kept";
    std::sort(t.begin(), t.end());
    EXPECT_TRUE(distinct.insert(t).second) << "duplicate face kept";
  }
  return distinct;
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

using test::decode_array;
using test::decode_base64;
using test::page_data;

// The page's colour convention, written out here independently of colormap.cpp: Moreland's
// cool-warm end points (blue 59 76 192 at -1, white 221 221 221 at 0, red 180 4 38 at +1),
// linear in between, values scaled by a limit and clamped.
Eigen::Vector3d documented_color(double value, double limit) {
  const double t = std::clamp(value / limit, -1.0, 1.0);
  const Eigen::Vector3d blue(59, 76, 192), white(221, 221, 221), red(180, 4, 38);
  return t >= 0 ? Eigen::Vector3d(white + t * (red - white)) : Eigen::Vector3d(white - t * (blue - white));
}

// The robust limit the page promises (colormap.h): the larger of |5th| and |95th| percentile
// (nearest rank), by sorting here.
double documented_limit(const Eigen::VectorXd& values) {
  std::vector<double> sorted(values.data(), values.data() + values.size());
  std::sort(sorted.begin(), sorted.end());
  auto rank = [&](double p) {
    return sorted[static_cast<std::size_t>(std::ceil(p / 100.0 * static_cast<double>(sorted.size()))) - 1];
  };
  return std::max(std::abs(rank(5)), std::abs(rank(95)));
}

// The page's colours for `values` (one RGB triple each) are the documented map's, to a unit of
// rounding.
void expect_colors(const nlohmann::json& field, const Eigen::VectorXd& values, double limit, const std::string& what) {
  const std::vector<unsigned char> bytes = decode_base64(field.get<std::string>());
  ASSERT_EQ(bytes.size(), static_cast<std::size_t>(3 * values.size())) << what;
  double worst = 0;
  for (Eigen::Index i = 0; i < values.size(); ++i) {
    const Eigen::Vector3d expected = documented_color(values[i], limit);
    for (int k = 0; k < 3; ++k)
      worst = std::max(worst, std::abs(static_cast<double>(bytes[static_cast<std::size_t>(3 * i + k)]) - expected[k]));
  }
  EXPECT_LE(worst, 0.5 + 1e-9) << what;
}

TEST(HtmlReport, IsSelfContained) {
  const Pair p = torus_pair();
  const std::string html = html_report(p.input, p.result, R"({"answer": 42})");
  const std::string l = lower(html);
  // Nothing that makes the browser fetch: no src/href to a URL, no external script, style sheet
  // or import; exactly the data and the inline viewer as scripts.
  for (const char* bad : {"src=\"http", "src='http", "src=http", "href=\"http", "href='http", "href=http", "<link",
                          "@import", "src=\"//", "href=\"//"})
    EXPECT_EQ(count(l, bad), 0u) << bad;
  EXPECT_EQ(count(l, "<script"), 2u);
  EXPECT_EQ(count(l, "</script"), 2u);
  for (const std::string& tag :
       std::vector<std::string>{"<script id=\"vertexflow-data\" type=\"application/json\">", "<script>"})
    EXPECT_EQ(count(l, tag), 1u) << tag;
  EXPECT_EQ(count(html, "@VF_"), 0u) << "a template marker was left in";
  EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_NE(l.find("three.js authors"), std::string::npos) << "the bundled viewer (three.js) is inline";
}

TEST(HtmlReport, HoldsBothMeshesAndTheirColours) {
  const Pair p = torus_pair();
  const std::string metrics = R"({"flipped_faces": 0, "edge_error_cv": {"input": 0.7, "result": 0.6}})";
  HtmlReportOptions options;
  options.input_label = "in.off";
  options.result_label = "out.ply";
  const nlohmann::json data = page_data(html_report(p.input, p.result, metrics, options));
  const Index nv = p.input.num_vertices(), nf = p.input.num_faces();
  EXPECT_EQ(data["counts"]["vertices"], nv);
  EXPECT_EQ(data["counts"]["faces"], nf);
  EXPECT_EQ(data["display"]["vertices"], nv);
  EXPECT_EQ(data["display"]["faces"], nf);
  EXPECT_EQ(data["display"]["decimated"], false);
  EXPECT_EQ(data["display"]["note"], "");
  EXPECT_FALSE(data["display"].contains("result_indices")) << "the result has the input's faces";
  EXPECT_FALSE(data["display"].contains("result_faces"));
  EXPECT_EQ(data["labels"]["input"], "in.off");
  EXPECT_EQ(data["labels"]["result"], "out.ply");
  EXPECT_EQ(data["metrics"], nlohmann::json::parse(metrics));

  const auto indices = decode_array<std::uint32_t>(data["display"]["indices"]);
  ASSERT_EQ(indices.size(), static_cast<std::size_t>(3 * nf));
  for (Index f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k)
      ASSERT_EQ(indices[static_cast<std::size_t>(3 * f + k)], static_cast<std::uint32_t>(p.input.F(f, k)));

  const Eigen::Vector3d offset(data["offset"][0].get<double>(), data["offset"][1].get<double>(),
                               data["offset"][2].get<double>());
  for (const auto& [name, mesh] : {std::pair<std::string, const Mesh*>{"input", &p.input}, {"result", &p.result}}) {
    const auto positions = decode_array<float>(data[name]["positions"]);
    ASSERT_EQ(positions.size(), static_cast<std::size_t>(3 * nv)) << name;
    double worst = 0;
    for (Index v = 0; v < nv; ++v)
      for (int k = 0; k < 3; ++k)
        worst = std::max(worst, std::abs(positions[static_cast<std::size_t>(3 * v + k)] + offset[k] - mesh->V(v, k)));
    EXPECT_LT(worst, 1e-6) << name << ": float32 of the positions";
  }

  // Colours: mean curvature on a common scale (the input's), quality per face, displacement.
  const Eigen::VectorXd H_input = principal_curvatures(p.input.V, p.input.F).mean();
  const Eigen::VectorXd H_result = principal_curvatures(p.result.V, p.result.F).mean();
  const double limit = documented_limit(H_input);
  expect_colors(data["input"]["mean_curvature"], H_input, limit, "input H");
  expect_colors(data["result"]["mean_curvature"], H_result, limit, "result H");
  // Quality: white at 0.5, red towards 0, blue towards 1.
  const Eigen::VectorXd q = triangle_quality(p.result.V, p.result.F);
  expect_colors(data["result"]["quality"], Eigen::VectorXd(0.5 - q.array()), 0.5, "result quality");
  const Eigen::VectorXd moved = (p.result.V - p.input.V).rowwise().norm();
  expect_colors(data["displacement"], moved, documented_limit(moved), "displacement");
  // On this torus the outer equator is convex (red) and the inner one saddle-shaped with H < 0
  // (blue): the map's sign convention reaches the page.
  Index outer = 0, inner = 0;
  H_input.maxCoeff(&outer);
  H_input.minCoeff(&inner);
  const auto colors = decode_base64(data["input"]["mean_curvature"].get<std::string>());
  EXPECT_GT(colors[static_cast<std::size_t>(3 * outer)], colors[static_cast<std::size_t>(3 * outer + 2)]);
  EXPECT_LT(colors[static_cast<std::size_t>(3 * inner)], colors[static_cast<std::size_t>(3 * inner + 2)]);

  const auto histogram = [](const Mesh& m) {
    const auto counts = summarize_quality(triangle_quality(m.V, m.F)).histogram;
    return std::vector<std::int64_t>(counts.begin(), counts.end());
  };
  EXPECT_EQ(data["histograms"]["input"].get<std::vector<std::int64_t>>(), histogram(p.input));
  EXPECT_EQ(data["histograms"]["result"].get<std::vector<std::int64_t>>(), histogram(p.result));
}

TEST(HtmlReport, SameInputSameBytes) {
  const Pair p = torus_pair();
  const std::string a = html_report(p.input, p.result, R"({"x": 1.5})");
  const std::string b = html_report(p.input, p.result, R"({"x": 1.5})");
  EXPECT_EQ(a, b);
  Pair q = p;
  q.result.V(0, 0) += 1e-3;
  EXPECT_NE(html_report(q.input, q.result, R"({"x": 1.5})"), a);
}

TEST(HtmlReport, GivenCurvatureIsUsedAndGivesTheSameBytes) {
  const Pair p = torus_pair();
  const Curvature input = principal_curvatures(p.input.V, p.input.F);
  const Curvature result = principal_curvatures(p.result.V, p.result.F);
  const std::string page = html_report(p.input, p.result, R"({"x": 1.5})");
  EXPECT_EQ(html_report(p.input, p.result, input, result, R"({"x": 1.5})"), page);
  // Swapped, the input view shows the result's curvature: the given curvature is what is drawn.
  const nlohmann::json swapped = page_data(html_report(p.input, p.result, result, input, ""));
  const nlohmann::json data = page_data(page);
  EXPECT_NE(swapped["input"]["mean_curvature"], data["input"]["mean_curvature"]);
  EXPECT_EQ(swapped["input"]["positions"], data["input"]["positions"]);
  test::ScratchDir dir("html-report-curvature");
  write_html_report(dir.file("r.html"), p.input, p.result, input, result, R"({"x": 1.5})");
  EXPECT_EQ(test::read_text(dir.file("r.html")), page);
  // Curvature of another mesh, and the checks of the other overload.
  const Mesh other = test::torus(1.0, 0.6, 40, 24);
  const Curvature other_curvature = principal_curvatures(other.V, other.F);
  EXPECT_THROW(html_report(p.input, p.result, other_curvature, result, ""), std::invalid_argument);
  EXPECT_THROW(html_report(p.input, p.result, input, other_curvature, ""), std::invalid_argument);
  EXPECT_THROW(html_report(p.input, other, input, other_curvature, ""), std::invalid_argument);
  EXPECT_THROW(html_report(p.input, p.result, input, result, "[1, 2]"), std::invalid_argument);
}

TEST(HtmlReport, LargeMeshIsDecimatedForDisplayWithANote) {
  const Mesh sphere = test::icosphere(1.0, 5);  // 20480 faces
  Mesh moved = sphere;
  moved.V *= 1.01;
  HtmlReportOptions options;
  options.max_display_faces = 3000;
  const std::string html = html_report(sphere, moved, "", options);
  const nlohmann::json data = page_data(html);
  EXPECT_EQ(data["display"]["decimated"], true);
  const std::string note = data["display"]["note"];
  EXPECT_NE(note.find("decimation for display"), std::string::npos) << note;
  EXPECT_NE(note.find("of 20480 faces"), std::string::npos) << note;
  const Index faces = data["display"]["faces"], vertices = data["display"]["vertices"];
  EXPECT_LE(faces, 3000);
  EXPECT_GE(faces, 3000 / 4) << "decimated far below the limit";
  // Histograms describe the full meshes.
  std::int64_t total = 0;
  for (const auto& c : data["histograms"]["input"]) total += c.get<std::int64_t>();
  EXPECT_EQ(total, sphere.num_faces());

  const auto indices = decode_array<std::uint32_t>(data["display"]["indices"]);
  ASSERT_EQ(indices.size(), static_cast<std::size_t>(3 * faces));
  std::set<std::array<std::uint32_t, 3>> distinct;
  for (std::size_t f = 0; f < indices.size(); f += 3) {
    std::array<std::uint32_t, 3> t{indices[f], indices[f + 1], indices[f + 2]};
    for (const auto i : t) ASSERT_LT(i, static_cast<std::uint32_t>(vertices));
    ASSERT_TRUE(t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) << "collapsed face kept";
    std::sort(t.begin(), t.end());
    EXPECT_TRUE(distinct.insert(t).second) << "duplicate face kept";
  }
  // Cluster centres are means of nearby points of the sphere: just inside it. The result's
  // clusters are the same vertex groups, so they are the input's scaled by 1.01.
  const auto in = decode_array<float>(data["input"]["positions"]);
  const auto out = decode_array<float>(data["result"]["positions"]);
  ASSERT_EQ(in.size(), static_cast<std::size_t>(3 * vertices));
  ASSERT_EQ(out.size(), in.size());
  for (std::size_t v = 0; v < in.size(); v += 3) {
    const double r = std::sqrt(double(in[v]) * in[v] + double(in[v + 1]) * in[v + 1] + double(in[v + 2]) * in[v + 2]);
    EXPECT_GT(r, 0.95);
    EXPECT_LT(r, 1.0 + 1e-6);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(out[v + k], 1.01 * in[v + k], 1e-6);
  }
  EXPECT_EQ(decode_base64(data["displacement"].get<std::string>()).size(), static_cast<std::size_t>(3 * vertices));
  EXPECT_EQ(decode_base64(data["input"]["quality"].get<std::string>()).size(), static_cast<std::size_t>(3 * faces));
}

TEST(HtmlReport, LimitIsInclusive) {
  const Pair p = torus_pair();
  HtmlReportOptions options;
  options.max_display_faces = p.input.num_faces();
  EXPECT_EQ(page_data(html_report(p.input, p.result, "", options))["display"]["decimated"], false);
  options.max_display_faces = p.input.num_faces() - 1;
  EXPECT_EQ(page_data(html_report(p.input, p.result, "", options))["display"]["decimated"], true);
}

TEST(HtmlReport, NamesCannotBreakOutOfThePage) {
  const Pair p = torus_pair();
  HtmlReportOptions options;
  options.title = "a </title><script>alert(1)</script>";
  options.input_label = "</script><!--";
  const std::string html = html_report(p.input, p.result, R"({"file": "</script>"})", options);
  EXPECT_EQ(count(lower(html), "</script"), 2u);
  EXPECT_EQ(count(lower(html), "<script"), 2u);
  EXPECT_NE(html.find("<title>a &lt;/title&gt;&lt;script&gt;"), std::string::npos);
  const nlohmann::json data = page_data(html);
  EXPECT_EQ(data["title"], options.title);
  EXPECT_EQ(data["labels"]["input"], "</script><!--");
  EXPECT_EQ(data["metrics"]["file"], "</script>");
  // A label that is not UTF-8 (file names need not be) is replaced, not an error.
  options.input_label = "bad\xff.off";
  EXPECT_EQ(page_data(html_report(p.input, p.result, "", options))["labels"]["input"], "bad\xef\xbf\xbd.off");
}

TEST(HtmlReport, RefusesMismatchedMeshesAndBadMetrics) {
  const Pair p = torus_pair();
  const Mesh other = test::torus(1.0, 0.6, 40, 24);
  EXPECT_THROW(html_report(p.input, other, ""), std::invalid_argument);
  // The same vertices with a face fewer: not a result of this input (edge flips keep the count).
  Mesh fewer = p.result;
  fewer.F.conservativeResize(fewer.F.rows() - 1, 3);
  try {
    html_report(p.input, fewer, "");
    ADD_FAILURE() << "a result with another face count was accepted";
  } catch (const std::invalid_argument& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(fmt::format("{} faces", p.input.num_faces() - 1)), std::string::npos) << message;
    EXPECT_NE(message.find("vertex and face counts"), std::string::npos) << message;
  }
  EXPECT_THROW(html_report(p.input, fewer, principal_curvatures(p.input.V, p.input.F),
                           principal_curvatures(p.input.V, p.input.F), ""),
               std::invalid_argument);
  Mesh out_of_range = p.result;
  out_of_range.F(3, 1) = p.result.num_vertices();
  EXPECT_THROW(html_report(p.input, out_of_range, principal_curvatures(p.input.V, p.input.F),
                           principal_curvatures(p.input.V, p.input.F), ""),
               std::invalid_argument);
  EXPECT_THROW(html_report(p.input, p.result, "[1, 2]"), std::invalid_argument);
  EXPECT_THROW(html_report(p.input, p.result, "{not json"), std::invalid_argument);
  HtmlReportOptions options;
  options.max_display_faces = 0;
  EXPECT_THROW(html_report(p.input, p.result, "", options), std::invalid_argument);
}

// A result of edge flips: the same vertices, faces of its own. Its view, quality and curvature
// are its own faces'; displacement stays per vertex.
TEST(HtmlReport, ResultWithItsOwnFacesIsShownOnThem) {
  const Pair p = flipped_ellipsoid_pair(3);
  ASSERT_GT(changed_faces(p), 100);
  const std::string html = html_report(p.input, p.result, "");
  const nlohmann::json data = page_data(html);
  const Index nv = p.input.num_vertices(), nf = p.input.num_faces();
  EXPECT_EQ(data["counts"]["faces"], nf);
  EXPECT_EQ(data["display"]["faces"], nf);
  EXPECT_EQ(data["display"]["result_faces"], nf);
  EXPECT_EQ(data["display"]["vertices"], nv);
  const auto indices = decode_array<std::uint32_t>(data["display"]["indices"]);
  const auto result_indices = decode_array<std::uint32_t>(data["display"]["result_indices"]);
  ASSERT_EQ(indices.size(), static_cast<std::size_t>(3 * nf));
  ASSERT_EQ(result_indices.size(), static_cast<std::size_t>(3 * nf));
  for (Index f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(indices[static_cast<std::size_t>(3 * f + k)], static_cast<std::uint32_t>(p.input.F(f, k)));
      ASSERT_EQ(result_indices[static_cast<std::size_t>(3 * f + k)], static_cast<std::uint32_t>(p.result.F(f, k)));
    }

  // Quality: the result's faces, which the flips made worse than the input's faces would be.
  const Eigen::VectorXd q_own = triangle_quality(p.result.V, p.result.F);
  ASSERT_NE(histogram(p.result.V, p.result.F), histogram(p.result.V, p.input.F));
  EXPECT_EQ(data["histograms"]["result"].get<std::vector<std::int64_t>>(), histogram(p.result.V, p.result.F));
  EXPECT_EQ(data["histograms"]["input"].get<std::vector<std::int64_t>>(), histogram(p.input.V, p.input.F));
  expect_colors(data["result"]["quality"], Eigen::VectorXd(0.5 - q_own.array()), 0.5, "result quality");
  expect_colors(data["input"]["quality"], Eigen::VectorXd(0.5 - triangle_quality(p.input.V, p.input.F).array()), 0.5,
                "input quality");

  // Curvature of the result's own faces, visibly unlike that of the input's faces.
  const Curvature input_curvature = principal_curvatures(p.input.V, p.input.F);
  const Curvature own = principal_curvatures(p.result.V, p.result.F);
  const Eigen::VectorXd H_own = own.mean();
  const Eigen::VectorXd H_shared = principal_curvatures(p.result.V, p.input.F).mean();
  const double limit = documented_limit(input_curvature.mean());
  double apart = 0;
  for (Index v = 0; v < nv; ++v)
    apart = std::max(apart,
                     (documented_color(H_own[v], limit) - documented_color(H_shared[v], limit)).cwiseAbs().maxCoeff());
  ASSERT_GT(apart, 3) << "the curvature of the two face sets gives the same colours: the check below tells nothing";
  expect_colors(data["result"]["mean_curvature"], H_own, limit, "result H");
  const Eigen::VectorXd moved = (p.result.V - p.input.V).rowwise().norm();
  expect_colors(data["displacement"], moved, documented_limit(moved), "displacement");

  // The given curvature (each mesh's own faces') gives the same page.
  EXPECT_TRUE(html_report(p.input, p.result, input_curvature, own, "") == html) << "not the same page";
}

// Decimated for display, the result's own faces go through the input's clusters: faces that
// only differ in their first corner give the input's display faces, so rotated corners, and
// flipped faces stay within the limit.
TEST(HtmlReport, DecimatedResultMapsItsOwnFacesThroughTheSameClusters) {
  const Mesh sphere = test::icosphere(1.0, 5);  // 20480 faces
  Mesh rotated = sphere;
  rotated.V *= 1.01;
  for (Index f = 0; f < sphere.num_faces(); ++f) rotated.F.row(f) << sphere.F(f, 1), sphere.F(f, 2), sphere.F(f, 0);
  HtmlReportOptions options;
  options.max_display_faces = 3000;
  const nlohmann::json data = page_data(html_report(sphere, rotated, "", options));
  ASSERT_EQ(data["display"]["decimated"], true);
  const Index faces = data["display"]["faces"];
  ASSERT_EQ(data["display"]["result_faces"], faces);
  const auto indices = decode_array<std::uint32_t>(data["display"]["indices"]);
  const auto result_indices = decode_array<std::uint32_t>(data["display"]["result_indices"]);
  ASSERT_EQ(result_indices.size(), static_cast<std::size_t>(3 * faces));
  ASSERT_EQ(indices.size(), result_indices.size());
  for (std::size_t f = 0; f < indices.size(); f += 3)
    for (std::size_t k = 0; k < 3; ++k) ASSERT_EQ(result_indices[f + k], indices[f + (k + 1) % 3]) << f / 3;
  // Quality is invariant to the scale and the corner order: the same colours per display face.
  const auto q_input = decode_base64(data["input"]["quality"].get<std::string>());
  const auto q_result = decode_base64(data["result"]["quality"].get<std::string>());
  ASSERT_EQ(q_result.size(), static_cast<std::size_t>(3 * faces));
  ASSERT_EQ(q_input.size(), q_result.size());
  for (std::size_t i = 0; i < q_input.size(); ++i) EXPECT_LE(std::abs(int(q_input[i]) - int(q_result[i])), 1) << i;
  const std::string note = data["display"]["note"];
  EXPECT_NE(note.find(fmt::format("faces, {} of the result's own faces, ", faces)), std::string::npos) << note;

  // Flipped faces: mapped, collapsed ones dropped, within the limit, and not the input's.
  Mesh flipped = rotated;
  flipped.F = with_flipped_edges(sphere.F, sphere.num_vertices());
  const nlohmann::json fd = page_data(html_report(sphere, flipped, "", options));
  const Index vertices = fd["display"]["vertices"], result_faces = fd["display"]["result_faces"];
  EXPECT_LE(result_faces, 3000);
  EXPECT_LE(fd["display"]["faces"].get<Index>(), 3000);
  EXPECT_GE(result_faces, 3000 / 4);
  const auto flipped_indices = decode_array<std::uint32_t>(fd["display"]["result_indices"]);
  ASSERT_EQ(flipped_indices.size(), static_cast<std::size_t>(3 * result_faces));
  EXPECT_NE(display_triples(flipped_indices, vertices),
            display_triples(decode_array<std::uint32_t>(fd["display"]["indices"]), vertices));
  EXPECT_EQ(decode_base64(fd["result"]["quality"].get<std::string>()).size(),
            static_cast<std::size_t>(3 * result_faces));
  EXPECT_EQ(decode_base64(fd["displacement"].get<std::string>()).size(), static_cast<std::size_t>(3 * vertices));
}

// Texture coordinates (u, v) = f(position) per corner: a corner channel with one row per
// corner (as a seam would give), or a vertex channel.
Mesh with_texcoords(Mesh mesh, double shift, bool per_corner) {
  const auto uv_of = [&](Index v) {
    return Eigen::RowVector2d(0.5 + 0.3 * mesh.V(v, 0) + shift, 0.5 + 0.3 * mesh.V(v, 1) - 0.2 * mesh.V(v, 2));
  };
  AttributeChannel uv;
  uv.name = "uv";
  uv.components = {"u", "v"};
  uv.role = AttributeRole::TexCoord;
  if (!per_corner) {
    uv.values.resize(mesh.V.rows(), 2);
    for (Index v = 0; v < mesh.V.rows(); ++v) uv.values.row(v) = uv_of(v);
    mesh.attributes.vertex.push_back(std::move(uv));
    return mesh;
  }
  CornerChannel corners;
  corners.corners.resize(mesh.F.rows(), 3);
  uv.values.resize(3 * mesh.F.rows(), 2);
  for (Index f = 0; f < mesh.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      uv.values.row(3 * f + k) = uv_of(mesh.F(f, k));
      corners.corners(f, k) = 3 * f + k;
    }
  corners.channel = std::move(uv);
  mesh.attributes.corner.push_back(std::move(corners));
  return mesh;
}

// The page's (u, v) of every display corner against the mesh's, face by face.
void expect_texcoords(const nlohmann::json& field, const Mesh& mesh, double shift, const char* what) {
  const auto uv = decode_array<float>(field);
  ASSERT_EQ(uv.size(), static_cast<std::size_t>(6 * mesh.num_faces())) << what;
  for (Index f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      const Index v = mesh.F(f, k);
      const std::size_t i = 6 * static_cast<std::size_t>(f) + 2 * static_cast<std::size_t>(k);
      ASSERT_NEAR(uv[i], 0.5 + 0.3 * mesh.V(v, 0) + shift, 1e-6) << what << " face " << f;
      ASSERT_NEAR(uv[i + 1], 0.5 + 0.3 * mesh.V(v, 1) - 0.2 * mesh.V(v, 2), 1e-6) << what << " face " << f;
    }
}

TEST(HtmlReport, CheckerViewGetsEachMeshsOwnTextureCoordinates) {
  const Pair plain = torus_pair();
  for (const bool per_corner : {true, false}) {
    // The result's coordinates differ from the input's (as re-sampled ones do): the page must
    // carry each mesh's own, not one set for both.
    const Mesh input = with_texcoords(plain.input, 0, per_corner);
    const Mesh result = with_texcoords(plain.result, 0.01, per_corner);
    const std::string html = html_report(input, result, "");
    const nlohmann::json data = page_data(html);
    ASSERT_TRUE(data.contains("texture")) << per_corner;
    EXPECT_EQ(data["texture"]["squares"], 16);
    expect_texcoords(data["input"]["uv"], input, 0, "input");
    expect_texcoords(data["result"]["uv"], result, 0.01, "result");
    // The page offers the view: its controls in the page, the viewer script using them.
    EXPECT_NE(html.find(R"(id="checker")"), std::string::npos);
    EXPECT_NE(html.find(R"(id="checker-squares")"), std::string::npos);
    EXPECT_NE(html.find("checker-controls"), std::string::npos);
    EXPECT_GE(count(html, "checker-squares"), 2u) << "the viewer script does not read the control";
  }
  // Without coordinates on both sides, no texture data at all (the page as before).
  for (const auto& [input, result] :
       {std::pair{plain.input, plain.result}, std::pair{with_texcoords(plain.input, 0, true), plain.result},
        std::pair{plain.input, with_texcoords(plain.result, 0, true)}}) {
    const nlohmann::json data = page_data(html_report(input, result, ""));
    EXPECT_FALSE(data.contains("texture"));
    EXPECT_FALSE(data["input"].contains("uv"));
    EXPECT_FALSE(data["result"].contains("uv"));
  }
  // A channel of another role is not texture coordinates.
  Mesh labelled = plain.input;
  labelled.set_vertex_property("u", Eigen::VectorXd::Zero(labelled.num_vertices()));
  EXPECT_FALSE(page_data(html_report(labelled, labelled, "")).contains("texture"));
}

// Edge flips: the result's coordinates follow its own faces; decimated, every display face has
// its corners' coordinates (those of a mesh face mapped to it).
TEST(HtmlReport, CheckerCoordinatesFollowOwnAndDecimatedFaces) {
  const Pair flipped = flipped_ellipsoid_pair(3);
  const Mesh input = with_texcoords(flipped.input, 0, true);
  const Mesh result = with_texcoords(flipped.result, 0.02, true);
  const nlohmann::json data = page_data(html_report(input, result, ""));
  expect_texcoords(data["input"]["uv"], input, 0, "input");
  expect_texcoords(data["result"]["uv"], result, 0.02, "flipped result");

  const Mesh sphere = with_texcoords(test::icosphere(1.0, 5), 0, true);
  HtmlReportOptions options;
  options.max_display_faces = 3000;
  const nlohmann::json d = page_data(html_report(sphere, sphere, "", options));
  ASSERT_EQ(d["display"]["decimated"], true);
  const std::size_t faces = d["display"]["faces"];
  const auto uv = decode_array<float>(d["input"]["uv"]);
  ASSERT_EQ(uv.size(), 6 * faces);
  // Each display corner's coordinates are those of a vertex in its cluster: within a cluster's
  // size (the display's mean positions) of f(display position).
  const auto positions = decode_array<float>(d["input"]["positions"]);
  const auto indices = decode_array<std::uint32_t>(d["display"]["indices"]);
  double worst = 0;
  for (std::size_t i = 0; i < indices.size(); ++i) {
    const float* p = &positions[3 * indices[i]];
    worst = std::max(worst, std::abs(uv[2 * i] - (0.5 + 0.3 * p[0])));
    worst = std::max(worst, std::abs(uv[2 * i + 1] - (0.5 + 0.3 * p[1] - 0.2 * p[2])));
  }
  EXPECT_LT(worst, 0.05);
  EXPECT_EQ(d["result"]["uv"], d["input"]["uv"]);
}

TEST(HtmlReport, WritesTheFileAtomically) {
  const Pair p = torus_pair();
  test::ScratchDir dir("html-report");
  const auto file = dir.file("report.html");
  write_html_report(file, p.input, p.result, "");
  EXPECT_EQ(test::read_text(file), html_report(p.input, p.result, ""));
  EXPECT_THROW(write_html_report(dir.file("missing/report.html"), p.input, p.result, ""), IoError);
  EXPECT_FALSE(std::filesystem::exists(dir.file("missing")));
}

}  // namespace
}  // namespace vertexflow
