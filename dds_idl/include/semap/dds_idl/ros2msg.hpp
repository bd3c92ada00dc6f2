#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace semap::dds_idl {

// The ROS 2 message definitions (.msg text, dds_idl/msg/<pkg>/<Type>.msg, compiled into the
// library) of every type semap writes, for tools that carry semap's CDR with its schema: the
// viewer's Foxglove WebSocket channels (schemaEncoding "ros2msg") and MCAP recordings.

// Every type with a definition, as "pkg/msg/Type", sorted.
std::vector<std::string> ros2msg_types();

// The schema of `type` ("nav_msgs/msg/Odometry"; "nav_msgs/Odometry" too) in ROS 2's
// concatenated form, as rosbag2 and foxglove_bridge give it: the type's own text, then for each
// type it depends on (recursively, each once) a line of 80 '=', a line "MSG: pkg/Type" and its
// text. Throws std::invalid_argument naming the type when semap has no definition of it (or of
// a type it uses).
std::string ros2msg_schema(std::string_view type);

// "nav_msgs::msg::dds_::Odometry_" (the DDS type name idlc and rmw use) -> "nav_msgs/msg/Odometry".
std::string ros2_type_name(std::string_view dds_type_name);

// "rt/semap/odometry" -> "/semap/odometry", "rt/robot1/tf" -> "/robot1/tf": the topic as ROS 2
// names it (a name without the "rt/" prefix only gets its leading '/').
std::string ros2_topic_name(std::string_view dds_topic);

}  // namespace semap::dds_idl
