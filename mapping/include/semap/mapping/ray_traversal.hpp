#pragma once

#include <Eigen/Core>
#include <cmath>
#include <limits>

#include "semap/common/map_grid.hpp"

namespace semap::mapping {

// Visits the cells a segment crosses, from the cell of `from` up to but excluding the cell of
// `to` (the endpoint is a hit, the cells before it are free), in order. Amanatides & Woo's
// 3D DDA: one step per crossed cell face, no sampling gaps or repeats.
template <typename Visit>
void traverse_ray(const Eigen::Vector3d& from, const Eigen::Vector3d& to, double resolution,
                  Visit&& visit) {
  // The map's own point -> cell function; the walk itself runs in double.
  const common::MapGrid grid(static_cast<float>(resolution), 1);
  common::CellIndex cell = grid.cell_of(from);
  const common::CellIndex end = grid.cell_of(to);
  const Eigen::Vector3d dir = to - from;
  const double length = dir.norm();
  if (length <= 0.0 || cell == end) return;
  const Eigen::Vector3d unit = dir / length;
  Eigen::Vector3i step;
  Eigen::Vector3d t_max;
  Eigen::Vector3d t_delta;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    if (unit[i] > 0.0) {
      step[i] = 1;
      t_max[i] = ((cell[i] + 1) * resolution - from[i]) / unit[i];
      t_delta[i] = resolution / unit[i];
    } else if (unit[i] < 0.0) {
      step[i] = -1;
      t_max[i] = (cell[i] * resolution - from[i]) / unit[i];
      t_delta[i] = -resolution / unit[i];
    } else {
      step[i] = 0;
      t_max[i] = kInf;
      t_delta[i] = kInf;
    }
  }
  // The cell count bounds the loop even when rounding makes the walk miss `end`.
  const int max_steps = (end - cell).cwiseAbs().sum() + 1;
  for (int n = 0; n < max_steps && cell != end; ++n) {
    visit(static_cast<const common::CellIndex&>(cell));
    int axis = 0;
    if (t_max[1] < t_max[axis]) axis = 1;
    if (t_max[2] < t_max[axis]) axis = 2;
    if (t_max[axis] > length) break;
    cell[axis] += step[axis];
    t_max[axis] += t_delta[axis];
  }
}

}  // namespace semap::mapping
