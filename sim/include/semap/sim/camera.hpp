#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <numbers>
#include <opencv2/core/mat.hpp>

#include "semap/perception/depth_projection.hpp"
#include "semap/sim/world.hpp"

namespace semap::sim {

struct SimCameraOptions {
  perception::PinholeIntrinsics intrinsics =
      perception::PinholeIntrinsics::from_fov(640, 480, std::numbers::pi_v<float> / 2.0f);
  float max_range = 40.0f;      // depth returns up to this range along the ray
  float visual_range = 150.0f;  // colour and labels up to this range, sky beyond
  float fog_distance = 250.0f;  // a fraction exp(-t / fog_distance) of a surface's light arrives
  float image_noise = 4.0f;     // sigma of the per-pixel, per-channel noise, grey levels
  // Depth noise sigma = quadratic * z^2 + floor (metres), as for active stereo.
  float depth_noise_quadratic = 0.001f;
  float depth_noise_floor = 0.005f;
  float dropout = 0.005f;           // probability of a missing return anywhere
  float grazing_start_deg = 75.0f;  // incidence angle beyond which returns start to go missing
  float grazing_dropout = 0.5f;     // ... reaching this probability at 90 degrees
  std::uint64_t seed = 1;
};

// One rendered frame, all images width x height.
struct SimFrame {
  cv::Mat bgr;      // CV_8UC3
  cv::Mat depth_m;  // CV_32FC1, z-depth in metres, 0 = no return
  cv::Mat
      labels;  // CV_8UC1, Cityscapes train id (perception::sim_train_id), sky where nothing is hit
};

// A colour + depth camera with perfect labels in a SimWorld. Colour: textured albedo,
// Lambertian sun + sky-light shading, haze with distance, sky with clouds, vignetting,
// per-frame exposure, a 3x3 optical blur and sensor noise. Depth: range-dependent noise and
// returns missing beyond max_range, at grazing incidence and at random. Everything random is
// a hash of (seed, frame index, pixel), so a frame is the same each time it is rendered.
class SimCamera {
 public:
  explicit SimCamera(const SimCameraOptions& options = {});

  SimFrame render(const SimWorld& world, const Eigen::Isometry3f& world_from_optical,
                  std::uint64_t frame_index) const;

  const SimCameraOptions& options() const { return options_; }

 private:
  SimCameraOptions options_;
};

// A Z16 depth image (CV_16UC1, round(z / depth_scale), saturating; 0 stays 0) from metres.
cv::Mat depth_to_z16(const cv::Mat& depth_m, float depth_scale);

}  // namespace semap::sim
