// Writing is atomic and never clobbers the input by accident.
#include "test_support.h"

#include "vertexflow/io.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>

#include <sys/stat.h>

namespace vertexflow {
namespace {

Mesh triangle() {
  Mesh mesh;
  mesh.V.resize(3, 3);
  mesh.V << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  mesh.F.resize(1, 3);
  mesh.F << 0, 1, 2;
  return mesh;
}

int count_entries(const std::filesystem::path& dir) {
  int n = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++n;
  return n;
}

TEST(WriteMesh, FailureLeavesExistingFileUntouchedAndNoTemporary) {
  test::ScratchDir dir("atomic");
  const auto path = dir.file("out.ply");
  { std::ofstream(path) << "precious"; }
  Mesh bad = triangle();
  bad.set_vertex_property("broken", Eigen::VectorXd::Zero(3));
  bad.attributes.vertex.back().values.resize(2, 1);  // wrong size: the write fails
  EXPECT_THROW(write_mesh(path, bad), IoError);
  EXPECT_EQ(test::read_text(path), "precious");
  EXPECT_EQ(count_entries(dir.path()), 1);
}

TEST(WriteMesh, InvalidFaceIndexIsRefusedBeforeWriting) {
  test::ScratchDir dir("invalid");
  Mesh bad = triangle();
  bad.F(0, 2) = 7;
  EXPECT_THROW(write_mesh(dir.file("out.obj"), bad), IoError);
  EXPECT_EQ(count_entries(dir.path()), 0);
}

TEST(WriteMesh, ErrorsNameTheFile) {
  test::ScratchDir dir("errors");
  const auto missing_dir = dir.file("no/such/dir/out.off");
  try {
    write_mesh(missing_dir, triangle());
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(missing_dir.string(), 0), 0u) << e.what();
  }
  EXPECT_THROW(write_mesh(dir.file("out.xyz"), triangle()), IoError);
  EXPECT_THROW(write_mesh(dir.path(), triangle()), IoError);
}

TEST(WriteMesh, ReplacesAnExistingFile) {
  test::ScratchDir dir("replace");
  const auto path = dir.file("out.obj");
  { std::ofstream(path) << "old"; }
  write_mesh(path, triangle());
  EXPECT_EQ(read_mesh(path).num_faces(), 1);
}

TEST(CheckOutputPath, RefusesTheInputUnlessForced) {
  test::ScratchDir dir("same");
  const auto input = dir.file("in.obj");
  write_mesh(input, triangle());
  EXPECT_THROW(check_output_path(input, input, false), IoError);
  // The same file under another spelling, and through a hard link.
  EXPECT_THROW(check_output_path(input, dir.path() / "." / "in.obj", false), IoError);
  std::filesystem::create_hard_link(input, dir.file("link.obj"));
  EXPECT_THROW(check_output_path(input, dir.file("link.obj"), false), IoError);
  EXPECT_NO_THROW(check_output_path(input, input, true));
  EXPECT_NO_THROW(check_output_path(input, dir.file("out.ply"), false));
  EXPECT_THROW(check_output_path(input, dir.path(), false), IoError);
  EXPECT_THROW(check_output_path(input, dir.file("out.unknown"), false), IoError);
}

// Sets VERTEXFLOW_NO_O_TMPFILE for one scope: writes then use a named temporary file, as on
// file systems without O_TMPFILE.
class NamedTemporaryFiles {
 public:
  explicit NamedTemporaryFiles(bool on) {
    if (on) ::setenv("VERTEXFLOW_NO_O_TMPFILE", "1", 1);
  }
  NamedTemporaryFiles(const NamedTemporaryFiles&) = delete;
  NamedTemporaryFiles& operator=(const NamedTemporaryFiles&) = delete;
  ~NamedTemporaryFiles() { ::unsetenv("VERTEXFLOW_NO_O_TMPFILE"); }
};

class WriteBothWays : public ::testing::TestWithParam<bool> {};

TEST_P(WriteBothWays, NewFileGetsTheModeTheUmaskGives) {
  const NamedTemporaryFiles named(GetParam());
  test::ScratchDir dir("mode");
  const mode_t old_mask = ::umask(022);
  write_mesh(dir.file("a.obj"), triangle());
  ::umask(077);
  write_text_file(dir.file("b.txt"), "text\n");
  ::umask(old_mask);
  EXPECT_EQ(std::filesystem::status(dir.file("a.obj")).permissions(), static_cast<std::filesystem::perms>(0644));
  EXPECT_EQ(std::filesystem::status(dir.file("b.txt")).permissions(), static_cast<std::filesystem::perms>(0600));
  EXPECT_EQ(count_entries(dir.path()), 2);
}

TEST_P(WriteBothWays, FailureLeavesNoTemporaryFile) {
  const NamedTemporaryFiles named(GetParam());
  test::ScratchDir dir("atomic-both");
  const auto path = dir.file("out.ply");
  { std::ofstream(path) << "precious"; }
  Mesh bad = triangle();
  bad.set_vertex_property("broken", Eigen::VectorXd::Zero(3));
  bad.attributes.vertex.back().values.resize(2, 1);
  EXPECT_THROW(write_mesh(path, bad), IoError);
  EXPECT_EQ(test::read_text(path), "precious");
  write_mesh(path, triangle());
  EXPECT_EQ(read_mesh(path).num_faces(), 1);
  EXPECT_EQ(count_entries(dir.path()), 1);
}

TEST_P(WriteBothWays, CheckOutputWritableNamesThePathAndLeavesNothing) {
  const NamedTemporaryFiles named(GetParam());
  test::ScratchDir dir("writable");
  EXPECT_NO_THROW(check_output_writable(dir.file("out.ply")));
  EXPECT_NO_THROW(check_output_writable(dir.file("no-extension-needed")));
  EXPECT_EQ(count_entries(dir.path()), 0);
  { std::ofstream(dir.file("file")) << "x"; }
  for (const auto& path : {dir.file("missing/out.ply"), dir.file("file/out.ply"), dir.path()}) {
    try {
      check_output_writable(path);
      ADD_FAILURE() << "expected IoError for " << path;
    } catch (const IoError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(path.string() + ": ", 0), 0u) << e.what();
    }
  }
  // An existing file is replaced by the write, so it does not stop the check.
  EXPECT_NO_THROW(check_output_writable(dir.file("file")));
  EXPECT_EQ(count_entries(dir.path()), 1);
}

