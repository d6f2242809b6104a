// Attributes follow the moved vertices (enhance.h, docs/attributes.md): texture coordinates
// re-sampled in their own chart do not swim, seam vertices stay on their seams, the face list
// comes back as it went in.
#include "test_support.h"

#include "vertexflow/distance.h"
#include "vertexflow/enhance.h"
#include "vertexflow/io.h"
#include "vertexflow/reference_surface.h"
#include "vertexflow/topology.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <numbers>
#include <optional>
#include <set>

namespace vertexflow {
namespace {

// A parametric surface on a (nu x nv) grid of quads, each split in two, with texture coordinates
// (i / nu, j / nv) per corner: where the surface closes (wrap_u, wrap_v) the vertices are
// shared and the texture coordinates are not, so the closing line is a seam. Without wrap_v the
// rows j = 0 and j = nv are the poles of a sphere (collapse_v): one vertex each, with its own
// texture coordinate in every face.
struct Parametric {
  Mesh mesh;
  std::vector<char> on_seam;  // per vertex
};

Parametric parametric(int nu, int nv, bool wrap_v, const std::function<Eigen::Vector3d(double, double)>& at) {
  Parametric p;
  Mesh& m = p.mesh;
  const bool poles = !wrap_v;
  const int rows = wrap_v ? nv : nv - 1;      // rows of shared vertices (poles apart)
  auto vertex = [&](int i, int j) -> Index {  // i mod nu; j in 0..nv
    i = (i % nu + nu) % nu;
    if (wrap_v) return static_cast<Index>((j % nv) * nu + i);
    if (j == 0) return rows * nu;
    if (j == nv) return rows * nu + 1;
    return static_cast<Index>((j - 1) * nu + i);
  };
  m.V.resize(rows * nu + (poles ? 2 : 0), 3);
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i < nu; ++i) m.V.row(vertex(i, j)) = at(double(i) / nu, double(j) / nv).transpose();
  std::vector<std::array<Index, 3>> faces;
  std::vector<std::array<Eigen::Vector2d, 3>> uvs;
  auto uv = [&](int i, int j) { return Eigen::Vector2d(double(i) / nu, double(j) / nv); };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const Index a = vertex(i, j), b = vertex(i + 1, j), c = vertex(i + 1, j + 1), d = vertex(i, j + 1);
      if (!(poles && j == 0)) {
        faces.push_back({a, b, c});
        uvs.push_back({uv(i, j), uv(i + 1, j), uv(i + 1, j + 1)});
      } else {
        faces.push_back({a, c, d});  // the pole a: one triangle
        uvs.push_back({Eigen::Vector2d((i + 0.5) / nu, 0), uv(i + 1, j + 1), uv(i, j + 1)});
        continue;
      }
      if (poles && j == nv - 1) continue;  // c is the other pole: (a, b, c) was the triangle
      faces.push_back({a, c, d});
      uvs.push_back({uv(i, j), uv(i + 1, j + 1), uv(i, j + 1)});
    }
  m.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
  CornerChannel uv_channel;
  uv_channel.channel.name = "uv";
  uv_channel.channel.components = {"u", "v"};
  uv_channel.channel.role = AttributeRole::TexCoord;
  uv_channel.corners.resize(m.F.rows(), 3);
  std::vector<Eigen::Vector2d> table;
  std::map<std::pair<long, long>, int> row_of;
  for (std::size_t f = 0; f < faces.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      m.F(static_cast<Eigen::Index>(f), k) = faces[f][static_cast<std::size_t>(k)];
      const Eigen::Vector2d t = uvs[f][static_cast<std::size_t>(k)];
      const std::pair<long, long> key{std::lround(t.x() * 1e6), std::lround(t.y() * 1e6)};
      auto [it, added] = row_of.emplace(key, static_cast<int>(table.size()));
      if (added) table.push_back(t);
      uv_channel.corners(static_cast<Eigen::Index>(f), k) = it->second;
    }
  uv_channel.channel.values.resize(static_cast<Eigen::Index>(table.size()), 2);
  for (std::size_t r = 0; r < table.size(); ++r) uv_channel.channel.values.row(static_cast<Eigen::Index>(r)) = table[r];
  m.attributes.corner.push_back(std::move(uv_channel));
  p.on_seam.assign(static_cast<std::size_t>(m.num_vertices()), 0);
  for (int j = 0; j <= nv; ++j) {
    p.on_seam[static_cast<std::size_t>(vertex(0, j))] = 1;
    if (wrap_v) p.on_seam[static_cast<std::size_t>(vertex(j, 0))] = 1;
  }
  if (wrap_v)
    for (int i = 0; i < nu; ++i) p.on_seam[static_cast<std::size_t>(vertex(i, 0))] = 1;
  if (poles) p.on_seam[static_cast<std::size_t>(vertex(0, 0))] = p.on_seam[static_cast<std::size_t>(vertex(0, nv))] = 1;
  return p;
}

