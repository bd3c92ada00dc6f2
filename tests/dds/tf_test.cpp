// What RViz and nav2 need to place semap's outputs: the robot's DDS side (DdsOutputs) writes
// TF's map -> base_link with every pose, on rt/<ns>/tf, and the sensors' frames once on
// rt/<ns>/tf_static, which a viewer started later still receives (transient local).
#include <gtest/gtest.h>

#include <cstring>
#include <optional>

#include "dds_fixture.hpp"
#include "semap/dds_idl/reader.hpp"
#include "semap/dds_idl/topic_names.hpp"
#include "semap/onboard/dds_outputs.hpp"
#include "semap/onboard/mapping_stage.hpp"

namespace semap::dds_idl::testing {
namespace {

struct Transform {
  std::string parent;
  std::string child;
  Eigen::Vector3d translation;
  Eigen::Quaterniond rotation;
  std::int32_t sec = 0;
};

std::optional<Transform> first_transform(Reader<msg::TFMessage>& reader) {
  std::optional<Transform> out;
  const auto deadline = std::chrono::steady_clock::now() + seconds(10);
  while (!out && std::chrono::steady_clock::now() < deadline) {
    reader.wait(milliseconds(100));
    reader.take_each([&](const msg::TFMessage& m, const dds_sample_info_t& info) {
      if (out || !info.valid_data || m.transforms_._length == 0) return;
      const msg::TransformStamped& t = m.transforms_._buffer[0];
      const auto& v = t.transform_.translation_;
      const auto& q = t.transform_.rotation_;
      out = Transform{t.header_.frame_id_,
                      t.child_frame_id_,
                      {v.x_, v.y_, v.z_},
                      Eigen::Quaterniond(q.w_, q.x_, q.y_, q.z_),
                      t.header_.stamp_.sec_};
    });
  }
  return out;
}

TEST_F(DdsTest, PosesGoOutOnTfAndSensorFramesOnTfStatic) {
  const std::string ns = unique_ns("tf");
  onboard::MappingConfig map;
  map.params.num_classes = 4;
  map.palette = mapping::ClassPalette::defaults(4);
  common::SpscRing<common::LabeledCloud> clouds(4);
  onboard::MappingStage stage(map, clouds, nullptr, {});
  onboard::DdsConfig config;
  config.domain = test_domain();
  config.ns = ns;
  Eigen::Isometry3d camera = Eigen::Isometry3d::Identity();
  camera.translation() = Eigen::Vector3d(0.3, 0.0, 1.5);
  camera.linear() = Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  onboard::DdsOutputs outputs(config, onboard::describe_map(map), stage.blocks(),
                              {{"camera_optical", camera}});

  const Participant viewer(test_domain());
  Topic<msg::TFMessage> tf_topic(viewer, topic_name(ns, SemapTopic::kTf),
                                 topic_qos(SemapTopic::kTf));
  EXPECT_EQ(topic_name(ns, SemapTopic::kTf), "rt/" + ns + "/tf");
  Reader<msg::TFMessage> tf(viewer, tf_topic, topic_qos(SemapTopic::kTf));
  onboard::PoseOutput pose;
  pose.pose.stamp = common::Stamp::now();
  pose.pose.position = Eigen::Vector3d(12.0, -3.5, 0.25);
  pose.pose.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()));
  std::optional<Transform> base;
  const auto deadline = std::chrono::steady_clock::now() + seconds(10);
  while (!base && std::chrono::steady_clock::now() < deadline) {
    outputs.publish_pose(pose);  // until the reader has matched
    base = first_transform(tf);
  }
  ASSERT_TRUE(base) << "no map -> base_link on tf";
  EXPECT_EQ(base->parent, "map");
  EXPECT_EQ(base->child, "base_link");
  EXPECT_TRUE(base->translation.isApprox(pose.pose.position));
  EXPECT_TRUE(base->rotation.isApprox(pose.pose.orientation));
  EXPECT_GT(base->sec, 1'600'000'000);  // ROS time

  // Joining after tf_static went out still gives the sensor frames.
  Topic<msg::TFMessage> static_topic(viewer, topic_name(ns, SemapTopic::kTfStatic),
                                     topic_qos(SemapTopic::kTfStatic));
  Reader<msg::TFMessage> tf_static(viewer, static_topic, topic_qos(SemapTopic::kTfStatic));
  const auto optical = first_transform(tf_static);
  ASSERT_TRUE(optical) << "a late joiner got no tf_static";
  EXPECT_EQ(optical->parent, "base_link");
  EXPECT_EQ(optical->child, "camera_optical");
  EXPECT_TRUE(optical->translation.isApprox(camera.translation()));
  EXPECT_TRUE(optical->rotation.isApprox(Eigen::Quaterniond(camera.rotation())));
}

}  // namespace
}  // namespace semap::dds_idl::testing
