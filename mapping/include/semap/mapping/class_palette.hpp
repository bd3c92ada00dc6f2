#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace semap::mapping {

using Rgb = std::array<std::uint8_t, 3>;

// Class colours and names for exports. The default palette is fixed (same class, same colour
// in every file and run); users replace it with their own list.
struct ClassPalette {
  std::vector<Rgb> colors;
  std::vector<std::string> names;

  // Class c of `num_classes`: a fixed table, repeated beyond its length; names "class c".
  static ClassPalette defaults(int num_classes);
  // Colour of a class; classes beyond the list get grey.
  Rgb color(int label) const;
  std::string name(int label) const;
};

// Reads a palette from YAML: `names: [ground, wall, ...]` and/or `colors: [r, g, b, r, g, b,
// ...]` (0..255); classes the file leaves out keep the default. Throws common::ConfigError
// naming the file, line and key for a bad value.
ClassPalette load_palette(const std::filesystem::path& path, int num_classes);

}  // namespace semap::mapping
