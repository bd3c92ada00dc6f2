#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <span>
#include <vector>

#include "semap/perception/depth_projection.hpp"
#include "semap/sim/solid.hpp"
#include "semap/sim/solid_grid.hpp"

namespace semap::sim {

// The solids of a world binned by where their bounds project in one camera view, so that a
// pixel's ray is tested only against the solids that can cover that pixel (what a rasteriser
// does, for primary rays). Most of a street view is ground and sky, whose pixels then test
// nothing; the world's grid walk costs a few cells per ray even there.
class SimScreenBins {
 public:
  SimScreenBins(std::span<const SimSolid> solids, const perception::PinholeIntrinsics& k,
                const Eigen::Isometry3f& world_from_optical, float max_range);

  // Nearest entry of the ray of pixel (u, v), o + t d (d unit), into one of `solids` (those
  // the bins were built from) for t in (0, t_end).
  SimSolidGrid::Hit cast(std::span<const SimSolid> solids, int u, int v, const Eigen::Vector3f& o,
                         const Eigen::Vector3f& d, float t_end) const;

 private:
  static constexpr int kTile = 16;  // pixels
  struct Entry {
    std::uint32_t solid;
    int u0, v0, u1, v1;  // projected bounds, pixels, inclusive
    float near;          // lower bound on t: the nearest corner's depth
  };

  int tiles_x_ = 0;
  int tiles_y_ = 0;
  std::vector<std::uint32_t> start_;  // the entries of tile i: entries_[start_[i] .. start_[i+1])
  std::vector<Entry> entries_;
};

}  // namespace semap::sim
