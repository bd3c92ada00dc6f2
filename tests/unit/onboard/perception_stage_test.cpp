// The onboard perception stage on real rings, a real palette segmenter and a pose history:
// frames in, posed labelled clouds out, every frame that cannot be used counted by reason.
#include "semap/onboard/perception_stage.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <numbers>
#include <thread>

#include "semap/perception/geometry_segmenter.hpp"
#include "semap/perception/palette_segmenter.hpp"

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
constexpr float kDepth = 5.0f;  // metres, every pixel

common::Stamp at(double seconds) { return Stamp::from_seconds(seconds); }

// A colour frame painted with the Cityscapes road colour (map class 1 in the default mapping),
// except its top row, which has an unknown colour.
ImageFrame colour_frame(double t, std::uint32_t sequence) {
  ImageFrame f;
  f.stamp = at(t);
  f.sequence = sequence;
  f.format = common::PixelFormat::kBgr24;
  f.width = kWidth;
  f.height = kHeight;
  f.stride = 3 * kWidth;
  f.data.resize(static_cast<std::size_t>(f.stride) * kHeight);
  for (int i = 0; i < kWidth * kHeight; ++i) {
    const bool top = i < kWidth;
    const std::uint8_t bgr[3] = {static_cast<std::uint8_t>(top ? 1 : 128),
                                 static_cast<std::uint8_t>(top ? 2 : 64),
                                 static_cast<std::uint8_t>(top ? 3 : 128)};
    std::memcpy(f.data.data() + 3 * i, bgr, 3);
  }
  return f;
}

ImageFrame depth_frame(double t, std::uint32_t sequence, int width = kWidth) {
  ImageFrame f;
  f.stamp = at(t);
  f.sequence = sequence;
  f.format = common::PixelFormat::kZ16;
  f.width = static_cast<std::uint32_t>(width);
  f.height = kHeight;
  f.stride = 2 * f.width;
  const auto units = static_cast<std::uint16_t>(kDepth * 1000.0f);
  f.data.resize(static_cast<std::size_t>(f.stride) * kHeight);
  for (std::size_t i = 0; i < f.data.size() / 2; ++i) std::memcpy(&f.data[2 * i], &units, 2);
  return f;
}

// Poses every 10 ms from t0 to t1: driving along x at 2 m/s, facing +x.
std::vector<estimation::StampedPose> drive(double t0, double t1) {
  std::vector<estimation::StampedPose> poses;
  for (double t = t0; t <= t1 + 1e-9; t += 0.01) {
    estimation::StampedPose p;
    p.stamp = at(t);
    p.position = Eigen::Vector3d(2.0 * t, 0.0, 0.0);
    poses.push_back(p);
  }
  return poses;
}

class PerceptionStageTest : public ::testing::Test {
 protected:
  PerceptionStageTest() {
    camera_.driver.width = kWidth;
    camera_.driver.height = kHeight;
    camera_.intrinsics =
        perception::PinholeIntrinsics::from_fov(kWidth, kHeight, std::numbers::pi_v<float> / 2);
    depth_.points.max_range = 20.0f;
  }

  std::unique_ptr<PerceptionStage> make_stage(double max_position_sigma_m = 0.0,
                                              HoldBuffer hold = HoldBuffer(0.0, 0)) {
    perception::PaletteOptions options;
    options.confidence = 0.8f;
    return std::make_unique<PerceptionStage>(
        camera_, depth_,
        std::make_unique<perception::PaletteSegmenter>(perception::cityscapes_palette(), kClasses,
                                                       options),
        colour_, &depth_ring_, nullptr, poses_, clouds_, max_position_sigma_m, SegmentRateConfig{},
        std::move(hold));
  }

  void push_pair(double t, std::uint32_t sequence) {
    colour_.try_push(colour_frame(t, sequence));
    depth_ring_.try_push(depth_frame(t, sequence));
  }

  CameraConfig camera_;
  DepthConfig depth_;
  SpscRing<ImageFrame> colour_{8, OverflowPolicy::kDropOldest};
  SpscRing<ImageFrame> depth_ring_{8, OverflowPolicy::kDropOldest};
  SpscRing<LabeledCloud> clouds_{8, OverflowPolicy::kDropOldest};
  SharedPoseHistory poses_{1024};
};

