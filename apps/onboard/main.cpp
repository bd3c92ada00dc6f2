// semap-onboard: the robot's main job. Drivers -> rings -> estimation stage (InEKF) and
// perception stage (segmentation, labelled points posed at their stamps) -> mapping stage
// (S-BKI) -> DDS. With rig.kind: sim it runs on the built-in
// simulated sensor rig and reports its own accuracy against the simulated truth (--report DIR:
// images, the map and summary.json, see SimReport). --record DIR saves the raw sensor streams
// (StreamRecorder); rig.kind: replay (or --replay DIR) plays them back (ReplayRig).
#include <sys/resource.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <stdexcept>

#include "dds_outputs.hpp"
#include "estimation_stage.hpp"
#include "health_monitor.hpp"
#include "mapping_stage.hpp"
#include "onboard_config.hpp"
#include "perception_stage.hpp"
#include "replay_rig.hpp"
#include "run_figures.hpp"
#include "run_summary.hpp"
#include "segmenter_factory.hpp"
#include "semap/common/config.hpp"
#include "semap/common/logging.hpp"
#include "semap/drivers/camera_driver.hpp"
#include "semap/drivers/can_imu_driver.hpp"
#include "semap/drivers/gnss_driver.hpp"
#include "semap/mapping/smap_io.hpp"
#include "service_notifier.hpp"
#include "shared_pose_history.hpp"
#include "sim_report.hpp"
#include "sim_rig.hpp"
#include "stream_recorder.hpp"

namespace {

// The sensors' frames on the robot, for tf_static: the camera's optical frame (z forward, x
// right) and the GNSS antenna.
std::vector<semap::onboard::SensorFrame> sensor_frames(const semap::onboard::OnboardConfig& c) {
  Eigen::Isometry3d antenna = Eigen::Isometry3d::Identity();
  antenna.translation() = c.estimator.lever_arm;
  return {{"camera_optical", c.camera.body_from_optical().cast<double>()}, {"gnss", antenna}};
}

std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop.store(true); }

using semap::common::OverflowPolicy;
using semap::common::SpscRing;
using semap::onboard::drops;
using semap::onboard::LiveAccuracy;
using semap::onboard::Progress;
using semap::onboard::Rings;
using semap::onboard::stage_figures;

// What the command line adds to the configuration.
struct RunOptions {
  std::filesystem::path config_path;
  std::string report_dir;
  std::string record_dir;
  std::string trajectory;
};

