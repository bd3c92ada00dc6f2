#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "semap/common/stamp.hpp"
#include "semap/dds_idl/block_snapshot.hpp"
#include "semap/dds_idl/types.hpp"

namespace semap::dds_idl {

// Occupied cells as sensor_msgs/PointCloud2 for RViz and any ROS 2 node: fields x, y, z
// (float32), rgb (float32 holding 0x00RRGGBB, PCL's packing, which RViz colours by), variance
// (float32, of the class probability) and class (uint16), little endian, 24 bytes a point
// (2 bytes of padding), one row.
class MapCloud {
 public:
  static constexpr std::uint32_t kPointStep = 24;
  // In map_cloud_updates: the cell at this point is no longer occupied.
  static constexpr std::uint16_t kRemovedClass = 0xFFFF;

  // `class_colors`: 0xRRGGBB per class (MapDescription::class_colors); classes beyond it are
  // grey.
  MapCloud(std::string frame_id, std::vector<std::uint32_t> class_colors);
  MapCloud(const MapCloud&) = delete;
  MapCloud& operator=(const MapCloud&) = delete;

  void clear() { data_.clear(); }
  void add(const Eigen::Vector3f& p, std::uint16_t cls, float variance);
  void add_occupied(const BlockSnapshot& block);
  // The cells of `block` whose occupancy or class differs from `sent` (one class per cell,
  // kRemovedClass for a cell not occupied; empty: none sent yet), which it then updates: a
  // newly occupied or relabelled cell with its class and variance, a cell no longer occupied
  // with kRemovedClass.
  void add_changed(const BlockSnapshot& block, std::vector<std::uint16_t>& sent);
  std::size_t size() const { return data_.size() / kPointStep; }

  // The message borrows this object's buffers: valid until the next add/clear.
  const msg::PointCloud2& message(common::Stamp stamp);

 private:
  std::string frame_id_;
  std::vector<std::uint32_t> class_colors_;
  std::array<std::string, 6> names_{"x", "y", "z", "rgb", "variance", "class"};
  std::array<msg::PointField, 6> fields_{};
  std::vector<std::uint8_t> data_;
  msg::PointCloud2 msg_{};
};

struct CloudPoint {
  Eigen::Vector3f position;
  std::uint16_t cls = 0;
  float variance = 0.0f;
  std::uint32_t rgb = 0;  // 0x00RRGGBB
};

// Reads a cloud written by MapCloud; throws std::runtime_error naming the field when the
// layout differs.
std::vector<CloudPoint> read_map_cloud(const msg::PointCloud2& m);

}  // namespace semap::dds_idl
