#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "semap/common/stamp.hpp"
#include "semap/dds_idl/types.hpp"

namespace semap::dds_idl {

// The plain form of semap_msgs/MapInfo.
struct MapDescription {
  float resolution = 0.1f;
  std::uint16_t block_cells = 8;
  std::uint16_t num_classes = 0;
  std::vector<std::string> class_names;     // empty or num_classes names
  std::vector<std::uint32_t> class_colors;  // empty or num_classes 0xRRGGBB
  Eigen::Vector3d min_bound = Eigen::Vector3d::Zero();
  Eigen::Vector3d max_bound = Eigen::Vector3d::Zero();
  std::uint32_t num_blocks = 0;
  std::uint64_t sequence = 0;
};

// A MapInfo message that borrows the description's strings and arrays.
class MapInfoMessage {
 public:
  MapInfoMessage(const MapDescription& d, common::Stamp stamp, const std::string& frame_id);
  MapInfoMessage(const MapInfoMessage&) = delete;
  MapInfoMessage& operator=(const MapInfoMessage&) = delete;
  const msg::MapInfo& get() const { return msg_; }

 private:
  std::vector<char*> names_;
  msg::MapInfo msg_{};
};

// Throws std::runtime_error naming the field when the message is inconsistent.
MapDescription from_msg(const msg::MapInfo& m);

}  // namespace semap::dds_idl
