// The camera options `render` and `lines` share (camera_options.h).
#include "camera_options.h"

#include <algorithm>
#include <map>
#include <regex>

namespace vertexflow::cli {

void add_camera_options(CLI::App* command, CameraCliOptions& camera) {
  command->add_option("--view", camera.view, "Camera direction (+y up): front (+z), side (+x), top (+y), iso, custom")
      ->check(CLI::IsMember({"front", "side", "top", "iso", "custom"}));
  command->add_option("--azimuth", camera.azimuth_degrees, "Custom view: degrees about +y, from +z towards +x");
  command->add_option("--elevation", camera.elevation_degrees, "Custom view: degrees above the xz plane")
      ->check(CLI::Range(-90.0, 90.0));
  command->add_option("--size", camera.size, "Image size WxH in pixels (default 1600x1200)")->check(image_size_check());
  auto* frame_from =
      command->add_option("--frame-from", camera.frame_from,
                          "Use this mesh's bounding box as the camera frame, so renders of meshes sharing it line up");
  command->add_option("--frame", camera.frame, "Camera frame as a box: xmin ymin zmin xmax ymax zmax")
      ->expected(6)
      ->delimiter(',')
      ->excludes(frame_from);
}

std::pair<int, int> parse_image_size(const std::string& size) {
  std::smatch match;
  if (!std::regex_match(size, match, std::regex(R"((\d+)[xX](\d+))")))
    throw std::invalid_argument("--size " + size + ": expected WIDTHxHEIGHT, e.g. 1600x1200");
  // Any number of digits is the right form; a side of more than 5 (leading zeros aside) is out
  // of range whatever they are, and std::stoi would overflow.
  const auto side = [](std::string digits) {
    digits.erase(0, std::min(digits.find_first_not_of('0'), digits.size() - 1));
    return digits.size() > 5 ? 100000 : std::stoi(digits);
  };
  const int width = side(match[1]), height = side(match[2]);
  if (width < 16 || width > 8192 || height < 16 || height > 8192)
    throw std::invalid_argument("--size " + size + ": width and height must each be in [16, 8192] pixels");
  return {width, height};
}

CLI::Validator image_size_check() {
  return CLI::Validator(
      [](std::string& size) {
        parse_image_size(size);  // throws std::invalid_argument naming --size: one line, exit 1
        return std::string();
      },
      "");
}

nlohmann::json box_json(const BoundingBox& box) {
  return {box.min.x(), box.min.y(), box.min.z(), box.max.x(), box.max.y(), box.max.z()};
}

void apply_camera_options(const CameraCliOptions& camera, RenderOptions& options, const GlobalOptions& global) {
  std::tie(options.width, options.height) = parse_image_size(camera.size);
  const std::map<std::string, RenderView> views = {{"front", RenderView::Front},
                                                   {"side", RenderView::Side},
                                                   {"top", RenderView::Top},
                                                   {"iso", RenderView::Iso},
                                                   {"custom", RenderView::Custom}};
  options.view = views.at(camera.view);
  options.azimuth_degrees = camera.azimuth_degrees;
  options.elevation_degrees = camera.elevation_degrees;
  if (!camera.frame.empty()) {
    const auto& f = camera.frame;
    options.frame = BoundingBox{{f[0], f[1], f[2]}, {f[3], f[4], f[5]}};
    if (!(options.frame->max.array() >= options.frame->min.array()).all())
      throw std::invalid_argument("--frame: every max must be >= its min (xmin ymin zmin xmax ymax zmax)");
  }
  if (!camera.frame_from.empty()) options.frame = bounding_box(read_mesh_with_warnings(camera.frame_from, global).V);
}

}  // namespace vertexflow::cli
