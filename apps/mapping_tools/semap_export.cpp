// semap-export: writes a .smap map in the formats people open in their usual viewers.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <string>

#include "semap/mapping/map_export.hpp"
#include "semap/mapping/smap_io.hpp"

int main(int argc, char** argv) {
  CLI::App app{"Export a .smap map to PLY, PCD, OctoMap (.ot) and top-down PNGs"};
  std::string in_path, ply, pcd, octomap, png, variance_png, palette_path;
  bool salvage = false;
  semap::mapping::TopDownOptions top_down;
  app.add_option("input", in_path, "map (.smap)")->required();
  app.add_option("--ply", ply, "occupied cell centres, coloured by class (.ply)");
  app.add_option("--pcd", pcd, "occupied cell centres, coloured by class (.pcd)");
  app.add_option("--octomap", octomap, "OctoMap ColorOcTree (.ot) for octovis");
  app.add_option("--png", png, "top-down class map with legend (.png)");
  app.add_option("--variance-png", variance_png, "top-down variance heat map (.png)");
  app.add_option("--palette", palette_path, "YAML with class names and colors");
  app.add_option("--pixels-per-cell", top_down.pixels_per_cell, "PNG scale")
      ->check(CLI::Range(1, 64));
  app.add_flag("--salvage", salvage, "load a damaged map up to its last good block");
  CLI11_PARSE(app, argc, argv);

  try {
    const auto read = semap::mapping::read_smap(in_path, {.salvage = salvage});
    if (!read.complete) std::fprintf(stderr, "semap-export: salvaged: %s\n", read.problem.c_str());
    const auto& params = read.map.params();
    const auto palette = palette_path.empty()
                             ? semap::mapping::ClassPalette::defaults(params.num_classes)
                             : semap::mapping::load_palette(palette_path, params.num_classes);
    const auto cells = semap::mapping::occupied_cells(read.map);
    if (!ply.empty()) semap::mapping::write_ply(ply, cells, palette);
    if (!pcd.empty()) semap::mapping::write_cells_pcd(pcd, cells, palette);
    if (!octomap.empty()) semap::mapping::write_octomap(octomap, cells, params.resolution, palette);
    if (!png.empty() || !variance_png.empty()) {
      semap::mapping::write_top_down_pngs(png, variance_png, cells, params.resolution, palette,
                                          top_down);
    }
    std::printf("method %s\nsources %zu\noccupied_cells %zu\n",
                semap::mapping::to_string(params.method).c_str(), read.map.layers().size(),
                cells.size());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "semap-export: %s\n", e.what());
    return 1;
  }
  return 0;
}
