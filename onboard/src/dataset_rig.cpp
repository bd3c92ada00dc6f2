#include "semap/onboard/dataset_rig.hpp"

#include <chrono>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

#include "semap/common/logging.hpp"
#include "semap/drivers/frame_convert.hpp"

namespace semap::onboard {

DatasetRig::DatasetRig(perception::datasets::RgbdSequence sequence, std::string name,
                       const Eigen::Isometry3f& body_from_optical, DatasetSelection selection,
                       const SensorRings& rings)
    : sequence_(std::move(sequence)),
      name_(std::move(name)),
      optical_from_body_(body_from_optical.cast<double>().inverse()),
      rings_(rings),
      problems_(sequence_.problems) {
  if (selection.stride == 0) throw std::invalid_argument("dataset: stride must be at least 1");
  const std::size_t end = std::min(selection.last, sequence_.frames.size() - 1);
  for (std::size_t i = selection.first; i <= end && i < sequence_.frames.size();
       i += selection.stride) {
    selected_.push_back(i);
  }
}

DatasetRig::~DatasetRig() { stop(); }

std::string DatasetRig::describe() const {
  return "on the dataset " + name_ + " (" + std::to_string(selected_.size()) + " of " +
         std::to_string(sequence_.frames.size()) + " frames)";
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
    unreadable = problems_.size() - sequence_.problems.size();
  }
  lines.push_back("dataset          : " + name_ + ", " + std::to_string(handed_over()) + " of " +
                  std::to_string(selected_.size()) + " selected frames handed over, " +
                  std::to_string(unreadable) + " unreadable, " +
                  std::to_string(sequence_.problems.size()) + " skipped by the reader");
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
  for (const std::size_t index : selected_) {
    if (stop.stop_requested()) break;
    if (!hand_over(sequence_.frames[index], sequence++)) continue;
    ++handed.colour_frames;
    handed_.store(static_cast<std::size_t>(handed.colour_frames), std::memory_order_release);
    // Frame by frame: the rings drop their oldest entries when full, and the perception stage
    // passes over all but the newest frame it holds.
    while (taken_ && !taken_(handed) && !stop.stop_requested()) {
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
  }
  finished_.store(true, std::memory_order_release);
}

bool DatasetRig::hand_over(const perception::datasets::RgbdFrame& frame, std::uint32_t sequence) {
  const cv::Mat colour = cv::imread(frame.colour.string(), cv::IMREAD_COLOR);
  if (colour.empty()) {
    problem(frame.colour, "cannot read the colour image");
    return false;
  }
  const cv::Mat depth = cv::imread(frame.depth.string(), cv::IMREAD_UNCHANGED);
  if (depth.empty()) {
    problem(frame.depth, "cannot read the depth image");
    return false;
  }
  if (depth.type() != CV_16UC1) {
    problem(frame.depth, "the depth image is not 16-bit single-channel");
    return false;
  }
  if (depth.size() != colour.size()) {
    problem(frame.depth, "the depth image's size differs from the colour image's");
    return false;
  }
  const common::Stamp stamp = common::Stamp::now();
  const Eigen::Isometry3d world_from_body = frame.world_from_camera * optical_from_body_;
  estimation::StampedPose pose;
  pose.stamp = stamp;
  pose.orientation = Eigen::Quaterniond(world_from_body.linear()).normalized();
  pose.position = world_from_body.translation();
  rings_.poses.append(std::span(&pose, 1));
  rings_.depth.try_push(drivers::to_frame(depth, common::PixelFormat::kZ16, stamp, sequence));
  rings_.colour.try_push(drivers::to_frame(colour, common::PixelFormat::kBgr24, stamp, sequence));
  return true;
}

}  // namespace semap::onboard
