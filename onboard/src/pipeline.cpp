#include "semap/onboard/pipeline.hpp"

#include <malloc.h>
#include <spdlog/fmt/fmt.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "semap/common/logging.hpp"
#include "semap/common/process_usage.hpp"
#include "semap/drivers/realtime.hpp"
#include "semap/mapping/smap_io.hpp"
#include "semap/onboard/run_summary.hpp"
#include "semap/onboard/segmenter_factory.hpp"

namespace semap::onboard {

namespace {

using common::OverflowPolicy;

// The sensors' frames on the robot, for tf_static: the camera's optical frame (z forward, x
// right) and the GNSS antenna.
std::vector<SensorFrame> sensor_frames(const OnboardConfig& c) {
  Eigen::Isometry3d antenna = Eigen::Isometry3d::Identity();
  antenna.translation() = c.estimator.lever_arm;
  return {{"camera_optical", c.camera.body_from_optical().cast<double>()}, {"gnss", antenna}};
}

// A resumed map lives in the frame it was built in: the estimator anchors there too, and a
// configured anchor elsewhere is an error.
estimation::Geodetic checkpoint_anchor(const mapping::MapFrame& frame,
                                       const std::optional<estimation::Geodetic>& given) {
  const estimation::Geodetic anchor{frame[0], frame[1], frame[2]};
  if (given && (std::abs(given->latitude_deg - anchor.latitude_deg) > 1e-7 ||
                std::abs(given->longitude_deg - anchor.longitude_deg) > 1e-7 ||
                std::abs(given->altitude_m - anchor.altitude_m) > 0.01)) {
    throw std::runtime_error("map.resume: the checkpoint's map is anchored at " +
                             std::to_string(anchor.latitude_deg) + ", " +
                             std::to_string(anchor.longitude_deg) + ", " +
                             std::to_string(anchor.altitude_m) + " but estimator.anchor differs");
  }
  return anchor;
}

}  // namespace

Pipeline::Pipeline(const OnboardConfig& config, const RigFactory& make_rig,
                   const std::filesystem::path& trajectory)
    : config_(config),
      imu_ring_(config.imu.ring, OverflowPolicy::kDropOldest),
      gnss_ring_(config.gnss.ring, OverflowPolicy::kDropOldest),
      colour_ring_(config.camera.ring, OverflowPolicy::kDropOldest),
      depth_ring_(config.depth.ring, OverflowPolicy::kDropOldest),
      scan_ring_(config.depth.ring, OverflowPolicy::kDropOldest),
      cloud_ring_(config.depth.ring, OverflowPolicy::kDropOldest),
      poses_(config.estimator.history),
      rig_(make_rig(
          SensorRings{imu_ring_, gnss_ring_, colour_ring_, depth_ring_, scan_ring_, poses_})) {
  auto log = common::logger("onboard");
  const bool inekf = config_.estimator.filter == estimation::FilterKind::kLeftInekf;
  log->info(
      "estimator: {}{}; map: {} with the {} engine", inekf ? "left-inekf" : "eskf",
      inekf ? " (covariance window " + std::to_string(config_.estimator.covariance_window) + ")"
            : "",
      mapping::to_string(config_.map.params.method), mapping::to_string(config_.map.params.engine));
  // The configuration has read the model card, palette and calibration; a network OpenCV then
  // fails to load leaves the robot localising without a map: localisation must not depend on
  // the camera half.
  if (rig_->has_camera() || rig_->has_lidar()) {
    try {
      const DepthSource source = config_.depth.source;
      perception_ = std::make_unique<PerceptionStage>(
          config_.camera, config_.depth,
          make_segmenter(config_.segmenter, config_.map.params.num_classes), colour_ring_,
          source == DepthSource::kAligned ? &depth_ring_ : nullptr,
          source == DepthSource::kLidar ? &scan_ring_ : nullptr, poses_, cloud_ring_,
          config_.map.max_position_sigma_m, config_.perception,
          HoldBuffer(config_.map.hold_seconds, config_.map.hold_bytes));
      log->info("perception: {}", perception_->describe());
    } catch (const std::exception& e) {
      log->error("perception disabled, running without a map: {}", e.what());
    }
  }

  checkpoint_path_ = config_.map.checkpoint_path;
  if (checkpoint_path_.empty() && !config_.map.save_path.empty()) {
    checkpoint_path_ = config_.map.save_path + ".log";
  }
  mapping_ = std::make_unique<MappingStage>(
      config_.map, cloud_ring_,
      [this](const std::vector<common::BlockIndex>& changed,
             const std::vector<common::BlockIndex>& paged_out) {
        if (!first_blocks_logged_ && !changed.empty()) {
          first_blocks_logged_ = true;
          common::logger("onboard")->info(
              "first map blocks ({}) ready to publish {:.2f} s after start ({:.2f} s after the "
              "process started)",
              changed.size(),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - constructed_)
                  .count(),
              common::process_age_seconds());
        }
        if (dds_) dds_->blocks_changed(changed, paged_out);
        for (PipelineObserver* o : observers_) o->on_mapped(changed);
      },
      checkpoint_path_);
  // The publisher reads the map through the mapping stage's view.
  if (config_.dds.enabled) {
    dds_ = std::make_unique<DdsOutputs>(config_.dds, describe_map(config_.map), mapping_->blocks(),
                                        sensor_frames(config_), config_.costmap,
                                        &mapping_->costmaps());
  }

