#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include "semap/sim/solid.hpp"

namespace semap::sim {

// A uniform 2D grid over the ground listing the solids whose plan-view bounding box meets
// each cell. A ray walks it cell by cell (2D DDA, Amanatides & Woo), testing the solids of
// each cell, and stops at the first cell whose nearest hit lies inside it: nothing in a
// later cell can be nearer. Runs of empty cells are jumped over using each cell's Chebyshev
// distance to the nearest occupied cell, cells the ray passes above are not tested, and the
// last few solids tested are not tested again in the next cells.
class SimSolidGrid {
 public:
  struct Hit {
    float t;
    std::int32_t solid;  // -1: nothing before t_end
  };

  SimSolidGrid(std::span<const SimSolid> solids, const Eigen::AlignedBox2f& extent, float cell);

  // Nearest entry of o + t d (d unit) into one of `solids` (those the grid was built from)
  // for t in (0, t_end).
  Hit cast(std::span<const SimSolid> solids, const Eigen::Vector3f& o, const Eigen::Vector3f& d,
           float t_end) const;

  // Calls fn(solid index) for the solids listed in the cells that meet the square p +- r
  // (a solid may come more than once).
  template <class F>
  void for_each_near(const Eigen::Vector2f& p, float r, F&& fn) const {
    const int x0 = cell_x(p.x() - r);
    const int x1 = cell_x(p.x() + r);
    const int y0 = cell_y(p.y() - r);
    const int y1 = cell_y(p.y() + r);
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        const std::size_t c = index(x, y);
        for (std::uint32_t k = start_[c]; k < start_[c + 1]; ++k) fn(solids_[k]);
      }
    }
  }

 private:
  // Cells are clamped to the grid; the conversion truncates, which is floor for v >= origin.
  int cell_x(float x) const {
    return static_cast<int>(
        std::clamp((x - origin_.x()) / cell_, 0.0f, static_cast<float>(nx_ - 1)));
  }
  int cell_y(float y) const {
    return static_cast<int>(
        std::clamp((y - origin_.y()) / cell_, 0.0f, static_cast<float>(ny_ - 1)));
  }
  std::size_t index(int x, int y) const {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(nx_) +
           static_cast<std::size_t>(x);
  }
  void compute_empty_radius();

  Eigen::Vector2f origin_ = Eigen::Vector2f::Zero();
  float cell_ = 1.0f;
  int nx_ = 0;
  int ny_ = 0;
  std::vector<std::uint32_t> start_;  // the solids of cell c: solids_[start_[c] .. start_[c + 1])
  std::vector<std::uint32_t> solids_;
  std::vector<float> cell_top_;      // highest solid top in the cell
  std::vector<std::uint8_t> empty_;  // Chebyshev distance (cells) to the nearest occupied cell
  float top_ = 0.0f;
};

}  // namespace semap::sim
