// Every bundled mesh reads with the counts its provenance lists, and our readers agree with an
// independent implementation (CGAL's polygon-soup readers) vertex for vertex.
#include "test_support.h"

#include "vertexflow/io.h"

#include <CGAL/IO/polygon_soup_io.h>
#include <CGAL/Simple_cartesian.h>

#include <gtest/gtest.h>

#include <array>
#include <fstream>
#include <vector>

namespace vertexflow {
namespace {

using test::data_path;

struct Expected {
  const char* file;
  Index vertices;
  Index faces;  // triangles after triangulation
  std::int64_t polygons_triangulated;
  friend void PrintTo(const Expected& e, std::ostream* os) { *os << e.file; }
};

// data/README.md lists V and F; polygon files have F = triangles after splitting
// (fandisk_quads: 764 quads -> 1528; chamfer-cube: 18 quads + 8 triangles -> 44;
// suzanne: 468 quads + 32 triangles -> 968).
const Expected kBundled[] = {
    {"bunny.off", 34835, 69666, 0},         {"bunny_uniform.off", 8904, 17804, 0},
    {"bunny_adaptive.off", 5884, 11764, 0}, {"amo.off", 90112, 180220, 0},
    {"amo_adaptive.off", 5677, 11350, 0},   {"fandisk.off", 6475, 12946, 0},
    {"fandisk_quads.off", 766, 1528, 764},  {"chamfer-cube.off", 24, 44, 18},
    {"hemisphere.off", 1861, 3600, 0},      {"sphere.off", 16070, 32136, 0},
    {"sphere_low.off", 589, 1174, 0},       {"icosahedron_ascii.stl", 12, 20, 0},
    {"icosahedron_binary.stl", 12, 20, 0},  {"suzanne.obj", 507, 968, 468},
    {"max-planck-5k.obj", 5272, 10540, 0},  {"armadillo-43k.obj", 43243, 86482, 0},
    {"camelhead.off", 11381, 22704, 0},     {"fertility.off", 4494, 9000, 0},
    {"torus.obj", 2304, 4608, 0},           {"horse-48k.ply", 48485, 96966, 0},
    {"rocker-arm.obj", 10044, 20088, 0},    {"spot.obj", 2930, 5856, 0},
};

class BundledMesh : public ::testing::TestWithParam<Expected> {};

TEST_P(BundledMesh, ReadsWithExpectedCounts) {
  const Expected& e = GetParam();
  ReadReport report;
  const Mesh mesh = read_mesh(data_path(e.file), &report);
  EXPECT_EQ(mesh.num_vertices(), e.vertices);
  EXPECT_EQ(mesh.num_faces(), e.faces);
  EXPECT_EQ(report.polygons_triangulated, e.polygons_triangulated);
  EXPECT_EQ(report.polygons_fanned, 0);
  EXPECT_EQ(report.duplicate_faces_removed, 0);
  EXPECT_EQ(report.unreferenced_vertices_removed, 0);
  EXPECT_TRUE(mesh.V.allFinite());
  EXPECT_GE(mesh.F.minCoeff(), 0);
  EXPECT_LT(mesh.F.maxCoeff(), mesh.num_vertices());
}

INSTANTIATE_TEST_SUITE_P(Data, BundledMesh, ::testing::ValuesIn(kBundled),
                         [](const auto& param_info) { return test::test_name(param_info.param.file); });

TEST(ReadMesh, FormatsAreDetected) {
  ReadReport report;
  read_mesh(data_path("amo.off"), &report);
  EXPECT_EQ(report.format, MeshFormat::Off);
  EXPECT_TRUE(report.binary);
  read_mesh(data_path("horse-48k.ply"), &report);
  EXPECT_EQ(report.format, MeshFormat::Ply);
  EXPECT_TRUE(report.binary);
  read_mesh(data_path("icosahedron_ascii.stl"), &report);
  EXPECT_FALSE(report.binary);
  EXPECT_EQ(report.vertices_welded, 60 - 12);
  read_mesh(data_path("icosahedron_binary.stl"), &report);
  EXPECT_TRUE(report.binary);
  EXPECT_EQ(report.vertices_welded, 60 - 12);
}

TEST(ReadMesh, PlyVertexPropertiesAreKept) {
  // horse-48k.ply carries normals nx, ny, nz as float properties: one Normal channel.
  const Mesh mesh = read_mesh(data_path("horse-48k.ply"));
  const AttributeChannel* normal = mesh.attributes.find_vertex("normal");
  ASSERT_NE(normal, nullptr);
  EXPECT_EQ(normal->role, AttributeRole::Normal);
  EXPECT_EQ(normal->type, ScalarType::Float32);
  EXPECT_EQ(normal->components, (std::vector<std::string>{"nx", "ny", "nz"}));
  ASSERT_EQ(normal->rows(), mesh.num_vertices());
  // The stored normals (not normalised in this file) point like the area-weighted face normals.
  Vertices face_normal_sum = Vertices::Zero(mesh.num_vertices(), 3);
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    const Eigen::RowVector3d n = (b - a).cross(c - a).transpose();
    for (int k = 0; k < 3; ++k) face_normal_sum.row(mesh.F(f, k)) += n;
  }
  Index agreeing = 0;
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    const Eigen::Vector3d stored = normal->values.row(v).transpose();
    agreeing += stored.normalized().dot(face_normal_sum.row(v).normalized()) > 0.9;
  }
  EXPECT_GT(agreeing, 0.99 * mesh.num_vertices());
}