TEST_F(PerceptionStageTest, PosesLabelledPointsAtTheFrameStamp) {
  auto stage = make_stage();
  const auto poses = drive(1.0, 2.0);
  poses_.append(poses);
  push_pair(1.505, 7);
  ASSERT_TRUE(stage->step());
  LabeledCloud cloud;
  ASSERT_TRUE(clouds_.try_pop(cloud));
  EXPECT_EQ(cloud.stamp, at(1.505));
  // Every pixel but the unknown-colour top row becomes a point.
  ASSERT_EQ(cloud.size(), static_cast<std::size_t>(kWidth * (kHeight - 1)));
  const auto s = stage->stats();
  EXPECT_EQ(s.clouds, 1u);
  EXPECT_EQ(s.dropped.no_label, static_cast<std::uint64_t>(kWidth));
  EXPECT_EQ(s.points, cloud.size());

  // The body was at x = 2 * 1.505 when the frame was taken (interpolated between poses).
  const Eigen::Isometry3f body_from_optical = camera_.body_from_optical();
  const Eigen::Vector3f body(3.01f, 0.0f, 0.0f);
  EXPECT_NEAR((cloud.origin - (body + body_from_optical.translation())).norm(), 0.0f, 1e-4f);
  const auto& k = camera_.intrinsics;
  // First point: pixel (0, 1), the first row with a label.
  const Eigen::Vector3f optical = k.ray(0.0f, 1.0f) * kDepth;
  EXPECT_NEAR((cloud.points.front() - (body + body_from_optical * optical)).norm(), 0.0f, 1e-3f);
  // Soft labels: the palette's confidence on road's map class, the rest spread.
  ASSERT_EQ(cloud.num_classes, kClasses);
  ASSERT_EQ(cloud.probabilities.size(), cloud.size() * kClasses);
  EXPECT_FLOAT_EQ(cloud.probabilities[1], 0.8f);
  EXPECT_FLOAT_EQ(cloud.probabilities[0], 0.0f);
  EXPECT_NEAR(cloud.probabilities[2] + cloud.probabilities[3], 0.2f, 1e-6f);
}

TEST_F(PerceptionStageTest, WaitsForTheFilterToReachTheFrame) {
  auto stage = make_stage();
  poses_.append(drive(1.0, 2.0));
  push_pair(2.5, 1);
  stage->step();
  EXPECT_TRUE(clouds_.empty());  // newer than the filter: held, not dropped
  EXPECT_EQ(stage->stats().without_pose, 0u);
  EXPECT_EQ(stage->pose_wait().percentiles().count, 0u);
  std::this_thread::sleep_for(std::chrono::milliseconds(30));
  poses_.append(drive(2.01, 3.0));
  stage->step();
  LabeledCloud cloud;
  ASSERT_TRUE(clouds_.try_pop(cloud));
  EXPECT_NEAR(cloud.origin.x() - camera_.mount_xyz.x(), 5.0f, 1e-3f);
  // The wait is in the latency phases: from being queued for its pose until posed.
  const auto wait = stage->pose_wait().percentiles();
  EXPECT_EQ(wait.count, 1u);
  EXPECT_GE(wait.max_ms, 30.0f);
  EXPECT_EQ(stage->taken_age().percentiles().count, 1u);
}

TEST_F(PerceptionStageTest, CountsFramesWithoutAPose) {
  auto stage = make_stage();
  push_pair(0.5, 1);  // no filter yet
  stage->step();
  poses_.append(drive(1.0, 2.0));
  push_pair(0.9, 2);  // older than the history
  stage->step();
  EXPECT_TRUE(clouds_.empty());
  EXPECT_EQ(stage->stats().without_pose, 2u);
  EXPECT_EQ(stage->stats().clouds, 0u);
}

