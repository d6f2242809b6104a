// The camera options `render` and `lines` share: --view, --azimuth, --elevation, --size,
// --frame-from and --frame (render.h's conventions).
#pragma once

#include "cli_common.h"

#include "vertexflow/render.h"

namespace vertexflow::cli {

struct CameraCliOptions {
  std::string view = "iso";
  std::string size = "1600x1200";
  std::string frame_from;
  std::vector<double> frame;
  double azimuth_degrees = 30;
  double elevation_degrees = 20;
};

/// Registers the camera options on `command`.
void add_camera_options(CLI::App* command, CameraCliOptions& camera);

/// WIDTHxHEIGHT (--size) as (width, height). Throws std::invalid_argument naming --size when
/// malformed or when a side is outside render.h's [16, 8192].
std::pair<int, int> parse_image_size(const std::string& size);

/// A check of --size as it is parsed (parse_image_size), so that its error comes before any mesh
/// is read and names no mesh file.
CLI::Validator image_size_check();

/// A box as JSON: [xmin, ymin, zmin, xmax, ymax, zmax], as --frame takes it.
nlohmann::json box_json(const BoundingBox& box);

/// Sets options.view, azimuth, elevation, width, height and frame (reading --frame-from's
/// mesh). Throws std::invalid_argument for a malformed --size or --frame.
void apply_camera_options(const CameraCliOptions& camera, RenderOptions& options, const GlobalOptions& global);

}  // namespace vertexflow::cli
