#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "semap/mapping/block_index.hpp"

namespace semap::mapping {

// Integer index of a cell in the global grid: cell = floor(point / resolution).
using CellIndex = Eigen::Vector3i;
// Blocks (semap/mapping/block_index.hpp) hold block_side^3 cells: block = floor(cell / side).

// Hash of a block (or cell) index for the standard unordered containers.
struct BlockKeyHash {
  std::size_t operator()(const BlockIndex& key) const {
    // Large odd primes spread neighbouring blocks over the buckets.
    return static_cast<std::size_t>(key.x) * 73856093u ^
           static_cast<std::size_t>(key.y) * 19349663u ^
           static_cast<std::size_t>(key.z) * 83492791u;
  }
};

inline CellIndex cell_of_point(const Eigen::Vector3d& point, double resolution) {
  return CellIndex(static_cast<int>(std::floor(point.x() / resolution)),
                   static_cast<int>(std::floor(point.y() / resolution)),
                   static_cast<int>(std::floor(point.z() / resolution)));
}

inline Eigen::Vector3d cell_centre(const CellIndex& cell, double resolution) {
  return (cell.cast<double>() + Eigen::Vector3d::Constant(0.5)) * resolution;
}

inline BlockIndex block_of_cell(const CellIndex& cell, int block_side) {
  return {floor_div(cell.x(), block_side), floor_div(cell.y(), block_side),
          floor_div(cell.z(), block_side)};
}

// Position of a cell inside its block, x fastest.
inline int local_index(const CellIndex& cell, const BlockIndex& block, int block_side) {
  const int lx = cell.x() - block.x * block_side;
  const int ly = cell.y() - block.y * block_side;
  const int lz = cell.z() - block.z * block_side;
  return (lz * block_side + ly) * block_side + lx;
}

inline CellIndex cell_of_local(const BlockIndex& block, int local, int block_side) {
  const int lx = local % block_side;
  const int ly = (local / block_side) % block_side;
  const int lz = local / (block_side * block_side);
  return {block.x * block_side + lx, block.y * block_side + ly, block.z * block_side + lz};
}

}  // namespace semap::mapping