// map.hold_seconds: frames taken before the pose history has poses (the heading is not known
// yet) are held, and mapped at their own stamps once poses for them appear (the smoothed ones),
// after the first live frame and one at a time into an empty cloud ring; a frame older than the
// first pose is counted without a pose, and so is one still held when the stage stops.
TEST_F(PerceptionStageTest, HoldsFramesBeforeTheFirstPosesAndMapsThemAtTheirStamps) {
  auto stage = make_stage(0.0, HoldBuffer(10.0, std::size_t{64} << 20));
  push_pair(0.5, 1);  // before any pose
  stage->step();
  push_pair(1.2, 2);
  stage->step();
  push_pair(1.5, 3);
  stage->step();
  EXPECT_TRUE(clouds_.empty());
  auto s = stage->stats();
  EXPECT_EQ(s.held, 3u);
  EXPECT_EQ(s.holding, 3u);
  EXPECT_EQ(s.without_pose, 0u);
  EXPECT_GT(s.hold_bytes_max, 0u);

  poses_.append(drive(2.0, 3.0));  // the heading is known from 2 s
  push_pair(2.5, 4);               // a live frame
  while (stage->step()) {
  }
  push_pair(1.8, 5);  // late, from before 2 s: held too
  while (stage->step()) {
  }
  EXPECT_EQ(stage->stats().held, 4u);
  poses_.set_smoothed(drive(1.0, 2.0));  // later: the smoothed poses of those seconds
  while (stage->step()) {
  }
  std::vector<float> mapped_x;
  LabeledCloud cloud;
  while (clouds_.try_pop(cloud)) {
    mapped_x.push_back(cloud.origin.x() - camera_.mount_xyz.x());
    while (stage->step()) {  // the next held one goes into the emptied ring
    }
  }
  // The live frame first, then the held ones at the poses of their own stamps (x = 2 t).
  ASSERT_EQ(mapped_x.size(), 4u);
  EXPECT_NEAR(mapped_x[0], 5.0f, 1e-3f);
  EXPECT_NEAR(mapped_x[1], 2.4f, 1e-3f);
  EXPECT_NEAR(mapped_x[2], 3.0f, 1e-3f);
  EXPECT_NEAR(mapped_x[3], 3.6f, 1e-3f);
  s = stage->stats();
  EXPECT_EQ(s.clouds, 4u);
  EXPECT_EQ(s.without_pose, 1u);  // the frame at 0.5 s, older than the first pose
  EXPECT_EQ(s.hold_dropped, 1u);
  EXPECT_EQ(s.holding, 0u);
  EXPECT_EQ(s.clouds + s.without_pose, s.frames);
}

// With the heading known at once (a dual-antenna receiver) the smoothed poses come with the
// first live ones: a frame stamped before those but taken after takes its smoothed pose.
TEST_F(PerceptionStageTest, AFrameFromBeforeTheLivePosesTakesItsSmoothedPose) {
  auto stage = make_stage(0.0, HoldBuffer(10.0, std::size_t{64} << 20));
  poses_.set_smoothed(drive(1.0, 2.0));
  poses_.append(drive(2.0, 3.0));
  push_pair(1.5, 1);  // stamped before the live poses, taken after
  while (stage->step()) {
  }
  push_pair(0.5, 2);  // before the smoothed seconds too
  while (stage->step()) {
  }
  LabeledCloud cloud;
  ASSERT_TRUE(clouds_.try_pop(cloud));
  EXPECT_NEAR(cloud.origin.x() - camera_.mount_xyz.x(), 3.0f, 1e-3f);  // x = 2 t
  EXPECT_FALSE(clouds_.try_pop(cloud));
  const auto s = stage->stats();
  EXPECT_EQ(s.clouds, 1u);
  EXPECT_EQ(s.without_pose, 1u);  // the frame at 0.5 s
}

TEST_F(PerceptionStageTest, CountsHeldFramesLeftWhenItStops) {
  auto stage = make_stage(0.0, HoldBuffer(10.0, std::size_t{64} << 20));
  push_pair(0.5, 1);
  push_pair(0.6, 2);
  stage->start();
  while (stage->stats().holding < 1) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  stage->stop();
  const auto s = stage->stats();
  EXPECT_EQ(s.clouds, 0u);
  EXPECT_EQ(s.holding, 0u);
  EXPECT_EQ(s.skipped + s.without_pose, s.frames);
  EXPECT_EQ(s.hold_dropped, s.held);
}

