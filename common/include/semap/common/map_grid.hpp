#pragma once

#include <Eigen/Core>
#include <cmath>
#include <compare>
#include <cstddef>
#include <cstdint>

// The semantic map's grid, the one vocabulary of everything that stores, sends or reads the
// map (mapping, dds_idl, the apps): block and cell indices, the point -> cell -> block
// function, the order of cells inside a block, and a cell's state.
namespace semap::common {

// Integer coordinates of a block (or of a cell or voxel on its own grid).
struct BlockIndex {
  std::int32_t x = 0;
  std::int32_t y = 0;
  std::int32_t z = 0;

  friend bool operator==(const BlockIndex&, const BlockIndex&) = default;
  friend auto operator<=>(const BlockIndex&, const BlockIndex&) = default;
};

// Hash of a block (or cell) index for the standard unordered containers.
struct BlockIndexHash {
  std::size_t operator()(const BlockIndex& key) const {
    // Large odd primes spread neighbouring blocks over the buckets.
    return static_cast<std::size_t>(key.x) * 73856093u ^
           static_cast<std::size_t>(key.y) * 19349663u ^
           static_cast<std::size_t>(key.z) * 83492791u;
  }
};

// Integer index of a cell in the global grid.
using CellIndex = Eigen::Vector3i;

// What a cell says: never observed (or too uncertain), free space, or occupied by a class.
// The values are those of semap_msgs/SemanticMapBlock's state field.
enum class CellState : std::uint8_t { kUnknown = 0, kFree = 1, kOccupied = 2 };

// Floor division for negative grid coordinates (C++ `/` truncates towards zero).
inline std::int32_t floor_div(std::int32_t a, std::int32_t b) {
  const std::int32_t q = a / b;
  return (a % b != 0 && ((a < 0) != (b < 0))) ? q - 1 : q;
}

// Cells are grouped in cubic blocks of `side`^3 cells; inside a block they are numbered x
// fastest, then y, then z.
inline BlockIndex block_of_cell(const CellIndex& cell, int side) {
  return {floor_div(cell.x(), side), floor_div(cell.y(), side), floor_div(cell.z(), side)};
}
// Position of `cell` inside `block` (which must hold it).
inline int local_index(const CellIndex& cell, const BlockIndex& block, int side) {
  const int lx = cell.x() - block.x * side;
  const int ly = cell.y() - block.y * side;
  const int lz = cell.z() - block.z * side;
  return (lz * side + ly) * side + lx;
}
inline CellIndex cell_of_local(const BlockIndex& block, int local, int side) {
  return {block.x * side + local % side, block.y * side + (local / side) % side,
          block.z * side + local / (side * side)};
}

// Cells of edge `resolution` metres in blocks of `block_side`^3 cells.
class MapGrid {
 public:
  MapGrid(float resolution, int block_side)
      : resolution_(resolution), inv_resolution_(1.0f / resolution), block_side_(block_side) {}

  float resolution() const { return resolution_; }
  int block_side() const { return block_side_; }
  int cells_per_block() const { return block_side_ * block_side_ * block_side_; }
  float block_size() const { return resolution_ * static_cast<float>(block_side_); }

  // cell = floor(p / resolution), in float as floor(p * (1 / resolution)): the map's insert and
  // query compute exactly this, so every reader of the map puts a point in the same cell.
  CellIndex cell_of(const Eigen::Vector3f& p) const {
    return {static_cast<int>(std::floor(p.x() * inv_resolution_)),
            static_cast<int>(std::floor(p.y() * inv_resolution_)),
            static_cast<int>(std::floor(p.z() * inv_resolution_))};
  }
  CellIndex cell_of(const Eigen::Vector3d& p) const {
    return cell_of(Eigen::Vector3f(p.cast<float>()));
  }
  BlockIndex block_of(const CellIndex& cell) const { return block_of_cell(cell, block_side_); }
  // Always through the cell, never floor(p / block size): the two differ near block faces.
  BlockIndex block_of(const Eigen::Vector3f& p) const { return block_of(cell_of(p)); }
  int local_index(const CellIndex& cell, const BlockIndex& block) const {
    return common::local_index(cell, block, block_side_);
  }
  CellIndex cell_of_local(const BlockIndex& block, int local) const {
    return common::cell_of_local(block, local, block_side_);
  }

  Eigen::Vector3f cell_centre(const CellIndex& cell) const {
    return (cell.cast<float>() + Eigen::Vector3f::Constant(0.5f)) * resolution_;
  }
  Eigen::Vector3f block_origin(const BlockIndex& block) const {
    return Eigen::Vector3f(static_cast<float>(block.x), static_cast<float>(block.y),
                           static_cast<float>(block.z)) *
           block_size();
  }
  Eigen::Vector3f block_centre(const BlockIndex& block) const {
    return block_origin(block) + Eigen::Vector3f::Constant(block_size() / 2);
  }

 private:
  float resolution_;
  float inv_resolution_;
  int block_side_;
};

}  // namespace semap::common
