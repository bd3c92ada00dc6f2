// What a ROS 2 node receives from the robot's real writers (DdsOutputs over the mapping stage,
// as semap-onboard runs them), read by tests/dds/ros2_node/ros2_reader: another process with
// rmw_cyclonedds_cpp's view of the types (keyless, no type information) and `ros2 topic echo`'s
// QoS. Joining late, it must get the whole map cloud and the costmap, then follow their updates
// to exactly the robot's map, decode a sample of every topic stamped in ROS time, and not match
// map_blocks (keyed, for DDS-native clients).
#include <gtest/gtest.h>

#include <map>
#include <sstream>

#include "dds_fixture.hpp"
#include "ros2_node/map_digest.hpp"
#include "semap/onboard/dds_outputs.hpp"
#include "semap/onboard/mapping_stage.hpp"

namespace semap::dds_idl::testing {
namespace {

constexpr std::uint16_t kClasses = 4;  // free, road, car, grass

// Points of one class on a grid of (x, y) at height z, seen from above the robot.
common::LabeledCloud layer(float x0, float x1, float y0, float y1, float z, std::uint16_t label,
                           int repeat = 1) {
  common::LabeledCloud cloud;
  cloud.stamp = common::Stamp::now();
  cloud.origin = {0.3f, -0.2f, 2.0f};
  cloud.num_classes = kClasses;
  for (int r = 0; r < repeat; ++r) {
    for (float x = x0; x < x1; x += 0.2f) {
      for (float y = y0; y < y1; y += 0.2f) {
        cloud.points.emplace_back(x + 0.1f, y + 0.1f, z);
        cloud.labels.push_back(label);
      }
    }
  }
  return cloud;
}

common::LabeledCloud operator+(common::LabeledCloud a, const common::LabeledCloud& b) {
  a.points.insert(a.points.end(), b.points.begin(), b.points.end());
  a.labels.insert(a.labels.end(), b.labels.begin(), b.labels.end());
  return a;
}

// The map cloud a subscriber should hold: the occupied cells of every block, read as the
// publisher reads them.
std::string expected_cloud(const BlockSource& blocks) {
  ros2_check::CloudCells cells;
  std::vector<common::BlockIndex> indices;
  blocks.for_each_block([&](const common::BlockIndex& index) { indices.push_back(index); });
  BlockSnapshot block;
  for (const auto& index : indices) {
    if (!blocks.read(index, block)) continue;
    for (std::size_t i = 0; i < block.cell_count(); ++i) {
      if (block.state[i] != common::CellState::kOccupied) continue;
      const Eigen::Vector3f c = block.cell_center(i);
      cells[ros2_check::cell_key(c.x(), c.y(), c.z())] = block.argmax_class[i];
    }
  }
  return ros2_check::cloud_digest(cells);
}

std::string expected_costmap(const mapping::Costmap& c) {
  return ros2_check::grid_digest(static_cast<std::uint32_t>(c.width),
                                 static_cast<std::uint32_t>(c.height), c.origin_x(), c.origin_y(),
                                 c.data);
}

// The reader's output, gathered line by line.
struct ReaderView {
  std::map<std::string, std::string> qos, samples, matched;
  std::string cloud, costmap;
  bool joined = false;
  std::vector<std::string> errors;

  void take(const std::string& line) {
    std::istringstream s(line);
    std::string kind, leaf;
    s >> kind;
    std::string rest;
    std::getline(s >> std::ws, rest);
    const auto split = [&] {
      const auto sp = rest.find(' ');
      leaf = rest.substr(0, sp);
      return sp == std::string::npos ? std::string() : rest.substr(sp + 1);
    };
    if (kind == "qos") qos[leaf] = split();
    if (kind == "sample") samples.emplace(leaf, split());  // the first one stays
    if (kind == "matched") matched[leaf] = split();
    if (kind == "cloud") cloud = rest;
    if (kind == "costmap") costmap = rest;
    if (kind == "joined") joined = true;
    if (kind == "error") errors.push_back(rest);
  }
};

// Reads the reader's lines into `view` until `done` holds or the time is up.
bool read_until(ChildProcess& reader, ReaderView& view, const std::function<bool()>& done,
                std::chrono::seconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!done()) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return false;
    const auto line = reader.read_line(left);
    if (!line) return done();
    view.take(*line);
  }
  return true;
}

