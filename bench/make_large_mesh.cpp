// Writes the ~1M-vertex benchmark mesh (data/armadillo-43k.obj subdivided 1-to-25, see
// bench_support.h) to each path given, in the format its extension names; used to measure the
// CLI on large files (docs/benchmarks.md):
//
//   build/bin/make_large_mesh /tmp/armadillo-1m.ply /tmp/armadillo-1m.obj
//
// Options before the paths: --ply-float (float32 PLY coordinates), --ply-ascii,
// --stl-ascii, --off-binary, and --split N: each edge of that mesh split again in N (the size
// ladder's larger rungs, docs/benchmarks.md: 3 gives the 9.7M-vertex mesh, 5 the 27M one).
//
//   build/bin/make_large_mesh --split 5 /tmp/arm27m.ply
#include "bench_support.h"

#include "vertexflow/io.h"

#include <cstdlib>
#include <exception>
#include <iostream>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  vertexflow::WriteOptions options;
  std::vector<std::string> paths;
  int split = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--split" && i + 1 < argc) {
      split = std::atoi(argv[++i]);
      if (split < 1 || split > 10) {
        std::cerr << "make_large_mesh: --split needs a number from 1 to 10\n";
        return 2;
      }
    } else if (arg == "--ply-float")
      options.ply_double_precision = false;
    else if (arg == "--ply-ascii")
      options.ply_encoding = vertexflow::PlyEncoding::Ascii;
    else if (arg == "--stl-ascii")
      options.stl_binary = false;
    else if (arg == "--off-binary")
      options.off_binary = true;
    else if (arg == "-h" || arg == "--help") {
      std::cout
          << "usage: make_large_mesh [--split N] [--ply-float] [--ply-ascii] [--stl-ascii] [--off-binary] OUTPUT...\n";
      return 0;
    } else if (!arg.empty() && arg[0] == '-') {
      std::cerr << "make_large_mesh: unknown option " << arg << '\n';
      return 2;
    } else {
      paths.push_back(arg);
    }
  }
  if (paths.empty()) {
    std::cerr
        << "usage: make_large_mesh [--split N] [--ply-float] [--ply-ascii] [--stl-ascii] [--off-binary] OUTPUT...\n";
    return 2;
  }
  try {
    vertexflow::Mesh mesh = vertexflow::bench::make_large_test_mesh();
    if (split > 1) mesh = vertexflow::bench::subdivide_uniform(mesh, split);
    if (!vertexflow::bench::report_topology(mesh, std::cout)) return 1;
    for (const std::string& path : paths) {
      vertexflow::write_mesh(path, mesh, options);
      std::cout << "wrote " << path << '\n';
    }
  } catch (const std::exception& e) {
    std::cerr << "make_large_mesh: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