// CGAL's readers are an independent implementation of the same formats: for triangle files
// (where no triangulation is involved) both must give the same positions and faces.
class AgreesWithCgal : public ::testing::TestWithParam<const char*> {};

TEST_P(AgreesWithCgal, SameVerticesAndFaces) {
  using Point = CGAL::Simple_cartesian<double>::Point_3;
  std::vector<Point> points;
  std::vector<std::vector<std::size_t>> polygons;
  ASSERT_TRUE(CGAL::IO::read_polygon_soup(data_path(GetParam()).string(), points, polygons));
  const Mesh mesh = read_mesh(data_path(GetParam()));
  ASSERT_EQ(static_cast<std::size_t>(mesh.num_vertices()), points.size());
  ASSERT_EQ(static_cast<std::size_t>(mesh.num_faces()), polygons.size());
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    for (int c = 0; c < 3; ++c) ASSERT_EQ(mesh.V(v, c), points[static_cast<std::size_t>(v)][c]) << "vertex " << v;
  }
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    ASSERT_EQ(polygons[static_cast<std::size_t>(f)].size(), 3u);
    for (int c = 0; c < 3; ++c)
      ASSERT_EQ(static_cast<std::size_t>(mesh.F(f, c)),
                polygons[static_cast<std::size_t>(f)][static_cast<std::size_t>(c)]);
  }
}

INSTANTIATE_TEST_SUITE_P(Data, AgreesWithCgal,
                         ::testing::Values("bunny_uniform.off", "fandisk.off", "horse-48k.ply", "spot.obj",
                                           "max-planck-5k.obj"),
                         [](const auto& param_info) { return test::test_name(param_info.param); });

// --- cleanup and triangulation on small in-memory files ---

Mesh read_text(const std::string& text, MeshFormat format, ReadReport* report = nullptr) {
  return read_mesh_from_memory(text, format, "memory", report);
}

