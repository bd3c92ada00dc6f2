#include "semap/onboard/perception_stage.hpp"

#include <chrono>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "semap/common/logging.hpp"
#include "semap/drivers/frame_convert.hpp"
#include "semap/perception/depth_cloud.hpp"
#include "semap/perception/geometry_segmenter.hpp"
#include "semap/perception/label_carrying.hpp"
#include "semap/perception/lidar_projection.hpp"
#include "semap/perception/stereo_depth.hpp"

namespace semap::onboard {

namespace {

std::string frame_name(const common::ImageFrame& f) {
  return "frame " + std::to_string(f.sequence) + " (" + std::to_string(f.width) + "x" +
         std::to_string(f.height) + ", stamp " + std::to_string(f.stamp.ns) + " ns)";
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

std::string scan_name(const common::PointScan& s) {
  return "scan " + std::to_string(s.sequence) + " (" + std::to_string(s.points.size()) +
         " points, stamp " + std::to_string(s.stamp.ns) + " ns)";
}

// Hands the newest `leads` item that has a partner within `tolerance` (the partner nearest in
// time) to `process`, passing over the older ones (skipped) and the partners before the one
// used (partner_unused). Without a pair, drops what can never pair: items older than the other
// stream's newest minus the tolerance, and items beyond `capacity` (a stream that stopped
// delivering must not let the other pile up).
template <class Lead, class Partner, class Process>
bool process_newest_pair(std::deque<Lead>& leads, std::deque<Partner>& partners, double tolerance,
                         std::size_t lead_capacity, std::size_t partner_capacity,
                         PerceptionStageStats& figures, Process&& process) {
  for (auto lead = leads.rbegin(); lead != leads.rend(); ++lead) {
    auto best = partners.end();
    double best_dt = tolerance;
    for (auto p = partners.begin(); p != partners.end(); ++p) {
      const double dt = std::abs(common::seconds_between(p->stamp, lead->stamp));
      if (dt <= best_dt) {
        best_dt = dt;
        best = p;
      }
    }
    if (best == partners.end()) continue;
    const auto index = static_cast<std::size_t>(leads.rend() - lead) - 1;
    figures.skipped += index;
    const Lead taken = std::move(*lead);
    const Partner partner = std::move(*best);
    leads.erase(leads.begin(), leads.begin() + static_cast<std::ptrdiff_t>(index) + 1);
    // Partners before the one used are too old for any later lead.
    figures.partner_unused += static_cast<std::uint64_t>(best - partners.begin());
    partners.erase(partners.begin(), best + 1);
    process(taken, partner);
    return true;
  }
  const auto expire = [&](auto& mine, const auto& other, std::uint64_t& count) {
    if (other.empty()) return;
    const common::Stamp horizon = other.back().stamp + (-tolerance);
    while (!mine.empty() && mine.front().stamp < horizon) {
      mine.pop_front();
      ++count;
    }
  };
  expire(leads, partners, figures.unpaired);
  expire(partners, leads, figures.partner_unused);
  while (leads.size() > lead_capacity) {
    leads.pop_front();
    ++figures.unpaired;
  }
  while (partners.size() > partner_capacity) {
    partners.pop_front();
    ++figures.partner_unused;
  }
  return false;
}

}  // namespace

PerceptionStage::PerceptionStage(
    const CameraConfig& camera, const DepthConfig& depth,
    std::unique_ptr<perception::Segmenter> segmenter, common::SpscRing<common::ImageFrame>& colour,
    common::SpscRing<common::ImageFrame>* depth_frames, common::SpscRing<common::PointScan>* scans,
    const SharedPoseHistory& poses, common::SpscRing<common::LabeledCloud>& clouds,
    double max_position_sigma_m, const SegmentRateConfig& rate, HoldBuffer hold)
    : camera_(camera),
      depth_(depth),
      segmenter_(std::move(segmenter)),
      rate_(rate),
      colour_ring_(colour),
      depth_ring_(depth_frames),
      scan_ring_(scans),
      poses_(poses),
      cloud_ring_(clouds),
      max_position_sigma_m_(max_position_sigma_m),
      body_from_optical_(camera.body_from_optical()),
      hold_(std::move(hold)) {
  if (!segmenter_) throw std::invalid_argument("perception stage: no segmenter");
  if (rate_.carry_labels) {
    if (depth_.source != DepthSource::kAligned) {
      throw std::invalid_argument("perception stage: carrying labels needs aligned depth");
    }
    network_ = std::make_unique<perception::AsyncSegmenter>(std::move(segmenter_));
  }
  if (depth_.source == DepthSource::kAligned && !depth_ring_) {
    throw std::invalid_argument("perception stage: aligned depth needs a depth frame ring");
  }
  if (depth_.source == DepthSource::kLidar) {
    if (!scan_ring_) throw std::invalid_argument("perception stage: LiDAR needs a scan ring");
    whole_scans_ = dynamic_cast<const perception::GeometrySegmenter*>(segmenter_.get()) != nullptr;
  }
  if (depth_.source == DepthSource::kStereo) {
    stereo_ = std::make_unique<perception::StereoDepth>(
        load_stereo_calibration(depth_.stereo_calibration), depth_.stereo);
  }
}

PerceptionStage::~PerceptionStage() { stop(); }

void PerceptionStage::start(std::vector<int> cpus) {
  stage_.start([this](std::stop_token stop) { run(stop); }, "perception", std::move(cpus));
}

void PerceptionStage::stop() { stage_.stop(); }

PerceptionStageStats PerceptionStage::stats() const { return stage_.stats(); }

std::uint32_t PerceptionStage::queue_depth() const {
  const std::size_t depth = depth_ring_ ? depth_ring_->size() : 0;
  const std::size_t scans = scan_ring_ ? scan_ring_->size() : 0;
  return static_cast<std::uint32_t>(colour_ring_.size() + depth + scans);
}

std::string PerceptionStage::describe() const {
  switch (depth_.source) {
    case DepthSource::kStereo:
      return segmenter_->describe() + ", stereo (" + depth_.stereo_calibration.string() + ")";
    case DepthSource::kLidar:
      return segmenter_->describe() +
             (whole_scans_ ? ", whole LiDAR scans" : ", LiDAR scans projected into the image");
    case DepthSource::kAligned:
      break;
  }
  if (network_) {
    return network_->describe() + " on its own thread (" +
           (rate_.segment_hz > 0.0 ? "at most " + std::to_string(rate_.segment_hz) + " Hz"
                                   : std::string("as often as it can")) +
           "), labels carried to the aligned Z16 depth frames between";
  }
  return segmenter_->describe() + ", aligned Z16 depth";
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
  const bool lidar = depth_.source == DepthSource::kLidar;
  figures.unpaired += lidar ? scan_pending_.size() : colour_pending_.size();
  figures.partner_unused += lidar ? colour_pending_.size() : depth_pending_.size();
  figures.without_pose += unposed_.size();
  drain_held_posed();
  count_hold_drops(hold_.size() + held_posed_.size());
  colour_pending_.clear();
  depth_pending_.clear();
  scan_pending_.clear();
  unposed_.clear();
  while (!hold_.empty()) hold_.pop_front();
  held_posed_.clear();
  figures.holding = 0;
  share_stats();
}

bool PerceptionStage::step() {
  bool worked = take_frames();
  worked = take_segmentation() || worked;
  worked = process_next() || worked;
  worked = pose_clouds() || worked;
  worked = release_held() || worked;
  share_stats();
  return worked;
}

bool PerceptionStage::take_frames() {
  bool any = false;
  common::ImageFrame frame;
  const bool lidar = depth_.source == DepthSource::kLidar;
  while (colour_ring_.try_pop(frame)) {
    taken_age_.record(common::seconds_between(common::Stamp::now(), frame.stamp));
    if (tap_) tap_(frame, false);
    colour_pending_.push_back(std::move(frame));
    if (!lidar) ++stage_.figures().frames;
    any = true;
  }
  while (depth_ring_ && depth_ring_->try_pop(frame)) {
    if (tap_) tap_(frame, true);
    depth_pending_.push_back(std::move(frame));
    any = true;
  }
  common::PointScan scan;
  while (scan_ring_ && scan_ring_->try_pop(scan)) {
    scan_pending_.push_back(std::move(scan));
    ++stage_.figures().frames;
    any = true;
  }
  return any;
}

// Picks the newest frame that can be processed now and passes over the older ones. A colour
// frame pairs with the depth frame of a separate depth device nearest in time, a LiDAR scan
// with the colour frame nearest in time, within the sync tolerance.
bool PerceptionStage::process_next() {
  auto& figures = stage_.figures();
  switch (depth_.source) {
    case DepthSource::kStereo: {
      if (colour_pending_.empty()) return false;
      figures.skipped += colour_pending_.size() - 1;
      const common::ImageFrame colour = std::move(colour_pending_.back());
      colour_pending_.clear();
      process(colour, nullptr);
      return true;
    }
    case DepthSource::kLidar: {
      if (whole_scans_) {
        figures.partner_unused += colour_pending_.size();
        colour_pending_.clear();
        if (scan_pending_.empty()) return false;
        figures.skipped += scan_pending_.size() - 1;
        const common::PointScan scan = std::move(scan_pending_.back());
        scan_pending_.clear();
        process_scan(scan, nullptr);
        return true;
      }
      return process_newest_pair(
          scan_pending_, colour_pending_, depth_.sync_tolerance_s, scan_ring_->capacity(),
          colour_ring_.capacity(), figures,
          [this](const common::PointScan& scan, const common::ImageFrame& colour) {
            process_scan(scan, &colour);
          });
    }
    case DepthSource::kAligned:
      break;
  }
  return process_newest_pair(colour_pending_, depth_pending_, depth_.sync_tolerance_s,
                             colour_ring_.capacity(), depth_ring_->capacity(), figures,
                             [this](const common::ImageFrame& colour,
                                    const common::ImageFrame& depth) { process(colour, &depth); });
}

void PerceptionStage::reject(const std::string& frame, const std::string& why) {
  ++stage_.figures().bad_frames;
  // One line per bad frame would flood the log at camera rates: the first few and then every
  // hundredth, each with its count.
  if (stage_.figures().bad_frames <= 5 || stage_.figures().bad_frames % 100 == 0) {
    common::logger("perception")
        ->warn("{} rejected ({} so far): {}", frame, stage_.figures().bad_frames, why);
  }
}

cv::Mat PerceptionStage::colour_image(const common::ImageFrame& colour) {
  cv::Mat image = drivers::to_mat(colour, jpeg_);
  if (image.empty()) {
    reject(frame_name(colour), "truncated frame or corrupt JPEG");
    return {};
  }
  if (image.type() == CV_8UC1) cv::cvtColor(image, image, cv::COLOR_GRAY2BGR);
  if (image.type() != CV_8UC3) {
    reject(frame_name(colour), "not a colour or grey image");
    return {};
  }
  return image;
}

perception::Segmentation PerceptionStage::segment(const common::ImageFrame& colour,
                                                  const cv::Mat& image) {
  const auto t0 = std::chrono::steady_clock::now();
  perception::Segmentation segmentation = segmenter_->segment(image);
  count_segmentation(seconds_since(t0));
  if (observer_) observer_(colour.sequence, colour.stamp, image, segmentation);
  return segmentation;
}

void PerceptionStage::count_segmentation(double seconds) {
  segment_time_.record(seconds);
  stage_.figures().segment_seconds_total += seconds;
  stage_.figures().segment_seconds_max = std::max(stage_.figures().segment_seconds_max, seconds);
}

// Carrying labels: the network gets the frame unless segment_hz holds it back, and the frame
// waits for its pose with its depth, to be labelled then from the newest segmentation.
void PerceptionStage::hand_to_network(const common::ImageFrame& colour, const cv::Mat& image,
                                      const cv::Mat& depth_m) {
  const double interval = rate_.segment_hz > 0.0 ? 1.0 / rate_.segment_hz : 0.0;
  if (!last_handed_ || common::seconds_between(colour.stamp, *last_handed_) >= interval) {
    network_->submit({image, depth_m, colour.stamp, colour.sequence, {}, 0.0});
    last_handed_ = colour.stamp;
  }
  queue_for_pose(common::LabeledCloud{}, colour.stamp, colour.sequence);
  unposed_.back().unlabelled_depth_m = depth_m;
}

bool PerceptionStage::take_segmentation() {
  if (!network_) return false;
  auto& figures = stage_.figures();
  figures.segment_failures = network_->failures();
  std::optional<perception::SegmentJob> job = network_->take();
  if (!job) return false;
  ++figures.segmented;
  count_segmentation(job->seconds);
  if (observer_) observer_(job->sequence, job->stamp, job->bgr, job->segmentation);
  newest_ = std::move(job);
  return true;
}

// Labels a posed depth frame from the newest segmentation, carried to it by the poses at the
// two stamps; waits while the segmented frame's pose is still to come.
PerceptionStage::Carried PerceptionStage::carry_labels(BodyCloud& frame,
                                                       const estimation::StampedPose& pose) {
  auto& figures = stage_.figures();
  const common::Stamp stamp = frame.cloud.stamp;
  if (!newest_ ||
      std::abs(common::seconds_between(stamp, newest_->stamp)) > rate_.max_label_age_s) {
    ++figures.labels_too_old;
    return Carried::kDropped;
  }
  const auto segmented = poses_.at(newest_->stamp);
  if (segmented.status == SharedPoseHistory::Status::kPending) return Carried::kWaitForPose;
  if (segmented.status != SharedPoseHistory::Status::kPosed) {
    ++figures.without_pose;
    return Carried::kDropped;
  }
  try {
    const auto t0 = std::chrono::steady_clock::now();
    frame.cloud = perception::cloud_from_carried_labels(
        frame.unlabelled_depth_m, newest_->segmentation, newest_->depth_m,
        perception::segmented_from_current(segmented.pose.world_from_body(), pose.world_from_body(),
                                           body_from_optical_),
        camera_.intrinsics, body_from_optical_, depth_.points, rate_.carry, figures.dropped);
    points_time_.record(seconds_since(t0));
  } catch (const std::exception& e) {
    reject("frame " + std::to_string(frame.sequence), e.what());
    return Carried::kDropped;
  }
  frame.cloud.stamp = stamp;
  if (newest_->sequence != frame.sequence) ++figures.carried;
  return Carried::kLabelled;
}

void PerceptionStage::process(const common::ImageFrame& colour, const common::ImageFrame* depth) {
  cv::Mat image = colour_image(colour);
  if (image.empty()) return;
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
        return reject(frame_name(*depth), "depth frame is not Z16");
      }
      const cv::Mat z16 = drivers::to_mat(*depth, jpeg_);
      if (z16.empty()) return reject(frame_name(*depth), "truncated depth frame");
      depth_m = perception::depth_metres(z16, depth_.depth_scale);
    }
    if (network_) return hand_to_network(colour, image, depth_m);
    const perception::Segmentation segmentation = segment(colour, image);
    const auto t0 = std::chrono::steady_clock::now();
    common::LabeledCloud cloud =
        perception::cloud_from_depth(depth_m, segmentation, intrinsics, body_from_optical,
                                     depth_.points, stage_.figures().dropped);
    points_time_.record(seconds_since(t0));
    queue_for_pose(std::move(cloud), colour.stamp, colour.sequence);
  } catch (const std::exception& e) {
    reject(frame_name(colour), e.what());
  }
}

void PerceptionStage::process_scan(const common::PointScan& scan,
                                   const common::ImageFrame* colour) {
  auto& drops = stage_.figures().dropped;
  const LidarConfig& lidar = depth_.lidar;
  try {
    common::LabeledCloud cloud;
    if (colour) {
      const cv::Mat image = colour_image(*colour);
      if (image.empty()) return;
      const perception::Segmentation segmentation = segment(*colour, image);
      const auto t0 = std::chrono::steady_clock::now();
      cloud = perception::label_lidar_points(scan.points, segmentation, lidar.camera,
                                             lidar.body_from_lidar, depth_.points, drops);
      points_time_.record(seconds_since(t0));
    } else {
      const auto t0 = std::chrono::steady_clock::now();
      cloud = perception::occupied_lidar_points(scan.points, segmenter_->num_classes(),
                                                lidar.body_from_lidar, depth_.points, drops);
      points_time_.record(seconds_since(t0));
    }
    queue_for_pose(std::move(cloud), scan.stamp, scan.sequence);
  } catch (const std::exception& e) {
    reject(scan_name(scan), e.what());
  }
}

void PerceptionStage::share_stats() { stage_.share(); }

}  // namespace semap::onboard
