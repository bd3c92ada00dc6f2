// The perception stage with a network slower than the camera (perception.carry_labels): the
// network segments on its own thread as often as it can, every depth frame is mapped with the
// labels of the newest segmentation carried to it, and what cannot be labelled is counted.
#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <numbers>
#include <stdexcept>
#include <thread>

#include "semap/onboard/perception_stage.hpp"

namespace semap::onboard {
namespace {

using common::ImageFrame;
using common::LabeledCloud;
using common::OverflowPolicy;
using common::SpscRing;
using common::Stamp;

constexpr int kWidth = 32;
constexpr int kHeight = 24;
constexpr int kClasses = 4;
constexpr std::uint16_t kLabel = 2;
constexpr double kFrameS = 1.0 / 15.0;

// A network that takes as long as the test says: each segment() waits for a release, then
// labels every pixel kLabel (or throws, when told to).
class GatedSegmenter : public perception::Segmenter {
 public:
  struct Gate {
    std::mutex mutex;
    std::condition_variable cv;
    int releases = 0;
    bool fail = false;
    int started = 0;
  };
  explicit GatedSegmenter(Gate& gate) : gate_(gate) {}

  perception::Segmentation segment(const cv::Mat& bgr) override {
    std::unique_lock lock(gate_.mutex);
    ++gate_.started;
    gate_.cv.notify_all();
    gate_.cv.wait(lock, [&] { return gate_.releases > 0; });
    --gate_.releases;
    if (gate_.fail) throw std::runtime_error("the network fell over");
    perception::Segmentation s;
    s.num_classes = kClasses;
    s.labels = cv::Mat(bgr.size(), CV_16UC1, cv::Scalar(kLabel));
    s.confidence = cv::Mat(bgr.size(), CV_32FC1, cv::Scalar(0.9f));
    return s;
  }
  int num_classes() const override { return kClasses; }
  std::string describe() const override { return "gated test network"; }

 private:
  Gate& gate_;
};

ImageFrame frame(double t, std::uint32_t sequence, bool depth) {
  ImageFrame f;
  f.stamp = Stamp::from_seconds(t);
  f.sequence = sequence;
  f.format = depth ? common::PixelFormat::kZ16 : common::PixelFormat::kBgr24;
  f.width = kWidth;
  f.height = kHeight;
  f.stride = (depth ? 2 : 3) * kWidth;
  f.data.assign(static_cast<std::size_t>(f.stride) * kHeight, 100);
  if (depth) {
    const std::uint16_t mm = 5000;  // a wall 5 m away, every pixel
    for (std::size_t i = 0; i < f.data.size(); i += 2) std::memcpy(&f.data[i], &mm, 2);
  }
  return f;
}

class PerceptionStageCarryTest : public ::testing::Test {
 protected:
  PerceptionStageCarryTest() {
    camera_.driver.width = kWidth;
    camera_.driver.height = kHeight;
    camera_.intrinsics =
        perception::PinholeIntrinsics::from_fov(kWidth, kHeight, std::numbers::pi_v<float> / 2);
    depth_.points.max_range = 20.0f;
    rate_.carry_labels = true;
    rate_.max_label_age_s = 0.5;
    // The robot stands still for 10 s: carried labels land on the pixels they came from.
    std::vector<estimation::StampedPose> poses;
    for (double t = 0.0; t <= 10.0; t += 0.01) {
      estimation::StampedPose p;
      p.stamp = Stamp::from_seconds(t);
      poses.push_back(p);
    }
    poses_.append(poses);
    stage_ = std::make_unique<PerceptionStage>(camera_, depth_,
                                               std::make_unique<GatedSegmenter>(gate_), colour_,
                                               &depth_ring_, nullptr, poses_, clouds_, 0.0, rate_);
  }

  // The network may be waiting at its gate: opened for good, the stage can stop.
  ~PerceptionStageCarryTest() override {
    {
      const std::lock_guard lock(gate_.mutex);
      gate_.releases = 1 << 20;
    }
    gate_.cv.notify_all();
    stage_.reset();
  }

