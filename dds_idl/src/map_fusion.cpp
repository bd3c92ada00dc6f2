#include "semap/dds_idl/map_fusion.hpp"

#include <stdexcept>
#include <unordered_set>

namespace semap::dds_idl {

namespace {

MapClientConfig client_config(const std::string& ns, const MapDescription& d) {
  MapClientConfig c;
  c.ns = ns;
  c.limits.resolution = d.resolution;
  c.limits.block_cells = d.block_cells;
  c.limits.num_classes = d.num_classes;
  return c;
}

}  // namespace

MapFusion::MapFusion(const Participant& participant, MapFusionConfig config)
    : config_(std::move(config)), publisher_(participant, config_.output, config_.description) {
  if (config_.robots.empty()) throw std::invalid_argument("MapFusion: no robots to follow");
  for (const auto& ns : config_.robots) {
    if (ns == config_.output.ns) {
      throw std::invalid_argument("MapFusion: output namespace '" + ns + "' is also an input");
    }
    clients_.push_back(
        std::make_unique<MapClient>(participant, client_config(ns, config_.description)));
  }
}

std::size_t MapFusion::spin_once(common::Stamp now) {
  std::unordered_set<BlockIndex, BlockIndexHash> dirty;
  for (auto& client : clients_) {
    client->poll();
    for (const BlockIndex& index : client->take_changed()) dirty.insert(index);
  }
  std::vector<const BlockSnapshot*> inputs;
  for (const BlockIndex& index : dirty) {
    inputs.clear();
    for (const auto& client : clients_) {
      const auto it = client->blocks().find(index);
      if (it != client->blocks().end()) inputs.push_back(&it->second);
    }
    publisher_.update(merge_blocks(inputs, config_.merge));
  }
  publisher_.spin_once(now);
  return dirty.size();
}

}  // namespace semap::dds_idl
