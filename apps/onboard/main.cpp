// semap-onboard: the robot's main job. Reads the configuration, chooses the sensor rig (the
// robot's devices, a recording, or the built-in simulated rig), runs the pipeline
// (onboard::Pipeline) until it is stopped or the rig has played all it had, saves the map and
// prints the summary. --record FILE.mcap saves the raw sensor streams and the outputs; --report DIR
// (simulated rig) writes images, the map and summary.json scored against the simulated truth.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <vector>

#include "semap/common/logging.hpp"
#include "semap/onboard/hardware_rig.hpp"
#include "semap/onboard/mcap_recorder.hpp"
#include "semap/onboard/mcap_recording.hpp"
#include "semap/onboard/pipeline.hpp"
#include "semap/onboard/replay_rig.hpp"
#include "semap/onboard/service.hpp"
#include "semap/onboard/viewer.hpp"
#include "semap/sim/report.hpp"
#include "semap/sim/rig.hpp"

namespace {

using namespace semap;

std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop.store(true); }

// What the command line adds to the configuration.
struct RunOptions {
  std::string config_path;
  std::string record_file;
  std::string record_compression = "lz4";
  std::string report_dir;
  std::string trajectory;
};

int run(const onboard::OnboardConfig& config, const sim::SimRigConfig& sim_config,
        const RunOptions& options) {
  sim::SimRig* sim_rig = nullptr;
  onboard::Pipeline pipeline(
      config,
      [&](const onboard::SensorRings& rings) -> std::unique_ptr<onboard::SensorRig> {
        switch (config.rig.kind) {
          case onboard::RigKind::kHardware:
            return std::make_unique<onboard::HardwareRig>(config, rings);
          case onboard::RigKind::kReplay:
            return std::make_unique<onboard::ReplayRig>(config, rings);
          case onboard::RigKind::kSim:
            break;
        }
        auto rig = std::make_unique<sim::SimRig>(config, sim_config, rings);
        sim_rig = rig.get();
        return rig;
      },
      options.trajectory);
  std::unique_ptr<onboard::McapRecorder> recorder;
  if (!options.record_file.empty()) {
    onboard::McapRecorderOptions record;
    record.can_interface = config.imu.interface.empty() ? "sim" : config.imu.interface;
    record.writer.compression =
        options.record_compression == "lz4"    ? drivers::mcap::Compression::kLz4
        : options.record_compression == "none" ? drivers::mcap::Compression::kNone
                                               : drivers::mcap::Compression::kZstd;
    recorder =
        std::make_unique<onboard::McapRecorder>(options.record_file, options.config_path, record);
    recorder->attach(pipeline);
  }
  std::unique_ptr<sim::SimReport> report;
  if (sim_rig) {
    report = std::make_unique<sim::SimReport>(*sim_rig, options.report_dir);
    pipeline.attach(*report);
  }
  // viewer: the Foxglove WebSocket server and the built-in page (docs/viewer.md).
  const std::unique_ptr<onboard::Viewer> viewer = onboard::start_viewer(pipeline, config);
  std::vector<std::filesystem::path> save_paths;
  if (!config.map.save_path.empty()) save_paths.emplace_back(config.map.save_path);
  if (!options.report_dir.empty()) save_paths.push_back(report->dir() / "map.smap");

  onboard::run_service(pipeline, g_stop, save_paths);

  std::printf("\n== semap-onboard summary ==\n");
  for (const auto& line : pipeline.summary()) std::printf("%s\n", line.c_str());
  if (!options.report_dir.empty()) {
    std::printf("report           : %s\n", report->write(pipeline).c_str());
  }
  // A map that could not be saved (disk full) is a failure of its own: exit 3, after the
  // summary; the checkpoint log still holds the map of its last checkpoint.
  if (!pipeline.save_failures().empty()) return 3;
  // Stopped by a signal (systemctl stop, Ctrl-C), the run ended as asked: the map is saved, and
  // a service stopped before its filter initialised or its camera mapped has not failed.
  return g_stop.load() || pipeline.succeeded() ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"semap-onboard: drivers, InEKF, S-BKI semantic map and DDS on one robot"};
  app.footer(
      "Exit status: 0 the run did its job or was stopped by a signal; 1 the filter never "
      "initialised or nothing was mapped; 2 a configuration or start-up error; 3 the map "
      "could not be saved at exit (the checkpoint log keeps it: --resume).");
  RunOptions options;
  std::string replay_dir, pace, save_path;
  std::filesystem::path extracted_config;  // --replay FILE.mcap: its configuration, for loading
  std::optional<double> duration;
  std::optional<int> domain;
  bool resume = false;
  app.add_option("--config", options.config_path,
                 "YAML configuration (see config/sim.yaml); with --replay, the recording's")
      ->check(CLI::ExistingFile);
  app.add_option("--record", options.record_file,
                 "record the raw sensor streams and the outputs into this new MCAP file "
                 "(docs/record-replay.md)");
  app.add_option("--record-compression", options.record_compression,
                 "the recording's chunk compression: lz4 (default) | zstd | none")
      ->check(CLI::IsMember({"zstd", "lz4", "none"}));
  app.add_option("--replay", replay_dir,
                 "play back a recording made with --record (rig.kind: replay, rig.replay: "
                 "FILE.mcap, or the directory of a recording of the older format)")
      ->check(CLI::ExistingPath)
      ->excludes("--record");
  app.add_option("--pace", pace, "replay pace, overrides rig.pace: recorded | fast")
      ->check(CLI::IsMember({"recorded", "fast"}));
  app.add_option("--trajectory", options.trajectory,
                 "write the filter's pose after every IMU sample to this CSV file");
  app.add_option("--save", save_path, "save the map to this .smap file at exit (map.save_path)");
  app.add_option("--duration", duration, "seconds to run; overrides rig.duration_s (0: Ctrl-C)");
  app.add_option("--domain", domain, "DDS domain id; overrides dds.domain")
      ->check(CLI::Range(0, 232));
  app.add_flag("--resume", resume,
               "continue the map in the checkpoint log (map.resume) instead of starting anew");
  app.add_option("--report", options.report_dir,
                 "simulated rig only: write camera.png, trajectory.png, map.smap and "
                 "summary.json into this directory");
  CLI11_PARSE(app, argc, argv);
  if (options.config_path.empty() && replay_dir.empty()) {
    std::cerr << "semap-onboard: --config is required (or --replay DIR)\n";
    return 2;
  }
  if (options.config_path.empty() && std::filesystem::is_directory(replay_dir)) {
    options.config_path = replay_dir + "/config.yaml";
  } else if (options.config_path.empty()) {
    // An MCAP recording holds its configuration: loaded from a copy beside nothing else.
    try {
      const std::string text = onboard::recorded_config(replay_dir);
      extracted_config = std::filesystem::temp_directory_path() /
                         ("semap-replay-" + std::to_string(::getpid()) + ".yaml");
      std::ofstream(extracted_config) << text;
      options.config_path = extracted_config.string();
    } catch (const std::exception& e) {
      std::cerr << "semap-onboard: --replay " << e.what() << "\n";
      return 2;
    }
  }

  onboard::OnboardConfig config;
  sim::SimRigConfig sim_config;
  try {
    config = onboard::load_onboard_config(options.config_path, sim::sim_rig_keys(sim_config));
    if (!replay_dir.empty()) {
      config.rig.kind = onboard::RigKind::kReplay;
      config.rig.replay = replay_dir;
    }
    if (!pace.empty()) {
      config.rig.pace =
          pace == "fast" ? onboard::ReplayPace::kFast : onboard::ReplayPace::kRecorded;
    }
    if (!save_path.empty()) config.map.save_path = save_path;
    if (duration) config.rig.duration_s = *duration;
    if (domain) config.dds.domain = *domain;
    if (resume) config.map.resume = true;
    // The report's map keeps a checkpoint beside it when nothing else names one.
    if (!options.report_dir.empty() && config.map.checkpoint_path.empty() &&
        config.map.save_path.empty()) {
      config.map.checkpoint_path = options.report_dir + "/map.log";
    }
    onboard::check_paths(config, options.config_path);
    if (!options.record_file.empty() && config.rig.kind == onboard::RigKind::kReplay) {
      throw std::invalid_argument("--record cannot record a replay");
    }
    if (!options.report_dir.empty() && config.rig.kind != onboard::RigKind::kSim) {
      throw std::invalid_argument("--report needs the simulated rig (rig.kind: sim)");
    }
  } catch (const std::exception& e) {
    if (!extracted_config.empty()) std::filesystem::remove(extracted_config);
    std::cerr << "semap-onboard: " << e.what() << "\n";
    return 2;
  }
  if (!extracted_config.empty()) std::filesystem::remove(extracted_config);
  common::setup_logging(config.log_level);
  if (config.dds.enabled && !config.dds.cyclone_config.empty() && !std::getenv("CYCLONEDDS_URI")) {
    setenv("CYCLONEDDS_URI", ("file://" + config.dds.cyclone_config.string()).c_str(), 1);
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  // A file reaching the file-size limit (ulimit -f, LimitFSIZE=) would kill the robot with
  // SIGXFSZ; ignored, the write fails with EFBIG instead and the writer handles it as a full
  // disk: counted, reported in health, retried, while the robot drives on
  // (docs/reliability.md).
  std::signal(SIGXFSZ, SIG_IGN);
  try {
    return run(config, sim_config, options);
  } catch (const std::exception& e) {
    std::cerr << "semap-onboard: " << e.what() << "\n";
    return 1;
  }
}
