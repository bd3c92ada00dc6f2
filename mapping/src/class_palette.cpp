#include "semap/mapping/class_palette.hpp"

#include <cmath>

#include "semap/common/config.hpp"

namespace semap::mapping {

namespace {

// SemanticKITTI-like colours, well apart from each other.
constexpr std::array<Rgb, 12> kTable = {{
    {0, 0, 0},
    {255, 0, 255},
    {255, 200, 0},
    {0, 175, 0},
    {100, 150, 245},
    {245, 150, 100},
    {80, 30, 180},
    {255, 30, 30},
    {135, 60, 0},
    {150, 240, 255},
    {75, 0, 75},
    {255, 240, 150},
}};

}  // namespace

ClassPalette ClassPalette::defaults(int num_classes) {
  ClassPalette p;
  for (int c = 0; c < num_classes; ++c) {
    p.colors.push_back(kTable[static_cast<std::size_t>(c) % kTable.size()]);
    p.names.push_back("class " + std::to_string(c));
  }
  return p;
}

Rgb ClassPalette::color(int label) const {
  if (label < 0 || static_cast<std::size_t>(label) >= colors.size()) return {128, 128, 128};
  return colors[static_cast<std::size_t>(label)];
}

std::string ClassPalette::name(int label) const {
  if (label < 0 || static_cast<std::size_t>(label) >= names.size()) {
    return "class " + std::to_string(label);
  }
  return names[static_cast<std::size_t>(label)];
}

ClassPalette load_palette(const std::filesystem::path& path, int num_classes) {
  ClassPalette p = ClassPalette::defaults(num_classes);
  const auto config = common::ConfigSection::load_file(path);
  const auto names = config.get<std::vector<std::string>>("names", {});
  for (std::size_t c = 0; c < names.size() && c < p.names.size(); ++c) p.names[c] = names[c];
  const auto colors = config.get<std::vector<double>>("colors", {});
  if (colors.size() % 3 != 0) {
    throw common::ConfigError(path.string() + ": colors: " + std::to_string(colors.size()) +
                              " values, expected r, g, b triples");
  }
  for (std::size_t i = 0; i < colors.size(); ++i) {
    if (!(colors[i] >= 0.0 && colors[i] <= 255.0) || colors[i] != std::floor(colors[i])) {
      throw common::ConfigError(path.string() + ": colors[" + std::to_string(i) +
                                "]: not an integer in 0..255");
    }
  }
  for (std::size_t c = 0; c < colors.size() / 3; ++c) {
    const Rgb rgb = {static_cast<std::uint8_t>(colors[3 * c]),
                     static_cast<std::uint8_t>(colors[3 * c + 1]),
                     static_cast<std::uint8_t>(colors[3 * c + 2])};
    if (c < p.colors.size()) {
      p.colors[c] = rgb;
    } else {
      p.colors.push_back(rgb);
      p.names.push_back("class " + std::to_string(c));
    }
  }
  config.finish();
  return p;
}

}  // namespace semap::mapping
