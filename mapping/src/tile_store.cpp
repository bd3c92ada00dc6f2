#include "semap/mapping/tile_store.hpp"

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "semap/mapping/smap_io.hpp"

namespace semap::mapping {

TileStore::TileStore(std::filesystem::path dir, const LayeredMapParams& params, bool durable)
    : dir_(std::move(dir)), params_(params), durable_(durable) {
  std::filesystem::create_directories(dir_);
  for (const auto& entry : std::filesystem::directory_iterator(dir_)) {
    common::BlockIndex key;
    char tail = 0;
    const std::string name = entry.path().filename().string();
    if (std::sscanf(name.c_str(), "tile_%d_%d_%d.smap%c", &key.x, &key.y, &key.z, &tail) == 3) {
      keys_.insert(key);
    }
  }
}

std::filesystem::path TileStore::tile_path(const common::BlockIndex& key) const {
  return dir_ / ("tile_" + std::to_string(key.x) + "_" + std::to_string(key.y) + "_" +
                 std::to_string(key.z) + ".smap");
}

std::size_t TileStore::evict(LayeredMap& map, const common::BlockIndex& key) {
  LayeredMap tile(map.params());
  std::size_t moved = 0;
  for (const auto& [source, layer] : map.layers()) {
    const Block* block = layer.find_block(key);
    if (block == nullptr) continue;
    EvidenceGrid& out = tile.layer(source);
    out.set_updates(layer.updates());
    out.restore_block(key, block->evidence(), block->observed_words());
    ++moved;
  }
  if (moved == 0) return 0;
  if (contains(key)) restore(map, key);  // never overwrite evidence already on disk
  write_smap(tile_path(key), tile, durable_);
  keys_.insert(key);
  // Drop from memory only once the tile is durable.
  for (const auto& [source, layer] : tile.layers()) map.layer(source).evict(key);
  return moved;
}

bool TileStore::restore(LayeredMap& map, const common::BlockIndex& key) {
  if (!contains(key)) return false;
  const std::filesystem::path path = tile_path(key);
  const SmapReadResult tile = read_smap(path);
  if (!(tile.map.params() == params_)) {
    throw SmapError(path.string() + ": tile parameters differ from the map's");
  }
  for (const auto& [source, layer] : tile.map.layers()) {
    EvidenceGrid& target = map.layer(source);
    target.set_updates(std::max(target.updates(), layer.updates()));
    for (const common::BlockIndex& tile_key : layer.keys()) {
      if (tile_key != key) throw SmapError(path.string() + ": holds a block of another tile");
    }
    // Adds to any evidence the block gathered in memory since it went out.
    if (const Block* block = layer.find_block(key)) target.add_block(key, block->evidence());
  }
  std::filesystem::remove(path);
  keys_.erase(key);
  return true;
}

}  // namespace semap::mapping
