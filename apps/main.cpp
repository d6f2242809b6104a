// vertexflow: command-line interface. Each subcommand lives in its own command_*.cpp; this file
// parses the command line and turns every error into one line on stderr and exit code 1.
#include "allocator.h"
#include "cli_common.h"
#include "page_pool.h"

#include <fmt/format.h>

#include <cstdio>
#include <exception>
#include <new>
#include <string>
#include <string_view>

namespace {

// "FILE: " for the mesh the command read last, or nothing before any read.
std::string input_prefix() {
  const std::string& input = vertexflow::cli::last_input_path();
  return input.empty() ? std::string() : input + ": ";
}

}  // namespace

int main(int argc, char** argv) {
  using namespace vertexflow::cli;
  install_page_pool();
  CLI::App app{"vertexflow: enhance the shape features of triangle meshes by vertex flow"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "vertexflow 0.1.0\nallocator: " + allocator_description());
  GlobalOptions global;
  app.add_flag("-q,--quiet", global.quiet, "Print no warnings or progress")->configurable(false);
  app.fallthrough();
  register_info_command(app, global);
  register_curvature_command(app, global);
  register_enhance_command(app, global);
  register_simplify_command(app, global);
  register_remesh_command(app, global);
  register_render_command(app, global);
  register_lines_command(app, global);
  register_compare_lines_command(app, global);
  register_report_command(app, global);
  register_compare_command(app, global);
  register_batch_command(app, global);
  register_lod_command(app, global);
  require_finite_numbers(app);
  plain_option_messages(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    // A usage error is one line and exit 1, as every other error (CLI11 would add a hint line
    // and exit 105-109 by kind).
    fmt::print(stderr, "vertexflow: error: {}\n", e.what());
    return 1;
  } catch (const vertexflow::IoError& e) {
    fmt::print(stderr, "vertexflow: error: {}\n", e.what());  // names its file already
    return 1;
  } catch (const std::bad_alloc&) {
    fmt::print(stderr, "vertexflow: error: {}out of memory\n", input_prefix());
    return 1;
  } catch (const std::exception& e) {
    // The computation's errors (and the system's, such as a thread that cannot start) concern
    // the mesh read last.
    fmt::print(stderr, "vertexflow: error: {}{}\n", names_an_input(e.what()) ? "" : input_prefix(), e.what());
    return 1;
  }
  print_page_pool_stats();
  return 0;
}