Parametric uv_sphere(int nu, int nv) {
  return parametric(nu, nv, false, [](double u, double v) {
    const double phi = 2 * std::numbers::pi * u, theta = std::numbers::pi * v;
    return Eigen::Vector3d(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
  });
}

// A torus whose tube is an ellipse, so that the flow has curvature to move towards.
Parametric textured_torus(int nu, int nv) {
  return parametric(nu, nv, true, [](double u, double v) {
    const double phi = 2 * std::numbers::pi * u, theta = 2 * std::numbers::pi * v;
    const double rho = 1 + 0.45 * std::cos(theta);
    return Eigen::Vector3d(rho * std::cos(phi), rho * std::sin(phi), 0.2 * std::sin(theta));
  });
}

// The point of the input surface whose texture coordinate is t: the face whose UV triangle
// holds t, at the same barycentric coordinates (the input's UV-to-surface map).
struct SurfacePoint {
  Eigen::Vector3d point, normal;
};

std::optional<SurfacePoint> surface_at(const Mesh& input, const Eigen::Vector2d& t) {
  const CornerChannel& uv = input.attributes.corner.front();
  for (Index f = 0; f < input.num_faces(); ++f) {
    Eigen::Vector2d c[3];
    for (int k = 0; k < 3; ++k) c[k] = uv.channel.values.row(uv.corners(f, k)).transpose();
    const Eigen::Vector2d e1 = c[1] - c[0], e2 = c[2] - c[0], d = t - c[0];
    const double det = e1.x() * e2.y() - e1.y() * e2.x();
    if (std::abs(det) < 1e-300) continue;
    const double b1 = (d.x() * e2.y() - d.y() * e2.x()) / det, b2 = (e1.x() * d.y() - e1.y() * d.x()) / det;
    const double tolerance = -1e-9;
    if (b1 < tolerance || b2 < tolerance || 1 - b1 - b2 < tolerance) continue;
    const Eigen::Vector3d point =
        ((1 - b1 - b2) * input.V.row(input.F(f, 0)) + b1 * input.V.row(input.F(f, 1)) + b2 * input.V.row(input.F(f, 2)))
            .transpose();
    return SurfacePoint{point, face_normal(input.V, input.F, f).normalized()};
  }
  return std::nullopt;
}

// Over the moved vertices off the seams, in mean edge lengths: how far the point of the input
// surface that the vertex's texture coordinate names is from the vertex, in all (`_raw`) and
// along the surface (the part across the input's face normal: a vertex that the method lifted
// off the facets, by the flow's Phong lift or a fit's move along the normal, is that far off
// any point of the facets whatever its texture coordinate).
//
// `resampled_excess` is the independent measure for the flow's vertices, which its projection
// lifts off the facets along the Phong surface's normal rather than a face's: how much farther
// the named point is from the vertex than the input surface is (a global closest-point query,
// distance.h). 0 when the texture coordinate names the point of the input nearest the vertex.
struct Swim {
  double resampled = 0, resampled_raw = 0, resampled_excess = 0;
  double kept_uv = 0, kept_uv_raw = 0;  // the same with the input's texture coordinates kept
  Index measured = 0;
};

Swim measure_swim(const Parametric& in, const Mesh& out) {
  const Mesh& input = in.mesh;
  const double h = mean_edge_length(input.V, build_topology(input.F, input.num_vertices()));
  const CornerChannel& before = input.attributes.corner.front();
  const CornerChannel& after = out.attributes.corner.front();
  const DistanceQuery surface(input.V, input.F);
  Swim swim;
  std::vector<char> done(static_cast<std::size_t>(input.num_vertices()), 0);
  for (Index f = 0; f < input.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      const Index v = input.F(f, k);
      if (done[static_cast<std::size_t>(v)] || in.on_seam[static_cast<std::size_t>(v)]) continue;
      done[static_cast<std::size_t>(v)] = 1;
      if ((out.V.row(v) - input.V.row(v)).norm() < 1e-3 * h) continue;
      const auto now = surface_at(input, after.channel.values.row(after.corners(f, k)).transpose());
      const auto old = surface_at(input, before.channel.values.row(before.corners(f, k)).transpose());
      if (!now || !old) {
        ADD_FAILURE() << "vertex " << v << ": its texture coordinate lies in no face of the input";
        continue;
      }
      const Eigen::Vector3d p = out.V.row(v).transpose();
      auto along = [&](const SurfacePoint& s) {
        const Eigen::Vector3d d = s.point - p;
        return (d - d.dot(s.normal) * s.normal).norm() / h;
      };
      swim.resampled = std::max(swim.resampled, along(*now));
      swim.kept_uv = std::max(swim.kept_uv, along(*old));
      swim.resampled_raw = std::max(swim.resampled_raw, (now->point - p).norm() / h);
      const double nearest = (surface.closest_point(p).point - p).norm();
      swim.resampled_excess = std::max(swim.resampled_excess, ((now->point - p).norm() - nearest) / h);
      swim.kept_uv_raw = std::max(swim.kept_uv_raw, (old->point - p).norm() / h);
      ++swim.measured;
    }
  return swim;
}

struct ModeCase {
  const char* name;
  std::function<void(EnhanceOptions&)> set;
  bool slides;             // the method moves vertices along the surface (else mostly along the normal)
  bool reference = false;  // a reference mode: the same shape sampled twice as finely
  friend void PrintTo(const ModeCase& c, std::ostream* os) { *os << c.name; }
};

class NoSwimming : public ::testing::TestWithParam<ModeCase> {};

TEST_P(NoSwimming, ResampledTextureCoordinatesLandWhereTheVertexIs) {
  for (const bool torus : {false, true}) {
    SCOPED_TRACE(torus ? "torus" : "sphere");
    const Parametric in = torus ? textured_torus(96, 48) : uv_sphere(96, 48);
    EnhanceOptions options;
    GetParam().set(options);
    std::optional<ReferenceSurface> reference;
    if (GetParam().reference) {
      Parametric dense = torus ? textured_torus(192, 96) : uv_sphere(192, 96);
      reference.emplace(std::move(dense.mesh.V), std::move(dense.mesh.F), "dense");
    }
    const EnhanceResult result = enhance(in.mesh, reference ? &*reference : nullptr, options);
    EXPECT_EQ(result.mesh.F, in.mesh.F);
    const Swim swim = measure_swim(in, result.mesh);
    std::printf(
        "[ swim     ] %s %s: %d moved vertices; along the surface re-sampled %.2e, kept %.2e; in all re-sampled "
        "%.2e, kept %.2e (mean edge lengths)\n",
        GetParam().name, torus ? "torus" : "sphere", static_cast<int>(swim.measured), swim.resampled, swim.kept_uv,
        swim.resampled_raw, swim.kept_uv_raw);
    // The acceptance bar: 1% of the mean edge length. Measured (96 x 48 grids) along the
    // surface: 1e-14 for the flow and the density passes (the vertices stay on the input), 6.0e-3
    // for the unsharp mask and 2.6e-3 for smooth mode (which leave it: their closest point).
    EXPECT_LT(swim.resampled, 0.01);
    if (GetParam().slides) {
      // Doing nothing (the texture coordinates kept) swims by the displacement itself: measured
      // 0.041 (flow, torus) to 0.32 (density passes), 0.078-0.131 for the unsharp mask.
      EXPECT_GT(swim.measured, 50);
      EXPECT_GT(swim.kept_uv, 0.02);
      EXPECT_GT(swim.kept_uv, 3 * swim.resampled);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    Modes, NoSwimming,
    // The UV sphere's strips at the poles are thin triangles, which the flow holds as decimated
    // unless told the vertices lie on the surface (input_check.h).
    ::testing::Values(ModeCase{"flow", [](EnhanceOptions& o) { o.assume_on_surface = true; }, true},
                      ModeCase{"density",
                               [](EnhanceOptions& o) {
                                 o.flow.density.passes = 10;
                                 o.assume_on_surface = true;
                               },
                               true},
                      ModeCase{"unsharp", [](EnhanceOptions& o) { o.method = EnhanceMethod::Unsharp; }, true},
                      ModeCase{"smooth", [](EnhanceOptions& o) { o.surface = EnhanceSurface::Smooth; }, false},
                      ModeCase{"reference_fit", [](EnhanceOptions&) {}, false, true},
                      ModeCase{"reference_flow", [](EnhanceOptions& o) { o.reference_method = ReferenceMethod::Flow; },
                               true, true}),
    [](const auto& param_info) { return std::string(param_info.param.name); });

TEST(Seams, SeamVerticesStayOnTheirSeamPolyline) {
  const Parametric in = uv_sphere(96, 48);
  EnhanceOptions options;
  options.assume_on_surface = true;  // its thin polar strips look decimated (input_check.h)
  const EnhanceResult result = enhance(in.mesh, nullptr, options);
  const double h = mean_edge_length(in.mesh.V, build_topology(in.mesh.F, in.mesh.num_vertices()));
  // The seam is the meridian u = 0: its vertices from pole to pole.
  std::vector<Index> seam;
  for (Index v = 0; v < in.mesh.num_vertices(); ++v)
    if (in.on_seam[static_cast<std::size_t>(v)]) seam.push_back(v);
  double worst = 0, moved = 0;
  for (const Index v : seam) {
    const Eigen::Vector3d p = result.mesh.V.row(v);
    moved = std::max(moved, (p - in.mesh.V.row(v).transpose()).norm() / h);
    // Distance to the seam polyline: the input's meridian (y = 0, x >= 0) is a planar polyline.
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < seam.size(); ++i)
      for (std::size_t j = 0; j < seam.size(); ++j) {
        const Eigen::Vector3d a = in.mesh.V.row(seam[i]), b = in.mesh.V.row(seam[j]);
        if (i == j || (a - b).norm() > 1.5 * (std::numbers::pi / 48)) continue;  // neighbours along the seam
        const double t = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
        best = std::min(best, (a + t * (b - a) - p).norm());
      }
    worst = std::max(worst, best / h);
  }
  std::printf("[ seam     ] %zu seam vertices, moved up to %.3f edge lengths, off the seam %.2e\n", seam.size(), moved,
              worst);
  EXPECT_LT(worst, 1e-9);
  EXPECT_GT(moved, 0.01);  // they do slide along it
}

TEST(FaceList, ComesBackAsItWentInWithDegenerateFacesHeld) {
  Mesh mesh = read_mesh(test::data_path("bunny_uniform.off"));
  const Index n = mesh.num_vertices(), m = mesh.num_faces();
  // A repeated-vertex face, a duplicate (reversed), a zero-area face on three new collinear
  // vertices, and a vertex without faces.
  mesh.V.conservativeResize(n + 4, 3);
  const Eigen::RowVector3d far = mesh.V.colwise().maxCoeff() * 2;
  for (int i = 0; i < 4; ++i) mesh.V.row(n + i) = far + Eigen::RowVector3d(i, 0, 0);
  mesh.F.conservativeResize(m + 3, 3);
  mesh.F.row(m) << mesh.F(10, 0), mesh.F(10, 0), mesh.F(10, 1);
  mesh.F.row(m + 1) << mesh.F(20, 2), mesh.F(20, 1), mesh.F(20, 0);
  mesh.F.row(m + 2) << n, n + 1, n + 2;
  const EnhanceResult result = enhance(mesh, nullptr, EnhanceOptions{});
  EXPECT_EQ(result.mesh.F, mesh.F);
  ASSERT_EQ(result.mesh.num_vertices(), mesh.num_vertices());
  for (const Index v : {mesh.F(10, 0), mesh.F(10, 1), mesh.F(20, 0), mesh.F(20, 1), mesh.F(20, 2), n, n + 1, n + 3})
    EXPECT_EQ(result.mesh.V.row(v), mesh.V.row(v)) << v;
  EXPECT_GT((result.mesh.V - mesh.V).rowwise().norm().maxCoeff(), 1e-3);  // the rest moved
  EXPECT_EQ(result.report["face_list"]["faces_held"].get<int>(), 3);
  EXPECT_FALSE(result.warnings.empty());
}

TEST(FaceList, EveryEnhanceOfTheBundledMeshesKeepsTheFaceList) {
  ReadOptions keep;
  keep.keep_face_list = true;
  for (const char* name : {"bunny_uniform.off", "bunny_adaptive.off", "amo_adaptive.off", "fandisk.off",
                           "fandisk_quads.off", "spot.obj", "suzanne.obj", "sphere_low.off", "hemisphere.off",
                           "torus.obj", "rocker-arm.obj", "chamfer-cube.off", "camelhead.off", "max-planck-5k.obj"}) {
    SCOPED_TRACE(name);
    const Mesh mesh = read_mesh(test::data_path(name), nullptr, keep);
    const EnhanceResult result = enhance(mesh, nullptr, EnhanceOptions{});
    EXPECT_EQ(result.mesh.F, mesh.F);
    EXPECT_EQ(result.mesh.attributes.corner.size(), mesh.attributes.corner.size());
    EXPECT_EQ(result.mesh.attributes.face.size(), mesh.attributes.face.size());
  }
}

// On spot, whose texture atlas is real: the vertices off the seams (all of whose corners share one
// row) are measured as on the sphere, through the input face whose UV triangle holds the vertex's
// new coordinate.
TEST(Spot, NoSwimming) {
  Parametric in;
  in.mesh = read_mesh(test::data_path("spot.obj"));
  const CornerChannel& uv = in.mesh.attributes.corner.front();
  std::vector<std::int32_t> row(static_cast<std::size_t>(in.mesh.num_vertices()), -1);
  in.on_seam.assign(static_cast<std::size_t>(in.mesh.num_vertices()), 0);
  for (Index f = 0; f < in.mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      std::int32_t& r = row[static_cast<std::size_t>(in.mesh.F(f, k))];
      if (r >= 0 && r != uv.corners(f, k)) in.on_seam[static_cast<std::size_t>(in.mesh.F(f, k))] = 1;
      r = uv.corners(f, k);
    }
  const EnhanceResult result = enhance(in.mesh, nullptr, EnhanceOptions{});
  const Swim swim = measure_swim(in, result.mesh);
  std::printf(
      "[ swim     ] spot: %d moved vertices; along the surface re-sampled %.2e, kept %.2e; in all re-sampled %.2e "
      "(%.2e farther than the surface), kept %.2e (mean edge lengths)\n",
      static_cast<int>(swim.measured), swim.resampled, swim.kept_uv, swim.resampled_raw, swim.resampled_excess,
      swim.kept_uv_raw);
  EXPECT_GT(swim.measured, 1000);
  // The acceptance bar, 1% of the mean edge length, on the excess: measured 2.8e-14, the texture
  // coordinate names the input's point nearest the vertex. The flow lifts spot's vertices up to
  // 0.146 edge lengths off the facets (Phong), along normals that are not the faces', so the
  // part across the face normal reads up to 1.3e-2; the kept coordinates swim by up to 1.09.
  EXPECT_LT(swim.resampled_excess, 0.01);
  EXPECT_LT(swim.resampled, 0.03);
  EXPECT_GT(swim.kept_uv, 30 * swim.resampled);
}

TEST(Spot, TextureCoordinatesAreResampledNotKept) {
  const Mesh spot = read_mesh(test::data_path("spot.obj"));
  const EnhanceResult result = enhance(spot, nullptr, EnhanceOptions{});
  const nlohmann::json& a = result.report["attributes"];
  std::printf("[ spot     ] %s\n", a.dump().c_str());
  EXPECT_GT(a["vertices_moved"].get<int>(), 1000);
  // spot's texture has seams: they are creases for the flow.
  EXPECT_GT(a["chart_boundary_edges"].get<int>(), 100);
  // The flow's vertices stay on the surface, Phong-lifted off its facets: measured 0.146 mean
  // edge lengths at most (spot is coarse where it is most curved).
  EXPECT_LT(a["max_location_distance_edges"].get<double>(), 0.3);
  const CornerChannel& before = spot.attributes.corner.front();
  const CornerChannel& after = result.mesh.attributes.corner.front();
  EXPECT_EQ(after.corners.rows(), before.corners.rows());
  EXPECT_FALSE(after.channel.values == before.channel.values);
}

}  // namespace
}  // namespace vertexflow

