#include "semap/dds_idl/ros2msg.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>

namespace semap::dds_idl {
namespace {

TEST(Ros2Msg, OdometrySchemaHasEveryDependencyOnceInRos2ConcatenatedForm) {
  const std::string s = ros2msg_schema("nav_msgs/msg/Odometry");
  EXPECT_EQ(s.rfind("std_msgs/Header header\nstring child_frame_id\n", 0), 0u) << s;
  const std::string sep = std::string(80, '=') + "\nMSG: ";
  for (const char* dep :
       {"std_msgs/Header", "builtin_interfaces/Time", "geometry_msgs/PoseWithCovariance",
        "geometry_msgs/Pose", "geometry_msgs/Point", "geometry_msgs/Quaternion",
        "geometry_msgs/TwistWithCovariance", "geometry_msgs/Twist", "geometry_msgs/Vector3"}) {
    const auto first = s.find(sep + dep + "\n");
    EXPECT_NE(first, std::string::npos) << dep;
    EXPECT_EQ(s.find(sep + dep + "\n", first + 1), std::string::npos) << dep << " twice";
  }
  EXPECT_EQ(ros2msg_schema("nav_msgs/Odometry"), s);
}

TEST(Ros2Msg, EveryTypeResolves) {
  const auto types = ros2msg_types();
  for (const char* t :
       {"nav_msgs/msg/Odometry", "nav_msgs/msg/OccupancyGrid", "map_msgs/msg/OccupancyGridUpdate",
        "tf2_msgs/msg/TFMessage", "sensor_msgs/msg/NavSatFix", "sensor_msgs/msg/PointCloud2",
        "sensor_msgs/msg/CompressedImage", "geometry_msgs/msg/PoseWithCovarianceStamped",
        "semap_msgs/msg/Health", "semap_msgs/msg/MapInfo", "semap_msgs/msg/SemanticMapBlock"}) {
    EXPECT_NE(std::find(types.begin(), types.end(), t), types.end()) << t;
  }
  for (const auto& t : types) EXPECT_NO_THROW(ros2msg_schema(t)) << t;
  const std::string health = ros2msg_schema("semap_msgs/msg/Health");
  EXPECT_NE(health.find("MSG: semap_msgs/ViewerClient\n"), std::string::npos);
  EXPECT_THROW(ros2msg_schema("nav_msgs/msg/Path"), std::invalid_argument);
}

TEST(Ros2Msg, NamesAsRos2SeesThem) {
  EXPECT_EQ(ros2_type_name("nav_msgs::msg::dds_::Odometry_"), "nav_msgs/msg/Odometry");
  EXPECT_EQ(ros2_type_name("semap_msgs::msg::dds_::Health_"), "semap_msgs/msg/Health");
  EXPECT_EQ(ros2_topic_name("rt/semap/odometry"), "/semap/odometry");
  EXPECT_EQ(ros2_topic_name("rt/robot1/tf_static"), "/robot1/tf_static");
}

}  // namespace
}  // namespace semap::dds_idl
