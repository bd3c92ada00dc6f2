#include "semap/mapping/costmap.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

#include "semap/common/cell_posterior.hpp"

namespace semap::mapping {

namespace {

constexpr std::int8_t kUnknown = -1;
constexpr std::int8_t kLethal = 100;

// Rule 5's inputs, gathered over the bands of one costmap cell's columns.
struct CellEvidence {
  std::int8_t max_cost = kUnknown;  // largest class cost of a certain band cell; -1: none
  bool uncertain = false;           // a band holds an uncertain cell
  bool free = false;                // a column holds a free cell

  std::int8_t value() const {
    if (max_cost == kLethal) return kLethal;
    if (uncertain) return kUnknown;
    if (max_cost >= 0) return max_cost;
    return free ? 0 : kUnknown;
  }
};

// Cells [x0, x1) x [y0, y1) of a costmap.
struct Rect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;

  bool empty() const { return x0 >= x1 || y0 >= y1; }
  int width() const { return x1 - x0; }
  int height() const { return y1 - y0; }
  bool contains(int x, int y) const { return x >= x0 && x < x1 && y >= y0 && y < y1; }
  void add(int x, int y) {
    if (empty()) {
      *this = {x, y, x + 1, y + 1};
      return;
    }
    x0 = std::min(x0, x);
    y0 = std::min(y0, y);
    x1 = std::max(x1, x + 1);
    y1 = std::max(y1, y + 1);
  }
};

// Map columns onto the costmap lattice: a column belongs to the costmap cell holding its
// centre. Monotonic, so a run of columns covers a run of costmap cells.
class ColumnLattice {
 public:
  ColumnLattice(const MapParams& map, double cost_resolution)
      : map_resolution_(map.resolution), cost_resolution_(cost_resolution) {}

  std::int32_t cell_of_column(std::int32_t column) const {
    return static_cast<std::int32_t>(
        std::floor((column + 0.5) * map_resolution_ / cost_resolution_));
  }
  // Costmap lattice cells [first, last] of the columns of blocks at `block` along one axis.
  std::pair<std::int32_t, std::int32_t> cells_of_block(std::int32_t block, int side) const {
    return {cell_of_column(block * side), cell_of_column(block * side + side - 1)};
  }

 private:
  double map_resolution_;
  double cost_resolution_;
};

void check_inputs(const EvidenceGrid& grid, const MapParams& map, const CostmapParams& p) {
  if (map.method == MapMethod::kLogOdds) {
    throw std::invalid_argument("costmap: a log-odds map has no Dirichlet cells to read");
  }
  if (grid.channels() != map.num_classes || grid.block_side() != map.cells_per_side()) {
    throw std::invalid_argument("costmap: the grid does not have the map parameters' layout");
  }
  p.validate(map.num_classes);
}

int cells_across(double metres, double resolution) {
  // The tolerance keeps 40 m / 0.2 m at 200 cells despite rounding in the division.
  return static_cast<int>(std::ceil(metres / resolution - 1e-9));
}

// An all-unknown costmap over the window around `centre`, or over every block in memory.
Costmap empty_costmap(const EvidenceGrid& grid, const CostmapParams& p,
                      const ColumnLattice& lattice, const Eigen::Vector2d& centre) {
  Costmap costmap;
  costmap.resolution = p.resolution;
  if (p.whole_map()) {
    std::int32_t x0 = 0, y0 = 0, x1 = -1, y1 = -1;
    bool any = false;
    grid.for_each_block([&](const common::BlockIndex& key, const Block&) {
      const auto [bx0, bx1] = lattice.cells_of_block(key.x, grid.block_side());
      const auto [by0, by1] = lattice.cells_of_block(key.y, grid.block_side());
      x0 = any ? std::min(x0, bx0) : bx0;
      y0 = any ? std::min(y0, by0) : by0;
      x1 = any ? std::max(x1, bx1) : bx1;
      y1 = any ? std::max(y1, by1) : by1;
      any = true;
    });
    costmap.first_x = x0;
    costmap.first_y = y0;
    costmap.width = x1 - x0 + 1;
    costmap.height = y1 - y0 + 1;
  } else {
    costmap.width = cells_across(p.width_m, p.resolution);
    costmap.height = cells_across(p.height_m, p.resolution);
    costmap.first_x =
        static_cast<std::int32_t>(std::floor(centre.x() / p.resolution)) - costmap.width / 2;
    costmap.first_y =
        static_cast<std::int32_t>(std::floor(centre.y() / p.resolution)) - costmap.height / 2;
  }
  costmap.data.assign(static_cast<std::size_t>(costmap.width) * costmap.height, kUnknown);
  return costmap;
}

// An occupied cell of a column, from the bottom up.
struct OccupiedCell {
  std::int32_t z;
  int label;
  bool certain;  // rule 2
};

// Rules 1 to 4 over the cells of the column (x, y) (local to its blocks), whose blocks are
// `stack` from the lowest up: folds its band into `evidence`.
class ColumnReader {
 public:
  ColumnReader(const MapParams& map, const CostmapParams& p)
      : map_(map),
        p_(p),
        band_low_(static_cast<int>(std::ceil(p.min_height_m / map.resolution - 1e-6))),
        band_high_(static_cast<int>(std::floor(p.max_height_m / map.resolution + 1e-6))),
        values_(static_cast<std::size_t>(map.channels())) {}

