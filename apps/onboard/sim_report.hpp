#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <mutex>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "estimation_stage.hpp"
#include "latency_window.hpp"
#include "semap/perception/segmentation.hpp"
#include "semap/perception/sim_classes.hpp"
#include "sim_rig.hpp"

namespace semap::mapping {
class SemanticMap;
}

namespace semap::onboard {

// The filter's live position and the rig's truth at its stamp, both in the simulator's frame;
// nullopt before the filter initialised.
struct PoseVsTruth {
  Eigen::Vector3d estimate;
  Eigen::Vector3d truth;
  common::Stamp stamp;
};
std::optional<PoseVsTruth> pose_vs_truth(const SimRig& rig, const EstimationStageStats& s);

// A confusion matrix over the K = 8 map classes: rows the true class (0 = free), columns the
// predicted class, plus a last column for "no label".
class ClassConfusion {
 public:
  static constexpr int K = perception::kSimMapClasses;
  void add(std::uint16_t truth, std::uint16_t predicted, std::uint64_t count = 1);
  // IoU of map class c (1..K-1), nullopt when the truth never has it.
  std::optional<double> iou(int c) const;
  // Mean IoU over the classes the truth has (NaN when it has none).
  double mean_iou() const;
  // Counted with true class c.
  std::uint64_t truth_count(int c) const;
  // Counted with true class `truth` and predicted class `predicted` (K: no label).
  std::uint64_t count(int truth, int predicted) const { return counts_[truth][predicted]; }
  std::uint64_t total() const;
  // The same without the true free cells (the semantic part of a map's errors alone).
  ClassConfusion without_free() const;

 private:
  std::array<std::array<std::uint64_t, K + 1>, K> counts_{};
};

// The figures of the run the report does not measure itself.
struct RunFigures {
  std::string segmenter;  // "onnx" or "palette"
  std::optional<double> pose_rmse_m;
  std::uint64_t frames_captured = 0;  // rendered by the rig's camera
  std::uint64_t frames_mapped = 0;    // clouds inserted into the map
  LatencyPercentiles latency_frame_to_map;
  std::vector<std::pair<std::string, std::uint64_t>> ring_drops;
  double cpu_cores_used = 0.0;
};

// What semap-onboard --report DIR writes on the simulated rig: camera.png (one frame: what
// the segmenter saw | its output | the true classes), trajectory.png (estimate vs truth),
// truth.csv (the simulated truth in the map frame at every IMU stamp, `stamp_s,x,y,z` as
// --trajectory writes the estimate, for a test to score the published poses itself),
// summary.json (pose RMSE, pixel mIoU of the segmenter, mIoU of the map's occupied cells
// against the world's true class at each cell centre (and over the cells on a surface
// alone), frame counts, latency, ring drops,
// CPU). The perception stage shows it each segmentation (observe), the main loop the live
// pose (sample_pose); write() after the stages stopped.
class SimReport {
 public:
  SimReport(const SimRig& rig, std::filesystem::path dir);

  // The perception stage's observer (its thread).
  void observe(std::uint32_t sequence, const cv::Mat& bgr, const perception::Segmentation& seg);
  // The main thread, a few times a second.
  void sample_pose(const EstimationStageStats& s);
  // Writes the files; `final` is the estimation stage's last state (the map frame's anchor).
  // Returns summary.json's path.
  std::filesystem::path write(const RunFigures& run, const mapping::SemanticMap& map,
                              const EstimationStageStats& final) const;

  const std::filesystem::path& dir() const { return dir_; }

 private:
  struct Sample {
    cv::Mat bgr;
    cv::Mat predicted;  // CV_16UC1 map classes
    cv::Mat truth;      // CV_8UC1 train ids
  };

  ClassConfusion map_confusion(const mapping::SemanticMap& map,
                               const EstimationStageStats& final) const;
  void write_camera_png() const;
  void write_trajectory_png(std::optional<double> rmse) const;
  void write_truth_csv(const EstimationStageStats& final) const;

  const SimRig& rig_;
  std::filesystem::path dir_;
  mutable std::mutex mutex_;  // the segmentation figures, written on the perception thread
  ClassConfusion pixels_;
  std::uint64_t frames_observed_ = 0;
  std::optional<Sample> sample_;
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> track_;  // (truth, estimate) xy
  std::optional<common::Stamp> last_pose_;
};

}  // namespace semap::onboard
