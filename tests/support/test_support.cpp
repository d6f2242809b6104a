#include "test_support.h"

#include "vertexflow/topology.h"

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>
#include <cctype>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>

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

void expect_same_topology(const Mesh& input, const Mesh& output) {
  const Topology before = build_topology(input.F, input.num_vertices());
  const Topology after = build_topology(output.F, output.num_vertices());
  EXPECT_TRUE(after.is_manifold());
  EXPECT_TRUE(after.is_oriented);
  EXPECT_EQ(after.genus(), before.genus());
  EXPECT_EQ(after.num_components, before.num_components);
  EXPECT_EQ(after.boundary_loops.size(), before.boundary_loops.size());
}

}  // namespace vertexflow::test
