#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <thread>

#include "semap/common/latency_window.hpp"
#include "semap/common/messages.hpp"
#include "semap/common/spsc_ring.hpp"
#include "semap/drivers/v4l2_output.hpp"
#include "semap/sim/camera.hpp"
#include "semap/sim/world.hpp"

namespace semap::sim {

// What the simulated camera shows the perception stage.
enum class SimCameraImage {
  kRgb,      // the rendered scene: textures, shading, noise (for a trained segmenter)
  kClasses,  // each pixel painted in its class's Cityscapes colour (a perfect segmenter via
             // the palette)
};

// Where the colour frames go instead of the colour ring: a V4L2 output device looped to a
// capture device that a CameraDriver reads. Such a loop shows each frame until the next one and
// stamps every capture of it when it is taken, so the captures of one frame carry stamps spread
// over the whole frame period. The feed therefore writes each frame `period - tolerance` before
// its stamp: the captures stamped within the sync tolerance of it (those that pair with its
// depth frame) show this frame and no other, as long as it reaches the capture side within
// `period - 2 tolerance` of being due. A frame rendered so late that less than half of that is
// left is not shown and its depth frame not published, so that no colour frame pairs with the
// wrong depth frame.
struct SimCameraOutput {
  std::unique_ptr<drivers::V4l2Output> device;  // format set and streaming
  double period_s = 0.0;                        // between the rig's frames
  double tolerance_s = 0.0;                     // depth.sync_tolerance, below period / 2
};

// The simulated rig's camera on a thread of its own, so that rendering never delays the IMU
// and GNSS streams: the rig asks for a frame at a pose and stamp, the feed renders it and
// pushes a BGR24 colour frame and an aligned Z16 depth frame into the rings the camera drivers
// fill on hardware (the colour frame to a V4L2 output instead when one is given). It keeps the
// true classes of recent frames for evaluation.
// Frames for the rings are asked for `period_s` (a frame period) ahead of their stamp and
// pushed at it, as a camera hands over the image it took: rendering, which a camera does in
// hardware, is then not part of the pipeline's latency unless it takes longer than a period (the
// frame is pushed when done, its delay in delivery_age()). 0: rendered after the stamp.
// `render_nice` (0..19) lowers the renderer thread's priority below the pipeline's threads.
class SimCameraFeed {
 public:
  SimCameraFeed(const sim::SimWorld& world, const sim::SimCameraOptions& camera,
                SimCameraImage image, float depth_scale,
                common::SpscRing<common::ImageFrame>& colour_ring,
                common::SpscRing<common::ImageFrame>& depth_ring, double period_s = 0.0,
                SimCameraOutput output = {}, int render_nice = 0);
  ~SimCameraFeed();
  SimCameraFeed(const SimCameraFeed&) = delete;
  SimCameraFeed& operator=(const SimCameraFeed&) = delete;

  void start();
  void stop();
  // A frame at this camera pose (world from optical) and capture stamp. A request the feed
  // has not started on yet is replaced by the newer one (counted as skipped).
  void request(const Eigen::Isometry3f& world_from_optical, common::Stamp stamp);
  // How long before its stamp the rig should ask for a frame: a frame period to render it
  // before it is due (to the rings: the period given, at the stamp; to an output: earlier).
  double request_ahead_s() const;

  // True classes (CV_8UC1, Cityscapes train ids) of a recent frame, by its sequence number.
  std::optional<cv::Mat> true_labels(std::uint32_t sequence) const;
  std::uint64_t rendered() const;
  std::uint64_t skipped() const;
  std::uint64_t not_shown() const;  // rendered but not written to the output (late, errors)
  double render_seconds_mean() const;
  // Each frame's age (since its capture stamp) when it goes into the rings: the wait for the
  // renderer and the rendering, which a real camera does in hardware.
  const common::LatencyWindow& delivery_age() const { return delivery_age_; }

 private:
  struct Request {
    Eigen::Isometry3f world_from_optical;
    common::Stamp stamp;
  };
  void run(std::stop_token stop);
  // False when stopped before a frame for the rings was due: it never went out.
  bool publish(const sim::SimFrame& frame, common::Stamp stamp, std::uint32_t sequence,
               std::stop_token stop);
  bool show(const cv::Mat& colour, common::Stamp stamp, std::stop_token stop);
  // Sleeps until `due`; false when asked to stop.
  bool wait_until(common::Stamp due, std::stop_token stop);
  double output_lead_s() const { return output_.period_s - output_.tolerance_s; }

  const sim::SimWorld& world_;
  sim::SimCamera camera_;
  SimCameraImage image_;
  float depth_scale_;
  common::SpscRing<common::ImageFrame>& colour_ring_;
  common::SpscRing<common::ImageFrame>& depth_ring_;
  double period_s_;
  SimCameraOutput output_;
  int render_nice_;
  mutable std::mutex mutex_;
  std::condition_variable_any wake_;
  std::optional<Request> pending_;
  std::deque<std::pair<std::uint32_t, cv::Mat>> truth_;  // the last few frames' classes
  std::uint64_t rendered_ = 0;
  std::uint64_t skipped_ = 0;
  std::uint64_t not_shown_ = 0;
  double render_seconds_ = 0.0;
  common::LatencyWindow delivery_age_;
  std::jthread thread_;
};

}  // namespace semap::sim