TEST(Cleanup, RemovesUnreferencedDuplicateRepeatedAndZeroAreaFaces) {
  const std::string obj =
      "v 0 0 0\n"  // 1
      "v 9 9 9\n"  // 2: unreferenced
      "v 1 0 0\n"  // 3
      "v 0 1 0\n"  // 4
      "v 2 0 0\n"  // 5: collinear with 1 and 3
      "f 1 3 4\n"
      "f 4 3 1\n"   // duplicate with the opposite orientation
      "f 3 1 4\n"   // duplicate (rotation)
      "f 1 1 4\n"   // repeated index
      "f 1 3 5\n";  // zero area
  ReadReport report;
  const Mesh mesh = read_text(obj, MeshFormat::Obj, &report);
  ASSERT_EQ(mesh.num_faces(), 1);
  EXPECT_EQ(report.duplicate_faces_removed, 2);
  EXPECT_EQ(report.repeated_index_faces_removed, 1);
  EXPECT_EQ(report.zero_area_faces_removed, 1);
  // Vertices 2 and 5 (1-based) are unreferenced after cleanup; the others keep their order.
  EXPECT_EQ(report.unreferenced_vertices_removed, 2);
  ASSERT_EQ(mesh.num_vertices(), 3);
  EXPECT_EQ(mesh.V.row(0), Eigen::RowVector3d(0, 0, 0));
  EXPECT_EQ(mesh.V.row(1), Eigen::RowVector3d(1, 0, 0));
  EXPECT_EQ(mesh.V.row(2), Eigen::RowVector3d(0, 1, 0));
  EXPECT_EQ(mesh.F.row(0), Eigen::RowVector3i(0, 1, 2));
  EXPECT_EQ(report.warnings().size(), 4u);
}

TEST(Cleanup, ObjIndexForms) {
  const std::string obj =
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvn 0 0 1\n"
      "f 1/1/1 2/1/1 3/1/1\n"
      "f -3//1 -1//1 -2//1\n";  // = 2 4 3
  const Mesh mesh = read_text(obj, MeshFormat::Obj);
  ASSERT_EQ(mesh.num_faces(), 2);
  EXPECT_EQ(mesh.F.row(1), Eigen::RowVector3i(1, 3, 2));
}

// --- real-world forms: OBJ line continuation, OFF header on the keyword line, PLY extra values ---

// The message of the IoError that reading `text` throws, or "" (plus a test failure).
std::string read_error(const std::string& text, MeshFormat format) {
  try {
    read_mesh_from_memory(text, format, "memory");
    ADD_FAILURE() << "accepted: " << text;
  } catch (const IoError& e) {
    return e.what();
  }
  return {};
}

const std::string kSquareVertices = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\n";

TEST(ReadObj, ABackslashEndingALineContinuesTheStatement) {
  // Two quads; each file splits the statements differently and must read as this one does.
  const std::string plain = kSquareVertices + "f 1 2 3 4\nf 2 5 6 3\n";
  ReadReport plain_report;
  const Mesh expected = read_text(plain, MeshFormat::Obj, &plain_report);
  ASSERT_EQ(expected.num_faces(), 4);
  const std::string continued[] = {
      kSquareVertices + "f 1 2 \\\n3 4\nf 2 5 6 3\n",                 // a backslash token
      kSquareVertices + "f 1 2\\\n 3 4\nf 2 5 6 3\n",                 // attached to the index
      kSquareVertices + "f 1/1/1 2/1/1\\\n3/1/1 4/1/1\nf 2 5 6 3\n",  // attached to a v/t/n corner
      kSquareVertices + "f 1 2 \\ \t\r\n3 4\r\nf 2 5 6 3\r\n",        // blanks and CR after it
      kSquareVertices + "f 1 \\\n\\\n  \\\n2 3 \\\n4\nf 2 5 6 3\n",   // lines holding only a backslash
      kSquareVertices + "f 1 2 3 4 \\\n\nf 2 5 6 3\n",                // continued by an empty line
      kSquareVertices + "f\\\n1 2 3 4\nf 2 5 6 3\n",                  // after the keyword
      kSquareVertices + "f 1 2 3 4\nf 2 5 6 3 \\",                    // at the end of the file
      "v 0 0 \\\n0\nv 1\\\n0 0\nv 1 1 0 \\\n1.0\nv \\\n0 1 0\n" + kSquareVertices.substr(32) +
          "f 1 2 3 4\nf 2 5 6 3\n",  // vertices, one with a w continued
      "vn 0 0 \\\n1\n" + kSquareVertices + "# a comment continues too \\\nf 9 9 9\nf 1 2 3 4\nf 2 5 6 3\n",
  };
  for (const std::string& text : continued) {
    SCOPED_TRACE(text);
    ReadReport report;
    const Mesh mesh = read_text(text, MeshFormat::Obj, &report);
    EXPECT_EQ(mesh.V, expected.V);
    EXPECT_EQ(mesh.F, expected.F);
    EXPECT_EQ(report.polygons_triangulated, 2);
    // The spec allows it: no warning (but the one naming texture and normal indices without a
    // vt or vn table, which are not kept).
    std::vector<std::string> warnings = report.warnings();
    std::erase_if(warnings, [](const std::string& w) { return w.rfind("not kept", 0) == 0; });
    EXPECT_EQ(warnings, plain_report.warnings());
  }
}

