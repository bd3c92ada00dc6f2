#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>

namespace semap::mapping {

// Integer index of a cell in the global grid: cell = floor(point / resolution).
using CellIndex = Eigen::Vector3i;

// Index of a block of block_side^3 cells: block = floor(cell / block_side).
struct BlockKey {
  std::int32_t x = 0;
  std::int32_t y = 0;
  std::int32_t z = 0;

  bool operator==(const BlockKey&) const = default;
};

struct BlockKeyHash {
  std::size_t operator()(const BlockKey& key) const {
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

// Floor division that stays correct for negative cells.
inline std::int32_t floor_div(std::int32_t value, std::int32_t divisor) {
  const std::int32_t q = value / divisor;
  return (value % divisor != 0 && (value < 0) != (divisor < 0)) ? q - 1 : q;
}

inline BlockKey block_of(const CellIndex& cell, int block_side) {
  return {floor_div(cell.x(), block_side), floor_div(cell.y(), block_side),
          floor_div(cell.z(), block_side)};
}

// Position of a cell inside its block, x fastest.
inline int local_index(const CellIndex& cell, const BlockKey& block, int block_side) {
  const int lx = cell.x() - block.x * block_side;
  const int ly = cell.y() - block.y * block_side;
  const int lz = cell.z() - block.z * block_side;
  return (lz * block_side + ly) * block_side + lx;
}

inline CellIndex cell_of_local(const BlockKey& block, int local, int block_side) {
  const int lx = local % block_side;
  const int ly = (local / block_side) % block_side;
  const int lz = local / (block_side * block_side);
  return {block.x * block_side + lx, block.y * block_side + ly, block.z * block_side + lz};
}

}  // namespace semap::mapping
