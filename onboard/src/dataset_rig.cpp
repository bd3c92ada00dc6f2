#include "semap/onboard/dataset_rig.hpp"

#include <chrono>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

#include "semap/common/logging.hpp"
#include "semap/drivers/frame_convert.hpp"
#include "semap/perception/datasets/velodyne_bin.hpp"

namespace semap::onboard {

namespace {

std::vector<DatasetFrame> rgbd_frames(const perception::datasets::RgbdSequence& sequence,
                                      const Eigen::Isometry3f& body_from_optical) {
  const Eigen::Isometry3d optical_from_body = body_from_optical.cast<double>().inverse();
  std::vector<DatasetFrame> frames;
  frames.reserve(sequence.frames.size());
  for (const auto& f : sequence.frames) {
    frames.push_back({f.colour, f.depth, {}, f.world_from_camera * optical_from_body});
  }
  return frames;
}

std::vector<DatasetFrame> lidar_frames(const perception::datasets::KittiOdometrySequence& sequence,
                                       const Eigen::Isometry3f& body_from_lidar) {
  const Eigen::Isometry3d lidar_from_body = body_from_lidar.cast<double>().inverse();
  std::vector<DatasetFrame> frames;
  frames.reserve(sequence.frames.size());
  for (const auto& f : sequence.frames) {
    frames.push_back({f.image.value_or(std::filesystem::path{}),
                      {},
                      f.scan,
                      f.world_from_lidar * lidar_from_body});
  }
  return frames;
}

}  // namespace

DatasetRig::DatasetRig(perception::datasets::RgbdSequence sequence, std::string name,
                       const Eigen::Isometry3f& body_from_optical, DatasetSelection selection,
                       const SensorRings& rings)
    : DatasetRig(rgbd_frames(sequence, body_from_optical), std::move(sequence.problems),
                 std::move(name), selection, rings) {}

DatasetRig::DatasetRig(const perception::datasets::KittiOdometrySequence& sequence,
                       std::string name, const Eigen::Isometry3f& body_from_lidar,
                       DatasetSelection selection, const SensorRings& rings)
    : DatasetRig(lidar_frames(sequence, body_from_lidar), sequence.problems, std::move(name),
                 selection, rings) {}

DatasetRig::DatasetRig(std::vector<DatasetFrame> frames,
                       std::vector<perception::datasets::InputProblem> reader_problems,
                       std::string name, DatasetSelection selection, const SensorRings& rings)
    : frames_(std::move(frames)),
      reader_problems_(reader_problems.size()),
      name_(std::move(name)),
      rings_(rings),
      problems_(std::move(reader_problems)) {
  if (selection.stride == 0) throw std::invalid_argument("dataset: stride must be at least 1");
  for (std::size_t i = selection.first; i < frames_.size() && i <= selection.last;
       i += selection.stride) {
    selected_.push_back(i);
    has_colour_ = has_colour_ || !frames_[i].colour.empty();
    has_scans_ = has_scans_ || !frames_[i].scan.empty();
  }
}

DatasetRig::~DatasetRig() { stop(); }

std::string DatasetRig::describe() const {
  return "on the dataset " + name_ + " (" + std::to_string(selected_.size()) + " of " +
         std::to_string(frames_.size()) + " frames)";
}

void DatasetRig::set_taps(RawTaps) {
  throw std::invalid_argument("a dataset has no raw device streams to record");
}

void DatasetRig::start() {
  thread_ = std::jthread([this](std::stop_token stop) { run(stop); });
}

void DatasetRig::stop() {
  if (thread_.joinable()) {
    thread_.request_stop();
    thread_.join();
  }
}

void DatasetRig::summary(std::vector<std::string>& lines) const {
  std::size_t unreadable = 0;
  {
    std::lock_guard lock(mutex_);
    unreadable = problems_.size() - reader_problems_;
  }
  lines.push_back("dataset          : " + name_ + ", " + std::to_string(handed_over()) + " of " +
                  std::to_string(selected_.size()) + " selected frames handed over, " +
                  std::to_string(unreadable) + " unreadable, " + std::to_string(reader_problems_) +
                  " skipped by the reader");
}

std::vector<perception::datasets::InputProblem> DatasetRig::problems() const {
  std::lock_guard lock(mutex_);
  return problems_;
}

void DatasetRig::problem(const std::filesystem::path& file, const std::string& what) {
  common::logger("dataset")->warn("{}: {}", file.string(), what);
  std::lock_guard lock(mutex_);
  problems_.push_back({file.string(), what});
}

void DatasetRig::run(std::stop_token stop) {
  HandedOver handed;
  std::uint32_t sequence = 0;
  // Reads the next frame while the stages work on this one.
  std::optional<Loaded> next;
  auto position = selected_.begin();
  const auto load_next = [&] {
    next.reset();
    while (!next && position != selected_.end() && !stop.stop_requested()) {
      next = load(frames_[*position++]);
    }
  };
  load_next();
  while (next && !stop.stop_requested()) {
    Loaded frame = std::move(*next);
    hand_over(frame, sequence++);
    ++handed.frames;
    handed_.store(static_cast<std::size_t>(handed.frames), std::memory_order_release);
    load_next();
    // Frame by frame: the rings drop their oldest entries when full, and the perception stage
    // passes over all but the newest frame it holds.
    while (taken_ && !taken_(handed) && !stop.stop_requested()) {
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
  }
  finished_.store(true, std::memory_order_release);
}

std::optional<DatasetRig::Loaded> DatasetRig::load(const DatasetFrame& frame) {
  // Scans are labelled with their image; a scan without one would wait for it forever.
  if (has_colour_ && !frame.scan.empty() && frame.colour.empty()) {
    problem(frame.scan, "no image to label the scan with");
    return std::nullopt;
  }
  Loaded loaded;
  loaded.world_from_body = frame.world_from_body;
  if (!frame.colour.empty()) {
    loaded.colour = cv::imread(frame.colour.string(), cv::IMREAD_COLOR);
    if (loaded.colour.empty()) {
      problem(frame.colour, "cannot read the colour image");
      return std::nullopt;
    }
  }
  if (!frame.depth.empty()) {
    loaded.depth = cv::imread(frame.depth.string(), cv::IMREAD_UNCHANGED);
    if (loaded.depth.empty()) {
      problem(frame.depth, "cannot read the depth image");
      return std::nullopt;
    }
    if (loaded.depth.type() != CV_16UC1) {
      problem(frame.depth, "the depth image is not 16-bit single-channel");
      return std::nullopt;
    }
    if (loaded.depth.size() != loaded.colour.size()) {
      problem(frame.depth, "the depth image's size differs from the colour image's");
      return std::nullopt;
    }
  }
  if (!frame.scan.empty()) {
    try {
      const auto points = perception::datasets::read_velodyne_bin(frame.scan);
      common::PointScan scan;
      scan.points.reserve(points.size());
      for (const Eigen::Vector4f& p : points) scan.points.push_back(p.head<3>());
      loaded.scan = std::move(scan);
    } catch (const perception::datasets::DatasetError& e) {
      problem(frame.scan, e.what());
      return std::nullopt;
    }
  }
  return loaded;
}

void DatasetRig::hand_over(Loaded& frame, std::uint32_t sequence) {
  const common::Stamp stamp = common::Stamp::now();
  estimation::StampedPose pose;
  pose.stamp = stamp;
  pose.orientation = Eigen::Quaterniond(frame.world_from_body.linear()).normalized();
  pose.position = frame.world_from_body.translation();
  rings_.poses.append(std::span(&pose, 1));
  if (!frame.depth.empty()) {
    rings_.depth.try_push(
        drivers::to_frame(frame.depth, common::PixelFormat::kZ16, stamp, sequence));
  }
  if (frame.scan) {
    frame.scan->stamp = stamp;
    frame.scan->sequence = sequence;
    rings_.scans.try_push(std::move(*frame.scan));
  }
  if (!frame.colour.empty()) {
    rings_.colour.try_push(
        drivers::to_frame(frame.colour, common::PixelFormat::kBgr24, stamp, sequence));
  }
}

}  // namespace semap::onboard
