#pragma once

#include <memory>
#include <string>
#include <vector>

#include "semap/dds_idl/block_merge.hpp"
#include "semap/dds_idl/map_client.hpp"
#include "semap/dds_idl/map_publisher.hpp"

namespace semap::dds_idl {

struct MapFusionConfig {
  std::vector<std::string> robots;  // topic namespaces to subscribe to
  MapPublisherConfig output;        // namespace and rates of the merged map
  MapDescription description;       // shape every robot's map must have
  BlockMergeConfig merge;
};

// Subscribes to several robots' maps and republishes their merge: whenever a robot sends a
// new version of a block, the block is merged again from every robot that has it.
class MapFusion {
 public:
  MapFusion(const Participant& participant, MapFusionConfig config);

  // Polls every robot, merges the blocks that changed and publishes what is due. Returns the
  // number of blocks merged.
  std::size_t spin_once(common::Stamp now);

  const MapClient& robot(std::size_t i) const { return *clients_.at(i); }
  std::size_t num_robots() const { return clients_.size(); }
  const MapPublisher& publisher() const { return publisher_; }

 private:
  MapFusionConfig config_;
  std::vector<std::unique_ptr<MapClient>> clients_;
  MapPublisher publisher_;
};

}  // namespace semap::dds_idl
