#pragma once

#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "semap/common/latency_window.hpp"
#include "semap/common/messages.hpp"
#include "semap/common/spsc_ring.hpp"
#include "semap/drivers/jpeg_decoder.hpp"
#include "semap/onboard/hold_buffer.hpp"
#include "semap/onboard/perception_config.hpp"
#include "semap/onboard/shared_pose_history.hpp"
#include "semap/onboard/stage_thread.hpp"
#include "semap/perception/async_segmenter.hpp"
#include "semap/perception/labelled_points.hpp"
#include "semap/perception/segmentation.hpp"

namespace semap::perception {
class StereoDepth;
}

namespace semap::onboard {

struct PerceptionStageStats {
  // Counted in the frames that drive the stage, colour frames (LiDAR scans in LiDAR mode):
  // each frame taken becomes a cloud or one of the losses below.
  std::uint64_t frames = 0;          // frames taken from the ring
  std::uint64_t clouds = 0;          // posed clouds handed to the mapping stage
  std::uint64_t skipped = 0;         // passed over for a newer frame (the stage fell behind)
  std::uint64_t unpaired = 0;        // no partner (depth frame, colour image) within tolerance
  std::uint64_t partner_unused = 0;  // depth frames (LiDAR mode: colour frames) left unpaired
  std::uint64_t bad_frames = 0;      // undecodable, wrong format or wrong size
  std::uint64_t without_pose = 0;    // before the filter started, or older than its history
  // Frames taken before the filter's heading was known, held for the poses the smoother gives
  // those seconds once it is (HoldBuffer); of them, those dropped from the hold (its bounds,
  // poses that never came, the run's end) are also counted without_pose.
  std::uint64_t held = 0;
  std::uint64_t hold_dropped = 0;
  std::uint64_t holding = 0;         // held now, not yet mapped nor dropped
  std::uint64_t hold_bytes_max = 0;  // the most memory the held clouds took
  // Posed while the filter's position sigma was above map.max_position_sigma_m (a GNSS outage):
  // mapping pauses rather than smear the map.
  std::uint64_t uncertain_pose = 0;
  std::uint64_t points = 0;        // labelled points handed on
  perception::DropCounts dropped;  // pixels dropped on the way to points, by reason
  double segment_seconds_total = 0.0;
  double segment_seconds_max = 0.0;
  // perception.carry_labels: the network on its own thread.
  std::uint64_t segmented = 0;         // frames it segmented
  std::uint64_t segment_failures = 0;  // frames it failed on (logged)
  std::uint64_t carried = 0;           // clouds labelled from an earlier frame's segmentation
  std::uint64_t labels_too_old = 0;    // no segmentation within perception.max_label_age_s
};

// Owns the camera's half of the pipeline on its own thread: takes colour frames (and depth
// frames of a separate depth device, or LiDAR scans) from the drivers' rings, pairs them by
// stamp, segments, turns labelled pixels with depth (or scan points projected into the
// segmented image) into points in the body frame, poses them at the frame's stamp from the
// estimation stage's history and hands the cloud to the mapping stage, unless the pose's
// position sigma is above `max_position_sigma_m` (> 0; map.max_position_sigma_m): such a cloud
// is dropped and counted (uncertain_pose), so mapping pauses while the filter is unsure where
// it is and resumes when it knows again.
// Clouds without a pose before the estimation stage has given the smoothed poses of the
// seconds before the heading was known (SharedPoseHistory::set_smoothed) are held in `hold`
// (map.hold_seconds, map.hold_bytes) and then mapped at the smoothed poses of their own
// stamps, one at a time into an empty cloud ring after the first live cloud, so that live
// clouds keep their place.
// It keeps only the newest frame when it falls behind: drivers never wait for it.
// With rate.carry_labels (a network slower than the camera) the network runs on its own thread
// on the newest colour frame and every depth frame is labelled, once the poses at both stamps
// are known, from the newest segmentation carried to it (perception/label_carrying.hpp);
// a frame whose newest segmentation is older than rate.max_label_age_s is not mapped.
class PerceptionStage {
 public:
  PerceptionStage(const CameraConfig& camera, const DepthConfig& depth,
                  std::unique_ptr<perception::Segmenter> segmenter,
                  common::SpscRing<common::ImageFrame>& colour,
                  common::SpscRing<common::ImageFrame>* depth_frames,
                  common::SpscRing<common::PointScan>* scans, const SharedPoseHistory& poses,
                  common::SpscRing<common::LabeledCloud>& clouds, double max_position_sigma_m = 0.0,
                  const SegmentRateConfig& rate = {}, HoldBuffer hold = HoldBuffer(0.0, 0));
  ~PerceptionStage();
  PerceptionStage(const PerceptionStage&) = delete;
  PerceptionStage& operator=(const PerceptionStage&) = delete;

  // Called on the stage's thread after each segmentation with the colour frame's sequence and
  // stamp, the BGR image the segmenter saw and its result (evaluation on the simulated rig).
  // It delays the stage while it runs. Set before start().
  using SegmentationObserver =
      std::function<void(std::uint32_t sequence, common::Stamp stamp, const cv::Mat& bgr,
                         const perception::Segmentation&)>;
  void set_observer(SegmentationObserver observer) { observer_ = std::move(observer); }
  // Sees every frame taken from the rings, colour and depth, on the stage's thread (a
  // recorder). Set before start().
  using FrameTap = std::function<void(const common::ImageFrame&, bool depth)>;
  void set_frame_tap(FrameTap tap) { tap_ = std::move(tap); }

