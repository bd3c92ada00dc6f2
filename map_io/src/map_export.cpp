#include "semap/map_io/map_export.hpp"

#include <algorithm>
#include <cstring>
#include <string>
#include <tuple>

#include "semap/mapping/atomic_file.hpp"
#include "semap/mapping/cell_summary.hpp"

namespace semap::map_io {

namespace {

template <typename T>
void append(std::vector<std::uint8_t>& out, T value) {
  const auto* p = reinterpret_cast<const std::uint8_t*>(&value);
  out.insert(out.end(), p, p + sizeof(T));
}

void append_text(std::vector<std::uint8_t>& out, const std::string& text) {
  out.insert(out.end(), text.begin(), text.end());
}

}  // namespace

std::vector<OccupiedCell> occupied_cells(const mapping::LayeredMap& map) {
  const mapping::MapParams& p = map.params();
  const int side = p.cells_per_side();
  const common::MapGrid grid = p.grid();
  const auto channels = static_cast<std::size_t>(p.channels());
  std::vector<OccupiedCell> cells;
  std::vector<float> fused;
  for (const common::BlockIndex& key : map.block_keys()) {
    map.fused_block(key, fused);
    for (int c = 0; c < side * side * side; ++c) {
      const mapping::CellSummary s = mapping::summarize(
          p,
          std::span<const float>(fused.data() + static_cast<std::size_t>(c) * channels, channels));
      if (!s.known || !s.occupied) continue;
      cells.push_back({grid.cell_centre(grid.cell_of_local(key, c)).cast<double>(), s.label,
                       s.probability, s.variance});
    }
  }
  std::sort(cells.begin(), cells.end(), [](const OccupiedCell& a, const OccupiedCell& b) {
    return std::tie(a.centre.z(), a.centre.y(), a.centre.x()) <
           std::tie(b.centre.z(), b.centre.y(), b.centre.x());
  });
  return cells;
}

void write_ply(const std::filesystem::path& path, const std::vector<OccupiedCell>& cells,
               const mapping::ClassPalette& palette) {
  std::vector<std::uint8_t> out;
  append_text(out,
              "ply\nformat binary_little_endian 1.0\ncomment semap occupied cells\n"
              "element vertex " +
                  std::to_string(cells.size()) +
                  "\nproperty float x\nproperty float y\nproperty float z\n"
                  "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                  "property int label\nproperty float probability\nproperty float variance\n"
                  "end_header\n");
  for (const OccupiedCell& c : cells) {
    for (int i = 0; i < 3; ++i) append(out, static_cast<float>(c.centre[i]));
    for (const std::uint8_t v : palette.color(c.label)) append(out, v);
    append(out, static_cast<std::int32_t>(c.label));
    append(out, c.probability);
    append(out, c.variance);
  }
  mapping::write_file_atomically(path, out);
}

void write_cells_pcd(const std::filesystem::path& path, const std::vector<OccupiedCell>& cells,
                     const mapping::ClassPalette& palette) {
  std::vector<std::uint8_t> out;
  append_text(out,
              "# .PCD v0.7 - semap occupied cells\nVERSION 0.7\n"
              "FIELDS x y z rgb label probability variance\nSIZE 4 4 4 4 4 4 4\n"
              "TYPE F F F F U F F\nCOUNT 1 1 1 1 1 1 1\nWIDTH " +
                  std::to_string(cells.size()) + "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " +
                  std::to_string(cells.size()) + "\nDATA binary\n");
  for (const OccupiedCell& c : cells) {
    for (int i = 0; i < 3; ++i) append(out, static_cast<float>(c.centre[i]));
    const mapping::Rgb rgb = palette.color(c.label);
    // PCL packs 0x00RRGGBB into the bytes of a float field named rgb.
    const std::uint32_t packed = (static_cast<std::uint32_t>(rgb[0]) << 16) |
                                 (static_cast<std::uint32_t>(rgb[1]) << 8) | rgb[2];
    float as_float = 0.0f;
    std::memcpy(&as_float, &packed, sizeof(as_float));
    append(out, as_float);
    append(out, static_cast<std::uint32_t>(c.label));
    append(out, c.probability);
    append(out, c.variance);
  }
  mapping::write_file_atomically(path, out);
}

}  // namespace semap::map_io
