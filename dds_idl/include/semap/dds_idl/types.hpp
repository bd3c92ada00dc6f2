#pragma once

// The idlc-generated C types and the descriptor of each, so that the typed templates need only
// the C struct as parameter.
#include <builtin_interfaces/msg/Time_.h>
#include <geometry_msgs/msg/PoseWithCovarianceStamped_.h>
#include <map_msgs/msg/OccupancyGridUpdate_.h>
#include <nav_msgs/msg/OccupancyGrid_.h>
#include <nav_msgs/msg/Odometry_.h>
#include <semap_msgs/msg/Health_.h>
#include <semap_msgs/msg/MapInfo_.h>
#include <semap_msgs/msg/SemanticMapBlock_.h>
#include <sensor_msgs/msg/CompressedImage_.h>
#include <sensor_msgs/msg/Imu_.h>
#include <sensor_msgs/msg/NavSatFix_.h>
#include <sensor_msgs/msg/PointCloud2_.h>
#include <tf2_msgs/msg/TFMessage_.h>

namespace semap::dds_idl {

namespace msg {
using Time = builtin_interfaces_msg_dds__Time_;
using Header = std_msgs_msg_dds__Header_;
using PoseWithCovarianceStamped = geometry_msgs_msg_dds__PoseWithCovarianceStamped_;
using Odometry = nav_msgs_msg_dds__Odometry_;
using OccupancyGrid = nav_msgs_msg_dds__OccupancyGrid_;
using OccupancyGridUpdate = map_msgs_msg_dds__OccupancyGridUpdate_;
using TransformStamped = geometry_msgs_msg_dds__TransformStamped_;
using TFMessage = tf2_msgs_msg_dds__TFMessage_;
using Imu = sensor_msgs_msg_dds__Imu_;
using NavSatFix = sensor_msgs_msg_dds__NavSatFix_;
using PointField = sensor_msgs_msg_dds__PointField_;
using PointCloud2 = sensor_msgs_msg_dds__PointCloud2_;
using SemanticMapBlock = semap_msgs_msg_dds__SemanticMapBlock_;
using MapInfo = semap_msgs_msg_dds__MapInfo_;
using StageHealth = semap_msgs_msg_dds__StageHealth_;
using DriverCounters = semap_msgs_msg_dds__DriverCounters_;
using WriterHealth = semap_msgs_msg_dds__WriterHealth_;
using ViewerClient = semap_msgs_msg_dds__ViewerClient_;
using Health = semap_msgs_msg_dds__Health_;
using CompressedImage = sensor_msgs_msg_dds__CompressedImage_;
}  // namespace msg

template <typename T>
struct TypeDescriptor;

#define SEMAP_DDS_TYPE(T, DESC)                                  \
  template <>                                                    \
  struct TypeDescriptor<T> {                                     \
    static const dds_topic_descriptor_t* get() { return &DESC; } \
  }

SEMAP_DDS_TYPE(msg::PoseWithCovarianceStamped,
               geometry_msgs_msg_dds__PoseWithCovarianceStamped__desc);
SEMAP_DDS_TYPE(msg::Odometry, nav_msgs_msg_dds__Odometry__desc);
SEMAP_DDS_TYPE(msg::Imu, sensor_msgs_msg_dds__Imu__desc);
SEMAP_DDS_TYPE(msg::NavSatFix, sensor_msgs_msg_dds__NavSatFix__desc);
SEMAP_DDS_TYPE(msg::PointCloud2, sensor_msgs_msg_dds__PointCloud2__desc);
SEMAP_DDS_TYPE(msg::SemanticMapBlock, semap_msgs_msg_dds__SemanticMapBlock__desc);
SEMAP_DDS_TYPE(msg::MapInfo, semap_msgs_msg_dds__MapInfo__desc);
SEMAP_DDS_TYPE(msg::Health, semap_msgs_msg_dds__Health__desc);
SEMAP_DDS_TYPE(msg::OccupancyGrid, nav_msgs_msg_dds__OccupancyGrid__desc);
SEMAP_DDS_TYPE(msg::TFMessage, tf2_msgs_msg_dds__TFMessage__desc);
SEMAP_DDS_TYPE(msg::OccupancyGridUpdate, map_msgs_msg_dds__OccupancyGridUpdate__desc);
SEMAP_DDS_TYPE(msg::CompressedImage, sensor_msgs_msg_dds__CompressedImage__desc);

#undef SEMAP_DDS_TYPE

// A C sequence that borrows `data` for the duration of one write (no copy, never freed by DDS).
template <typename Seq, typename V>
Seq borrow_sequence(V* data, std::size_t n) {
  Seq s{};
  s._maximum = static_cast<uint32_t>(n);
  s._length = static_cast<uint32_t>(n);
  s._buffer = data;
  s._release = false;
  return s;
}

}  // namespace semap::dds_idl