  // `cpus`: the CPUs its thread may run on (realtime.stage_cpus; empty: any).
  void start(std::vector<int> cpus = {});
  void stop();
  PerceptionStageStats stats() const;
  // Age of each frame (its capture stamp) when its posed cloud goes to the mapping stage.
  const common::LatencyWindow& latency() const { return latency_; }
  // Where that age comes from: the colour frame's age when the stage takes it from its ring
  // (the camera's delivery and the ring's wait while the stage was busy), and how long each
  // cloud waited for the filter to reach its stamp.
  const common::LatencyWindow& taken_age() const { return taken_age_; }
  const common::LatencyWindow& pose_wait() const { return pose_wait_; }
  // Time each segmentation took, and each turning of a segmented frame into points
  // (back-projecting depth, projecting a scan).
  const common::LatencyWindow& segment_time() const { return segment_time_; }
  const common::LatencyWindow& points_time() const { return points_time_; }
  std::uint32_t queue_depth() const;
  // The segmenter and depth source, for the log.
  std::string describe() const;

  // One round of the stage's loop, for tests that drive it without its thread: takes what
  // the rings hold, processes at most one frame, poses what the filter has reached.
  // Returns whether it did anything.
  bool step();

 private:
  struct BodyCloud {
    common::LabeledCloud cloud;  // body frame
    std::uint32_t sequence = 0;
    common::Stamp queued_at;  // when it began to wait for its pose
    // Carrying labels: the frame's depth (metres), labelled once it is posed; the cloud holds
    // only the stamp until then.
    cv::Mat unlabelled_depth_m;
  };
  enum class Carried { kLabelled, kWaitForPose, kDropped };

  void run(std::stop_token stop);
  bool take_frames();
  bool process_next();
  void process(const common::ImageFrame& colour, const common::ImageFrame* depth);
  void process_scan(const common::PointScan& scan, const common::ImageFrame* colour);
  cv::Mat colour_image(const common::ImageFrame& colour);
  perception::Segmentation segment(const common::ImageFrame& colour, const cv::Mat& image);
  void count_segmentation(double seconds);
  void hand_to_network(const common::ImageFrame& colour, const cv::Mat& image,
                       const cv::Mat& depth_m);
  bool take_segmentation();
  Carried carry_labels(BodyCloud& frame, const estimation::StampedPose& pose);
  void queue_for_pose(common::LabeledCloud body_cloud, common::Stamp stamp, std::uint32_t sequence);
  bool pose_clouds();
  bool release_held();
  void drain_held_posed();
  void hand_over(common::LabeledCloud cloud);
  void count_hold_drops(std::uint64_t n);
  bool too_uncertain(const estimation::StampedPose& pose);
  void reject(const std::string& frame, const std::string& why);
  void share_stats();

  CameraConfig camera_;
  DepthConfig depth_;
  std::unique_ptr<perception::Segmenter> segmenter_;
  SegmentationObserver observer_;
  FrameTap tap_;
  std::unique_ptr<perception::StereoDepth> stereo_;
  SegmentRateConfig rate_;
  std::unique_ptr<perception::AsyncSegmenter> network_;  // rate_.carry_labels: owns the segmenter
  std::optional<perception::SegmentJob> newest_;         // the newest segmentation it gave
  std::optional<common::Stamp> last_handed_;             // stamp of the last frame handed to it
  common::SpscRing<common::ImageFrame>& colour_ring_;
  common::SpscRing<common::ImageFrame>* depth_ring_;
  common::SpscRing<common::PointScan>* scan_ring_;
  // LiDAR mode with a segmenter that labels nothing: whole scans, no colour image needed.
  bool whole_scans_ = false;
  const SharedPoseHistory& poses_;
  common::SpscRing<common::LabeledCloud>& cloud_ring_;
  double max_position_sigma_m_;
  bool paused_ = false;  // the last cloud's pose was too uncertain
  std::uint64_t uncertain_at_pause_ = 0;
  Eigen::Isometry3f body_from_optical_;
  drivers::JpegDecoder jpeg_;
  std::deque<common::ImageFrame> colour_pending_;
  std::deque<common::ImageFrame> depth_pending_;
  std::deque<common::PointScan> scan_pending_;
  std::deque<BodyCloud> unposed_;
  HoldBuffer hold_;
  std::deque<common::LabeledCloud> held_posed_;  // held clouds posed, waiting for the ring
  std::uint64_t hold_dropped_seen_ = 0;          // hold_.dropped() already counted
  bool live_handed_over_ = false;                // held clouds go after the first live one
  common::LatencyWindow latency_;
  common::LatencyWindow taken_age_;
  common::LatencyWindow pose_wait_;
  common::LatencyWindow segment_time_;
  common::LatencyWindow points_time_;
  StageThread<PerceptionStageStats> stage_;  // last: joined before the members it uses
};

}  // namespace semap::onboard
