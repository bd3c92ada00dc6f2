#include "semap/mapping/tile_pager.hpp"

#include <stdexcept>
#include <vector>

#include "semap/mapping/smap_io.hpp"

namespace semap::mapping {

TilePager::TilePager(LayeredMap& map, TileStore& store, double radius_m)
    : map_(map), store_(store), radius_(radius_m) {
  if (!(radius_m > 0.0)) throw std::invalid_argument("TilePager: radius must be positive");
}

Eigen::Vector3d TilePager::block_centre(const common::BlockIndex& key) const {
  const double size = map_.params().block_size();
  return (Eigen::Vector3d(key.x, key.y, key.z) + Eigen::Vector3d::Constant(0.5)) * size;
}

void TilePager::update(const Eigen::Vector3d& robot) {
  const double evict_beyond = radius_ + map_.params().block_size();
  for (const common::BlockIndex& key : map_.block_keys()) {
    if ((block_centre(key) - robot).norm() > evict_beyond) {
      stats_.evicted += store_.evict(map_, key);
    }
  }
  std::vector<common::BlockIndex> back;
  for (const common::BlockIndex& key : store_.keys()) {
    if ((block_centre(key) - robot).norm() <= radius_) back.push_back(key);
  }
  for (const common::BlockIndex& key : back) stats_.restored += store_.restore(map_, key) ? 1 : 0;
}

LayeredMap TilePager::full_map() const {
  LayeredMap full = map_;
  for (const common::BlockIndex& key : store_.keys()) {
    const SmapReadResult tile = read_smap(store_.tile_path(key));
    for (const auto& [source, layer] : tile.map.layers()) {
      EvidenceGrid& target = full.layer(source);
      layer.for_each_block([&](const common::BlockIndex& tile_key, const Block& block) {
        target.put_block(tile_key, block.evidence());
      });
    }
  }
  return full;
}

}  // namespace semap::mapping
