// semap-fusion: subscribes to several robots' maps and publishes their merge.
#include <chrono>
#include <iostream>
#include <thread>

#include "dds_app.hpp"
#include "semap/common/logging.hpp"
#include "semap/dds_idl/map_fusion.hpp"

namespace sd = semap::dds_idl;

int main(int argc, char** argv) {
  CLI::App app("Merges the semantic maps of several robots and republishes the result");
  semap::apps::DdsOptions dds;
  dds.add_flags(app);
  std::string config_path;
  double seconds = 0.0;
  app.add_option("--config", config_path, "YAML with dds: and fusion: sections")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("--seconds", seconds, "stop after this long (0: until Ctrl-C)");
  CLI11_PARSE(app, argc, argv);
  semap::common::setup_logging();

  try {
    const auto root = semap::common::ConfigSection::load_file(config_path);
    dds.read(root.section("dds"), app);
    const auto f = root.section("fusion");
    sd::MapFusionConfig cfg;
    cfg.robots = f.get<std::vector<std::string>>("robots");
    cfg.output.ns = f.get<std::string>("output", "fused");
    cfg.output.frame_id = f.get<std::string>("frame_id", "map");
    cfg.output.blocks_hz = f.get_in_range("publish_hz", 2.0, 0.01, 100.0);
    cfg.output.cloud_hz = f.get_in_range("cloud_hz", 0.5, 0.0, 100.0);
    cfg.description.resolution = static_cast<float>(f.get_in_range("resolution", 0.1, 1e-3, 10.0));
    cfg.description.block_cells =
        static_cast<std::uint16_t>(f.get_in_range("block_cells", 8, 1, 64));
    cfg.description.num_classes =
        static_cast<std::uint16_t>(f.get_in_range("num_classes", 0, 1, 65535));
    cfg.description.class_names = f.get<std::vector<std::string>>("class_names", {});
    cfg.merge.free_class = static_cast<std::uint16_t>(f.get_in_range("free_class", 0, 0, 65535));
    cfg.merge.prior = static_cast<float>(f.get_in_range("prior", 0.0, 0.0, 1e6));
    f.finish();
    root.finish();

    semap::apps::install_stop_handlers();
    const sd::Participant participant = dds.participant();
    sd::MapFusion fusion(participant, cfg);
    std::cout << "fusing " << cfg.robots.size() << " robots into namespace '" << cfg.output.ns
              << "'" << std::endl;
    const auto start = std::chrono::steady_clock::now();
    auto next_report = start;
    while (!semap::apps::stop_requested()) {
      fusion.spin_once(semap::common::Stamp::now());
      const auto now = std::chrono::steady_clock::now();
      if (now >= next_report) {
        std::cout << "merged blocks " << fusion.publisher().num_blocks() << " written "
                  << fusion.publisher().counters().blocks_written;
        for (std::size_t i = 0; i < fusion.num_robots(); ++i) {
          std::cout << " | " << cfg.robots[i] << ": " << fusion.robot(i).blocks().size()
                    << " blocks, " << fusion.robot(i).counters().rejected_total() << " rejected";
        }
        std::cout << std::endl;
        next_report = now + std::chrono::seconds(1);
      }
      if (seconds > 0 && now - start > std::chrono::duration<double>(seconds)) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  } catch (const std::exception& e) {
    std::cerr << "semap-fusion: " << e.what() << std::endl;
    return 1;
  }
  return 0;
}