int run(const semap::onboard::OnboardConfig& config, const RunOptions& options) {
  using namespace semap;
  const std::string& report_dir = options.report_dir;
  auto log = common::logger("onboard");
  SpscRing<common::ImuSample> imu_ring(config.imu.ring, OverflowPolicy::kDropOldest);
  SpscRing<common::GnssFix> gnss_ring(config.gnss.ring, OverflowPolicy::kDropOldest);
  SpscRing<common::ImageFrame> colour_ring(config.camera.ring, OverflowPolicy::kDropOldest);
  SpscRing<common::ImageFrame> depth_ring(config.depth.ring, OverflowPolicy::kDropOldest);
  SpscRing<common::LabeledCloud> cloud_ring(config.depth.ring, OverflowPolicy::kDropOldest);
  onboard::SharedPoseHistory poses(config.estimator.history);

  std::unique_ptr<onboard::SimRig> rig;
  std::unique_ptr<onboard::ReplayRig> replay;
  if (config.rig.kind == onboard::RigKind::kSim) {
    rig = std::make_unique<onboard::SimRig>(config, imu_ring, colour_ring, depth_ring);
  } else if (config.rig.kind == onboard::RigKind::kReplay) {
    replay =
        std::make_unique<onboard::ReplayRig>(config, imu_ring, gnss_ring, colour_ring, depth_ring);
  }
  std::unique_ptr<onboard::StreamRecorder> recorder;
  if (!options.record_dir.empty()) {
    recorder = std::make_unique<onboard::StreamRecorder>(options.record_dir, options.config_path,
                                                         config.imu.interface);
  }
  std::unique_ptr<onboard::SimReport> report;
  if (!report_dir.empty()) report = std::make_unique<onboard::SimReport>(*rig, report_dir);

  std::unique_ptr<drivers::GnssDriver> gnss_driver;
  auto gnss_config = config.gnss.driver;
  if (rig && !rig->gnss_device().empty()) gnss_config.serial.device = rig->gnss_device();
  // A replay feeds its pty (recorded pace) or the GNSS ring itself: never the robot's port.
  if (replay) gnss_config.serial.device = replay->gnss_device();
  if (!gnss_config.serial.device.empty() && gnss_config.serial.device != "pty") {
    gnss_driver = std::make_unique<drivers::GnssDriver>(gnss_config, gnss_ring);
    if (recorder) {
      gnss_driver->set_byte_tap([&](common::Stamp stamp, std::span<const std::uint8_t> bytes) {
        recorder->gnss_bytes(stamp, bytes);
      });
    }
  }
  std::unique_ptr<drivers::CanImuDriver> imu_driver;
  if (!config.imu.interface.empty() && !replay) {
    imu_driver = std::make_unique<drivers::CanImuDriver>(config.imu.driver, imu_ring);
    if (recorder) {
      imu_driver->set_frame_tap([&](const drivers::CanRxFrame& rx, drivers::CanRead read) {
        recorder->can_frame(rx.stamp, rx.frame, read == drivers::CanRead::kError);
      });
    }
  } else if (rig && recorder) {
    rig->set_can_tap([&](common::Stamp stamp, const SemapCanFrame& frame) {
      recorder->can_frame(stamp, frame, false);
    });
  }

  // On hardware the camera is optional (an empty camera.device): without it the robot still
  // estimates and publishes its pose, and its map stays empty. The configuration has read the
  // model card, palette and calibration; a network OpenCV then fails to load leaves the robot in
  // the same state, with the error logged: localisation must not depend on the camera half.
  const bool camera = rig || (replay ? replay->has_camera() : !config.camera.driver.device.empty());
  std::unique_ptr<onboard::PerceptionStage> perception_stage;
  if (camera) {
    try {
      perception_stage = std::make_unique<onboard::PerceptionStage>(
          config.camera, config.depth,
          onboard::make_segmenter(config.segmenter, config.map.params.num_classes), colour_ring,
          config.depth.source == onboard::DepthSource::kAligned ? &depth_ring : nullptr, poses,
          cloud_ring);
      log->info("perception: {}", perception_stage->describe());
    } catch (const std::exception& e) {
      log->error("perception disabled, running without a map: {}", e.what());
    }
  }
  std::unique_ptr<drivers::CameraDriver> camera_driver;
  std::unique_ptr<drivers::CameraDriver> depth_driver;
  // The simulated rig fills the rings itself, unless it shows its colour frames on a V4L2
  // output (rig.camera_output): the camera driver captures them back.
  if (perception_stage && recorder) {
    perception_stage->set_frame_tap([&](const common::ImageFrame& frame, bool depth) {
      depth ? recorder->depth_frame(frame) : recorder->colour_frame(frame);
    });
  }
  if (perception_stage && !replay && (!rig || !config.rig.camera_output.empty())) {
    camera_driver = std::make_unique<drivers::CameraDriver>(config.camera.driver, colour_ring);
    if (!rig && config.depth.source == onboard::DepthSource::kAligned) {
      depth_driver = std::make_unique<drivers::CameraDriver>(config.depth.driver, depth_ring);
    }
  }

  std::unique_ptr<onboard::DdsOutputs> dds;

  std::filesystem::path checkpoint_path = config.map.checkpoint_path;
  if (checkpoint_path.empty() && !config.map.save_path.empty()) {
    checkpoint_path = config.map.save_path + ".log";
  }
  if (checkpoint_path.empty() && report) checkpoint_path = report->dir() / "map.log";
  onboard::MappingStage mapping_stage(
      config.map, cloud_ring,
      config.dds.enabled
          ? onboard::MappingStage::BlockSink([&](const std::vector<common::BlockIndex>& changed) {
              dds->blocks_changed(changed);
            })
          : nullptr,
      checkpoint_path);
  // The publisher reads the map through the mapping stage's view (it is set before the
  // mapping thread starts).
  if (config.dds.enabled)
    dds = std::make_unique<onboard::DdsOutputs>(config.dds, onboard::describe_map(config.map),
                                                mapping_stage.blocks(), sensor_frames(config),
                                                config.costmap, &mapping_stage.costmaps());
  // A resumed map lives in the frame it was built in: the estimator anchors there too.
  onboard::EstimationStageConfig estimation_config{
      config.estimator, config.map.start_heading_sigma_deg, config.dds.odometry_hz,
      options.trajectory, replay ? replay->offset_ns() : 0};
  if (const auto frame = mapping_stage.map_frame()) {
    const estimation::Geodetic anchor{(*frame)[0], (*frame)[1], (*frame)[2]};
    const auto& given = config.estimator.anchor;
    if (given && (std::abs(given->latitude_deg - anchor.latitude_deg) > 1e-7 ||
                  std::abs(given->longitude_deg - anchor.longitude_deg) > 1e-7 ||
                  std::abs(given->altitude_m - anchor.altitude_m) > 0.01)) {
      throw std::runtime_error("map.resume: the checkpoint's map is anchored at " +
                               std::to_string(anchor.latitude_deg) + ", " +
                               std::to_string(anchor.longitude_deg) + ", " +
                               std::to_string(anchor.altitude_m) + " but estimator.anchor differs");
    }
    estimation_config.estimator.anchor = anchor;
    log->info("map frame anchored at {:.8f}, {:.8f}, {:.2f} (from the checkpoint)",
              anchor.latitude_deg, anchor.longitude_deg, anchor.altitude_m);
  }
  onboard::EstimationStage estimation_stage(
      estimation_config, imu_ring, gnss_ring, poses,
      dds ? onboard::EstimationStage::PoseSink(
                [&](const onboard::PoseOutput& p) { dds->publish_pose(p); })
          : nullptr);

  if (gnss_driver) gnss_driver->start();
  if (imu_driver) imu_driver->start();
  if (camera_driver) camera_driver->start();
  if (depth_driver) depth_driver->start();
  estimation_stage.start();
  if (perception_stage && report) {
    perception_stage->set_observer([&](std::uint32_t sequence, common::Stamp, const cv::Mat& bgr,
                                       const perception::Segmentation& segmentation) {
      report->observe(sequence, bgr, segmentation);
    });
  }
  if (perception_stage) perception_stage->start();
  mapping_stage.start();
  if (dds) dds->start();
  if (replay) {
    replay->set_settled([&](const onboard::ReplayCounters& handed) {
      const auto e = estimation_stage.stats();
      if (e.imu_samples < handed.imu_samples || e.gnss_fixes < handed.gnss_fixes) return false;
      if (!perception_stage) return true;
      const auto p = perception_stage->stats();
      const auto done = p.clouds + p.skipped + p.unpaired + p.bad_frames + p.without_pose;
      return p.frames == handed.colour_frames && done == p.frames &&
             mapping_stage.stats().scans + drops(cloud_ring) == p.clouds;
    });
  }
  if (rig) rig->start();
  if (replay) replay->start();
  log->info("running{}{}", rig ? " on the simulated rig (GNSS via " + rig->gnss_device() + ")" : "",
            replay ? " on a replay of " + config.rig.replay.string() : "");

  const onboard::ServiceNotifier service;
  service.ready();
  if (service.watchdog_enabled()) log->info("systemd watchdog: pinging every second");
  LiveAccuracy accuracy;
  const auto started = common::Stamp::now();
  auto next_report = started + 5.0;
  const Rings rings{imu_ring, gnss_ring, colour_ring, depth_ring, cloud_ring};
  onboard::HealthMonitor health;
  Progress progress;
  auto next_health = started;
  bool frame_recorded = false;
  while (!g_stop.load()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    const auto est = estimation_stage.stats();
    if (est.anchor && !frame_recorded) {
      mapping_stage.record_map_frame(
          {est.anchor->latitude_deg, est.anchor->longitude_deg, est.anchor->altitude_m});
      frame_recorded = true;
    }
    if (rig) accuracy.sample(*rig, est);
    if (report) report->sample_pose(est);
    const auto now = common::Stamp::now();
    // Once a second: the systemd watchdog (this loop is alive) and the health report.
    const bool health_due = now >= next_health;
    if (health_due) {
      next_health = now + 1.0;
      service.watchdog();
    }
    if (dds && health_due) {
      std::vector<dds_idl::DriverCountersData> driver_counters;
      if (gnss_driver)
        driver_counters.push_back(onboard::driver_health("gnss", gnss_driver->stats()));
      if (imu_driver) driver_counters.push_back(onboard::driver_health("imu", imu_driver->stats()));
      if (camera_driver) {
        driver_counters.push_back(onboard::driver_health("camera", camera_driver->stats()));
      }
      if (depth_driver) {
        driver_counters.push_back(onboard::driver_health("depth", depth_driver->stats()));
      }
      dds->publish_health(health.report(
          now, stage_figures(rings, estimation_stage, perception_stage.get(), mapping_stage, *dds),
          driver_counters));
    }
    if (now >= next_report) {
      next_report = now + 5.0;
      log->info("{}", progress.line(common::seconds_between(now, started), est,
                                    perception_stage ? perception_stage->stats()
                                                     : onboard::PerceptionStageStats{},
                                    mapping_stage.stats(), rings));
    }
    if ((rig && rig->finished()) || (replay && replay->finished())) {
      std::this_thread::sleep_for(std::chrono::milliseconds(500));  // let the stages drain
      break;
    }
    if (!rig && !replay && config.rig.duration_s > 0 &&
        common::seconds_between(now, started) > config.rig.duration_s) {
      break;
    }
  }

  service.stopping();
  if (rig) rig->stop();
  if (replay) replay->stop();
  if (imu_driver) imu_driver->stop();
  if (gnss_driver) gnss_driver->stop();
  if (camera_driver) camera_driver->stop();
  if (depth_driver) depth_driver->stop();
  if (recorder) recorder->flush();
  estimation_stage.stop();
  if (perception_stage) perception_stage->stop();
  mapping_stage.stop();
  if (dds) dds->stop();  // the map's last changes go out

  const auto est = estimation_stage.stats();
  const auto map = mapping_stage.stats();
  if (!config.map.save_path.empty()) {
    mapping::write_smap(config.map.save_path, mapping_stage.map().layers());
    log->info("map saved to {}", config.map.save_path);
  }
  if (report) {
    const auto path = report->dir() / "map.smap";
    mapping::write_smap(path, mapping_stage.map().layers());
    log->info("map saved to {}", path.string());
  }
  onboard::print_summary({.gnss_driver = gnss_driver.get(),
                          .imu_driver = imu_driver.get(),
                          .camera_driver = camera_driver.get(),
                          .estimation = est,
                          .accuracy = &accuracy,
                          .perception = perception_stage.get(),
                          .map = map,
                          .checkpoint_path = checkpoint_path,
                          .memory_radius_m = config.map.memory_radius_m,
                          .dds = dds.get(),
                          .recorder = recorder.get(),
                          .replay = replay.get(),
                          .rings = rings});
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  const double cpu_s = static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
                       1e-6 * static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
  const double wall_s = common::seconds_between(common::Stamp::now(), started);
  std::printf("cpu              : %.2f cores over %.1f s\n", cpu_s / wall_s, wall_s);
  if (report) {
    onboard::RunFigures figures;
    figures.segmenter =
        config.segmenter.kind == onboard::SegmenterConfig::Kind::kOnnx ? "onnx" : "palette";
    if (accuracy.any()) figures.pose_rmse_m = accuracy.rmse();
    figures.frames_captured = rig->camera().rendered();
    figures.frames_mapped = map.scans;
    figures.latency_frame_to_map = mapping_stage.latency().percentiles();
    figures.ring_drops = {{"imu", drops(imu_ring)},
                          {"gnss", drops(gnss_ring)},
                          {"colour", drops(colour_ring)},
                          {"depth", drops(depth_ring)},
                          {"clouds", drops(cloud_ring)}};
    figures.cpu_cores_used = cpu_s / wall_s;
    const auto summary = report->write(figures, mapping_stage.map(), est);
    std::printf("report           : %s\n", summary.c_str());
  }
  // Stopped by a signal (systemctl stop, Ctrl-C), the run ended as asked: the map is saved, and
  // a service stopped before its filter initialised or its camera mapped has not failed. A run
  // that ended by itself fails when the filter never initialised, or when it had a camera and
  // mapped nothing.
  if (g_stop.load()) return 0;
  const bool mapped = !camera || map.scans > 0;
  return est.initialised && mapped ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"semap-onboard: drivers, InEKF, S-BKI semantic map and DDS on one robot"};
  std::string config_path;
  std::optional<double> duration;
  RunOptions options;
  std::string replay_dir, pace, save_path;
  app.add_option("--config", config_path,
                 "YAML configuration (see config/sim.yaml); with --replay, the recording's")
      ->check(CLI::ExistingFile);
  app.add_option("--record", options.record_dir,
                 "save the raw sensor streams into this new directory (docs/record-replay.md)");
  app.add_option("--replay", replay_dir,
                 "play back a recording made with --record (rig.kind: replay, rig.replay: DIR)")
      ->check(CLI::ExistingDirectory)
      ->excludes("--record");
  app.add_option("--pace", pace, "replay pace, overrides rig.pace: recorded | fast")
      ->check(CLI::IsMember({"recorded", "fast"}));
  app.add_option("--trajectory", options.trajectory,
                 "write the filter's pose after every IMU sample to this CSV file");
  app.add_option("--save", save_path, "save the map to this .smap file at exit (map.save_path)");
  std::optional<int> domain;
  std::string report_dir;
  app.add_option("--duration", duration, "seconds to run; overrides rig.duration_s (0: Ctrl-C)");
  app.add_option("--domain", domain, "DDS domain id; overrides dds.domain")
      ->check(CLI::Range(0, 232));
  bool resume = false;
  app.add_flag("--resume", resume,
               "continue the map in the checkpoint log (map.resume) instead of starting anew");
  app.add_option("--report", report_dir,
                 "simulated rig only: write camera.png, trajectory.png, map.smap and "
                 "summary.json into this directory");
  CLI11_PARSE(app, argc, argv);
  if (config_path.empty() && replay_dir.empty()) {
    std::cerr << "semap-onboard: --config is required (or --replay DIR)\n";
    return 2;
  }
  if (config_path.empty()) config_path = replay_dir + "/config.yaml";
  options.config_path = config_path;
  options.report_dir = report_dir;

  semap::onboard::OnboardConfig config;
  try {
    config = semap::onboard::load_onboard_config(config_path);
  } catch (const std::exception& e) {
    std::cerr << "semap-onboard: " << e.what() << "\n";
    return 2;
  }
  if (!replay_dir.empty()) {
    config.rig.kind = semap::onboard::RigKind::kReplay;
    config.rig.replay = replay_dir;
  }
  if (!pace.empty()) {
    config.rig.pace =
        pace == "fast" ? semap::onboard::ReplayPace::kFast : semap::onboard::ReplayPace::kRecorded;
  }
  if (!save_path.empty()) config.map.save_path = save_path;
  // What the configuration names on this machine, checked before anything starts: a map that
  // cannot be saved at exit would be lost.
  if (config.dds.enabled && !config.dds.cyclone_config.empty() &&
      !std::filesystem::is_regular_file(config.dds.cyclone_config)) {
    std::cerr << "semap-onboard: " << config_path
              << ": dds.config: " << config.dds.cyclone_config.string() << ": no such file\n";
    return 2;
  }
  if (const auto dir = std::filesystem::path(config.map.save_path).parent_path(); !dir.empty()) {
    std::error_code error;
    std::filesystem::create_directories(dir, error);
    if (error) {
      std::cerr << "semap-onboard: map.save_path: cannot create " << dir.string() << ": "
                << error.message() << "\n";
      return 2;
    }
  }
  if (!options.record_dir.empty() && config.rig.kind == semap::onboard::RigKind::kReplay) {
    std::cerr << "semap-onboard: --record cannot record a replay\n";
    return 2;
  }
  if (!report_dir.empty() && config.rig.kind != semap::onboard::RigKind::kSim) {
    std::cerr << "semap-onboard: --report needs the simulated rig (rig.kind: sim)\n";
    return 2;
  }
  if (duration) config.rig.duration_s = *duration;
  if (domain) config.dds.domain = *domain;
  if (resume) config.map.resume = true;
  semap::common::setup_logging(config.log_level);
  if (config.dds.enabled && !config.dds.cyclone_config.empty() && !std::getenv("CYCLONEDDS_URI")) {
    setenv("CYCLONEDDS_URI", ("file://" + config.dds.cyclone_config.string()).c_str(), 1);
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  try {
    return run(config, options);
  } catch (const std::exception& e) {
    std::cerr << "semap-onboard: " << e.what() << "\n";
    return 1;
  }
}