namespace vertexflow {
namespace {

TEST(EdgeFlips, NeverFlipASeamAndKeepEveryCornerInItsChart) {
  const Mesh spot = read_mesh(test::data_path("spot.obj"));
  EnhanceOptions options;
  options.edge_flips = true;
  const EnhanceResult result = enhance(spot, nullptr, options);
  const Mesh& out = result.mesh;
  const Topology before = build_topology(spot.F, spot.num_vertices());
  const Topology after = build_topology(out.F, out.num_vertices());
  Index changed = 0;
  for (Index f = 0; f < spot.num_faces(); ++f) changed += out.F.row(f) != spot.F.row(f);
  std::printf("[ flips    ] %d faces changed by %d flips\n", static_cast<int>(changed),
              result.report["edge_flips"]["flips"].get<int>());
  ASSERT_GT(changed, 100);  // the flips happened (measured: 1060 faces by 536 flips)
  // Every seam edge of the input is still an edge: a flip removes the edge it flips.
  const CornerChannel& uv = spot.attributes.corner.front();
  auto row_at = [](const CornerChannel& c, const Faces& F, Index f, Index v) {
    for (int k = 0; k < 3; ++k)
      if (F(f, k) == v) return c.corners(f, k);
    return -1;
  };
  std::set<std::pair<Index, Index>> edges_after;
  for (Index e = 0; e < after.num_edges(); ++e) edges_after.insert({after.edges(e, 0), after.edges(e, 1)});
  Index seams = 0;
  for (Index f = 0; f < spot.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      const Index g = before.face_adjacency(f, k);
      if (g < f) continue;
      const Index a = spot.F(f, k), b = spot.F(f, (k + 1) % 3);
      if (row_at(uv, spot.F, f, a) == row_at(uv, spot.F, g, a) && row_at(uv, spot.F, f, b) == row_at(uv, spot.F, g, b))
        continue;
      ++seams;
      EXPECT_TRUE(edges_after.count({std::min(a, b), std::max(a, b)}))
          << "seam edge " << a << "-" << b << " was flipped";
    }
  EXPECT_EQ(seams, result.report["attributes"]["chart_boundary_edges"].get<int>());
  // A flipped face's corners take the rows of their own chart: no face's texture triangle spans
  // two islands of the atlas. Its longest edge in UV space: 0.082 over the input, 0.089 after
  // the flips; taking a row from across a seam gave 0.82 (80 faces over 0.1).
  auto longest_uv_edge = [](const Mesh& m) {
    const CornerChannel& c = m.attributes.corner.front();
    double longest = 0;
    for (Index f = 0; f < m.num_faces(); ++f)
      for (int k = 0; k < 3; ++k)
        longest = std::max(
            longest, (c.channel.values.row(c.corners(f, k)) - c.channel.values.row(c.corners(f, (k + 1) % 3))).norm());
    return longest;
  };
  EXPECT_LT(longest_uv_edge(out), 1.5 * longest_uv_edge(spot));
  // ... and rows their vertices have in the input: each row of the table still belongs to one
  // vertex (no texture coordinate of another vertex taken).
  const CornerChannel& out_uv = out.attributes.corner.front();
  std::vector<Index> owner(static_cast<std::size_t>(out_uv.channel.rows()), -1);
  for (Index f = 0; f < out.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      const auto r = static_cast<std::size_t>(out_uv.corners(f, k));
      if (owner[r] == -1) owner[r] = out.F(f, k);
      EXPECT_EQ(owner[r], out.F(f, k)) << "row " << r;
    }
}

}  // namespace
}  // namespace vertexflow

