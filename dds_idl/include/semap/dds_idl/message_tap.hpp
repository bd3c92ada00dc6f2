#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "semap/common/stamp.hpp"
#include "semap/dds_idl/types.hpp"

namespace semap::dds_idl {

// A channel of messages a tap receives: a DDS topic as ROS 2 sees it, or a channel of the
// tap's owner (the viewer's images).
struct TapChannel {
  std::string topic;  // "/semap/odometry" (ros2_topic_name of the DDS name)
  std::string type;   // "nav_msgs/msg/Odometry" (ros2msg_schema gives its schema)
  // Transient local: a late joiner gets the newest message (tf_static, map_cloud, costmap,
  // map_info); a tap keeps it and never drops it for a slow client.
  bool latched = false;
};

// What sees every message semap writes, as the CDR bytes DDS sends: the viewer's WebSocket
// server, a recorder. Writers call it only when one is attached (Writer::attach_tap), so it
// costs nothing otherwise.
class MessageTap {
 public:
  virtual ~MessageTap() = default;
  // Before messages flow, from the thread attaching the writers; the id on_message gets.
  virtual std::uint32_t add_channel(const TapChannel& channel) = 0;
  // Each message written: the CDR encapsulation header (4 bytes) and the body, valid only
  // during the call. From the writing stage's thread: must be quick (copy, enqueue) and must
  // not throw.
  virtual void on_message(std::uint32_t channel, common::Stamp stamp,
                          std::span<const std::uint8_t> cdr) noexcept = 0;
};

// Serialises `sample` of the type `desc` describes into `out` (replaced) exactly as Cyclone's
// writer puts it on the wire for semap's (final, XCDR1) types: encapsulation CDR_LE, the
// options' low bits the padding count, the body padded to 4 bytes. Reuses out's capacity.
void serialize_cdr(const void* sample, const dds_topic_descriptor_t& desc,
                   std::vector<std::uint8_t>& out);

template <typename T>
void serialize_cdr(const T& sample, std::vector<std::uint8_t>& out) {
  serialize_cdr(&sample, *TypeDescriptor<T>::get(), out);
}

// Reads CDR bytes (with their encapsulation header) back into `sample` (zero-initialised or
// earlier filled by this call; free with dds_sample_free(.., DDS_FREE_CONTENTS)). Checks the
// bytes first (Cyclone's normaliser): false when they are not a valid sample. For tests and
// tools; the robot only writes.
bool deserialize_cdr(std::span<const std::uint8_t> cdr, const dds_topic_descriptor_t& desc,
                     void* sample);

template <typename T>
bool deserialize_cdr(std::span<const std::uint8_t> cdr, T& sample) {
  return deserialize_cdr(cdr, *TypeDescriptor<T>::get(), &sample);
}

}  // namespace semap::dds_idl
