// How a file's properties become attribute channels (io_internal.h), shared by the readers.
#include "io_internal.h"

namespace vertexflow::io_detail {

AttributeChannel make_channel(std::string name, std::vector<std::string> components, ScalarType type,
                              AttributeRole role, const std::vector<std::vector<double>>& columns) {
  AttributeChannel channel;
  channel.name = std::move(name);
  channel.components = std::move(components);
  channel.type = type;
  channel.role = role;
  const auto rows = static_cast<Eigen::Index>(columns.empty() ? 0 : columns.front().size());
  channel.values.resize(rows, static_cast<Eigen::Index>(columns.size()));
  for (std::size_t c = 0; c < columns.size(); ++c)
    for (Eigen::Index r = 0; r < rows; ++r) channel.values(r, static_cast<Eigen::Index>(c)) = columns[c][r];
  return channel;
}

namespace {

struct Group {
  const char* channel;
  AttributeRole role;
  std::vector<std::string_view> names;
};

// The groups real writers use (MeshLab, CloudCompare, Blender, VCG, Open3D), longest first so
// that "red green blue alpha" wins over "red green blue".
const std::vector<Group>& known_groups() {
  static const std::vector<Group> groups = {
      {"color", AttributeRole::Color, {"red", "green", "blue", "alpha"}},
      {"color", AttributeRole::Color, {"red", "green", "blue"}},
      {"color", AttributeRole::Color, {"r", "g", "b", "a"}},
      {"color", AttributeRole::Color, {"r", "g", "b"}},
      {"color", AttributeRole::Color, {"diffuse_red", "diffuse_green", "diffuse_blue"}},
      {"normal", AttributeRole::Normal, {"nx", "ny", "nz"}},
      {"normal", AttributeRole::Normal, {"normal_x", "normal_y", "normal_z"}},
      {"uv", AttributeRole::TexCoord, {"s", "t"}},
      {"uv", AttributeRole::TexCoord, {"u", "v"}},
      {"uv", AttributeRole::TexCoord, {"texture_u", "texture_v"}},
      {"uv", AttributeRole::TexCoord, {"texture_s", "texture_t"}},
  };
  return groups;
}

}  // namespace

ChannelLayout group_properties(const std::vector<std::string>& names, const std::vector<ScalarType>& types) {
  ChannelLayout layout;
  layout.slot.resize(names.size());
  auto taken = [&](std::string_view name) {
    for (const AttributeChannel& c : layout.channels)
      if (c.name == name) return true;
    return false;
  };
  for (std::size_t i = 0; i < names.size();) {
    const Group* match = nullptr;
    for (const Group& g : known_groups()) {
      if (i + g.names.size() > names.size() || taken(g.channel)) continue;
      bool same = true;
      for (std::size_t k = 0; k < g.names.size() && same; ++k)
        same = names[i + k] == g.names[k] && types[i + k] == types[i];
      if (same) {
        match = &g;
        break;
      }
    }
    AttributeChannel& channel = layout.channels.emplace_back();
    channel.type = types[i];
    const int index = static_cast<int>(layout.channels.size()) - 1;
    if (match != nullptr) {
      channel.name = match->channel;
      channel.role = match->role;
      for (std::size_t k = 0; k < match->names.size(); ++k) {
        channel.components.emplace_back(match->names[k]);
        layout.slot[i + k] = {index, static_cast<int>(k)};
      }
      i += match->names.size();
    } else {
      channel.name = names[i];
      channel.components = {names[i]};
      channel.role = is_integer_type(types[i]) ? AttributeRole::Label : AttributeRole::Generic;
      layout.slot[i] = {index, 0};
      ++i;
    }
  }
  return layout;
}

}  // namespace vertexflow::io_detail
