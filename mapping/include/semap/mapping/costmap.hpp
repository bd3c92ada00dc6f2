#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "semap/common/config.hpp"
#include "semap/common/map_grid.hpp"
#include "semap/mapping/class_palette.hpp"
#include "semap/mapping/evidence_grid.hpp"
#include "semap/mapping/map_params.hpp"
#include "semap/mapping/semantic_map.hpp"

// A semantic 2D costmap for nav2, computed from an S-BKI / S-CSM map.
//
// Each costmap cell looks at the map's columns (cells of one x, y) whose centre lies in it:
//
//  1. A map cell is read with common::CellPosterior and the map's MapParams::unknown_variance.
//     A cell whose state is unknown (never observed, or too uncertain for the map) says nothing.
//  2. An occupied cell is *uncertain* when its argmax class's variance exceeds
//     CostmapParams::max_variance (when > 0), or when its class costs -1.
//  3. The ground of a column is its lowest occupied cell of a ground class
//     (CostmapParams::ground_class), or its lowest occupied cell when it has none.
//  4. The column's band is the ground cell plus every cell whose centre is between
//     min_height_m and max_height_m above the ground cell's centre. Occupied cells outside the
//     band (below the ground, a branch or a bridge above max_height_m, the ground's own
//     kernel spill below min_height_m) are ignored.
//  5. A costmap cell is, over the bands of all its columns:
//     a. 100 when a certain cell's class is lethal (cost 100);
//     b. else -1 when a band holds an uncertain cell: it may be anything up to lethal, so it
//        must not let a cheaper class or free space decide;
//     c. else the largest class cost of the bands' certain cells;
//     d. else 0 when a column holds a free cell (free space seen, nothing occupied);
//     e. else -1: nothing observed.
//
// Map blocks a pager has evicted are not read: keep the memory radius larger than the window.
namespace semap::mapping {

struct CostmapParams {
  double resolution = 0.2;  // costmap cell edge, m
  // Window around the centre given to build_costmap, m. Both 0: the whole map instead, the
  // bounding rectangle of every block in memory (the centre is then ignored).
  double width_m = 40.0;
  double height_m = 40.0;
  double min_height_m = 0.1;  // band above the ground cell, between cell centres (rule 4)
  double max_height_m = 2.0;
  // Rule 2: an occupied cell whose argmax variance exceeds this is uncertain; 0 turns it off.
  double max_variance = 0.02;
  // Per map class, -1..100 (100 lethal, -1 uncertain); class 0 (free space) is never used.
  std::vector<std::int8_t> class_cost;
  // Per map class: whether it is a ground surface (rule 3).
  std::vector<bool> ground_class;

  bool whole_map() const { return width_m == 0.0 && height_m == 0.0; }
  // Throws std::invalid_argument naming the first bad field (class lists must have K entries).
  void validate(int num_classes) const;
};

// Cost of a class the `costs:` section leaves out: lethal, so a class nobody thought about is
// avoided rather than driven through.
inline constexpr std::int8_t kDefaultClassCost = 100;

// Reads a `costmap:`-shaped section: resolution, width_m, height_m, min_height_m, max_height_m,
// max_variance, `costs: {class name: cost, ...}` and `ground: [class names]`, classes named as
// in `palette`. Classes not in `costs` cost kDefaultClassCost; without `ground` the ground
// classes are those of cost 0. Throws common::ConfigError naming the file, line and key for an
// unknown class name, a cost outside -1..100 or not an integer, a cost for class 0 (free space)
// and bad numbers. Like map_params_from_config it does not call finish() on `section`.
CostmapParams costmap_params_from_config(const common::ConfigSection& section,
                                         const ClassPalette& palette);

// A costmap in nav_msgs/OccupancyGrid's convention: cell (x, y) is data[y * width + x], row 0
// at the lowest y, covering [origin_x() + x r, origin_x() + (x + 1) r) x [origin_y() + y r, ...)
// in the map frame (origin z 0, no rotation); values -1 unknown, 0 free .. 100 lethal.
//
// Cells lie on one lattice with a corner at the map frame's origin: cell (0, 0) is lattice cell
// (first_x, first_y), so two costmaps of one resolution always align cell for cell.
struct Costmap {
  double resolution = 0.0;
  std::int32_t first_x = 0;
  std::int32_t first_y = 0;
  int width = 0;   // cells along x
  int height = 0;  // cells along y
  std::vector<std::int8_t> data;

  double origin_x() const { return first_x * resolution; }
  double origin_y() const { return first_y * resolution; }
  std::int8_t at(int x, int y) const {
    return data[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                static_cast<std::size_t>(x)];
  }
  // Same lattice, position and size: an OccupancyGridUpdate can go from one to the other.
  bool same_geometry(const Costmap& other) const {
    return resolution == other.resolution && first_x == other.first_x && first_y == other.first_y &&
           width == other.width && height == other.height;
  }
  friend bool operator==(const Costmap&, const Costmap&) = default;
};

// A rectangle of a costmap, as map_msgs/OccupancyGridUpdate: cells x .. x + width - 1 and
// y .. y + height - 1 of the costmap, data row-major as in Costmap. Empty (width 0) when
// nothing changed.
struct CostmapUpdate {
  int x = 0;
  int y = 0;
  int width = 0;
  int height = 0;
  std::vector<std::int8_t> data;

  bool empty() const { return width == 0; }
};

// The costmap of the window of p.width_m x p.height_m around `centre` (the cell holding the
// centre is cell (width / 2, height / 2)), or of the whole map (CostmapParams::whole_map).
// Throws std::invalid_argument for a log-odds grid or parameters that fail validate().
Costmap build_costmap(const EvidenceGrid& grid, const MapParams& map, const CostmapParams& p,
                      const Eigen::Vector2d& centre);
// The live map's own evidence.
inline Costmap build_costmap(const SemanticMap& map, const CostmapParams& p,
                             const Eigen::Vector2d& centre) {
  return build_costmap(map.grid(), map.params(), p, centre);
}

// Recomputes, in place, the cells of `costmap` whose columns lie in the blocks `changed`
// (e.g. InsertResult::updated_blocks) and returns the rectangle of cells whose value changed.
// After it the costmap equals build_costmap over the same cells. Costs one pass over the block
// keys in memory plus the cells of the columns touched. Throws as build_costmap, and when `p`
// has another resolution than the costmap.
CostmapUpdate update_costmap(Costmap& costmap, const EvidenceGrid& grid, const MapParams& map,
                             const CostmapParams& p, std::span<const common::BlockIndex> changed);
inline CostmapUpdate update_costmap(Costmap& costmap, const SemanticMap& map,
                                    const CostmapParams& p,
                                    std::span<const common::BlockIndex> changed) {
  return update_costmap(costmap, map.grid(), map.params(), p, changed);
}

// The smallest rectangle holding every cell that differs from `before` to `after`, with the
// values of `after`; nullopt when their geometry differs (the window moved: send `after` whole).
std::optional<CostmapUpdate> costmap_update(const Costmap& before, const Costmap& after);

}  // namespace semap::mapping