namespace vertexflow {
namespace {

// `welded` with its texture seams stored cut open, as formats with one texture coordinate per
// vertex (PLY, glTF) hold them: a copy of each vertex per texture-coordinate row it uses, the
// copies in vertex order so that welding them gives back `welded`'s vertex order. `original`
// maps each copy to its vertex.
struct CutOpen {
  Mesh mesh;
  std::vector<Index> original;
};

CutOpen cut_at_texture_seams(const Mesh& welded) {
  const CornerChannel& uv = welded.attributes.corner.front();
  std::vector<std::vector<std::int32_t>> rows(static_cast<std::size_t>(welded.num_vertices()));
  for (Index f = 0; f < welded.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      auto& r = rows[static_cast<std::size_t>(welded.F(f, k))];
      if (std::find(r.begin(), r.end(), uv.corners(f, k)) == r.end()) r.push_back(uv.corners(f, k));
    }
  CutOpen cut;
  std::map<std::pair<Index, std::int32_t>, Index> copy_of;
  for (Index v = 0; v < welded.num_vertices(); ++v)
    for (const std::int32_t r : rows[static_cast<std::size_t>(v)]) {
      copy_of[{v, r}] = static_cast<Index>(cut.original.size());
      cut.original.push_back(v);
    }
  const auto copies = static_cast<Eigen::Index>(cut.original.size());
  AttributeChannel channel{"uv", {"s", "t"}, ScalarType::Float64, AttributeRole::TexCoord, {}};
  channel.values.resize(copies, 2);
  cut.mesh.V.resize(copies, 3);
  for (const auto& [key, copy] : copy_of) {
    cut.mesh.V.row(copy) = welded.V.row(key.first);
    channel.values.row(copy) = uv.channel.values.row(key.second);
  }
  cut.mesh.F.resize(welded.F.rows(), 3);
  for (Index f = 0; f < welded.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) cut.mesh.F(f, k) = copy_of.at({welded.F(f, k), uv.corners(f, k)});
  cut.mesh.attributes.vertex.push_back(std::move(channel));
  return cut;
}

struct CutCase {
  const char* name;
  std::function<void(EnhanceOptions&)> set;
  bool reference = false;
  friend void PrintTo(const CutCase& c, std::ostream* os) { *os << c.name; }
};

class CutOpenSeams : public ::testing::TestWithParam<CutCase> {};

// The acceptance of docs/attributes.md: a mesh with its texture seams cut open flows to the same
// positions as the welded mesh with its seams held as creases, keeps every copy of a vertex
// together (no crack opens), and its texture coordinates come out as the welded mesh's corners.
TEST_P(CutOpenSeams, FlowToTheWeldedMeshsPositionsWithoutOpeningACrack) {
  for (const bool on_spot : {true, false}) {
    if (on_spot && GetParam().reference) continue;  // no denser spot: the sphere has a reference
    SCOPED_TRACE(on_spot ? "spot" : "sphere");
    const Mesh welded = on_spot ? read_mesh(test::data_path("spot.obj")) : uv_sphere(96, 48).mesh;
    const CutOpen cut = cut_at_texture_seams(welded);
    ASSERT_GT(cut.mesh.num_vertices(), welded.num_vertices());
    EnhanceOptions options;
    GetParam().set(options);
    std::optional<ReferenceSurface> reference;
    if (GetParam().reference) {
      Parametric dense = uv_sphere(192, 96);
      reference.emplace(std::move(dense.mesh.V), std::move(dense.mesh.F), "dense");
    }
    const ReferenceSurface* r = reference ? &*reference : nullptr;
    const EnhanceResult w = enhance(welded, r, options), c = enhance(cut.mesh, r, options);
    const double h = mean_edge_length(welded.V, build_topology(welded.F, welded.num_vertices()));
    double apart = 0, moved = 0, uv_apart = 0;
    for (Index i = 0; i < cut.mesh.num_vertices(); ++i) {
      const Index v = cut.original[static_cast<std::size_t>(i)];
      apart = std::max(apart, (c.mesh.V.row(i) - w.mesh.V.row(v)).norm() / h);
      moved = std::max(moved, (w.mesh.V.row(v) - welded.V.row(v)).norm() / h);
    }
    // The same faces, and each corner's texture coordinate that of the welded mesh's corner.
    const CornerChannel& w_uv = w.mesh.attributes.corner.front();
    const AttributeChannel& c_uv = c.mesh.attributes.vertex.front();
    Index faces_apart = 0, flipped = 0;
    for (Index f = 0; f < welded.num_faces(); ++f) {
      flipped += w.mesh.F.row(f) != welded.F.row(f);
      for (int k = 0; k < 3; ++k) {
        faces_apart += cut.original[static_cast<std::size_t>(c.mesh.F(f, k))] != w.mesh.F(f, k);
        uv_apart = std::max(
            uv_apart,
            (c_uv.values.row(c.mesh.F(f, k)) - w_uv.channel.values.row(w_uv.corners(f, k))).cwiseAbs().maxCoeff());
      }
    }
    std::printf(
        "[ cut open ] %s %s: %d seam edges welded; positions apart %.2e, moved %.3f edge lengths; %d faces "
        "flipped, %d corners apart; texture coordinates apart %.2e\n",
        GetParam().name, on_spot ? "spot" : "sphere", c.report["cut_seams"]["edges"].get<int>(), apart, moved,
        static_cast<int>(flipped), static_cast<int>(faces_apart), uv_apart);
    // The welded copies are the welded mesh's vertices in its order: measured 0 in every mode.
    EXPECT_LT(apart, 1e-9);
    EXPECT_GT(moved, 0.01);
    EXPECT_EQ(faces_apart, 0);
    // Measured 0 to 1.9e-4 (unsharp on spot: a copy whose faces are two fans apart, as where a
    // seam meets itself, is one vertex with one coordinate, located on its nearer fan; the welded
    // mesh gives each fan its own corner row).
    EXPECT_LT(uv_apart, 1e-3);
    // Every seam of the welded mesh's texture is one stored cut open.
    EXPECT_EQ(c.report["cut_seams"]["edges"].get<int>(), w.report["attributes"]["chart_boundary_edges"].get<int>());
  }
}

INSTANTIATE_TEST_SUITE_P(
    Modes, CutOpenSeams,
    // The UV sphere looks decimated (thin polar strips): flowed as on the surface (input_check.h).
    ::testing::Values(CutCase{"flow", [](EnhanceOptions& o) { o.assume_on_surface = true; }},
                      CutCase{"density",
                              [](EnhanceOptions& o) {
                                o.flow.density.passes = 5;
                                o.assume_on_surface = true;
                              }},
                      CutCase{"unsharp", [](EnhanceOptions& o) { o.method = EnhanceMethod::Unsharp; }},
                      CutCase{"smooth",
                              [](EnhanceOptions& o) {
                                o.surface = EnhanceSurface::Smooth;
                                o.assume_on_surface = true;
                              }},
                      CutCase{"flow_edge_flips",
                              [](EnhanceOptions& o) {
                                o.edge_flips = true;
                                o.assume_on_surface = true;
                              }},
                      CutCase{"reference_fit_edge_flips", [](EnhanceOptions& o) { o.edge_flips = true; }, true},
                      CutCase{"reference_flow", [](EnhanceOptions& o) { o.reference_method = ReferenceMethod::Flow; },
                              true}),
    [](const auto& param_info) { return std::string(param_info.param.name); });

}  // namespace
}  // namespace vertexflow
