// semap-export: writes a .smap map in the formats people open in their usual viewers.
#include <CLI/CLI.hpp>
#include <array>
#include <cmath>
#include <cstdio>
#include <exception>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>

#include "semap/map_io/map_export.hpp"
#include "semap/mapping/smap_io.hpp"

namespace {

using CellKey = std::array<long, 3>;

CellKey key_of(const Eigen::Vector3d& centre, double resolution) {
  return {std::lround(std::floor(centre.x() / resolution)),
          std::lround(std::floor(centre.y() / resolution)),
          std::lround(std::floor(centre.z() / resolution))};
}

// The occupied cells of a map semap-map-listener --save wrote (ASCII PCD: x y z class
// variance), by cell.
std::map<CellKey, int> read_received(const std::string& path, double resolution) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::string line;
  while (std::getline(in, line) && line.rfind("DATA ascii", 0) != 0) {
  }
  if (!in) throw std::runtime_error(path + ": not an ASCII PCD");
  std::map<CellKey, int> cells;
  Eigen::Vector3d c;
  int label = 0;
  float variance = 0.0f;
  while (in >> c.x() >> c.y() >> c.z() >> label >> variance) cells[key_of(c, resolution)] = label;
  if (!in.eof()) throw std::runtime_error(path + ": bad point line");
  return cells;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Export a .smap map to PLY, PCD, OctoMap (.ot) and top-down PNGs"};
  std::string in_path, ply, pcd, octomap, png, variance_png, palette_path, compare;
  bool salvage = false;
  semap::map_io::TopDownOptions top_down;
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
  app.add_option("--compare", compare,
                 "a map received over DDS (semap-map-listener --save .pcd): counts its occupied "
                 "cells and those with the same class in this map");
  CLI11_PARSE(app, argc, argv);

  try {
    const auto read = semap::mapping::read_smap(in_path, {.salvage = salvage});
    if (!read.complete) std::fprintf(stderr, "semap-export: salvaged: %s\n", read.problem.c_str());
    const auto& params = read.map.params();
    const auto palette = palette_path.empty()
                             ? semap::mapping::ClassPalette::defaults(params.num_classes)
                             : semap::mapping::load_palette(palette_path, params.num_classes);
    const auto cells = semap::map_io::occupied_cells(read.map);
    if (!ply.empty()) semap::map_io::write_ply(ply, cells, palette);
    if (!pcd.empty()) semap::map_io::write_cells_pcd(pcd, cells, palette);
    if (!octomap.empty()) semap::map_io::write_octomap(octomap, cells, params.resolution, palette);
    if (!png.empty() || !variance_png.empty()) {
      semap::map_io::write_top_down_pngs(png, variance_png, cells, params.resolution, palette,
                                         top_down);
    }
    std::printf("method %s\nsources %zu\noccupied_cells %zu\n",
                semap::mapping::to_string(params.method).c_str(), read.map.layers().size(),
                cells.size());
    if (!compare.empty()) {
      // agreement: cells occupied with the same class in both / cells occupied in either.
      const auto received = read_received(compare, params.resolution);
      std::size_t same = 0;
      for (const auto& cell : cells) {
        const auto it = received.find(key_of(cell.centre, params.resolution));
        same += it != received.end() && it->second == cell.label;
      }
      std::printf("received_cells %zu\nsame_cells %zu\nagreement %.4f\n", received.size(), same,
                  static_cast<double>(same) / static_cast<double>(std::max<std::size_t>(
                                                  1, cells.size() + received.size() - same)));
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "semap-export: %s\n", e.what());
    return 1;
  }
  return 0;
}