  EstimationStageConfig estimation;
  estimation.estimator = config_.estimator;
  estimation.map_start_heading_sigma_deg = config_.map.start_heading_sigma_deg;
  estimation.odometry_hz = config_.dds.odometry_hz;
  estimation.trajectory = trajectory;
  estimation.trajectory_offset_ns = rig_->stamp_offset_ns();
  // Without a perception stage nothing is held, so nothing is recorded for smoothing.
  const bool holding = perception_ && config_.map.hold_seconds > 0.0 && config_.map.hold_bytes > 0;
  estimation.smoothing_seconds = holding ? config_.map.hold_seconds : 0.0;
  estimation.smoothing_heading_sigma_deg = config_.map.hold_heading_sigma_deg;
  estimation.smoothing_lag_s = config_.map.hold_lag_s;
  if (const auto frame = mapping_->map_frame()) {
    estimation.estimator.anchor = checkpoint_anchor(*frame, config_.estimator.anchor);
    log->info("map frame anchored at {:.8f}, {:.8f}, {:.2f} (from the checkpoint)",
              estimation.estimator.anchor->latitude_deg, estimation.estimator.anchor->longitude_deg,
              estimation.estimator.anchor->altitude_m);
  }
  estimation_ = std::make_unique<EstimationStage>(
      estimation, imu_ring_, gnss_ring_, poses_,
      [this](const PoseOutput& pose) {
        if (dds_) dds_->publish_pose(pose);
        for (auto* o : observers_) o->on_pose(pose);
      },
      [this](const common::GnssFix& fix) {
        if (dds_) dds_->publish_fix(fix);
      });
}

Pipeline::~Pipeline() { stop(); }

void Pipeline::start() {
  taps_.seal();
  if (config_.realtime.lock_memory) {
    memory_lock_ = drivers::lock_memory();
    if (memory_lock_.empty()) {
      memory_lock_ = "memory locked (mlockall)";
      common::logger("onboard")->info("{}", memory_lock_);
    } else {
      common::logger("onboard")->error("{}; running with pageable memory", memory_lock_);
    }
  }
  if (perception_ && !observers_.empty()) {
    perception_->set_observer([this](std::uint32_t sequence, common::Stamp stamp,
                                     const cv::Mat& bgr, const perception::Segmentation& s) {
      for (PipelineObserver* o : observers_) o->on_segmentation(sequence, stamp, bgr, s);
    });
    perception_->set_frame_tap([this](const common::ImageFrame& frame, bool depth) {
      for (PipelineObserver* o : observers_) o->on_frame(frame, depth);
    });
  }
  rig_->pace_by([this](const HandedOver& handed) { return has_taken(handed); });
  const auto cpus = [this](const std::string& stage) {
    const auto it = config_.realtime.stage_cpus.find(stage);
    return it == config_.realtime.stage_cpus.end() ? std::vector<int>{} : it->second;
  };
  estimation_->start(cpus("estimation"));
  if (perception_) perception_->start(cpus("perception"));
  mapping_->start(cpus("mapping"));
  if (dds_) dds_->start(cpus("dds"));
  rig_->start();
  running_ = true;
  started_ = common::Stamp::now();
  cpu_at_start_s_ = common::process_cpu_seconds();
  next_health_ = started_;
  next_progress_ = started_ + 5.0;
  common::logger("onboard")->info("running {}", rig_->describe());
}

void Pipeline::tick() {
  const auto est = estimation_->stats();
  if (est.anchor && !frame_recorded_) {
    mapping_->record_map_frame(
        {est.anchor->latitude_deg, est.anchor->longitude_deg, est.anchor->altitude_m});
    frame_recorded_ = true;
  }
  for (PipelineObserver* o : observers_) o->on_estimate(est);
  const auto now = common::Stamp::now();
  if (dds_ && now >= next_health_) {
    next_health_ = now + 1.0;
    auto report = health_.report(
        now, stage_figures(rings(), *estimation_, perception_.get(), *mapping_, *dds_),
        rig_->drivers().health(), writers());
    for (const PipelineObserver* o : observers_) o->viewer_clients(report.viewers);
    dds_->publish_health(report);
  }
  if (now >= next_progress_) {
    next_progress_ = now + 5.0;
    // Paging and checkpoints free blocks on every thread; glibc keeps the freed pages in each
    // thread's arena, so without this the RSS grows by what the map pages out, not what it holds.
    malloc_trim(0);
    common::logger("onboard")->info(
        "{}", progress_.line(common::seconds_between(now, started_), est,
                             perception_ ? perception_->stats() : PerceptionStageStats{},
                             mapping_->stats(), rings()));
  }
}

