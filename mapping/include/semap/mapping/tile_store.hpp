#pragma once

#include <filesystem>
#include <optional>
#include <unordered_set>

#include "semap/mapping/layered_map.hpp"

namespace semap::mapping {

// Blocks kept on disk, one small .smap file per block position holding that block of every
// layer (so tiles carry the same CRCs and crash-safe writes as map files). The directory is
// scanned on construction, so a store survives restarts.
class TileStore {
 public:
  // Creates `dir` if needed; tiles already there must match `params` when read. `durable`
  // fsyncs every tile (see write_file_atomically); without it a power cut may lose tiles.
  TileStore(std::filesystem::path dir, const LayeredMapParams& params, bool durable = true);

  // Moves the block at `key` of every layer of `map` to disk and drops it from `map`.
  // Returns the number of layer blocks moved. A tile already on disk for `key` is replaced.
  std::size_t evict(LayeredMap& map, const common::BlockIndex& key);
  // Moves the tile at `key` back into `map` (adding to any evidence `map` gained there since)
  // and deletes it from disk. Returns false when there is no such tile. Throws SmapError for a
  // damaged tile, naming its file.
  bool restore(LayeredMap& map, const common::BlockIndex& key);

  bool contains(const common::BlockIndex& key) const { return keys_.contains(key); }
  const std::unordered_set<common::BlockIndex, common::BlockIndexHash>& keys() const {
    return keys_;
  }
  std::size_t size() const { return keys_.size(); }
  std::filesystem::path tile_path(const common::BlockIndex& key) const;

 private:
  std::filesystem::path dir_;
  LayeredMapParams params_;
  bool durable_;
  std::unordered_set<common::BlockIndex, common::BlockIndexHash> keys_;
};

}  // namespace semap::mapping
