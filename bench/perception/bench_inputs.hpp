#pragma once

// Inputs of perception_bench: one 640x480 street scene as an RGB-D camera would deliver it
// (YUYV colour, aligned Z16 depth), a model card around the synthetic benchmark network, the
// pose of a robot driving a circle, and percentile helpers.

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "semap/common/messages.hpp"
#include "semap/estimation/pose_history.hpp"
#include "semap/onboard/perception_config.hpp"

namespace semap::bench {

struct SceneImages {
  cv::Mat label_bgr;        // CV_8UC3, exact Cityscapes colours (what PaletteSegmenter reads)
  cv::Mat camera_bgr;       // the same with sensor noise, as a camera sees it
  common::ImageFrame yuyv;  // camera_bgr as a YUYV frame
  common::ImageFrame z16;   // aligned depth in depth_scale units, 0 = no return
};

// A street of the simulated world (SimWorld, seed 11) seen by the simulated camera at the
// camera's intrinsics and mount.
SceneImages render_scene(const onboard::CameraConfig& camera, float depth_scale);

struct BenchModel {
  std::filesystem::path card;
  int classes = 0;  // model classes; all but the last feed map classes 1..K-1 in turn
  double gflops = 0.0;
};

// Writes segmentation_benchmark_model (width 48, 3 middle layers) at width x height and a
// card (ImageNet normalisation, logits, `threads`) feeding a K-class map into dir.
BenchModel write_bench_model(const std::filesystem::path& dir, int width, int height,
                             int num_map_classes, int threads);

// Pose of a robot driving a circle of 10 m radius at 5 m/s, t seconds after the start.
estimation::StampedPose circle_pose(double t, common::Stamp stamp);

struct Spread {
  double p50 = 0.0;
  double p90 = 0.0;
  double p99 = 0.0;
};

inline Spread spread(std::vector<double> v) {
  if (v.empty()) return {};
  std::sort(v.begin(), v.end());
  const auto at = [&](double q) {
    return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5)];
  };
  return {at(0.5), at(0.9), at(0.99)};
}

// Runs f() n times; milliseconds per call.
template <typename F>
Spread time_ms(int n, F&& f) {
  std::vector<double> ms;
  for (int i = 0; i < n; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    f(i);
    ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  return spread(std::move(ms));
}

}  // namespace semap::bench
