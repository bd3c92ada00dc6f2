#pragma once

#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include "semap/mapping/class_palette.hpp"
#include "semap/onboard/foxglove_server.hpp"
#include "semap/onboard/onboard_config.hpp"
#include "semap/onboard/pipeline.hpp"

namespace semap::onboard {

// The files of onboard/web (the built-in page), compiled in: path relative to "/", contents.
std::vector<std::pair<std::string_view, std::string_view>> viewer_web_files();

// The robot seen live (the `viewer:` section; docs/viewer.md): a Foxglove WebSocket server and
// the built-in page on one port. Attached to the pipeline as an observer (camera frames and
// their segmentation, the health report's clients, the summary) and to its DDS outputs as their
// tap (Pipeline::attach_tap: every DDS topic's own CDR). The perception thread only copies a
// frame and its labels into a one-slot buffer, at most image_hz times a second and only while
// a client subscribes to an image; the viewer's own thread draws the overlay and encodes the
// JPEGs (sensor_msgs/msg/CompressedImage on <ns>/semap/camera/image/compressed and
// <ns>/semap/segmentation/overlay/compressed).
class Viewer : public PipelineObserver {
 public:
  // `ns`, `frame_id`: dds.namespace (topic names) and the camera images' frame.
  Viewer(const ViewerConfig& config, const mapping::ClassPalette& palette, const std::string& ns,
         std::string camera_frame_id = "camera_optical");
  ~Viewer() override;
  Viewer(const Viewer&) = delete;
  Viewer& operator=(const Viewer&) = delete;

  // Binds (throws std::runtime_error naming the address when it cannot), logs
  // "viewer: http://ADDRESS:PORT/" and serves.
  void start();
  void stop();

  FoxgloveServer& server() { return server_; }
  std::uint16_t port() const { return server_.port(); }
  std::string url() const { return server_.url(); }
  std::uint64_t images_sent() const;

  void on_segmentation(std::uint32_t sequence, common::Stamp stamp, const cv::Mat& bgr,
                       const perception::Segmentation& segmentation) override;
  void viewer_clients(std::vector<dds_idl::ViewerClientData>& out) const override;
  void summary(std::vector<std::string>& lines) const override;

 private:
  void run_images(std::stop_token stop);

  ViewerConfig config_;
  std::vector<cv::Vec3b> colours_;  // BGR per class
  std::string camera_frame_id_;
  FoxgloveServer server_;
  std::uint32_t camera_channel_ = 0;
  std::uint32_t overlay_channel_ = 0;

  std::mutex slot_mutex_;
  std::condition_variable_any slot_cv_;
  struct Slot {
    cv::Mat bgr;
    cv::Mat labels;
    common::Stamp stamp;
    bool fresh = false;
  } slot_;
  common::Stamp next_copy_;  // perception thread only
  mutable std::mutex images_mutex_;
  std::uint64_t images_sent_ = 0;
  std::jthread thread_;
};

// With viewer.enabled: a Viewer started and attached to `pipeline` (observer and DDS tap);
// otherwise null, and null (the error logged) when it cannot listen on viewer.address:port.
// Before pipeline.start().
std::unique_ptr<Viewer> start_viewer(Pipeline& pipeline, const OnboardConfig& config);

}  // namespace semap::onboard
