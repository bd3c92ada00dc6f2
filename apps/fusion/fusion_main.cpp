// semap-fusion: follows several robots' maps over DDS and publishes their fusion, merged with
// the mapping library's per-robot layers (see semap/fusion/map_fusion.hpp).
#include <chrono>
#include <iostream>
#include <thread>

#include "dds_app.hpp"
#include "semap/common/logging.hpp"
#include "semap/fusion/map_fusion.hpp"

namespace sf = semap::fusion;

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
    const sf::MapFusionConfig cfg = sf::read_fusion_config(root.section("fusion"));
    root.finish();

    semap::apps::install_stop_handlers();
    const semap::dds_idl::Participant participant = dds.participant();
    sf::MapFusion fusion(participant, cfg);
    std::cout << "fusing " << cfg.robots.size() << " robots into namespace '" << cfg.output.ns
              << "'" << std::endl;
    const auto start = std::chrono::steady_clock::now();
    auto next_report = start;
    while (!semap::apps::stop_requested()) {
      fusion.spin_once(semap::common::Stamp::now());
      const auto now = std::chrono::steady_clock::now();
      if (now >= next_report) {
        const auto& c = fusion.counters();
        std::cout << "fused blocks " << fusion.publisher().num_blocks() << " written "
                  << fusion.publisher().counters().blocks_written << " merge max "
                  << c.merge_seconds_max * 1e3 << " ms";
        for (std::size_t i = 0; i < fusion.num_robots(); ++i) {
          std::cout << " | " << cfg.robots[i].ns << ": " << fusion.robot(i).blocks().size()
                    << " blocks, " << fusion.robot(i).counters().rejected_total() << " rejected, "
                    << fusion.robot_counters(i).blocks_without_evidence << " without evidence";
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
