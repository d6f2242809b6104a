// The HTML report page: self-contained, both meshes' data decoded back and compared with the
// meshes, colours wired to the right quantities, deterministic bytes, display decimation of
// large meshes. The page in a real browser is tested by web/tests/report_browser.mjs.
#include "shapes.h"
#include "test_support.h"

#include "vertexflow/curvature.h"
#include "vertexflow/html_report.h"
#include "vertexflow/io.h"
#include "vertexflow/quality.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <set>
#include <string>
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

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// The JSON inside <script id="vertexflow-data">.
nlohmann::json page_data(const std::string& html) {
  const std::string open = R"(<script id="vertexflow-data" type="application/json">)";
  const std::size_t begin = html.find(open);
  EXPECT_NE(begin, std::string::npos);
  const std::size_t end = html.find("</script>", begin);
  return nlohmann::json::parse(html.substr(begin + open.size(), end - begin - open.size()));
}

// An independent base64 decoder (RFC 4648), for reading the arrays back.
std::vector<unsigned char> decode_base64(const std::string& text) {
  static const std::string alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::vector<unsigned char> out;
  unsigned buffer = 0;
  int bits = 0;
  for (const char c : text) {
    if (c == '=') break;
    const std::size_t value = alphabet.find(c);
    EXPECT_NE(value, std::string::npos) << "not base64: " << c;
    buffer = (buffer << 6) | static_cast<unsigned>(value);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<unsigned char>((buffer >> bits) & 0xFF));
    }
  }
  return out;
}

template <class T>
std::vector<T> decode_array(const nlohmann::json& field) {
  const std::vector<unsigned char> bytes = decode_base64(field.get<std::string>());
  EXPECT_EQ(bytes.size() % sizeof(T), 0u);
  std::vector<T> values(bytes.size() / sizeof(T));
  std::memcpy(values.data(), bytes.data(), values.size() * sizeof(T));
  return values;
}

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
  Mesh reordered = p.result;
  reordered.F.row(0) = reordered.F.row(0).reverse().eval();
  EXPECT_THROW(html_report(p.input, reordered, ""), std::invalid_argument);
  EXPECT_THROW(html_report(p.input, p.result, "[1, 2]"), std::invalid_argument);
  EXPECT_THROW(html_report(p.input, p.result, "{not json"), std::invalid_argument);
  HtmlReportOptions options;
  options.max_display_faces = 0;
  EXPECT_THROW(html_report(p.input, p.result, "", options), std::invalid_argument);
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
