#pragma once

#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "semap/common/messages.hpp"
#include "semap/common/spsc_ring.hpp"
#include "semap/onboard/dds_outputs.hpp"
#include "semap/onboard/estimation_stage.hpp"
#include "semap/onboard/health_monitor.hpp"
#include "semap/onboard/mapping_stage.hpp"
#include "semap/onboard/onboard_config.hpp"
#include "semap/onboard/perception_stage.hpp"
#include "semap/onboard/run_figures.hpp"
#include "semap/onboard/sensor_rig.hpp"
#include "semap/onboard/shared_pose_history.hpp"
#include "semap/onboard/tap_fanout.hpp"

namespace semap::onboard {

// Watches the pipeline without being part of it: a report, a recorder, a viewer. Each call
// comes on the thread its comment names and must not block for long; every one is optional.
class PipelineObserver {
 public:
  virtual ~PipelineObserver() = default;
  // The estimation stage's state, about ten times a second (the thread calling tick()).
  virtual void on_estimate(const EstimationStageStats&) {}
  // Each pose the estimation stage publishes, at dds.odometry_hz (the estimation thread).
  virtual void on_pose(const PoseOutput&) {}
  // Each colour or depth frame the perception stage takes (the perception thread).
  virtual void on_frame(const common::ImageFrame&, bool /*depth*/) {}
  // Each segmentation: its colour frame's sequence and stamp, the BGR image the segmenter saw
  // and its result (the perception thread).
  virtual void on_segmentation(std::uint32_t /*sequence*/, common::Stamp, const cv::Mat& /*bgr*/,
                               const perception::Segmentation&) {}
  // A cloud is in the map; these blocks changed (the mapping thread).
  virtual void on_mapped(std::span<const common::BlockIndex> /*changed*/) {}
  // The pipeline has stopped: every stage has emptied its input (the thread calling stop()).
  virtual void on_stopped() {}
  // The viewer's clients, for the health report (the thread calling tick(), once a second).
  virtual void viewer_clients(std::vector<dds_idl::ViewerClientData>&) const {}
  // Its lines for the exit summary (after stop()).
  virtual void summary(std::vector<std::string>&) const {}
  // The files it writes, for the health report (the thread calling tick(), once a second).
  virtual void writers(std::vector<dds_idl::WriterHealthData>&) const {}
};

// The robot's pipeline, built from an OnboardConfig: the rings, the sensor rig that fills them,
// the estimation stage (IMU + GNSS -> poses), the perception stage (frames -> posed labelled
// clouds, when the rig has a camera and the segmenter loads), the mapping stage (S-BKI, with its
// checkpoint) and the DDS outputs. Each stage runs on its own thread; the caller's thread calls
// tick() while the robot runs.
class Pipeline {
 public:
  using RigFactory = std::function<std::unique_ptr<SensorRig>(const SensorRings&)>;

  // Builds everything; nothing runs yet. `trajectory`: every pose of the filter as CSV.
  // Throws when the checkpoint cannot be opened or its map is anchored elsewhere than
  // estimator.anchor says.
  Pipeline(const OnboardConfig& config, const RigFactory& make_rig,
           const std::filesystem::path& trajectory = {});
  ~Pipeline();
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  // Before start().
  void attach(PipelineObserver& observer) { observers_.push_back(&observer); }
  // Before start(): every message the DDS outputs write also goes to `tap` (the viewer, a
  // recorder; each tap gets them all, through one fan-out). False when there are no DDS
  // outputs (dds.enabled: false).
  bool attach_tap(dds_idl::MessageTap& tap) {
    if (!dds_) return false;
    const bool first = taps_.empty();
    taps_.add(tap);
    if (first) dds_->attach_tap(taps_);
    return true;
  }
  SensorRig& rig() { return *rig_; }
  const SensorRig& rig() const { return *rig_; }

