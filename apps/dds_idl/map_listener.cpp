// semap-map-listener: follows one robot's map (and pose) over DDS, prints what arrives and can
// save the received map.
#include <chrono>
#include <cinttypes>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <thread>

#include "dds_app.hpp"
#include "semap/common/logging.hpp"
#include "semap/dds_idl/converters.hpp"
#include "semap/dds_idl/health.hpp"
#include "semap/dds_idl/map_client.hpp"
#include "semap/dds_idl/topic_names.hpp"

namespace sd = semap::dds_idl;

namespace {

// One line per Health sample, "health: <stage> rate .. | driver <name> frames .. | writer <name>
// writes .. failures .. failing 0|1 error '..' | viewer <address> bytes .. messages .. dropped ..
// connected_s ..", for people and for the end-to-end tests to parse.
void print_health(const sd::HealthReport& h) {
  std::cout << "health:";
  for (const auto& s : h.stages) {
    std::cout << " stage " << s.name << " rate " << s.rate_hz << " depth " << s.queue_depth
              << " drops " << s.drops << " p50 " << s.latency_p50_ms << " p99 " << s.latency_p99_ms
              << " |";
  }
  for (const auto& d : h.drivers) {
    std::cout << " driver " << d.name << " frames " << d.frames << " bad " << d.bad_frames
              << " dropped " << d.dropped << " reconnects " << d.reconnects << " bus_off "
              << d.bus_off << " error_passive " << d.error_passive << " bus_restarts "
              << d.bus_restarts << " wakeup_p99 " << d.wakeup_p99_ms << " wakeup_max "
              << d.wakeup_max_ms << " longest_gap_s " << d.longest_gap_s << " |";
  }
  for (const auto& w : h.writers) {
    std::cout << " writer " << w.name << " writes " << w.writes << " failures " << w.failures
              << " failing " << (w.failing ? 1 : 0) << " error '" << w.last_error << "' |";
  }
  for (const auto& v : h.viewers) {
    std::cout << " viewer " << v.address << " bytes " << v.bytes_sent << " messages "
              << v.messages_sent << " dropped " << v.messages_dropped << " connected_s "
              << v.connected_s << " |";
  }
  std::cout << std::endl;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("Prints the semantic map and pose a robot publishes over DDS");
  semap::apps::DdsOptions dds;
  dds.add_flags(app);
  std::string config_path;
  std::string save_path;
  std::string odometry_path;
  double seconds = 0.0;
  std::size_t expect_blocks = 0;
  int num_classes = 0;
  bool health = false;
  bool take_on_receive = false;
  app.add_option("--config", config_path, "semap YAML; its dds: section is used")
      ->check(CLI::ExistingFile);
  app.add_option("--save", save_path, "write the received map as PCD (x y z class variance)");
  app.add_option("--odometry", odometry_path,
                 "write every odometry sample received as CSV: stamp_s,x,y,z,ros_stamp_s (the "
                 "header's stamp on this machine's CLOCK_MONOTONIC, then as sent, in ROS time)");
  app.add_option("--seconds", seconds, "stop after this long (0: until Ctrl-C)");
  app.add_option("--expect-blocks", expect_blocks, "stop once this many blocks arrived");
  app.add_option("--classes", num_classes, "reject blocks with another class count");
  app.add_flag("--health", health, "also print the robot's health reports");
  app.add_flag("--take-on-receive", take_on_receive,
               "take blocks on Cyclone's receive thread instead of this one");
  CLI11_PARSE(app, argc, argv);
  semap::common::setup_logging();

  try {
    if (!config_path.empty()) {
      const auto root = semap::common::ConfigSection::load_file(config_path);
      dds.read(root.section("dds"), app);
    }
    semap::apps::install_stop_handlers();
    const sd::Participant participant = dds.participant();
    sd::MapClientConfig cfg;
    cfg.ns = dds.settings().ns;
    cfg.limits.num_classes = static_cast<std::uint16_t>(num_classes);
    cfg.take_on_receive = take_on_receive;
    sd::MapClient client(participant, cfg);
    sd::Topic<sd::msg::Odometry> odom_topic(
        participant, sd::topic_name(dds.settings().ns, sd::SemapTopic::kOdometry));
    sd::Reader<sd::msg::Odometry> odom(participant, odom_topic,
                                       sd::topic_qos(sd::SemapTopic::kOdometry));

    std::optional<sd::Topic<sd::msg::Health>> health_topic;
    std::optional<sd::Reader<sd::msg::Health>> health_reader;
    if (health) {
      health_topic.emplace(participant, sd::topic_name(dds.settings().ns, sd::SemapTopic::kHealth));
      health_reader.emplace(participant, *health_topic, sd::topic_qos(sd::SemapTopic::kHealth));
    }

    std::cout << "listening on " << sd::topic_name(dds.settings().ns, sd::SemapTopic::kMapBlocks)
              << " (domain " << dds.settings().domain << ")" << std::endl;
    const auto start = std::chrono::steady_clock::now();
    auto next_report = start;
    std::uint64_t info_seen = 0;
    std::optional<sd::PoseEstimate> last_pose;
    std::ofstream odometry_csv;
    if (!odometry_path.empty()) {
      odometry_csv.open(odometry_path);
      if (!odometry_csv)
        throw std::runtime_error("--odometry " + odometry_path + ": cannot create");
      odometry_csv << "stamp_s,x,y,z,ros_stamp_s\n";
    }
    while (!semap::apps::stop_requested()) {
      client.wait_for_blocks(SIZE_MAX, std::chrono::milliseconds(100));
      odom.take_each([&](const sd::msg::Odometry& m, const dds_sample_info_t&) {
        last_pose = sd::from_msg(m);
        if (odometry_csv.is_open()) {
          const std::int64_t ns = last_pose->stamp.ns;
          const Eigen::Vector3d& p = last_pose->position;
          const auto& ros = m.header_.stamp_;
          char line[160];
          std::snprintf(line, sizeof line,
                        "%" PRId64 ".%09" PRId64 ",%.6f,%.6f,%.6f,%" PRId32 ".%09" PRIu32 "\n",
                        ns / 1'000'000'000, ns % 1'000'000'000, p.x(), p.y(), p.z(), ros.sec_,
                        ros.nanosec_);
          odometry_csv << line << std::flush;
        }
      });
      if (health_reader) {
        health_reader->take_each([](const sd::msg::Health& m, const dds_sample_info_t&) {
          print_health(sd::from_msg(m));
        });
      }
      const auto now = std::chrono::steady_clock::now();
      const std::optional<sd::MapDescription> info = client.info();
      if (client.counters().infos != info_seen && info) {
        info_seen = client.counters().infos;
        const sd::MapDescription& i = *info;
        std::cout << "map_info: resolution " << i.resolution << " m, " << i.block_cells
                  << "^3 cells/block, " << i.num_classes << " classes, " << i.num_blocks
                  << " blocks, sequence " << i.sequence << std::endl;
      }
      if (now >= next_report) {
        const sd::MapClientCounters c = client.counters();
        std::cout << "blocks " << client.block_count() << " accepted " << c.accepted << " rejected "
                  << c.rejected_total() << " stale " << c.stale;
        if (last_pose) {
          std::cout << " pose " << last_pose->position.transpose();
        }
        std::cout << std::endl;
        if (c.rejected_total() > 0)
          std::cout << "  last error: " << client.last_error() << std::endl;
        next_report = now + std::chrono::seconds(1);
      }
      if (expect_blocks > 0 && client.block_count() >= expect_blocks) break;
      if (seconds > 0 && now - start > std::chrono::duration<double>(seconds)) break;
    }
    std::cout << "final: blocks " << client.block_count() << " accepted "
              << client.counters().accepted << " rejected " << client.counters().rejected_total()
              << std::endl;
    if (!save_path.empty()) {
      client.save_pcd(save_path);
      std::cout << "saved " << save_path << std::endl;
    }
  } catch (const std::exception& e) {
    std::cerr << "semap-map-listener: " << e.what() << std::endl;
    return 1;
  }
  return 0;
}
