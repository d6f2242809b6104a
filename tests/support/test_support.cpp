#include "test_support.h"

#include "shapes.h"
#include "vertexflow/compare.h"
#include "vertexflow/io.h"
#include "vertexflow/manifold_split.h"
#include "vertexflow/quality.h"
#include "vertexflow/topology.h"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <thread>

namespace vertexflow::test {

ScratchDir::ScratchDir(const std::string& tag) {
  std::random_device rd;
  path_ = std::filesystem::temp_directory_path() /
          ("vertexflow-" + tag + "-" + std::to_string(::getpid()) + "-" + std::to_string(rd()));
  std::filesystem::create_directories(path_);
}

ScratchDir::~ScratchDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

std::string test_name(const std::string& s) {
  std::string out = s;
  for (char& c : out) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return out;
}

std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (const char c : s) {
    if (c == '\'')
      out += "'\\''";
    else
      out += c;
  }
  return out + "'";
}

CommandResult run_command(const std::string& command) {
  ScratchDir scratch("cmd");
  const auto err_path = scratch.file("stderr.txt");
  CommandResult result;
  FILE* pipe = ::popen((command + " 2>" + shell_quote(err_path.string())).c_str(), "r");
  if (!pipe) return result;
  char buffer[4096];
  std::size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof(buffer), pipe)) > 0) result.out.append(buffer, n);
  const int status = ::pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  result.err = read_text(err_path);
  return result;
}

CommandResult run_cli(const std::string& arguments) {
  return run_command(shell_quote(VERTEXFLOW_CLI) + " " + arguments);
}

WatchedRun run_cli_watched(const std::vector<std::string>& arguments, double timeout_seconds,
                           const std::vector<std::string>& environment) {
  ScratchDir scratch("watched");
  const std::string err_path = scratch.file("stderr.txt").string();
  // Everything the child needs is built before fork: between fork and exec only
  // async-signal-safe calls are allowed (the parent may run TBB threads).
  std::vector<std::string> argv_text{VERTEXFLOW_CLI};
  argv_text.insert(argv_text.end(), arguments.begin(), arguments.end());
  std::vector<char*> argv;
  for (std::string& a : argv_text) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_text;
  for (char** e = environ; *e != nullptr; ++e) env_text.emplace_back(*e);
  env_text.insert(env_text.end(), environment.begin(), environment.end());
  std::vector<char*> envp;
  for (std::string& e : env_text) envp.push_back(e.data());
  envp.push_back(nullptr);

  WatchedRun result;
  const pid_t pid = ::fork();
  if (pid < 0) return result;
  if (pid == 0) {
    const int fd = ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) ::dup2(fd, 2);
    const int null = ::open("/dev/null", O_WRONLY);
    if (null >= 0) ::dup2(null, 1);
    ::execve(argv[0], argv.data(), envp.data());
    ::_exit(127);
  }
  const auto start = std::chrono::steady_clock::now();
  int status = 0;
  rusage usage{};
  for (;;) {
    const pid_t done = ::wait4(pid, &status, WNOHANG, &usage);
    if (done == pid) break;
    if (done < 0 && errno != EINTR) return result;
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > timeout_seconds) {
      ::kill(pid, SIGKILL);
      while (::wait4(pid, &status, 0, &usage) < 0 && errno == EINTR) {
      }
      result.timed_out = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  result.peak_rss_kb = usage.ru_maxrss;
  result.err = read_text(err_path);
  return result;
}

Eigen::VectorXd stated_quality_floor(const Mesh& input, double min_quality, double sliver_floor) {
  const Eigen::VectorXd q = triangle_quality(input.V, input.F);
  const Topology topology = build_topology(input.F, input.num_vertices());
  Eigen::VectorXd floor(input.num_faces());
  for (Index f = 0; f < input.num_faces(); ++f) {
    floor[f] = q[f] < min_quality ? std::min(min_quality, sliver_floor * q[f]) : min_quality;
    for (int k = 0; k < 3; ++k) {
      const auto v = static_cast<std::size_t>(input.F(f, k));
      for (Index j = topology.face_offsets[v]; j < topology.face_offsets[v + 1]; ++j)
        floor[f] = std::min(floor[f], q[topology.vertex_faces[static_cast<std::size_t>(j)]]);
    }
  }
  return floor;
}

void expect_guard_promises_kept(const Mesh& input, const Vertices& moved, bool fix_boundary,
                                const std::vector<Index>& pinned, double min_quality, double sliver_floor) {
  ASSERT_EQ(moved.rows(), input.V.rows());
  ASSERT_TRUE(moved.allFinite());
  EXPECT_TRUE(flipped_faces(input.V, moved, input.F).empty());
  EXPECT_TRUE(degenerate_faces(moved, input.F).empty());
  const Topology topology = build_topology(input.F, input.num_vertices());
  for (Index v = 0; v < input.num_vertices(); ++v) {
    if (fix_boundary && topology.is_boundary_vertex[static_cast<std::size_t>(v)]) {
      ASSERT_EQ(moved.row(v), input.V.row(v)) << v;
    }
  }
  for (const Index v : pinned) ASSERT_EQ(moved.row(v), input.V.row(v)) << v;
  const Eigen::VectorXd floor = stated_quality_floor(input, min_quality, sliver_floor);
  const Eigen::VectorXd q = triangle_quality(moved, input.F);
  for (Index f = 0; f < input.num_faces(); ++f) ASSERT_GE(q[f], floor[f] - 1e-12) << "face " << f;
}

void expect_clean_surface(const Mesh& mesh) {
  const Topology topology = build_topology(mesh.F, mesh.num_vertices());
  EXPECT_TRUE(topology.is_manifold()) << describe_non_manifold(topology);
  EXPECT_TRUE(topology.is_oriented);
  EXPECT_TRUE(degenerate_faces(mesh.V, mesh.F).empty());
  for (Index v = 0; v < mesh.num_vertices(); ++v)
    ASSERT_LT(topology.face_offsets[static_cast<std::size_t>(v)],
              topology.face_offsets[static_cast<std::size_t>(v) + 1])
        << "unreferenced vertex " << v;
}

void expect_same_topology(const Mesh& input, const Mesh& output) {
  const Topology before = build_topology(input.F, input.num_vertices());
  const Topology after = build_topology(output.F, output.num_vertices());
  EXPECT_TRUE(after.is_manifold());
  EXPECT_TRUE(after.is_oriented);
  EXPECT_EQ(after.genus(), before.genus());
  EXPECT_EQ(after.num_components, before.num_components);
  EXPECT_EQ(after.boundary_loops.size(), before.boundary_loops.size());
}

Mesh clustered_bunny(double fraction) {
  const Mesh bunny = read_mesh(data_path("bunny.off"));
  return vertex_clustered(bunny, fraction * bounding_box(bunny.V).diagonal());
}

RhoChange redistribution_rho_change(const Mesh& input, const Vertices& moved) {
  const ManifoldSplit split = split_non_manifold(input.V, input.F, build_topology(input.F, input.num_vertices()));
  Mesh before;
  before.V = split.V;
  before.F = split.F;
  Mesh after = before;
  for (Index s = 0; s < split.V.rows(); ++s)
    after.V.row(s) = moved.row(split.source_vertex[static_cast<std::size_t>(s)]);
  CompareOptions options;
  options.sampling.samples = 1000;
  const MeshComparison c = compare_meshes(after, before, nullptr, options);
  return {c.redistribution_rho_input, c.redistribution_rho_result};
}

}  // namespace vertexflow::test
