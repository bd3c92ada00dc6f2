#include "semap/sim/camera_feed.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <opencv2/core.hpp>

#include "semap/common/logging.hpp"
#include "semap/drivers/driver_error.hpp"
#include "semap/drivers/frame_convert.hpp"
#include "semap/perception/palette_segmenter.hpp"

namespace semap::sim {

namespace {

constexpr std::size_t kTruthKept = 64;  // frames: more than the perception stage holds

// Each pixel in its train id's Cityscapes colour (BGR), black where the id has none.
cv::Mat paint_classes(const cv::Mat& train_ids) {
  static const auto palette = perception::cityscapes_palette();
  cv::Mat lut(1, 256, CV_8UC3, cv::Scalar(0, 0, 0));
  for (std::size_t id = 0; id < palette.size(); ++id) {
    const auto& rgb = palette[id].color;
    lut.at<cv::Vec3b>(0, static_cast<int>(id)) = cv::Vec3b(rgb[2], rgb[1], rgb[0]);
  }
  cv::Mat three;
  cv::Mat channels[] = {train_ids, train_ids, train_ids};
  cv::merge(channels, 3, three);
  cv::Mat painted;
  cv::LUT(three, lut, painted);
  return painted;
}

}  // namespace

SimCameraFeed::SimCameraFeed(const sim::SimWorld& world, const sim::SimCameraOptions& camera,
                             SimCameraImage image, float depth_scale,
                             common::SpscRing<common::ImageFrame>& colour_ring,
                             common::SpscRing<common::ImageFrame>& depth_ring, double period_s,
                             SimCameraOutput output, int render_nice)
    : world_(world),
      camera_(camera),
      image_(image),
      depth_scale_(depth_scale),
      colour_ring_(colour_ring),
      depth_ring_(depth_ring),
      period_s_(period_s),
      output_(std::move(output)),
      render_nice_(render_nice) {}

SimCameraFeed::~SimCameraFeed() { stop(); }

void SimCameraFeed::start() {
  thread_ = std::jthread([this](std::stop_token stop) { run(stop); });
}

void SimCameraFeed::stop() {
  if (thread_.joinable()) {
    thread_.request_stop();
    wake_.notify_all();
    thread_.join();
  }
}

void SimCameraFeed::request(const Eigen::Isometry3f& world_from_optical, common::Stamp stamp) {
  {
    std::lock_guard lock(mutex_);
    if (pending_) ++skipped_;
    pending_ = Request{world_from_optical, stamp};
  }
  wake_.notify_one();
}

double SimCameraFeed::request_ahead_s() const {
  return output_.device ? output_.period_s + output_lead_s() : period_s_;
}

std::optional<cv::Mat> SimCameraFeed::true_labels(std::uint32_t sequence) const {
  std::lock_guard lock(mutex_);
  for (const auto& [s, labels] : truth_) {
    if (s == sequence) return labels;
  }
  return std::nullopt;
}

std::uint64_t SimCameraFeed::rendered() const {
  std::lock_guard lock(mutex_);
  return rendered_;
}

std::uint64_t SimCameraFeed::skipped() const {
  std::lock_guard lock(mutex_);
  return skipped_;
}

std::uint64_t SimCameraFeed::not_shown() const {
  std::lock_guard lock(mutex_);
  return not_shown_;
}

double SimCameraFeed::render_seconds_mean() const {
  std::lock_guard lock(mutex_);
  return rendered_ ? render_seconds_ / static_cast<double>(rendered_) : 0.0;
}

void SimCameraFeed::run(std::stop_token stop) {
  // Linux: the calling thread's nice value. A refusal only leaves it at the process's.
  if (render_nice_ > 0 &&
      setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), render_nice_) != 0) {
    common::logger("sim_camera")->warn("renderer nice {} refused", render_nice_);
  }
  std::uint32_t sequence = 0;
  while (true) {
    Request request;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, stop, [&] { return pending_.has_value(); });
      if (stop.stop_requested()) return;
      request = *pending_;
      pending_.reset();
    }
    const auto t0 = std::chrono::steady_clock::now();
    const auto frame = camera_.render(world_, request.world_from_optical, sequence);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    {
      // Before the frame is out, so that whoever evaluates it finds its truth.
      std::lock_guard lock(mutex_);
      truth_.emplace_back(sequence, frame.labels);
      if (truth_.size() > kTruthKept) truth_.pop_front();
    }
    // Rendered ahead for a stamp the run did not reach, the frame was never taken: not counted.
    if (!publish(frame, request.stamp, sequence, stop)) return;
    {
      std::lock_guard lock(mutex_);
      ++rendered_;
      render_seconds_ += seconds;
    }
    ++sequence;
  }
}

bool SimCameraFeed::publish(const sim::SimFrame& frame, common::Stamp stamp, std::uint32_t sequence,
                            std::stop_token stop) {
  const cv::Mat colour = image_ == SimCameraImage::kRgb ? frame.bgr : paint_classes(frame.labels);
  common::ImageFrame depth = drivers::to_frame(sim::depth_to_z16(frame.depth_m, depth_scale_),
                                               common::PixelFormat::kZ16, stamp, sequence);
  if (!output_.device) {
    common::ImageFrame bgr =
        drivers::to_frame(colour, common::PixelFormat::kBgr24, stamp, sequence);
    if (!wait_until(stamp, stop)) return false;
    delivery_age_.record(common::seconds_between(common::Stamp::now(), stamp));
    colour_ring_.try_push(std::move(bgr));
  } else if (!show(colour, stamp, stop)) {
    std::lock_guard lock(mutex_);
    ++not_shown_;
    return true;
  }
  depth_ring_.try_push(std::move(depth));
  return true;
}

// Writes the frame to the output `period - tolerance` before its stamp (see SimCameraOutput);
// false if it is too late for that by more than half the loop's allowance, or on an error.
bool SimCameraFeed::show(const cv::Mat& colour, common::Stamp stamp, std::stop_token stop) {
  const common::Stamp due = stamp + (-output_lead_s());
  const double allowance = output_.period_s - 2.0 * output_.tolerance_s;
  if (common::Stamp::now() > due + 0.5 * allowance) return false;
  if (!wait_until(due, stop)) return false;
  try {
    if (output_.device->write({colour.data, colour.total() * colour.elemSize()}, colour.step,
                              100)) {
      return true;
    }
    common::logger("sim_camera")->warn("{}: no output buffer came back", output_.device->path());
  } catch (const drivers::DriverError& e) {
    common::logger("sim_camera")->warn("camera frame not shown: {}", e.what());
  }
  return false;
}

bool SimCameraFeed::wait_until(common::Stamp due, std::stop_token stop) {
  std::unique_lock lock(mutex_);
  const auto wait = std::chrono::nanoseconds(
      std::max<std::int64_t>(0, static_cast<std::int64_t>(due.ns - common::Stamp::now().ns)));
  wake_.wait_for(lock, stop, wait, [] { return false; });
  return !stop.stop_requested();
}

}  // namespace semap::sim
