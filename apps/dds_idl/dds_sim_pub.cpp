// semap-dds-sim-pub: a stand-in robot for demos and manual checks. Publishes odometry along a
// circle and a growing synthetic semantic map, so listeners, RViz or ros2 topic echo have
// something to show before the real pipeline runs.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <thread>

#include "dds_app.hpp"
#include "semap/common/logging.hpp"
#include "semap/dds_idl/converters.hpp"
#include "semap/dds_idl/map_publisher.hpp"
#include "semap/dds_idl/topic_names.hpp"

namespace sd = semap::dds_idl;

namespace {

// Dirichlet prior the synthetic evidence assumes (semap-fusion's default `prior`).
constexpr float kPrior = 0.001f;

// A floor of class 1 under the robot's path, with walls of class 2 at its edge, the rest free
// (class 0). Each version adds one observation of every cell's class to its evidence (alpha
// minus the prior, as the mapping stage publishes it), so fusion has evidence to merge.
sd::BlockSnapshot synthetic_block(semap::common::BlockIndex index, const sd::MapDescription& d,
                                  std::uint32_t version) {
  sd::BlockSnapshot b =
      sd::BlockSnapshot::empty(index, d.resolution, d.block_cells, d.num_classes, true);
  b.version = version;
  const auto k = static_cast<std::size_t>(d.num_classes);
  const auto observations = static_cast<float>(version);
  for (std::size_t i = 0; i < b.cell_count(); ++i) {
    const Eigen::Vector3f c = b.cell_center(i);
    const float r = c.head<2>().norm();
    std::uint16_t cls = 0;
    if (c.z() < d.resolution) {
      cls = 1;
    } else if (std::fabs(r - 10.0f) < d.resolution && c.z() < 2.0f) {
      cls = static_cast<std::uint16_t>(std::min<int>(2, d.num_classes - 1));
    }
    b.state[i] = cls == 0 ? semap::common::CellState::kFree : semap::common::CellState::kOccupied;
    b.argmax_class[i] = cls;
    b.evidence[i * k + cls] = observations;
    // Dirichlet variance of the argmax class' probability.
    const float a = kPrior + observations;
    const float sum = static_cast<float>(k) * kPrior + observations;
    b.variance[i] = a * (sum - a) / (sum * sum * (sum + 1.0f));
  }
  return b;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("Publishes synthetic odometry and a synthetic semantic map over DDS");
  semap::apps::DdsOptions dds;
  dds.add_flags(app);
  double seconds = 0.0;
  double hz = 10.0;
  sd::MapPublisherConfig map_cfg;
  sd::MapDescription desc;
  desc.num_classes = 4;
  desc.class_names = {"free", "ground", "wall", "vegetation"};
  desc.class_colors = {0x000000, 0x808080, 0xff0000, 0x00ff00};
  app.add_option("--seconds", seconds, "stop after this long (0: until Ctrl-C)");
  app.add_option("--hz", hz, "odometry rate")->check(CLI::Range(0.1, 1000.0));
  app.add_option("--map-hz", map_cfg.blocks_hz, "changed-block publication rate");
  app.add_option("--cloud-hz", map_cfg.cloud_hz, "map_cloud rate");
  CLI11_PARSE(app, argc, argv);
  semap::common::setup_logging();

  try {
    semap::apps::install_stop_handlers();
    const sd::Participant participant = dds.participant();
    map_cfg.ns = dds.settings().ns;
    sd::SnapshotStore blocks;
    sd::MapPublisher map(participant, map_cfg, desc, blocks);
    sd::Topic<sd::msg::Odometry> topic(
        participant, sd::topic_name(dds.settings().ns, sd::SemapTopic::kOdometry));
    sd::Writer<sd::msg::Odometry> odom(participant, topic,
                                       sd::topic_qos(sd::SemapTopic::kOdometry));
    const std::string frame = "map";
    const std::string child = "base_link";
    std::unordered_map<semap::common::BlockIndex, std::uint32_t, semap::common::BlockIndexHash>
        versions;
    const auto start = std::chrono::steady_clock::now();
    std::cout << "publishing on " << sd::topic_name(dds.settings().ns, sd::SemapTopic::kOdometry)
              << " and " << sd::topic_name(dds.settings().ns, sd::SemapTopic::kMapBlocks)
              << std::endl;
    while (!semap::apps::stop_requested()) {
      const double t =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (seconds > 0 && t > seconds) break;
      sd::PoseEstimate pose;
      pose.stamp = semap::common::Stamp::now();
      const double angle = 0.1 * t;
      pose.position = {8.0 * std::cos(angle), 8.0 * std::sin(angle), 0.0};
      pose.orientation = Eigen::AngleAxisd(angle + M_PI / 2, Eigen::Vector3d::UnitZ());
      pose.velocity_body = {0.8, 0.0, 0.0};
      sd::msg::Odometry m;
      sd::to_msg(pose, frame, child, m);
      odom.write(m);
      // The robot "observes" the block under it and its neighbours.
      const semap::common::BlockIndex here =
          semap::common::MapGrid(desc.resolution, desc.block_cells)
              .block_of(Eigen::Vector3f(pose.position.cast<float>()));
      for (int dx = -1; dx <= 1; ++dx) {
        for (int dy = -1; dy <= 1; ++dy) {
          const semap::common::BlockIndex b{here.x + dx, here.y + dy, 0};
          map.changed(blocks.put(synthetic_block(b, desc, ++versions[b])));
        }
      }
      map.spin_once(pose.stamp);
      std::this_thread::sleep_for(std::chrono::duration<double>(1.0 / hz));
    }
    std::cout << "blocks " << map.num_blocks() << " written " << map.counters().blocks_written
              << std::endl;
  } catch (const std::exception& e) {
    std::cerr << "semap-dds-sim-pub: " << e.what() << std::endl;
    return 1;
  }
  return 0;
}
