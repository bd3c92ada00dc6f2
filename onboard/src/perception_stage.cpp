#include "semap/onboard/perception_stage.hpp"

#include <chrono>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "semap/common/logging.hpp"
#include "semap/drivers/frame_convert.hpp"
#include "semap/mapping/cloud_transform.hpp"
#include "semap/perception/depth_cloud.hpp"
#include "semap/perception/stereo_depth.hpp"

namespace semap::onboard {

namespace {

constexpr std::size_t kMaxUnposed = 8;  // clouds waiting for the filter to reach their stamp

std::string frame_name(const common::ImageFrame& f) {
  return "frame " + std::to_string(f.sequence) + " (" + std::to_string(f.width) + "x" +
         std::to_string(f.height) + ", stamp " + std::to_string(f.stamp.ns) + " ns)";
}

}  // namespace

PerceptionStage::PerceptionStage(const CameraConfig& camera, const DepthConfig& depth,
                                 std::unique_ptr<perception::Segmenter> segmenter,
                                 common::SpscRing<common::ImageFrame>& colour,
                                 common::SpscRing<common::ImageFrame>* depth_frames,
                                 const SharedPoseHistory& poses,
                                 common::SpscRing<common::LabeledCloud>& clouds)
    : camera_(camera),
      depth_(depth),
      segmenter_(std::move(segmenter)),
      colour_ring_(colour),
      depth_ring_(depth_frames),
      poses_(poses),
      cloud_ring_(clouds),
      body_from_optical_(camera.body_from_optical()) {
  if (!segmenter_) throw std::invalid_argument("perception stage: no segmenter");
  if (depth_.source == DepthSource::kAligned && !depth_ring_) {
    throw std::invalid_argument("perception stage: aligned depth needs a depth frame ring");
  }
  if (depth_.source == DepthSource::kStereo) {
    stereo_ = std::make_unique<perception::StereoDepth>(
        load_stereo_calibration(depth_.stereo_calibration), depth_.stereo);
  }
}

PerceptionStage::~PerceptionStage() { stop(); }

void PerceptionStage::start() {
  stage_.start([this](std::stop_token stop) { run(stop); });
}

void PerceptionStage::stop() { stage_.stop(); }

PerceptionStageStats PerceptionStage::stats() const { return stage_.stats(); }

std::uint32_t PerceptionStage::queue_depth() const {
  const std::size_t depth = depth_ring_ ? depth_ring_->size() : 0;
  return static_cast<std::uint32_t>(colour_ring_.size() + depth);
}

std::string PerceptionStage::describe() const {
  const std::string depth =
      stereo_ ? "stereo (" + depth_.stereo_calibration.string() + ")" : "aligned Z16 depth";
  return segmenter_->describe() + ", " + depth;
}

void PerceptionStage::run(std::stop_token stop) {
  // Asked to stop, it first processes what the rings still hold (the rig and the estimation
  // stage have stopped); what can then never be processed is counted by its reason.
  while (true) {
    if (step()) continue;
    if (stop.stop_requested()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  auto& figures = stage_.figures();
  figures.unpaired += colour_pending_.size();
  figures.depth_unused += depth_pending_.size();
  figures.without_pose += unposed_.size();
  colour_pending_.clear();
  depth_pending_.clear();
  unposed_.clear();
  share_stats();
}

bool PerceptionStage::step() {
  bool worked = take_frames();
  worked = process_next() || worked;
  worked = pose_clouds() || worked;
  share_stats();
  return worked;
}

bool PerceptionStage::take_frames() {
  bool any = false;
  common::ImageFrame frame;
  while (colour_ring_.try_pop(frame)) {
    if (tap_) tap_(frame, false);
    colour_pending_.push_back(std::move(frame));
    ++stage_.figures().frames;
    any = true;
  }
  while (depth_ring_ && depth_ring_->try_pop(frame)) {
    if (tap_) tap_(frame, true);
    depth_pending_.push_back(std::move(frame));
    any = true;
  }
  return any;
}

// Picks the newest colour frame that can be processed now and passes over the older ones.
// With a separate depth device, a colour frame pairs with the depth frame nearest in time
// within the sync tolerance; one that can no longer get a partner is dropped.
bool PerceptionStage::process_next() {
  if (colour_pending_.empty()) return false;
  if (depth_.source != DepthSource::kAligned) {
    stage_.figures().skipped += colour_pending_.size() - 1;
    const common::ImageFrame colour = std::move(colour_pending_.back());
    colour_pending_.clear();
    process(colour, nullptr);
    return true;
  }
  const double tolerance = depth_.sync_tolerance_s;
  // Newest colour frame with a depth partner.
  for (auto c = colour_pending_.rbegin(); c != colour_pending_.rend(); ++c) {
    auto best = depth_pending_.end();
    double best_dt = tolerance;
    for (auto d = depth_pending_.begin(); d != depth_pending_.end(); ++d) {
      const double dt = std::abs(common::seconds_between(d->stamp, c->stamp));
      if (dt <= best_dt) {
        best_dt = dt;
        best = d;
      }
    }
    if (best == depth_pending_.end()) continue;
    const auto index = static_cast<std::size_t>(colour_pending_.rend() - c) - 1;
    stage_.figures().skipped += index;
    const common::ImageFrame colour = std::move(*c);
    const common::ImageFrame depth = std::move(*best);
    colour_pending_.erase(colour_pending_.begin(),
                          colour_pending_.begin() + static_cast<std::ptrdiff_t>(index) + 1);
    // Depth frames before the partner are too old for any later colour frame.
    stage_.figures().depth_unused += static_cast<std::uint64_t>(best - depth_pending_.begin());
    depth_pending_.erase(depth_pending_.begin(), best + 1);
    process(colour, &depth);
    return true;
  }
  // No pair yet: drop what can never pair (the other stream is already past it).
  const auto expire = [&](std::deque<common::ImageFrame>& mine,
                          const std::deque<common::ImageFrame>& other, std::uint64_t& count) {
    if (other.empty()) return;
    const common::Stamp horizon = other.back().stamp + (-tolerance);
    while (!mine.empty() && mine.front().stamp < horizon) {
      mine.pop_front();
      ++count;
    }
  };
  expire(colour_pending_, depth_pending_, stage_.figures().unpaired);
  expire(depth_pending_, colour_pending_, stage_.figures().depth_unused);
  // A depth device that stopped delivering must not let colour frames pile up.
  while (colour_pending_.size() > colour_ring_.capacity()) {
    colour_pending_.pop_front();
    ++stage_.figures().unpaired;
  }
  while (depth_pending_.size() > depth_ring_->capacity()) {
    depth_pending_.pop_front();
    ++stage_.figures().depth_unused;
  }
  return false;
}

void PerceptionStage::reject(const common::ImageFrame& frame, const std::string& why) {
  ++stage_.figures().bad_frames;
  // One line per bad frame would flood the log at camera rates: the first few and then every
  // hundredth, each with its count.
  if (stage_.figures().bad_frames <= 5 || stage_.figures().bad_frames % 100 == 0) {
    common::logger("perception")
        ->warn("{} rejected ({} so far): {}", frame_name(frame), stage_.figures().bad_frames, why);
  }
}

void PerceptionStage::process(const common::ImageFrame& colour, const common::ImageFrame* depth) {
  cv::Mat image = drivers::to_mat(colour, jpeg_);
  if (image.empty()) return reject(colour, "truncated frame or corrupt JPEG");
  if (image.type() == CV_8UC1) cv::cvtColor(image, image, cv::COLOR_GRAY2BGR);
  if (image.type() != CV_8UC3) return reject(colour, "not a colour or grey image");

  perception::PinholeIntrinsics intrinsics = camera_.intrinsics;
  Eigen::Isometry3f body_from_optical = body_from_optical_;
  cv::Mat depth_m;
  try {
    if (stereo_) {
      auto frame = stereo_->compute(image);
      image = frame.left_bgr;
      depth_m = frame.depth;
      intrinsics = frame.intrinsics;
      body_from_optical.linear() = body_from_optical.linear() * frame.left_from_rectified;
    } else {
      if (depth->format != common::PixelFormat::kZ16) {
        return reject(*depth, "depth frame is not Z16");
      }
      const cv::Mat z16 = drivers::to_mat(*depth, jpeg_);
      if (z16.empty()) return reject(*depth, "truncated depth frame");
      depth_m = perception::depth_metres(z16, depth_.depth_scale);
    }
    const auto t0 = std::chrono::steady_clock::now();
    const perception::Segmentation segmentation = segmenter_->segment(image);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    stage_.figures().segment_seconds_total += seconds;
    stage_.figures().segment_seconds_max = std::max(stage_.figures().segment_seconds_max, seconds);
    if (observer_) observer_(colour.sequence, colour.stamp, image, segmentation);
    BodyCloud body{
        perception::cloud_from_depth(depth_m, segmentation, intrinsics, body_from_optical,
                                     depth_.points, stage_.figures().dropped),
        colour.sequence};
    body.cloud.stamp = colour.stamp;
    if (unposed_.size() == kMaxUnposed) {
      unposed_.pop_front();  // the filter has stalled; keep the newest
      ++stage_.figures().without_pose;
    }
    unposed_.push_back(std::move(body));
  } catch (const std::exception& e) {
    reject(colour, e.what());
  }
}

bool PerceptionStage::pose_clouds() {
  bool any = false;
  while (!unposed_.empty()) {
    const auto lookup = poses_.at(unposed_.front().cloud.stamp);
    if (lookup.status == SharedPoseHistory::Status::kPending) break;
    any = true;
    if (lookup.status != SharedPoseHistory::Status::kPosed) {
      ++stage_.figures().without_pose;
      unposed_.pop_front();
      continue;
    }
    common::LabeledCloud cloud =
        mapping::transform_cloud(std::move(unposed_.front().cloud), lookup.pose.world_from_body());
    const common::Stamp stamp = cloud.stamp;
    stage_.figures().points += cloud.size();
    unposed_.pop_front();
    cloud_ring_.try_push(std::move(cloud));  // drop-oldest: the ring counts what it drops
    ++stage_.figures().clouds;
    latency_.record(common::seconds_between(common::Stamp::now(), stamp));
  }
  return any;
}

void PerceptionStage::share_stats() { stage_.share(); }

}  // namespace semap::onboard