  // Frame `i` of a 15 Hz camera, through one round of the stage.
  void push(std::uint32_t i) {
    colour_.try_push(frame(1.0 + i * kFrameS, i, false));
    depth_ring_.try_push(frame(1.0 + i * kFrameS, i, true));
    stage_->step();
  }
  void release() {
    {
      const std::lock_guard lock(gate_.mutex);
      ++gate_.releases;
    }
    gate_.cv.notify_all();
  }
  // Steps the stage until the network has finished `n` frames (bounded: a hang fails).
  bool step_until_segmented(std::uint64_t n) {
    for (int i = 0; i < 5000 && stage_->stats().segmented + stage_->stats().segment_failures < n;
         ++i) {
      stage_->step();
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return stage_->stats().segmented + stage_->stats().segment_failures >= n;
  }
  void wait_until_started(int n) {
    std::unique_lock lock(gate_.mutex);
    gate_.cv.wait_for(lock, std::chrono::seconds(5), [&] { return gate_.started >= n; });
  }
  std::vector<LabeledCloud> drain() {
    std::vector<LabeledCloud> out;
    LabeledCloud c;
    while (clouds_.try_pop(c)) out.push_back(std::move(c));
    return out;
  }

  CameraConfig camera_;
  DepthConfig depth_;
  SegmentRateConfig rate_;
  GatedSegmenter::Gate gate_;
  SpscRing<ImageFrame> colour_{8, OverflowPolicy::kDropOldest};
  SpscRing<ImageFrame> depth_ring_{8, OverflowPolicy::kDropOldest};
  SpscRing<LabeledCloud> clouds_{32, OverflowPolicy::kDropOldest};
  SharedPoseHistory poses_{2048};
  std::unique_ptr<PerceptionStage> stage_;
};

TEST_F(PerceptionStageCarryTest, EveryFrameIsMappedWithLabelsOfTheNewestSegmentation) {
  push(0);  // the network starts on frame 0; frame 0 has no segmentation yet
  wait_until_started(1);
  release();
  ASSERT_TRUE(step_until_segmented(1));
  // The network is busy on frame 1 (held at its gate) while frames 1..6 arrive: each is mapped
  // with frame 0's labels.
  for (std::uint32_t i = 1; i <= 6; ++i) push(i);
  const auto clouds = drain();
  ASSERT_EQ(clouds.size(), 6u);
  for (std::uint32_t i = 0; i < clouds.size(); ++i) {
    EXPECT_EQ(clouds[i].stamp, Stamp::from_seconds(1.0 + (i + 1) * kFrameS));
    ASSERT_EQ(clouds[i].size(), static_cast<std::size_t>(kWidth * kHeight));
    for (const std::uint16_t label : clouds[i].labels) ASSERT_EQ(label, kLabel);
  }
  const auto s = stage_->stats();
  EXPECT_EQ(s.frames, 7u);
  EXPECT_EQ(s.segmented, 1u);
  EXPECT_EQ(s.carried, 6u);
  EXPECT_EQ(s.labels_too_old, 1u);  // frame 0
  EXPECT_EQ(s.clouds, 6u);
  EXPECT_EQ(s.skipped + s.unpaired + s.without_pose + s.dropped.occluded, 0u);
}

TEST_F(PerceptionStageCarryTest, FramesWhoseSegmentationIsTooOldAreCountedNotMapped) {
  push(0);
  wait_until_started(1);
  release();
  ASSERT_TRUE(step_until_segmented(1));
  // 0.5 s = 7.5 frames: frames 1..7 carry frame 0's labels, 8..11 do not.
  for (std::uint32_t i = 1; i <= 11; ++i) push(i);
  EXPECT_EQ(drain().size(), 7u);
  const auto s = stage_->stats();
  EXPECT_EQ(s.clouds, 7u);
  EXPECT_EQ(s.labels_too_old, 1u + 4u);
  EXPECT_EQ(s.frames, s.clouds + s.labels_too_old);
}

TEST_F(PerceptionStageCarryTest, ANetworkFailureIsCountedAndTheNextFrameSegmented) {
  {
    const std::lock_guard lock(gate_.mutex);
    gate_.fail = true;
  }
  push(0);
  wait_until_started(1);
  release();
  ASSERT_TRUE(step_until_segmented(1));
  EXPECT_EQ(stage_->stats().segment_failures, 1u);
  EXPECT_EQ(stage_->stats().segmented, 0u);
  {
    const std::lock_guard lock(gate_.mutex);
    gate_.fail = false;
  }
  push(1);
  wait_until_started(2);
  release();
  ASSERT_TRUE(step_until_segmented(2));
  push(2);
  EXPECT_EQ(drain().size(), 1u);  // frame 2, with frame 1's labels
  EXPECT_EQ(stage_->stats().segmented, 1u);
}

TEST_F(PerceptionStageCarryTest, SegmentHzHoldsTheNetworkBack) {
  rate_.segment_hz = 2.0;  // one frame in 7.5
  stage_ = std::make_unique<PerceptionStage>(camera_, depth_,
                                             std::make_unique<GatedSegmenter>(gate_), colour_,
                                             &depth_ring_, nullptr, poses_, clouds_, 0.0, rate_);
  {
    const std::lock_guard lock(gate_.mutex);
    gate_.releases = 1000;  // an instant network
  }
  for (std::uint32_t i = 0; i < 30; ++i) {
    push(i);
    ASSERT_TRUE(step_until_segmented(i / 8 + 1));  // frames 0, 8, 16, 24 (0.5 s apart)
  }
  EXPECT_EQ(stage_->stats().segmented, 4u);
}

TEST_F(PerceptionStageCarryTest, CarryingNeedsAlignedDepth) {
  DepthConfig lidar = depth_;
  lidar.source = DepthSource::kLidar;
  SpscRing<common::PointScan> scans{4, OverflowPolicy::kDropOldest};
  EXPECT_THROW(PerceptionStage(camera_, lidar, std::make_unique<GatedSegmenter>(gate_), colour_,
                               nullptr, &scans, poses_, clouds_, 0.0, rate_),
               std::invalid_argument);
}

}  // namespace
}  // namespace semap::onboard
