#pragma once

// The types of an MCAP recording's inputs (semap-onboard --record FILE.mcap,
// docs/record-replay.md), serialised by Cyclone's generated code like every other semap type:
// the IMU's CAN frames as can_msgs/msg/Frame, the GNSS port's reads as semap_msgs/msg/GnssBytes,
// camera frames as sensor_msgs/msg/Image (raw) or CompressedImage (MJPEG), the configuration as
// std_msgs/msg/String. Their channels, as the recorder names them.
#include <can_msgs/msg/Frame_.h>
#include <semap_msgs/msg/GnssBytes_.h>
#include <sensor_msgs/msg/Image_.h>
#include <std_msgs/msg/String_.h>

#include "semap/dds_idl/types.hpp"

namespace semap::dds_idl {

namespace msg {
using CanFrame = can_msgs_msg_dds__Frame_;
using GnssBytes = semap_msgs_msg_dds__GnssBytes_;
using Image = sensor_msgs_msg_dds__Image_;
using String = std_msgs_msg_dds__String_;
}  // namespace msg

template <>
struct TypeDescriptor<msg::CanFrame> {
  static const dds_topic_descriptor_t* get() { return &can_msgs_msg_dds__Frame__desc; }
};
template <>
struct TypeDescriptor<msg::GnssBytes> {
  static const dds_topic_descriptor_t* get() { return &semap_msgs_msg_dds__GnssBytes__desc; }
};
template <>
struct TypeDescriptor<msg::Image> {
  static const dds_topic_descriptor_t* get() { return &sensor_msgs_msg_dds__Image__desc; }
};
template <>
struct TypeDescriptor<msg::String> {
  static const dds_topic_descriptor_t* get() { return &std_msgs_msg_dds__String__desc; }
};

// The input channels of a recording: topic and ROS 2 type.
struct RecordingTopics {
  static constexpr const char* kCan = "/semap/raw/can";              // can_msgs/msg/Frame
  static constexpr const char* kGnss = "/semap/raw/gnss";            // semap_msgs/msg/GnssBytes
  static constexpr const char* kColour = "/semap/raw/colour/image";  // sensor_msgs/msg/Image
  static constexpr const char* kColourCompressed =
      "/semap/raw/colour/image/compressed";  // sensor_msgs/msg/CompressedImage
  static constexpr const char* kDepth = "/semap/raw/depth/image";  // sensor_msgs/msg/Image
  static constexpr const char* kDepthCompressed = "/semap/raw/depth/image/compressed";
  static constexpr const char* kConfig = "/semap/recording/config";  // std_msgs/msg/String
};

}  // namespace semap::dds_idl