INSTANTIATE_TEST_SUITE_P(TemporaryFile, WriteBothWays, ::testing::Values(false, true), [](const auto& param_info) {
  return param_info.param ? std::string("Named") : std::string("Unnamed");
});

TEST(WriteMesh, OptionsLeaveOutColoursAndProperties) {
  test::ScratchDir dir("options");
  Mesh mesh = triangle();
  mesh.set_vertex_colors(Colors::Constant(3, 3, 200));
  mesh.set_vertex_property("k1", Eigen::Vector3d(1, 2, 3));
  WriteOptions options;
  options.write_colors = false;
  options.write_vertex_properties = false;
  write_mesh(dir.file("plain.ply"), mesh, options);
  const Mesh plain = read_mesh(dir.file("plain.ply"));
  EXPECT_EQ(plain.vertex_colors().rows(), 0);
  EXPECT_TRUE(plain.attributes.vertex.empty());
  write_mesh(dir.file("full.ply"), mesh);
  const Mesh full = read_mesh(dir.file("full.ply"));
  EXPECT_EQ(full.vertex_colors().rows(), 3);
  ASSERT_NE(full.find_vertex_property("k1"), nullptr);
}

TEST(WriteMesh, PropertyErrorsNameTheFile) {
  test::ScratchDir dir("property-error");
  Mesh mesh = triangle();
  mesh.set_vertex_property("short", Eigen::VectorXd::Zero(3));
  mesh.attributes.vertex.back().values.resize(1, 1);
  try {
    write_mesh(dir.file("out.ply"), mesh);
    FAIL();
  } catch (const IoError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(
                  dir.file("out.ply").string() + ": attributes: vertex channel 'short' has 1 rows for 3 vertices", 0),
              0u)
        << e.what();
  }
}

}  // namespace
}  // namespace vertexflow