TEST_F(DdsTest, Ros2NodeJoiningLateGetsTheWholeMapAndFollowsIt) {
  onboard::MappingConfig mapping;
  mapping.params.method = mapping::MapMethod::kCsm;
  mapping.params.resolution = 0.2f;
  mapping.params.num_classes = kClasses;
  mapping.threads = 1;
  onboard::DdsConfig dds;
  dds.domain = test_domain();
  dds.ns = unique_ns("ros2node");
  dds.publish_hz = 10.0;
  dds.cloud_hz = 0.02;  // the whole cloud once in this test: later changes come as updates
  onboard::CostmapConfig costmap;
  costmap.params.resolution = 0.2;
  costmap.params.width_m = 8.0;
  costmap.params.height_m = 8.0;
  costmap.params.max_variance = 0.0;
  costmap.params.class_cost = {0, 0, 100, 40};
  costmap.params.ground_class = {false, true, false, true};
  costmap.publish_hz = 5.0;
  const Eigen::Vector2d robot(0.3, -0.2);

  common::SpscRing<common::LabeledCloud> clouds(8);
  onboard::DdsOutputs* outputs_of_stage = nullptr;
  onboard::MappingStage stage(
      mapping, clouds,
      [&](const std::vector<common::BlockIndex>& b, const std::vector<common::BlockIndex>&) {
        outputs_of_stage->blocks_changed(b);
      },
      {});
  Eigen::Isometry3d camera = Eigen::Isometry3d::Identity();
  camera.translation() = Eigen::Vector3d(0.2, 0.0, 1.1);
  onboard::DdsOutputs outputs(dds, onboard::describe_map(mapping), stage.blocks(),
                              {{"camera_optical", camera}}, costmap, &stage.costmaps());
  outputs_of_stage = &outputs;
  struct StopBoth {
    onboard::MappingStage& stage;
    onboard::DdsOutputs& outputs;
    ~StopBoth() {
      stage.stop();
      outputs.stop();
    }
  } stop_both{stage, outputs};

  onboard::PoseOutput pose;
  pose.pose.stamp = common::Stamp::now();
  pose.pose.position = {robot.x(), robot.y(), 0.0};
  outputs.publish_pose(pose);
  // Road with grass on its left, and a car.
  ASSERT_TRUE(clouds.try_push(layer(-4.0f, 3.0f, -4.0f, 4.0f, 0.05f, 1) +
                              layer(-4.0f, -2.0f, -4.0f, 4.0f, 0.05f, 3, 2) +
                              layer(1.0f, 1.6f, 1.0f, 1.4f, 0.5f, 2)));
  stage.start();
  const auto wait_scans = [&](std::uint64_t n) {
    const auto deadline = std::chrono::steady_clock::now() + seconds(20);
    while (stage.stats().scans < n && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(milliseconds(10));
    }
    return stage.stats().scans == n;
  };
  ASSERT_TRUE(wait_scans(1));
  outputs.start();
  while (outputs.map_counters().clouds_written == 0) std::this_thread::sleep_for(milliseconds(10));
  const std::string cloud1 = expected_cloud(stage.blocks());
  const std::string costmap1 =
      expected_costmap(stage.costmaps().build_costmap(costmap.params, robot));
  ASSERT_NE(cloud1.substr(0, 2), "0 ") << "the first scan left no occupied cell";

  // The ROS 2 node starts after the map went out.
  ChildProcess reader({SEMAP_ROS2_READER, std::to_string(test_domain()), dds.ns});
  ReaderView view;
  ASSERT_TRUE(read_until(
      reader, view, [&] { return view.joined && view.cloud == cloud1 && view.costmap == costmap1; },
      seconds(30)))
      << "joined " << view.joined << ", cloud " << view.cloud << " (robot " << cloud1
      << "), costmap " << view.costmap << " (robot " << costmap1 << ")";

  // Now the node is there: odometry, TF and health reach it; the car leaves (its cells are
  // seen free), another one parks on the road, and the node follows through the updates only.
  for (int i = 0; i < 3; ++i) {
    pose.pose.stamp = common::Stamp::now();
    outputs.publish_pose(pose);
    HealthReport health;
    health.stamp = common::Stamp::now();
    health.stages.push_back({"mapping", 10.0f, 0, 0, 1.0f, 2.0f});
    outputs.publish_health(health);
    std::this_thread::sleep_for(milliseconds(50));
  }
  ASSERT_TRUE(clouds.try_push(layer(1.0f, 1.6f, 1.0f, 1.4f, 0.5f, 0, 4) +
                              layer(-1.0f, -0.4f, 1.0f, 1.6f, 0.5f, 2)));
  ASSERT_TRUE(wait_scans(2));
  const std::string cloud2 = expected_cloud(stage.blocks());
  const std::string costmap2 =
      expected_costmap(stage.costmaps().build_costmap(costmap.params, robot));
  ASSERT_NE(cloud2, cloud1);
  ASSERT_NE(costmap2, costmap1);
  const std::vector<std::string> leaves{
      "odometry",          "tf",      "tf_static",      "health", "map_info", "map_cloud",
      "map_cloud_updates", "costmap", "costmap_updates"};
  EXPECT_TRUE(read_until(
      reader, view,
      [&] {
        bool all = view.cloud == cloud2 && view.costmap == costmap2;
        for (const auto& leaf : leaves) all = all && view.samples.count(leaf);
        return all;
      },
      seconds(30)))
      << "cloud " << view.cloud << " (robot " << cloud2 << "), costmap " << view.costmap
      << " (robot " << costmap2 << ")";
  EXPECT_EQ(outputs.map_counters().clouds_written, 1u) << "the node followed updates, not clouds";
  EXPECT_TRUE(view.errors.empty()) << view.errors.front();

  // QoS as `ros2 topic echo` adapts it to semap's writers.
  EXPECT_EQ(view.qos["map_cloud"], "reliable transient_local");
  EXPECT_EQ(view.qos["costmap"], "reliable transient_local");
  EXPECT_EQ(view.qos["tf_static"], "reliable transient_local");
  EXPECT_EQ(view.qos["map_info"], "reliable transient_local");
  EXPECT_EQ(view.qos["map_cloud_updates"], "reliable volatile");
  EXPECT_EQ(view.qos["costmap_updates"], "reliable volatile");
  EXPECT_EQ(view.qos["tf"], "reliable volatile");
  EXPECT_EQ(view.qos["odometry"], "best_effort volatile");
  // Every sample decodes, stamped in ROS time (system clock), in the right frame.
  const auto now_s = std::chrono::duration_cast<std::chrono::seconds>(
                         std::chrono::system_clock::now().time_since_epoch())
                         .count();
  for (const auto& leaf : leaves) {
    SCOPED_TRACE(leaf);
    ASSERT_TRUE(view.samples.count(leaf));
    std::istringstream s(view.samples[leaf]);
    std::int64_t sec = 0, nanosec = 0;
    std::string frame;
    s >> sec >> nanosec >> frame;
    EXPECT_LT(std::abs(sec - now_s), 120) << "not ROS time: " << view.samples[leaf];
    EXPECT_EQ(frame, leaf == "tf_static" ? "base_link" : "map");
  }
  EXPECT_NE(view.samples["odometry"].find(" base_link 0.3 -0.2"), std::string::npos)
      << view.samples["odometry"];
  EXPECT_NE(view.samples["tf"].find(" base_link"), std::string::npos) << view.samples["tf"];
  EXPECT_NE(view.samples["tf_static"].find(" camera_optical"), std::string::npos);
  EXPECT_NE(view.samples["map_cloud"].find(" 24 x y z rgb variance class"), std::string::npos)
      << view.samples["map_cloud"];
  EXPECT_NE(view.samples["costmap"].find(" 40 40 0.2"), std::string::npos)
      << view.samples["costmap"];
  // map_blocks' writer is keyed: an rmw reader never matches it (documented in docs/dds.md).
  EXPECT_EQ(view.matched["map_blocks"], "0");
  EXPECT_EQ(view.samples.count("map_blocks"), 0u);
  EXPECT_EQ(view.matched["map_cloud"], "1");
}

}  // namespace
}  // namespace semap::dds_idl::testing
