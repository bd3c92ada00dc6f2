#include "semap/mapping/class_palette.hpp"

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

}  // namespace semap::mapping