// map.max_position_sigma_m: a frame posed while the filter's position sigma is above the limit
// is dropped and counted; mapping resumes with the first pose below it.
TEST_F(PerceptionStageTest, DropsCloudsPosedTooUncertainly) {
  auto stage = make_stage(1.0);
  auto poses = drive(1.0, 4.0);
  // The sigma grows from 0.2 m to 3.2 m over 1..2.5 s (an outage), then a fix brings it back.
  for (auto& p : poses) {
    const double t = p.stamp.seconds();
    p.position_sigma_m = t < 2.5 ? 0.2 + 2.0 * (t - 1.0) : 0.3;
  }
  poses_.append(poses);
  std::uint32_t sequence = 0;
  for (const double t : {1.2, 1.35, 1.6, 2.0, 2.49, 2.6, 3.0}) {
    push_pair(t, ++sequence);
    while (stage->step()) {
    }
  }
  const auto s = stage->stats();
  EXPECT_EQ(s.uncertain_pose, 3u);  // sigma 1.4, 2.2 and 3.18 m
  EXPECT_EQ(s.clouds, 4u);          // 0.6, 0.9 m; 0.3 m after the fix
  EXPECT_EQ(s.without_pose, 0u);
  std::vector<float> mapped;
  LabeledCloud cloud;
  while (clouds_.try_pop(cloud)) mapped.push_back(static_cast<float>(cloud.stamp.seconds()));
  EXPECT_EQ(mapped, (std::vector<float>{1.2f, 1.35f, 2.6f, 3.0f}));
  // Off (0): every posed frame is mapped whatever the sigma.
  auto unlimited = make_stage(0.0);
  push_pair(2.0, ++sequence);
  while (unlimited->step()) {
  }
  EXPECT_EQ(unlimited->stats().uncertain_pose, 0u);
  EXPECT_EQ(unlimited->stats().clouds, 1u);
}

TEST_F(PerceptionStageTest, TakesTheNewestFrameWhenBehind) {
  auto stage = make_stage();
  poses_.append(drive(1.0, 2.0));
  push_pair(1.1, 1);
  push_pair(1.2, 2);
  push_pair(1.3, 3);
  stage->step();
  LabeledCloud cloud;
  ASSERT_TRUE(clouds_.try_pop(cloud));
  EXPECT_EQ(cloud.stamp, at(1.3));
  EXPECT_FALSE(clouds_.try_pop(cloud));
  EXPECT_EQ(stage->stats().skipped, 2u);
  EXPECT_EQ(stage->stats().frames, 3u);
}

TEST_F(PerceptionStageTest, PairsColourAndDepthByStampWithinTheTolerance) {
  auto stage = make_stage();
  poses_.append(drive(1.0, 2.0));
  colour_.try_push(colour_frame(1.10, 1));
  depth_ring_.try_push(depth_frame(1.15, 1));  // 50 ms off: beyond the 20 ms tolerance
  stage->step();
  EXPECT_TRUE(clouds_.empty());
  colour_.try_push(colour_frame(1.20, 2));
  depth_ring_.try_push(depth_frame(1.21, 2));  // 10 ms off: pairs
  stage->step();
  LabeledCloud cloud;
  ASSERT_TRUE(clouds_.try_pop(cloud));
  EXPECT_EQ(cloud.stamp, at(1.20));
  const auto s = stage->stats();
  // The 1.10 colour frame found no depth in time; the 1.15 depth frame was never used.
  EXPECT_EQ(s.unpaired, 1u);
  EXPECT_EQ(s.skipped, 0u);
  EXPECT_EQ(s.partner_unused, 1u);
  EXPECT_EQ(s.clouds, 1u);
}

TEST_F(PerceptionStageTest, RejectsBadFramesAndKeepsGoing) {
  auto stage = make_stage();
  poses_.append(drive(1.0, 2.0));
  colour_.try_push(colour_frame(1.1, 1));
  depth_ring_.try_push(depth_frame(1.1, 1, kWidth / 2));  // wrong size
  stage->step();
  auto truncated = colour_frame(1.2, 2);
  truncated.data.resize(10);
  colour_.try_push(truncated);
  depth_ring_.try_push(depth_frame(1.2, 2));
  stage->step();
  EXPECT_EQ(stage->stats().bad_frames, 2u);
  EXPECT_TRUE(clouds_.empty());
  push_pair(1.3, 3);
  stage->step();
  EXPECT_EQ(stage->stats().clouds, 1u);
}