  void start();
  // The caller's share while the robot runs, every ~100 ms: anchors the map's frame once the
  // filter has one, publishes health once a second and logs progress every five.
  void tick();
  // The rig has played all it had (a drive, a recording, the run's duration).
  bool finished() const { return rig_->finished(); }
  // Stops in the order data flows: the rig first (nothing more enters the rings), then each
  // stage once it has emptied its input, so every cloud made is in the map or counted as
  // dropped; then the outputs publish the map's last changes.
  void stop();

  // Whether frames are segmented and mapped (the rig has a camera or a LiDAR and the segmenter
  // loaded).
  bool perceiving() const { return perception_ != nullptr; }
  EstimationStageStats estimation() const { return estimation_->stats(); }
  std::optional<PerceptionStageStats> perception() const;
  // Null when not perceiving.
  const PerceptionStage* perception_stage() const { return perception_.get(); }
  MappingStageStats mapping() const { return mapping_->stats(); }
  const MappingStage& mapping_stage() const { return *mapping_; }
  const std::filesystem::path& checkpoint_path() const { return checkpoint_path_; }
  // Every ring's drops, by name.
  std::vector<std::pair<std::string, std::uint64_t>> ring_drops() const;
  // After stop(): the whole map (read back from the checkpoint when it was paged), and that map
  // written as a .smap file. A save that fails (disk full) throws naming the file and leaves
  // an older file there as it was; the failure is kept for the summary and succeeded().
  const mapping::SemanticMap& map() { return mapping_->map(); }
  void save_map(const std::filesystem::path& path);
  // Saves that failed: "<path>: <error>".
  const std::vector<std::string>& save_failures() const { return save_failures_; }
  // The files being written (checkpoint, observers' files), as the health report gives them.
  std::vector<dds_idl::WriterHealthData> writers() const;
  // After stop(): the exit summary, one line per part (tests read them).
  std::vector<std::string> summary() const;
  // After stop(): the process's CPU time over the run's wall time, in cores.
  double cpu_cores() const { return cpu_cores_; }
  // After stop(): whether the run did its job: the filter initialised, when the rig has a
  // camera something was mapped, and every map save worked.
  bool succeeded() const;
  const OnboardConfig& config() const { return config_; }

 private:
  // Fast replay: true once the stages have taken all that the rig handed over, the mapping
  // stage allowed to be one cloud behind (it inserts one while perception makes the next).
  bool has_taken(const HandedOver& handed) const;
  Rings rings() const;

  OnboardConfig config_;
  common::SpscRing<common::ImuSample> imu_ring_;
  common::SpscRing<common::GnssFix> gnss_ring_;
  common::SpscRing<common::ImageFrame> colour_ring_;
  common::SpscRing<common::ImageFrame> depth_ring_;
  common::SpscRing<common::PointScan> scan_ring_;
  common::SpscRing<common::LabeledCloud> cloud_ring_;
  SharedPoseHistory poses_;
  std::unique_ptr<SensorRig> rig_;
  std::vector<PipelineObserver*> observers_;
  std::filesystem::path checkpoint_path_;
  TapFanout taps_;  // the DDS outputs' taps (attach_tap); outlives their writers
  // Declared in the order they may be destroyed last: the publisher reads the mapping stage.
  std::unique_ptr<MappingStage> mapping_;
  // For the log line of the first blocks in the map; the flag only on the mapping thread.
  std::chrono::steady_clock::time_point constructed_ = std::chrono::steady_clock::now();
  bool first_blocks_logged_ = false;
  std::unique_ptr<DdsOutputs> dds_;
  std::unique_ptr<PerceptionStage> perception_;
  std::unique_ptr<EstimationStage> estimation_;
  HealthMonitor health_;
  Progress progress_;
  common::Stamp started_;
  double cpu_at_start_s_ = 0.0;
  std::string memory_lock_;  // realtime.lock_memory: what mlockall did
  double cpu_cores_ = 0.0;
  double wall_s_ = 0.0;
  common::Stamp next_health_;
  common::Stamp next_progress_;
  bool frame_recorded_ = false;
  bool running_ = false;
  std::vector<std::string> save_failures_;
};

}  // namespace semap::onboard
