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

#include "semap/common/latency_window.hpp"
#include "semap/mapping/confusion_matrix.hpp"
#include "semap/onboard/estimation_stage.hpp"
#include "semap/onboard/pipeline.hpp"
#include "semap/onboard/run_figures.hpp"
#include "semap/perception/segmentation.hpp"
#include "semap/perception/sim_classes.hpp"
#include "semap/sim/rig.hpp"

namespace semap::mapping {
class SemanticMap;
}

namespace semap::sim {

// Where the map frame's origin (the filter's anchor) lies in the simulator's ENU frame. The
// filter's frame stays where it was anchored: a re-anchoring after a GNSS jump shifts the fixes
// into it (EstimationStageStats::anchor_offset), not the frame, so the offset plays no part.
Eigen::Vector3d sim_from_map(const SimRig& rig, const estimation::Geodetic& anchor);

// The filter's live position and the rig's truth at its stamp, both in the simulator's frame;
// nullopt before the filter initialised.
struct PoseVsTruth {
  Eigen::Vector3d estimate;
  Eigen::Vector3d truth;
  common::Stamp stamp;
};
std::optional<PoseVsTruth> pose_vs_truth(const SimRig& rig, const onboard::EstimationStageStats& s);

// Position error of the live estimate against the rig's truth, in the simulator's frame.
class LiveAccuracy {
 public:
  void sample(const SimRig& rig, const onboard::EstimationStageStats& s);
  bool any() const { return count_ > 0; }
  double rmse() const;
  double max() const { return max_; }
  std::size_t count() const { return count_; }

 private:
  std::optional<common::Stamp> first_;
  double sum_sq_ = 0.0;
  double max_ = 0.0;
  std::size_t count_ = 0;
};

// The figures of the run the report does not measure itself.
struct RunFigures {
  std::string segmenter;  // "dnn", "palette" or "geometry"
  std::optional<double> pose_rmse_m;
  std::uint64_t frames_captured = 0;  // rendered by the rig's camera
  std::uint64_t frames_mapped = 0;    // clouds inserted into the map
  common::LatencyPercentiles latency_frame_to_map;
  // Where it comes from: the camera's delivery, then onboard::latency_phases().
  std::vector<onboard::LatencyPhase> latency_phases;
  std::vector<std::pair<std::string, std::uint64_t>> ring_drops;
  double cpu_cores_used = 0.0;
};

// What the simulated rig's run reports. Always the live pose error against the truth (the
// summary's "pose vs truth" line); with a directory (semap-onboard --report DIR) also
// camera.png (one frame: what the segmenter saw | its output | the true classes),
// trajectory.png (estimate vs truth), truth.csv (the simulated truth in the map frame at every
// IMU stamp, `stamp_s,x,y,z` as --trajectory writes the estimate, for a test to score the
// published poses itself) and summary.json (pose RMSE, pixel mIoU of the segmenter, mIoU of the
// map's occupied cells against the world's true class at each cell centre (and over the cells
// on a surface alone), frame counts, latency and its phases, ring drops, CPU), written by write()
// after the pipeline stopped.
class SimReport final : public onboard::PipelineObserver {
 public:
  SimReport(const SimRig& rig, std::filesystem::path dir);

  void on_estimate(const onboard::EstimationStageStats& s) override;
  void on_segmentation(std::uint32_t sequence, common::Stamp stamp, const cv::Mat& bgr,
                       const perception::Segmentation& seg) override;
  void summary(std::vector<std::string>& lines) const override;

  // Writes the files of the stopped pipeline's run; returns summary.json's path.
  std::filesystem::path write(onboard::Pipeline& pipeline) const;

  const std::filesystem::path& dir() const { return dir_; }

 private:
  struct Sample {
    cv::Mat bgr;
    cv::Mat predicted;  // CV_16UC1 map classes
    cv::Mat truth;      // CV_8UC1 train ids
  };

  void sample_pose(const onboard::EstimationStageStats& s);
  std::filesystem::path write(const RunFigures& run, const mapping::SemanticMap& map,
                              const onboard::EstimationStageStats& final) const;
  mapping::ConfusionMatrix map_confusion(const mapping::SemanticMap& map,
                                         const onboard::EstimationStageStats& final) const;
  void write_camera_png() const;
  void write_trajectory_png(std::optional<double> rmse) const;
  void write_truth_csv(const onboard::EstimationStageStats& final) const;

  const SimRig& rig_;
  std::filesystem::path dir_;
  mutable std::mutex mutex_;  // the segmentation figures, written on the perception thread
  mapping::ConfusionMatrix pixels_{perception::kSimMapClasses};
  std::uint64_t frames_observed_ = 0;
  std::optional<Sample> sample_;
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> track_;  // (truth, estimate) xy
  std::optional<common::Stamp> last_pose_;
  LiveAccuracy accuracy_;  // the thread calling tick()
};

}  // namespace semap::sim