TEST_F(PerceptionStageTest, ShowsEachSegmentationToTheObserver) {
  auto stage = make_stage();
  struct Seen {
    std::uint32_t sequence;
    Stamp stamp;
    cv::Mat bgr;
    perception::Segmentation segmentation;
  };
  std::vector<Seen> seen;
  stage->set_observer([&](std::uint32_t sequence, Stamp stamp, const cv::Mat& bgr,
                          const perception::Segmentation& segmentation) {
    seen.push_back({sequence, stamp, bgr.clone(), segmentation});
  });
  push_pair(0.5, 3);  // segmented, then dropped without a pose: the observer still sees it
  stage->step();
  poses_.append(drive(1.0, 2.0));
  push_pair(1.5, 4);
  stage->step();
  ASSERT_EQ(seen.size(), 2u);
  EXPECT_EQ(seen[0].sequence, 3u);
  EXPECT_EQ(seen[1].sequence, 4u);
  EXPECT_EQ(seen[1].stamp, at(1.5));
  ASSERT_EQ(seen[1].bgr.type(), CV_8UC3);
  ASSERT_EQ(seen[1].bgr.size(), cv::Size(kWidth, kHeight));
  EXPECT_EQ(seen[1].bgr.at<cv::Vec3b>(kHeight - 1, 0), cv::Vec3b(128, 64, 128));
  const cv::Mat& labels = seen[1].segmentation.labels;
  ASSERT_EQ(labels.size(), cv::Size(kWidth, kHeight));
  EXPECT_EQ(labels.at<std::uint16_t>(0, 0), perception::kNoLabel);  // the unknown top row
  EXPECT_EQ(labels.at<std::uint16_t>(kHeight - 1, 0), 1);           // road
  // A bad frame is never segmented, so never observed.
  auto truncated = colour_frame(1.6, 5);
  truncated.data.resize(10);
  colour_.try_push(truncated);
  depth_ring_.try_push(depth_frame(1.6, 5));
  stage->step();
  EXPECT_EQ(seen.size(), 2u);
}

TEST_F(PerceptionStageTest, RefusesAlignedDepthWithoutADepthRing) {
  EXPECT_THROW(PerceptionStage(camera_, depth_,
                               std::make_unique<perception::PaletteSegmenter>(
                                   perception::cityscapes_palette(), kClasses),
                               colour_, nullptr, nullptr, poses_, clouds_),
               std::invalid_argument);  // aligned depth without a depth ring
}

// LiDAR mode: a KITTI-like mount (camera looking along the LiDAR's x axis) with a 32x24 image.
class LidarStageTest : public PerceptionStageTest {
 protected:
  LidarStageTest() {
    depth_.source = DepthSource::kLidar;
    auto& calib = depth_.lidar.camera;
    calib.image_size = cv::Size(kWidth, kHeight);
    calib.p_rect << 16, 0, 16, 0, 0, 16, 12, 0, 0, 0, 1, 0;
    // LiDAR x forward, y left, z up -> camera x right, y down, z forward.
    calib.cam_from_lidar.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
    depth_.lidar.body_from_lidar.translation() = Eigen::Vector3f(0.0f, 0.0f, 1.7f);
  }

  std::unique_ptr<PerceptionStage> make_lidar_stage(bool labels) {
    std::unique_ptr<perception::Segmenter> segmenter;
    if (labels) {
      segmenter = std::make_unique<perception::PaletteSegmenter>(perception::cityscapes_palette(),
                                                                 kClasses);
    } else {
      segmenter = std::make_unique<perception::GeometrySegmenter>(kClasses);
    }
    return std::make_unique<PerceptionStage>(camera_, depth_, std::move(segmenter), colour_,
                                             nullptr, &scans_, poses_, clouds_);
  }

  // Two points ahead of the LiDAR (in the image's lower half: road) and two behind it.
  static common::PointScan scan(double t, std::uint32_t sequence) {
    common::PointScan s;
    s.stamp = at(t);
    s.sequence = sequence;
    s.points = {
        {10.0f, 0.0f, -1.0f}, {8.0f, 1.0f, -1.0f}, {-10.0f, 0.0f, 0.0f}, {0.0f, 30.0f, 0.0f}};
    return s;
  }

  SpscRing<common::PointScan> scans_{8, OverflowPolicy::kDropOldest};
};

