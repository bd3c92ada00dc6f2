#pragma once

#include <Eigen/Core>
#include <cstddef>

#include "semap/mapping/layered_map.hpp"
#include "semap/mapping/tile_store.hpp"

namespace semap::mapping {

// Bounds a map's memory to the neighbourhood of the robot: blocks whose centre is farther
// than radius + one block from the robot go to the tile store, tiles within radius come back.
// The extra block of hysteresis keeps a block on the boundary from bouncing. Call update()
// before each insertion; with radius >= max_range + block diagonal every block a scan touches
// is resident, so no evidence is ever split between memory and disk.
class TilePager {
 public:
  struct Stats {
    std::size_t evicted = 0;   // layer blocks written out
    std::size_t restored = 0;  // tiles read back
  };

  TilePager(LayeredMap& map, TileStore& store, double radius_m);

  void update(const Eigen::Vector3d& robot);
  // The whole map, resident blocks and tiles, without changing either (for saving or checks).
  LayeredMap full_map() const;

  double radius() const { return radius_; }
  const Stats& stats() const { return stats_; }

 private:
  Eigen::Vector3d block_centre(const common::BlockIndex& key) const;

  LayeredMap& map_;
  TileStore& store_;
  double radius_;
  Stats stats_;
};

}  // namespace semap::mapping