TEST(ReadObj, ContinuedStatementErrorsNameTheStatementsFirstLine) {
  // The face starts on line 7 and its bad index is on line 9; the next statement's line
  // numbers are the physical ones again.
  EXPECT_EQ(read_error(kSquareVertices + "f 1 2 \\\n3 \\\nx\n", MeshFormat::Obj),
            "memory: line 7: expected a face vertex index, found 'x'");
  EXPECT_EQ(read_error(kSquareVertices + "f 1 2 \\\n3\nf 1 \\\n\\\nx\n", MeshFormat::Obj),
            "memory: line 9: expected a face vertex index, found 'x'");
  EXPECT_EQ(read_error("v 0 \\\n0\nv 1 0 0\n", MeshFormat::Obj), "memory: line 1: a vertex needs three coordinates");
  // A backslash with more text after it on its line continues nothing.
  EXPECT_EQ(read_error(kSquareVertices + "f 1 2 \\ 3\n", MeshFormat::Obj),
            "memory: line 7: expected a face vertex index, found '\\'");
  EXPECT_EQ(read_error(kSquareVertices + "f 1 2\\3\n", MeshFormat::Obj),
            "memory: line 7: expected a face vertex index, found '2\\3'");
  // Continued to the end of the file, the face has two vertices.
  std::string endless = kSquareVertices + "f 1 2 \\\n";
  for (int i = 0; i < 100000; ++i) endless += "\\\n";
  EXPECT_EQ(read_error(endless, MeshFormat::Obj), "memory: face 0 has 2 vertices; a face needs at least 3");
}

TEST(ReadOff, CountsMayFollowTheKeywordOnItsLine) {
  // Each keyword the reader supports, with the counts on its line (with or without the edge
  // count and a comment), or a comment on the keyword's line and the counts on the next.
  const std::string vertices[] = {"0 0 0", "1 0 0", "1 1 0", "0 1 0"};
  struct Case {
    std::string keyword, extra;  // per-vertex values after x y z
  };
  const Case cases[] = {{"OFF", ""},           {"COFF", " 1 0 0 1"},
                        {"NOFF", " 0 0 1"},    {"CNOFF", " 1 0 0 1 0 0 1"},
                        {"STOFF", " 0.5 0.5"}, {"STCNOFF", " 0.5 0.5 1 0 0 1 0 0 1"}};
  for (const Case& c : cases) {
    std::string body;
    for (const std::string& v : vertices) body += v + c.extra + "\n";
    body += "4 0 1 2 3\n";
    for (const std::string& header : {c.keyword + " 4 1 0\n", c.keyword + "\t4 1\n", c.keyword + " 4 1 0 # counts\n",
                                      c.keyword + " # a comment\n4 1 0\n", c.keyword + "\n4 1 0\n"}) {
      SCOPED_TRACE(header);
      ReadReport report;
      const Mesh mesh = read_text(header + body, MeshFormat::Off, &report);
      EXPECT_EQ(mesh.num_vertices(), 4);
      EXPECT_EQ(mesh.num_faces(), 2);
      EXPECT_EQ(report.format, MeshFormat::Off);
      EXPECT_FALSE(report.format_differs_from_extension);
      EXPECT_EQ(report.warnings(), std::vector<std::string>{"1 polygons triangulated"});
    }
  }
  // Errors stay errors: a keyword glued to a count, a count missing, a count the file cannot
  // hold.
  const std::string body = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  EXPECT_EQ(read_error("OFF3 1 0\n" + body, MeshFormat::Off),
            "memory: not an OFF file (expected 'OFF' at the start, found 'OFF3')");
  EXPECT_EQ(read_error("OFF 3 # no face count\n", MeshFormat::Off),
            "memory: line 2: expected the face count, found ''");
  const std::string huge = read_error("OFF 3 2000000000 0\n" + body, MeshFormat::Off);
  EXPECT_EQ(huge.rfind("memory: header declares 3 vertices and 2000000000 faces, but the remaining", 0), 0u) << huge;
}

