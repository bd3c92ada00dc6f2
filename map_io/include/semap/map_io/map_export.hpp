#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <vector>

#include "semap/mapping/class_palette.hpp"
#include "semap/mapping/layered_map.hpp"

namespace semap::map_io {

// One occupied cell as exported.
struct OccupiedCell {
  Eigen::Vector3d centre;
  int label = 0;
  float probability = 0.0f;  // of `label`
  float variance = 0.0f;     // of `label`'s probability (see mapping::CellSummary)
};

// Occupied cells of the fused map, sorted by position (stable output for equal maps).
std::vector<OccupiedCell> occupied_cells(const mapping::LayeredMap& map);

// Binary little-endian PLY: x y z (float), red green blue (uchar), label (int),
// probability and variance (float). Opens in CloudCompare, MeshLab, Open3D.
void write_ply(const std::filesystem::path& path, const std::vector<OccupiedCell>& cells,
               const mapping::ClassPalette& palette);
// Binary PCD v0.7: x y z rgb (packed float, PCL convention), label (uint32), probability and
// variance (float).
void write_cells_pcd(const std::filesystem::path& path, const std::vector<OccupiedCell>& cells,
                     const mapping::ClassPalette& palette);
// OctoMap ColorOcTree (.ot) at `resolution`, occupied cells coloured by class, for octovis.
void write_octomap(const std::filesystem::path& path, const std::vector<OccupiedCell>& cells,
                   double resolution, const mapping::ClassPalette& palette);

struct TopDownOptions {
  int pixels_per_cell = 4;
};

// Top-down renderings through OpenCV, one pixel block per (x, y) column showing its highest
// occupied cell: the class map with a legend of class colours and names, and the variance of
// that cell as a heat map (COLORMAP_JET) with a colour bar from 0 to the largest variance.
// Either path may be empty to skip that image. Throws std::runtime_error when writing fails.
void write_top_down_pngs(const std::filesystem::path& class_png,
                         const std::filesystem::path& variance_png,
                         const std::vector<OccupiedCell>& cells, double resolution,
                         const mapping::ClassPalette& palette, const TopDownOptions& options = {});

}  // namespace semap::map_io
