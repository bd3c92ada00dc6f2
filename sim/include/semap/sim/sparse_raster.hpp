#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace semap::sim {

// A raster over a possibly huge extent (the bounding box of a long drive) that stores only
// the 64 x 64-cell tiles written to; everywhere else reads as the background value. Fields
// that matter only near a path then cost memory in proportion to the path's length.
template <class T>
class SimSparseRaster {
 public:
  SimSparseRaster(const Eigen::AlignedBox2f& extent, float cell, T background)
      : origin_(extent.min()), cell_(cell), background_(background) {
    nx_ = std::max(2, static_cast<int>(std::ceil(extent.sizes().x() / cell)) + 1);
    ny_ = std::max(2, static_cast<int>(std::ceil(extent.sizes().y() / cell)) + 1);
    tiles_x_ = (nx_ + kTile - 1) / kTile;
    tile_of_.assign(
        static_cast<std::size_t>(tiles_x_) * static_cast<std::size_t>((ny_ + kTile - 1) / kTile),
        -1);
  }

  int nx() const { return nx_; }
  int ny() const { return ny_; }
  float cell() const { return cell_; }
  // Cell (ix, iy) is the point origin + cell * (ix, iy).
  const Eigen::Vector2f& origin() const { return origin_; }

  // 0 <= ix < nx, 0 <= iy < ny.
  T get(int ix, int iy) const {
    const std::int32_t t = tile_of_[tile(ix, iy)];
    return t < 0 ? background_ : cells_[offset(t, ix, iy)];
  }
  // Cells (ix, iy), (ix + 1, iy), (ix, iy + 1), (ix + 1, iy + 1), for ix < nx - 1 and
  // iy < ny - 1: one tile lookup when all four share a tile, as they mostly do.
  std::array<T, 4> quad(int ix, int iy) const {
    if ((ix & (kTile - 1)) == kTile - 1 || (iy & (kTile - 1)) == kTile - 1) {
      return {get(ix, iy), get(ix + 1, iy), get(ix, iy + 1), get(ix + 1, iy + 1)};
    }
    const std::int32_t t = tile_of_[tile(ix, iy)];
    if (t < 0) return {background_, background_, background_, background_};
    const T* c = &cells_[offset(t, ix, iy)];
    return {c[0], c[1], c[kTile], c[kTile + 1]};
  }
  T& at(int ix, int iy) {
    std::int32_t& t = tile_of_[tile(ix, iy)];
    if (t < 0) {
      t = static_cast<std::int32_t>(cells_.size() / (kTile * kTile));
      cells_.resize(cells_.size() + kTile * kTile, background_);
    }
    return cells_[offset(t, ix, iy)];
  }

 private:
  static constexpr int kBits = 6;
  static constexpr int kTile = 1 << kBits;

  std::size_t tile(int ix, int iy) const {
    return static_cast<std::size_t>(iy >> kBits) * static_cast<std::size_t>(tiles_x_) +
           static_cast<std::size_t>(ix >> kBits);
  }
  static std::size_t offset(std::int32_t t, int ix, int iy) {
    return static_cast<std::size_t>(t) * (kTile * kTile) +
           static_cast<std::size_t>(((iy & (kTile - 1)) << kBits) | (ix & (kTile - 1)));
  }

  Eigen::Vector2f origin_;
  float cell_;
  T background_;
  int nx_ = 0;
  int ny_ = 0;
  int tiles_x_ = 0;
  std::vector<std::int32_t> tile_of_;  // per tile: its index in cells_, or -1
  std::vector<T> cells_;
};

}  // namespace semap::sim
