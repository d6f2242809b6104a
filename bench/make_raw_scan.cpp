// Writes a raw range scan made from a clean mesh (issue 31; tests/remesh/raw_scan.h): holes of
// varied size, floating pieces (some smaller than the target edge), slivers along the hole
// rims, all scaled to the edge length of a remesh to --target-vertices. For trying `remesh` and
// `enhance` on scanner output without committing it (docs/remesh.md):
//
//   build/bin/make_raw_scan data/bunny.off /tmp/bunny_raw.ply
//   build/bin/make_raw_scan data/horse-48k.ply /tmp/horse_raw.ply --pieces 0 --slivers 0
//
// Options after the paths: --target-vertices N (6000), --holes N (320), --pieces N (120),
// --slivers SHARE (0.5, share of holes with rim slivers), --subdivisions N (0: midpoint
// subdivisions before cutting, each x4 the faces), --hole-radius-min R and --hole-radius-max R
// (0.1 and 2.5 target edges), --seed S (31).
#include "raw_scan.h"

#include "vertexflow/io.h"
#include "vertexflow/mesh_info.h"
#include "vertexflow/topology.h"

#include <exception>
#include <iostream>
#include <string>

int main(int argc, char** argv) {
  using namespace vertexflow;
  const char* usage =
      "usage: make_raw_scan IN OUT [--target-vertices N] [--holes N] [--pieces N] [--slivers SHARE]\n"
      "       [--subdivisions N] [--hole-radius-min R] [--hole-radius-max R] [--seed S]\n";
  if (argc < 3) {
    std::cerr << usage;
    return 2;
  }
  test::RawScanOptions options;
  try {
    for (int i = 3; i < argc; i += 2) {
      const std::string arg = argv[i];
      if (i + 1 >= argc) throw std::invalid_argument(arg + " needs a value");
      const std::string value = argv[i + 1];
      if (arg == "--target-vertices")
        options.target_vertices = std::stoll(value);
      else if (arg == "--holes")
        options.holes = std::stoi(value);
      else if (arg == "--pieces")
        options.pieces = std::stoi(value);
      else if (arg == "--slivers")
        options.sliver_hole_share = std::stod(value);
      else if (arg == "--subdivisions")
        options.subdivisions = std::stoi(value);
      else if (arg == "--hole-radius-min")
        options.hole_radius_min = std::stod(value);
      else if (arg == "--hole-radius-max")
        options.hole_radius_max = std::stod(value);
      else if (arg == "--seed")
        options.seed = static_cast<unsigned>(std::stoul(value));
      else
        throw std::invalid_argument("unknown option " + arg);
    }
    const test::RawScan scan = test::make_raw_scan(read_mesh(argv[1]), options);
    const Topology topology = build_topology(scan.mesh.F, scan.mesh.num_vertices());
    const MeshInfo info = describe_mesh(scan.mesh, topology);
    std::cout << "target edge " << scan.target_edge << "; " << scan.holes << " holes cut, " << scan.pieces
              << " pieces (" << scan.pieces_below_target << " below one target edge), " << scan.slivers
              << " rim slivers\n"
              << info.num_vertices << " vertices, " << info.num_faces << " faces, " << info.components
              << " components, " << info.boundary_loops << " boundary loops, " << info.non_manifold_vertices
              << " non-manifold vertices, min edge " << info.edge_length_min << ", "
              << 100 * info.quality.fraction_below_0_3 << "% faces below quality 0.3\n";
    write_mesh(argv[2], scan.mesh);
  } catch (const std::exception& e) {
    std::cerr << "make_raw_scan: " << e.what() << '\n' << usage;
    return 1;
  }
  return 0;
}