void Pipeline::stop() {
  if (!running_) return;
  running_ = false;
  rig_->stop();
  // Each stage empties its input before its thread ends; the next one then takes the rest.
  estimation_->stop();
  if (perception_) perception_->stop();
  mapping_->stop();
  if (dds_) dds_->stop();  // the map's last changes go out
  for (PipelineObserver* o : observers_) o->on_stopped();
  wall_s_ = common::seconds_between(common::Stamp::now(), started_);
  cpu_cores_ = wall_s_ > 0.0 ? (common::process_cpu_seconds() - cpu_at_start_s_) / wall_s_ : 0.0;
}

bool Pipeline::succeeded() const {
  const bool mapped = !(rig_->has_camera() || rig_->has_lidar()) || mapping_->stats().scans > 0;
  return (rig_->gives_poses() || estimation_->stats().initialised) && mapped &&
         save_failures_.empty();
}

std::vector<dds_idl::WriterHealthData> Pipeline::writers() const {
  std::vector<dds_idl::WriterHealthData> out;
  if (!checkpoint_path_.empty() && config_.map.checkpoint_s > 0.0) {
    out.push_back(checkpoint_health(mapping_->stats(), checkpoint_path_));
  }
  for (const PipelineObserver* o : observers_) o->writers(out);
  return out;
}

bool Pipeline::has_taken(const HandedOver& handed) const {
  const auto e = estimation_->stats();
  if (e.imu_samples < handed.imu_samples || e.gnss_fixes < handed.gnss_fixes) return false;
  if (!perception_) return true;
  const auto p = perception_->stats();
  const auto done = p.clouds + p.skipped + p.unpaired + p.bad_frames + p.without_pose +
                    p.uncertain_pose + p.holding + p.labels_too_old;
  // One cloud in the ring (capacity depth.ring >= 2) and none dropped: the same map as when
  // waiting for each insert, at the pace of the slower stage instead of the sum of both.
  return p.frames == handed.frames && done == p.frames &&
         mapping_->stats().scans + drops(cloud_ring_) + 1 >= p.clouds;
}

void Pipeline::save_map(const std::filesystem::path& path) {
  try {
    mapping::write_smap(path, map().layers());
  } catch (const std::exception& e) {
    // write_smap names the file and step; an older map there is left as it was.
    const std::string what = e.what();
    save_failures_.push_back(
        what.find(path.string()) == std::string::npos ? path.string() + ": " + what : what);
    throw;
  }
  common::logger("onboard")->info("map saved to {}", path.string());
}

std::optional<PerceptionStageStats> Pipeline::perception() const {
  if (!perception_) return std::nullopt;
  return perception_->stats();
}

Rings Pipeline::rings() const {
  return Rings{imu_ring_, gnss_ring_, colour_ring_, depth_ring_, scan_ring_, cloud_ring_};
}

std::vector<std::pair<std::string, std::uint64_t>> Pipeline::ring_drops() const {
  return {{"imu", drops(imu_ring_)},       {"gnss", drops(gnss_ring_)},
          {"colour", drops(colour_ring_)}, {"depth", drops(depth_ring_)},
          {"scans", drops(scan_ring_)},    {"clouds", drops(cloud_ring_)}};
}

std::vector<std::string> Pipeline::summary() const {
  std::vector<std::string> lines;
  rig_->drivers().summary(lines);
  if (!rig_->gives_poses()) estimation_summary(estimation_->stats(), lines);
  if (perception_) perception_summary(*perception_, lines);
  mapping_summary(mapping_->stats(), checkpoint_path_, config_.map.memory_radius_m, lines);
  latency_summary(latency_phases(perception_.get(), *mapping_), lines);
  for (const std::string& failure : save_failures_) {
    lines.push_back("map save failed  : " + failure);
  }
  if (dds_) dds_summary(*dds_, lines);
  rig_->summary(lines);
  for (const PipelineObserver* o : observers_) o->summary(lines);
  ring_summary(rings(), lines);
  lines.push_back(
      fmt::format("cpu              : {:.2f} cores over {:.1f} s", cpu_cores_, wall_s_));
  if (!memory_lock_.empty()) lines.push_back("realtime         : " + memory_lock_);
  return lines;
}

}  // namespace semap::onboard