  void read(std::span<const std::pair<common::BlockIndex, const Block*>> stack, int x, int y,
            CellEvidence& evidence) {
    occupied_.clear();
    const int side = map_.cells_per_side();
    for (const auto& [key, block] : stack) {
      for (int z = 0; z < side; ++z) {
        const int c = block->cell_of(x, y, z);
        if (!block->observed(c)) continue;
        block->read_cell(c, values_);
        const auto cell =
            common::CellPosterior(values_, map_.prior, true).summary(map_.unknown_variance);
        if (cell.state == common::CellState::kUnknown) continue;
        if (cell.state == common::CellState::kFree) {
          evidence.free = true;
          continue;
        }
        const int label = cell.argmax;
        const bool too_uncertain = p_.max_variance > 0.0 && cell.variance > p_.max_variance;
        occupied_.push_back(
            {key.z * side + z, label,
             !too_uncertain && p_.class_cost[static_cast<std::size_t>(label)] >= 0});
      }
    }
    if (occupied_.empty()) return;
    const auto ground_it = std::find_if(occupied_.begin(), occupied_.end(), [&](const auto& cell) {
      return p_.ground_class[static_cast<std::size_t>(cell.label)];
    });
    const std::int32_t ground = ground_it != occupied_.end() ? ground_it->z : occupied_.front().z;
    for (const OccupiedCell& cell : occupied_) {
      const std::int32_t above = cell.z - ground;
      if (above != 0 && (above < band_low_ || above > band_high_)) continue;
      if (!cell.certain) {
        evidence.uncertain = true;
        continue;
      }
      evidence.max_cost =
          std::max(evidence.max_cost, p_.class_cost[static_cast<std::size_t>(cell.label)]);
    }
  }

