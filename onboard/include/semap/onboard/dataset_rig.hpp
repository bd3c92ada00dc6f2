#pragma once

#include <Eigen/Geometry>
#include <atomic>
#include <cstddef>
#include <limits>
#include <mutex>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "semap/onboard/sensor_rig.hpp"
#include "semap/perception/datasets/kitti_odometry.hpp"
#include "semap/perception/datasets/rgbd_sequence.hpp"

namespace semap::onboard {

// Which frames of a dataset to play: first, first + stride, ... up to last (indices into the
// sequence's frames).
struct DatasetSelection {
  std::size_t first = 0;
  std::size_t last = std::numeric_limits<std::size_t>::max();
  std::size_t stride = 1;
};

// One frame of a dataset as the rig plays it: the files it reads and the body's pose.
struct DatasetFrame {
  std::filesystem::path colour;  // colour image (or label image); empty: none
  std::filesystem::path depth;   // 16-bit depth PNG aligned with the colour image; empty: none
  std::filesystem::path scan;    // Velodyne .bin scan; empty: none
  Eigen::Isometry3d world_from_body = Eigen::Isometry3d::Identity();
};

// Plays a recorded dataset through the pipeline's own perception and mapping stages, as fast as
// they take it: RGB-D frames (TUM, Redwood: perception::datasets::RgbdSequence) or LiDAR scans
// with their images when there are any (KITTI odometry: KittiOdometrySequence). For each frame
// the dataset's pose goes into the pose history, then the depth image (raw units, Z16), the scan
// and the colour image into their rings, stamped with the time they are handed over; the next
// frame waits until the stages have mapped this one or counted it as dropped with a reason
// (pace_by), so a run maps every frame it can, and the same map every time. A frame whose file
// cannot be read, or whose depth image is not 16-bit, is named and counted (problems()) and
// skipped.
class DatasetRig final : public SensorRig {
 public:
  // RGB-D: the body frame is the configured camera mount's, a frame's body pose its camera pose
  // times optical-from-body.
  DatasetRig(perception::datasets::RgbdSequence sequence, std::string name,
             const Eigen::Isometry3f& body_from_optical, DatasetSelection selection,
             const SensorRings& rings);
  // LiDAR: a frame's body pose is its LiDAR pose times lidar-from-body. Frames without an image
  // hand over the scan alone (for a stage that maps whole scans).
  DatasetRig(const perception::datasets::KittiOdometrySequence& sequence, std::string name,
             const Eigen::Isometry3f& body_from_lidar, DatasetSelection selection,
             const SensorRings& rings);
  ~DatasetRig() override;
  DatasetRig(const DatasetRig&) = delete;
  DatasetRig& operator=(const DatasetRig&) = delete;

  std::string describe() const override;
  bool has_camera() const override { return has_colour_; }
  bool has_lidar() const override { return has_scans_; }
  bool gives_poses() const override { return true; }
  // A dataset has no raw device streams to record: throws.
  void set_taps(RawTaps taps) override;
  void pace_by(Taken taken) override { taken_ = std::move(taken); }
  void start() override;
  void stop() override;
  bool finished() const override { return finished_.load(std::memory_order_acquire); }
  const RigDrivers& drivers() const override { return drivers_; }
  void summary(std::vector<std::string>& lines) const override;

  // Frames selected, and of those handed to the pipeline.
  std::size_t selected() const { return selected_.size(); }
  std::size_t handed_over() const { return handed_.load(std::memory_order_acquire); }
  // The reader's problems and the frames this rig could not read, each naming its file.
  std::vector<perception::datasets::InputProblem> problems() const;

 private:
  DatasetRig(std::vector<DatasetFrame> frames,
             std::vector<perception::datasets::InputProblem> reader_problems, std::string name,
             DatasetSelection selection, const SensorRings& rings);
  // A frame's files, read.
  struct Loaded {
    cv::Mat colour;
    cv::Mat depth;
    std::optional<common::PointScan> scan;
    Eigen::Isometry3d world_from_body;
  };

  void run(std::stop_token stop);
  // Reads the frame's files; a file that cannot be used is named in problems(): nullopt.
  std::optional<Loaded> load(const DatasetFrame& frame);
  // Its pose into the history, then its frames into the rings, stamped now.
  void hand_over(Loaded& frame, std::uint32_t sequence);
  void problem(const std::filesystem::path& file, const std::string& what);

  std::vector<DatasetFrame> frames_;
  std::size_t reader_problems_ = 0;
  std::string name_;
  bool has_colour_ = false;
  bool has_scans_ = false;
  std::vector<std::size_t> selected_;
  SensorRings rings_;
  RigDrivers drivers_;
  Taken taken_;
  mutable std::mutex mutex_;  // problems_
  std::vector<perception::datasets::InputProblem> problems_;
  std::atomic<std::size_t> handed_{0};
  std::atomic<bool> finished_{false};
  std::jthread thread_;
};

}  // namespace semap::onboard