TEST(ReadPly, AsciiLinesWithMoreValuesThanDeclaredAreReadAndCounted) {
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 2\nproperty list uchar int vertex_indices\nend_header\n";
  const std::string clean = header + "0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n";
  const Mesh expected = read_text(clean, MeshFormat::Ply);
  // Undeclared normals on two vertex lines, a face colour on one face line, and a quad's
  // fourth index after a count of 3 (read as the triangle the count declares).
  const std::string extra = header + "0 0 0 0 0 1\n1 0 0 0 0 1\n1 1 0\n0 1 0\n3 0 1 2 255 0 0\n3 0 2 3 1\n";
  ReadReport report;
  const Mesh mesh = read_text(extra, MeshFormat::Ply, &report);
  EXPECT_EQ(mesh.V, expected.V);
  EXPECT_EQ(mesh.F, expected.F);
  EXPECT_EQ(report.ply_extra_values_lines, 4);
  EXPECT_EQ(
      report.warnings(),
      std::vector<std::string>{"4 lines had more values than their element declares; the extra values were ignored"});
  // Also in elements that are skipped, and with CRLF line ends.
  const std::string with_edges =
      "ply\r\nformat ascii 1.0\r\nelement vertex 3\r\nproperty float x\r\nproperty float y\r\nproperty float z\r\n"
      "element edge 1\r\nproperty int vertex1\r\nproperty int vertex2\r\nelement face 1\r\n"
      "property list uchar int vertex_indices\r\nend_header\r\n0 0 0\r\n1 0 0 7\r\n0 1 0\r\n0 1 +2 -3e5 nan\r\n"
      "3 0 1 2\r\n";
  EXPECT_EQ(read_text(with_edges, MeshFormat::Ply, &report).num_faces(), 1);
  EXPECT_EQ(report.ply_extra_values_lines, 2);
}

TEST(ReadPly, AsciiExtraTextAndMissingValuesAreErrors) {
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  // Extra tokens must be numbers: text after a record is no value a writer forgot to declare.
  EXPECT_EQ(read_error(header + "0 0 0\n1 0 0 normal\n0 1 0\n3 0 1 2\n", MeshFormat::Ply),
            "memory: line 11: more values than the 'vertex' element declares, and 'normal' is not a number");
  // Fewer values than declared would shift every later value: an error on its line.
  EXPECT_EQ(read_error(header + "0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n", MeshFormat::Ply),
            "memory: line 13: too few values on the line (expected a face vertex index)");
  EXPECT_EQ(read_error(header + "0 0 0\n1 0\n0 1 0\n3 0 1 2\n", MeshFormat::Ply),
            "memory: line 11: too few values on the line (expected a vertex coordinate)");
}

// Sum of the triangles' areas projected on the polygon's normal, and of their absolute areas:
// equal exactly when no triangle is folded over.
std::pair<double, double> signed_and_absolute_area(const Mesh& mesh, const Eigen::Vector3d& normal) {
  double signed_area = 0, absolute = 0;
  for (Index f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    const Eigen::Vector3d n = 0.5 * (b - a).cross(c - a);
    signed_area += n.dot(normal);
    absolute += n.norm();
  }
  return {signed_area, absolute};
}