 private:
  const MapParams& map_;
  const CostmapParams& p_;
  int band_low_;   // rule 4's band in cells above the ground cell
  int band_high_;  // (centres min_height_m .. max_height_m above it)
  std::vector<OccupiedCell> occupied_;
  std::vector<float> values_;  // the cell being read
};

// Recomputes the cells of `costmap` in `rect` for which `dirty` (one flag per costmap cell;
// empty: all) is set, from every block whose columns reach them.
void recompute(Costmap& costmap, const EvidenceGrid& grid, const MapParams& map,
               const CostmapParams& p, const Rect& rect, std::span<const std::uint8_t> dirty) {
  const ColumnLattice lattice(map, p.resolution);
  const int side = grid.block_side();
  const std::int32_t lx0 = costmap.first_x + rect.x0, lx1 = costmap.first_x + rect.x1 - 1;
  const std::int32_t ly0 = costmap.first_y + rect.y0, ly1 = costmap.first_y + rect.y1 - 1;
  // The blocks whose columns reach the rectangle, by column of blocks and from the bottom up.
  std::vector<std::pair<common::BlockIndex, const Block*>> blocks;
  grid.for_each_block([&](const common::BlockIndex& key, const Block& block) {
    const auto [bx0, bx1] = lattice.cells_of_block(key.x, side);
    const auto [by0, by1] = lattice.cells_of_block(key.y, side);
    if (bx1 >= lx0 && bx0 <= lx1 && by1 >= ly0 && by0 <= ly1) blocks.emplace_back(key, &block);
  });
  std::sort(blocks.begin(), blocks.end(), [](const auto& a, const auto& b) {
    return std::tie(a.first.x, a.first.y, a.first.z) < std::tie(b.first.x, b.first.y, b.first.z);
  });

  const auto is_dirty = [&](int x, int y) {
    return rect.contains(x, y) &&
           (dirty.empty() || dirty[static_cast<std::size_t>(y) * costmap.width + x]);
  };
  std::vector<CellEvidence> evidence(static_cast<std::size_t>(rect.width()) * rect.height());
  ColumnReader reader(map, p);
  for (std::size_t first = 0; first < blocks.size();) {
    std::size_t last = first;
    while (last < blocks.size() && blocks[last].first.x == blocks[first].first.x &&
           blocks[last].first.y == blocks[first].first.y) {
      ++last;
    }
    const std::span stack(blocks.data() + first, last - first);
    const common::BlockIndex& column_block = blocks[first].first;
    for (int y = 0; y < side; ++y) {
      const int cy = lattice.cell_of_column(column_block.y * side + y) - costmap.first_y;
      for (int x = 0; x < side; ++x) {
        const int cx = lattice.cell_of_column(column_block.x * side + x) - costmap.first_x;
        if (!is_dirty(cx, cy)) continue;
        reader.read(
            stack, x, y,
            evidence[static_cast<std::size_t>(cy - rect.y0) * rect.width() + (cx - rect.x0)]);
      }
    }
    first = last;
  }
  for (int y = rect.y0; y < rect.y1; ++y) {
    for (int x = rect.x0; x < rect.x1; ++x) {
      if (!is_dirty(x, y)) continue;
      costmap.data[static_cast<std::size_t>(y) * costmap.width + x] =
          evidence[static_cast<std::size_t>(y - rect.y0) * rect.width() + (x - rect.x0)].value();
    }
  }
}

// The rectangle of the cells in `within` where `before(x, y)` differs from `after`, with the
// values of `after`.
template <typename Before>
CostmapUpdate changed_cells(const Costmap& after, const Rect& within, Before before) {
  Rect changed;
  for (int y = within.y0; y < within.y1; ++y) {
    for (int x = within.x0; x < within.x1; ++x) {
      if (before(x, y) != after.at(x, y)) changed.add(x, y);
    }
  }
  CostmapUpdate update;
  if (changed.empty()) return update;
  update.x = changed.x0;
  update.y = changed.y0;
  update.width = changed.width();
  update.height = changed.height();
  update.data.reserve(static_cast<std::size_t>(update.width) * update.height);
  for (int y = changed.y0; y < changed.y1; ++y) {
    for (int x = changed.x0; x < changed.x1; ++x) update.data.push_back(after.at(x, y));
  }
  return update;
}

}  // namespace

void CostmapParams::validate(int num_classes) const {
  const auto fail = [](const std::string& what) {
    throw std::invalid_argument("CostmapParams: " + what);
  };
  if (!(resolution > 0.0) || !std::isfinite(resolution)) fail("resolution must be > 0");
  if (!(width_m >= 0.0 && height_m >= 0.0) || (width_m == 0.0) != (height_m == 0.0)) {
    fail("width_m and height_m must both be > 0, or both 0 (the whole map)");
  }
  if (!(min_height_m >= 0.0 && max_height_m >= min_height_m)) {
    fail("need 0 <= min_height_m <= max_height_m");
  }
  if (!(max_variance >= 0.0)) fail("max_variance must be >= 0");
  const auto classes = static_cast<std::size_t>(num_classes);
  if (class_cost.size() != classes || ground_class.size() != classes) {
    fail("class_cost and ground_class need one entry per map class (" +
         std::to_string(num_classes) + ")");
  }
  for (std::size_t c = 0; c < classes; ++c) {
    if (class_cost[c] < -1 || class_cost[c] > kLethal) {
      fail("class_cost[" + std::to_string(c) + "] outside -1..100");
    }
  }
}