TEST_F(LidarStageTest, LabelsScanPointsWithTheColourFrameNearestInTime) {
  depth_.points.max_range = 20.0f;
  depth_.points.soft_labels = false;
  auto stage = make_lidar_stage(true);
  poses_.append(drive(1.0, 2.0));
  scans_.try_push(scan(1.10, 1));
  colour_.try_push(colour_frame(1.16, 1));  // 60 ms off: no partner
  stage->step();
  EXPECT_TRUE(clouds_.empty());
  scans_.try_push(scan(1.20, 2));
  colour_.try_push(colour_frame(1.21, 2));
  stage->step();
  LabeledCloud cloud;
  ASSERT_TRUE(clouds_.try_pop(cloud));
  EXPECT_EQ(cloud.stamp, at(1.20));  // the scan's stamp
  // The two points ahead, labelled road (class 1), placed with the body pose at 1.20 s.
  ASSERT_EQ(cloud.size(), 2u);
  EXPECT_EQ(cloud.labels, std::vector<std::uint16_t>(2, 1));
  EXPECT_NEAR((cloud.points[0] - Eigen::Vector3f(2.4f + 10.0f, 0.0f, 0.7f)).norm(), 0.0f, 1e-4f);
  EXPECT_NEAR((cloud.origin - Eigen::Vector3f(2.4f, 0.0f, 1.7f)).norm(), 0.0f, 1e-4f);
  const auto s = stage->stats();
  EXPECT_EQ(s.frames, 2u);  // scans
  EXPECT_EQ(s.unpaired, 1u);
  EXPECT_EQ(s.partner_unused, 1u);
  EXPECT_EQ(s.dropped.out_of_image, 1u);  // behind the camera
  EXPECT_EQ(s.dropped.out_of_range, 1u);  // 30 m away
}

TEST_F(LidarStageTest, MapsWholeScansWithoutLabels) {
  depth_.points.max_range = 20.0f;
  auto stage = make_lidar_stage(false);
  poses_.append(drive(1.0, 2.0));
  scans_.try_push(scan(1.5, 1));
  stage->step();
  LabeledCloud cloud;
  ASSERT_TRUE(clouds_.try_pop(cloud));
  // No image needed: every point within range, behind the camera too, as class 1.
  ASSERT_EQ(cloud.size(), 3u);
  EXPECT_EQ(cloud.labels, std::vector<std::uint16_t>(3, 1));
  EXPECT_NEAR((cloud.points[2] - Eigen::Vector3f(3.0f - 10.0f, 0.0f, 1.7f)).norm(), 0.0f, 1e-4f);
  EXPECT_EQ(stage->stats().dropped.out_of_range, 1u);
  EXPECT_EQ(stage->stats().frames, 1u);
}

TEST_F(LidarStageTest, RefusesLidarWithoutAScanRing) {
  EXPECT_THROW(PerceptionStage(camera_, depth_, std::make_unique<perception::GeometrySegmenter>(2),
                               colour_, nullptr, nullptr, poses_, clouds_),
               std::invalid_argument);
}

// The stage's own thread against a producer thread and the pose writer, as on the robot.
TEST_F(PerceptionStageTest, RunsOnItsThreadWhileDriversPush) {
  auto stage = make_stage();
  stage->start();
  std::jthread filter([this] {
    for (int i = 0; i < 50; ++i) {
      poses_.append(drive(1.0 + 0.02 * i, 1.0 + 0.02 * i + 0.019));
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  });
  for (int i = 0; i < 40; ++i) {
    push_pair(1.0 + 0.025 * i, static_cast<std::uint32_t>(i));
    std::this_thread::sleep_for(std::chrono::milliseconds(3));
  }
  filter.join();
  // A stage slower than the pushes (emulated under qemu-user in the arm64 cross build, or on a
  // loaded machine) lets the colour ring drop the oldest frames: every frame pushed is either
  // taken by the stage or counted as dropped by the ring.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (stage->stats().clouds + stage->stats().skipped + stage->stats().without_pose +
                 colour_.counters().drops() <
             40 &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  stage->stop();
  const auto s = stage->stats();
  EXPECT_EQ(s.frames + colour_.counters().drops(), 40u);
  EXPECT_EQ(s.clouds + s.skipped + s.without_pose + colour_.counters().drops(), 40u);
  EXPECT_GT(s.clouds, 0u);
  EXPECT_EQ(s.bad_frames, 0u);
}

}  // namespace
}  // namespace semap::onboard