TEST(Triangulation, NonConvexPolygonIsTriangulatedInside) {
  // An L-shaped hexagon (area 3) in a tilted plane, and a non-convex "arrow" pentagon. A fan
  // from the first corner folds triangles over for both.
  const std::string off =
      "OFF\n11 2 0\n"
      "0 0 0\n2 0 0\n2 1 1\n1 1 1\n1 2 2\n0 2 2\n"  // L, plane y = z
      "0 0 5\n4 0 5\n1 1 5\n4 4 5\n0 4 5\n"         // arrow, z = 5
      "6 3 4 5 0 1 2\n"                             // starts at the reflex corner's neighbour
      "5 8 9 10 6 7\n";                             // starts at the reflex corner
  ReadReport report;
  const Mesh mesh = read_text(off, MeshFormat::Off, &report);
  EXPECT_EQ(report.polygons_triangulated, 2);
  EXPECT_EQ(report.polygons_fanned, 0);
  ASSERT_EQ(mesh.num_faces(), 4 + 3);
  Mesh l_shape = mesh, arrow = mesh;
  l_shape.F = mesh.F.topRows(4);
  arrow.F = mesh.F.bottomRows(3);
  const auto [l_signed, l_abs] = signed_and_absolute_area(l_shape, Eigen::Vector3d(0, -1, 1).normalized());
  EXPECT_NEAR(l_signed, 3 * std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(l_abs, 3 * std::sqrt(2.0), 1e-12);
  // Arrow area: square 16 minus the notch triangle (0,0)-(4,0)-(1,1) and (4,4)... computed by shoelace.
  const double xs[] = {0, 4, 1, 4, 0}, ys[] = {0, 0, 1, 4, 4};
  double shoelace = 0;
  for (int i = 0; i < 5; ++i) shoelace += xs[i] * ys[(i + 1) % 5] - xs[(i + 1) % 5] * ys[i];
  const auto [a_signed, a_abs] = signed_and_absolute_area(arrow, Eigen::Vector3d(0, 0, 1));
  EXPECT_NEAR(a_signed, 0.5 * shoelace, 1e-12);
  EXPECT_NEAR(a_abs, 0.5 * shoelace, 1e-12);
}

TEST(Triangulation, NonConvexQuadUsesTheValidDiagonal) {
  // A dart: corner 2 is reflex, so only the diagonal 0-2 is valid.
  const std::string off = "OFF\n4 1 0\n0 0 0\n4 0 0\n1 1 0\n0 4 0\n4 0 1 2 3\n";
  const Mesh mesh = read_text(off, MeshFormat::Off);
  ASSERT_EQ(mesh.num_faces(), 2);
  const auto [signed_area, absolute] = signed_and_absolute_area(mesh, Eigen::Vector3d(0, 0, 1));
  EXPECT_NEAR(signed_area, 4.0, 1e-12);
  EXPECT_NEAR(absolute, 4.0, 1e-12);
}

TEST(Triangulation, SelfIntersectingPolygonIsFannedWithAWarning) {
  // A bow-tie pentagon whose edges cross.
  const std::string off = "OFF\n5 1 0\n0 0 0\n2 2 0\n2 0 0\n0 2 0\n1 3 0\n5 0 1 2 3 4\n";
  ReadReport report;
  const Mesh mesh = read_text(off, MeshFormat::Off, &report);
  EXPECT_EQ(report.polygons_fanned, 1);
  EXPECT_EQ(mesh.num_faces(), 3);
}

TEST(ReadPly, AsciiWithColoursAndProperties) {
  const std::string ply =
      "ply\nformat ascii 1.0\ncomment test\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nproperty double k1\n"
      "element face 1\nproperty list uchar int vertex_indices\nproperty int flags\nend_header\n"
      "0 0 0 255 0 0 0.5\n1 0 0 0 255 0 -1.5\n0 1 0 0 0 255 2\n3 0 1 2 7\n";
  const Mesh mesh = read_text(ply, MeshFormat::Ply);
  ASSERT_EQ(mesh.num_faces(), 1);
  ASSERT_EQ(mesh.vertex_colors().rows(), 3);
  EXPECT_EQ(mesh.vertex_colors()(1, 1), 255);
  const AttributeChannel* k1 = mesh.find_vertex_property("k1");
  ASSERT_NE(k1, nullptr);
  EXPECT_EQ(k1->values(1, 0), -1.5);
  // The face property is a face channel with its type.
  const AttributeChannel* flags = mesh.attributes.find_face("flags");
  ASSERT_NE(flags, nullptr);
  EXPECT_EQ(flags->type, ScalarType::Int32);
  EXPECT_EQ(flags->values(0, 0), 7);
}

TEST(ReadMesh, ErrorsStayOnOneLineWhateverTheFileName) {
  test::ScratchDir dir("newline");
  const auto path = dir.file("two\nlines.obj");
  { std::ofstream(path) << "v 0 0 0\n"; }
  try {
    read_mesh(path);
    FAIL();
  } catch (const IoError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_NE(message.find("two?lines.obj: the file contains no faces"), std::string::npos) << message;
  }
}

TEST(ReadMesh, CoordinatesWhoseSquaresOverflowOrUnderflowAreRefused) {
  const std::string huge = "v 0 0 0\nv 1e70 0 0\nv 0 1e70 0\nf 1 2 3\n";
  const std::string tiny = "v 0 0 0\nv 1e-70 0 0\nv 0 1e-70 0\nf 1 2 3\n";
  EXPECT_THROW(read_text(huge, MeshFormat::Obj), IoError);
  EXPECT_THROW(read_text(tiny, MeshFormat::Obj), IoError);
  // Large and small but representable scales are fine.
  EXPECT_EQ(read_text("v 0 0 0\nv 1e50 0 0\nv 0 1e50 0\nf 1 2 3\n", MeshFormat::Obj).num_faces(), 1);
  EXPECT_EQ(read_text("v 0 0 0\nv 1e-50 0 0\nv 0 1e-50 0\nf 1 2 3\n", MeshFormat::Obj).num_faces(), 1);
}

TEST(ReadPly, AsciiRecordsMustMatchTheHeaderLineByLine) {
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  EXPECT_NO_THROW(read_text(header + "0 0 0\n1 0 0\n\n0 1 0\n3 0 1 2\n", MeshFormat::Ply));
  // A missing coordinate would otherwise silently shift every later value.
  try {
    read_text(header + "0 0\n1 0 0\n0 1 0\n3 0 1 2\n", MeshFormat::Ply);
    FAIL();
  } catch (const IoError& e) {
    EXPECT_STREQ(e.what(), "memory: line 10: too few values on the line (expected a vertex coordinate)");
  }
  // More values than declared: the declared ones are read, the rest ignored and counted
  // (ReadPly.AsciiLinesWithMoreValuesThanDeclaredAreReadAndCounted); the record does not
  // spill over to the next line either way.
  ReadReport report;
  EXPECT_EQ(read_text(header + "0 0 0\n1 0 0\n0 1 0\n4 0 1 2 1 5\n", MeshFormat::Ply, &report).num_faces(), 1);
  EXPECT_EQ(report.ply_extra_values_lines, 1);
}

TEST(Cleanup, ZeroAreaFacesCanBeKept) {
  const std::string obj = "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 4\nf 1 2 3\n";
  ReadOptions keep;
  keep.remove_zero_area_faces = false;
  ReadReport report;
  EXPECT_EQ(read_mesh_from_memory(obj, MeshFormat::Obj, "memory", &report, keep).num_faces(), 2);
  EXPECT_EQ(report.zero_area_faces_removed, 0);
  EXPECT_EQ(read_mesh_from_memory(obj, MeshFormat::Obj, "memory", &report).num_faces(), 1);
  EXPECT_EQ(report.zero_area_faces_removed, 1);
}

}  // namespace
}  // namespace vertexflow