CostmapParams costmap_params_from_config(const common::ConfigSection& section,
                                         const ClassPalette& palette) {
  const auto classes = palette.names.size();
  CostmapParams p;
  p.resolution = section.get_in_range("resolution", p.resolution, 1e-3, 100.0);
  p.width_m = section.get_in_range("width_m", p.width_m, 0.0, 1e5);
  p.height_m = section.get_in_range("height_m", p.height_m, 0.0, 1e5);
  if ((p.width_m == 0.0) != (p.height_m == 0.0)) {
    section.reject(section.has("height_m") ? "height_m" : "width_m",
                   "width_m and height_m are both > 0, or both 0 (the whole map)");
  }
  p.min_height_m = section.get_in_range("min_height_m", p.min_height_m, 0.0, 1e3);
  p.max_height_m = section.get_in_range("max_height_m", p.max_height_m, 0.0, 1e3);
  if (p.max_height_m < p.min_height_m) {
    section.reject("max_height_m", "below min_height_m (" + std::to_string(p.min_height_m) + ")");
  }
  // A Dirichlet marginal's variance is at most 1/4.
  p.max_variance = section.get_in_range("max_variance", p.max_variance, 0.0, 0.25);

  p.class_cost.assign(classes, kDefaultClassCost);
  if (classes > 0) p.class_cost[0] = 0;  // free space: never occupied, so never read
  const common::ConfigSection costs = section.section_or_empty("costs");
  for (std::size_t c = 0; c < classes; ++c) {
    const std::string& name = palette.names[c];
    if (!costs.has(name)) continue;
    if (c == 0) costs.reject(name, "class 0 is free space: it has no cost");
    const int cost = costs.get<int>(name);
    if (cost < -1 || cost > kLethal) {
      costs.reject(name,
                   "cost " + std::to_string(cost) + " outside -1..100 (100 lethal, -1 unknown)");
    }
    p.class_cost[c] = static_cast<std::int8_t>(cost);
  }
  try {
    costs.finish();
  } catch (const common::ConfigError& e) {
    std::string names;
    for (std::size_t c = 1; c < classes; ++c) names += (c > 1 ? ", " : "") + palette.names[c];
    throw common::ConfigError(std::string(e.what()) + ": not a class name (classes: " + names +
                              ")");
  }

  p.ground_class.assign(classes, false);
  if (section.has("ground")) {
    const auto names = section.get<std::vector<std::string>>("ground");
    for (std::size_t i = 0; i < names.size(); ++i) {
      const auto it = std::find(palette.names.begin(), palette.names.end(), names[i]);
      if (it == palette.names.end()) {
        section.reject("ground", i, "'" + names[i] + "' is not a class name");
      }
      if (it == palette.names.begin()) section.reject("ground", i, "class 0 is free space");
      p.ground_class[static_cast<std::size_t>(it - palette.names.begin())] = true;
    }
  } else {
    for (std::size_t c = 1; c < classes; ++c) p.ground_class[c] = p.class_cost[c] == 0;
  }
  p.validate(static_cast<int>(classes));
  return p;
}

Costmap build_costmap(const EvidenceGrid& grid, const MapParams& map, const CostmapParams& p,
                      const Eigen::Vector2d& centre) {
  check_inputs(grid, map, p);
  Costmap costmap = empty_costmap(grid, p, ColumnLattice(map, p.resolution), centre);
  recompute(costmap, grid, map, p, Rect{0, 0, costmap.width, costmap.height}, {});
  return costmap;
}

CostmapUpdate update_costmap(Costmap& costmap, const EvidenceGrid& grid, const MapParams& map,
                             const CostmapParams& p, std::span<const common::BlockIndex> changed) {
  check_inputs(grid, map, p);
  if (p.resolution != costmap.resolution) {
    throw std::invalid_argument("update_costmap: the costmap has another resolution");
  }
  const ColumnLattice lattice(map, p.resolution);
  const Rect window{0, 0, costmap.width, costmap.height};
  std::vector<std::uint8_t> dirty(costmap.data.size(), 0);
  Rect rect;
  for (const common::BlockIndex& key : changed) {
    const auto [bx0, bx1] = lattice.cells_of_block(key.x, grid.block_side());
    const auto [by0, by1] = lattice.cells_of_block(key.y, grid.block_side());
    const int x0 = std::max(bx0 - costmap.first_x, window.x0);
    const int x1 = std::min(bx1 - costmap.first_x + 1, window.x1);
    const int y0 = std::max(by0 - costmap.first_y, window.y0);
    const int y1 = std::min(by1 - costmap.first_y + 1, window.y1);
    for (int y = y0; y < y1; ++y) {
      for (int x = x0; x < x1; ++x) {
        dirty[static_cast<std::size_t>(y) * costmap.width + x] = 1;
        rect.add(x, y);
      }
    }
  }
  if (rect.empty()) return {};
  std::vector<std::int8_t> before;
  before.reserve(static_cast<std::size_t>(rect.width()) * rect.height());
  for (int y = rect.y0; y < rect.y1; ++y) {
    for (int x = rect.x0; x < rect.x1; ++x) before.push_back(costmap.at(x, y));
  }
  recompute(costmap, grid, map, p, rect, dirty);
  return changed_cells(costmap, rect, [&](int x, int y) {
    return before[static_cast<std::size_t>(y - rect.y0) * rect.width() + (x - rect.x0)];
  });
}

std::optional<CostmapUpdate> costmap_update(const Costmap& before, const Costmap& after) {
  if (!before.same_geometry(after)) return std::nullopt;
  return changed_cells(after, Rect{0, 0, after.width, after.height},
                       [&](int x, int y) { return before.at(x, y); });
}

}  // namespace semap::mapping