namespace vertexflow {
namespace {

// PLY `tristrips` (Cyberware and Stanford scans): strips separated by -1 (or its uint32 spelling),
// each triangle of a strip turned to keep the strip's orientation, the stitching triangles
// (a repeated corner) skipped.
TEST(ReadPly, TriangleStripsBecomeTriangles) {
  // A 3 x 2 grid of the plane z = 0: 0 1 2 on y = 0, 3 4 5 on y = 1.
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\nproperty float z\n"
      "element tristrips 1\nproperty list int {} vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n2 0 0\n0 1 0\n1 1 0\n2 1 0\n";
  for (const auto& [type, restart] : {std::pair{"int", "-1"}, std::pair{"uint", "4294967295"}}) {
    std::string text = header;
    text.replace(text.find("{}"), 2, type);
    // One strip over the first square, a restart, then one over the second that starts with
    // two stitching triangles (4 4 4, 4 4 1), which are no faces.
    text += std::string("11 3 0 4 1 ") + restart + " 4 4 4 1 5 2\n";
    ReadReport report;
    const Mesh mesh = read_mesh_from_memory(text, MeshFormat::Ply, "strips.ply", &report);
    ASSERT_EQ(mesh.num_faces(), 4) << type;
    EXPECT_EQ(report.strip_triangles, 4);
    for (Index f = 0; f < 4; ++f)  // the strips' orientation: every face faces +z
      EXPECT_GT(face_normal(mesh.V, mesh.F, f).z(), 0) << type << " face " << f;
    // The four triangles cover both squares: total area 2.
    double area = 0;
    for (Index f = 0; f < 4; ++f) area += 0.5 * face_normal(mesh.V, mesh.F, f).norm();
    EXPECT_DOUBLE_EQ(area, 2.0);
  }
}

// What a file holds and the mesh does not keep is named, with counts, in one warning line; what
// it keeps (attributes.h) is not.
TEST(ReadReport, AttributesNotKeptAreNamed) {
  const std::string obj =
      "mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\ng part\n"
      "usemtl red\ns 1\nf 1/1/1 2/2/1 3/3/1\nusemtl blue\nf 2/2/1 4/1/1 3/3/1\nl 1 2\nl 2 3\n";
  ReadReport report;
  const Mesh mesh = read_mesh_from_memory(obj, MeshFormat::Obj, "a.obj", &report);
  EXPECT_EQ(report.not_kept, std::vector<std::string>{"OBJ lines l (2)"});
  const std::vector<std::string> warnings = report.warnings();
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0], "not kept: OBJ lines l (2)");
  EXPECT_NE(mesh.attributes.find_corner("uv"), nullptr);
  EXPECT_NE(mesh.attributes.find_face("material"), nullptr);

  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "property list uchar int neighbours\nelement face 1\nproperty list uchar int vertex_indices\n"
      "property int material\nelement edge 2\nproperty int vertex1\nproperty int vertex2\nend_header\n"
      "0 0 0 0\n1 0 0 0\n0 1 0 0\n3 0 1 2 7\n0 1\n1 2\n";
  ReadReport ply_report;
  (void)read_mesh_from_memory(ply, MeshFormat::Ply, "a.ply", &ply_report);
  const std::vector<std::string> ply_expected = {"PLY vertex list property 'neighbours' (3)", "PLY element 'edge' (2)"};
  EXPECT_EQ(ply_report.not_kept, ply_expected);
  // A file with nothing beyond positions and faces warns of nothing.
  ReadReport plain;
  (void)read_mesh(test::data_path("bunny_uniform.off"), &plain);
  EXPECT_TRUE(plain.not_kept.empty());
}

}  // namespace
}  // namespace vertexflow
