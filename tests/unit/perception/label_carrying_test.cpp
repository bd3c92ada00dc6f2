// Labels carried by the pose from a segmented view to a depth frame of a moved camera, on a
// ray-traced scene whose labels are known in every view: a wall with a panel in front of it.
#include "semap/perception/label_carrying.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace semap::perception {
namespace {

constexpr int kWidth = 80;
constexpr int kHeight = 60;
constexpr int kClasses = 4;
constexpr std::uint16_t kWall = 1;
constexpr std::uint16_t kPanel = 2;
constexpr float kWallZ = 10.0f;  // the wall: z = 10 in the segmented camera's frame
constexpr float kPanelZ = 6.0f;  // the panel: z = 6, |x| <= 1, |y| <= 1
constexpr float kPanelHalf = 1.0f;

PinholeIntrinsics intrinsics() {
  return PinholeIntrinsics::from_fov(kWidth, kHeight, std::numbers::pi_v<float> / 2);
}

// What a camera at `scene_from_camera` (optical frames) sees: z-depth and label per pixel.
struct View {
  cv::Mat depth_m;
  Segmentation segmentation;
};

View render(const Eigen::Isometry3f& scene_from_camera) {
  const PinholeIntrinsics k = intrinsics();
  View view;
  view.depth_m = cv::Mat(kHeight, kWidth, CV_32FC1, cv::Scalar(0.0f));
  view.segmentation.num_classes = kClasses;
  view.segmentation.labels = cv::Mat(kHeight, kWidth, CV_16UC1, cv::Scalar(kNoLabel));
  view.segmentation.confidence = cv::Mat(kHeight, kWidth, CV_32FC1, cv::Scalar(1.0f));
  const Eigen::Vector3f o = scene_from_camera.translation();
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      // The ray o + t d, with d the pixel's ray (z = 1 in the camera): t is the z-depth.
      const Eigen::Vector3f d =
          scene_from_camera.linear() * k.ray(static_cast<float>(u), static_cast<float>(v));
      const auto hit = [&](float plane_z) { return (plane_z - o.z()) / d.z(); };
      const float t_panel = hit(kPanelZ);
      const Eigen::Vector3f on_panel = o + t_panel * d;
      if (t_panel > 0.0f && std::abs(on_panel.x()) <= kPanelHalf &&
          std::abs(on_panel.y()) <= kPanelHalf) {
        view.depth_m.at<float>(v, u) = t_panel;
        view.segmentation.labels.at<std::uint16_t>(v, u) = kPanel;
      } else if (hit(kWallZ) > 0.0f) {
        view.depth_m.at<float>(v, u) = hit(kWallZ);
        view.segmentation.labels.at<std::uint16_t>(v, u) = kWall;
      }
    }
  }
  return view;
}

// The segmented camera at the scene's origin; the current one 2 m to the right and turned 5
// degrees: it sees wall the panel hid from the segmented camera, and wall beyond its image.
Eigen::Isometry3f current_pose() {
  Eigen::Isometry3f t = Eigen::Isometry3f::Identity();
  t.linear() =
      Eigen::AngleAxisf(5.0f * std::numbers::pi_v<float> / 180.0f, Eigen::Vector3f::UnitY())
          .toRotationMatrix();
  t.translation() = Eigen::Vector3f(2.0f, 0.0f, 0.0f);
  return t;
}

// A wall point (segmented frame) that the panel hid from the segmented camera.
bool hidden_from_segmented(const Eigen::Vector3f& q) {
  const float s = kPanelZ / q.z();
  return q.z() > kPanelZ + 1.0f && std::abs(q.x() * s) <= kPanelHalf &&
         std::abs(q.y() * s) <= kPanelHalf;
}

bool outside_segmented_image(const Eigen::Vector3f& q) {
  const PinholeIntrinsics k = intrinsics();
  const float u = k.fx * q.x() / q.z() + k.cx;
  const float v = k.fy * q.y() / q.z() + k.cy;
  return u < -0.5f || v < -0.5f || u >= kWidth - 0.5f || v >= kHeight - 0.5f;
}

class LabelCarryingTest : public ::testing::Test {
 protected:
  const PinholeIntrinsics k_ = intrinsics();
  const Eigen::Isometry3f moved_ = current_pose();
  const View segmented_ = render(Eigen::Isometry3f::Identity());
  const View current_ = render(moved_);
  // The body frame is the optical frame here: the cloud's points are in the current camera.
  const Eigen::Isometry3f body_from_optical_ = Eigen::Isometry3f::Identity();
  PointOptions options_;
  CarryOptions carry_;
  DropCounts drops_;

  common::LabeledCloud carry() {
    options_.max_range = 100.0f;
    return cloud_from_carried_labels(current_.depth_m, segmented_.segmentation, segmented_.depth_m,
                                     moved_, k_, body_from_optical_, options_, carry_, drops_);
  }
};

TEST_F(LabelCarryingTest, CarriedLabelsAreTheLabelsOfTheNewView) {
  const common::LabeledCloud cloud = carry();
  ASSERT_TRUE(cloud.probabilities.empty());
  ASSERT_EQ(cloud.labels.size(), cloud.size());
  ASSERT_GT(cloud.size(), static_cast<std::size_t>(kWidth * kHeight / 2));
  std::size_t wrong = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f& p = cloud.points[i];
    const int u = static_cast<int>(std::lround(k_.fx * p.x() / p.z() + k_.cx));
    const int v = static_cast<int>(std::lround(k_.fy * p.y() / p.z() + k_.cy));
    ASSERT_GE(u, 0);
    ASSERT_LT(u, kWidth);
    ASSERT_GE(v, 0);
    ASSERT_LT(v, kHeight);
    if (cloud.labels[i] != current_.segmentation.labels.at<std::uint16_t>(v, u)) ++wrong;
  }
  // Only the panel's outline can round to the other class (one pixel each side).
  EXPECT_LE(wrong, static_cast<std::size_t>(2 * (kWidth + kHeight) / 10)) << wrong;
  std::size_t panel = 0;
  for (const std::uint16_t label : cloud.labels) panel += label == kPanel;
  EXPECT_GT(panel, 50u);  // both classes were carried, not only the wall
}

TEST_F(LabelCarryingTest, PixelsTheSegmentedViewDidNotSeeGetNoLabel) {
  const common::LabeledCloud cloud = carry();
  // Ground truth: the current view's pixels behind the panel or outside the segmented image.
  std::uint64_t hidden = 0;
  std::uint64_t outside = 0;
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      const float z = current_.depth_m.at<float>(v, u);
      const Eigen::Vector3f q = moved_ * (k_.ray(static_cast<float>(u), static_cast<float>(v)) * z);
      if (outside_segmented_image(q)) {
        ++outside;
      } else if (hidden_from_segmented(q)) {
        ++hidden;
      }
    }
  }
  ASSERT_GT(hidden, 50u);
  ASSERT_GT(outside, 100u);
  for (const Eigen::Vector3f& p : cloud.points) {
    const Eigen::Vector3f q = moved_ * p;
    EXPECT_FALSE(hidden_from_segmented(q)) << p.transpose();
    EXPECT_FALSE(outside_segmented_image(q)) << p.transpose();
  }
  // Counted by reason, give or take the pixels whose projection rounds across the border.
  EXPECT_NEAR(static_cast<double>(drops_.occluded), static_cast<double>(hidden),
              0.1 * static_cast<double>(hidden));
  EXPECT_NEAR(static_cast<double>(drops_.out_of_image), static_cast<double>(outside),
              static_cast<double>(kHeight));
  EXPECT_EQ(cloud.size() + drops_.total(), static_cast<std::size_t>(kWidth * kHeight));
}

TEST_F(LabelCarryingTest, WithoutTheOcclusionTestHiddenWallTakesThePanelsLabel) {
  // What the depth comparison prevents: the tolerance opened wide, hidden wall is labelled.
  carry_.depth_tolerance_m = 100.0f;
  const common::LabeledCloud cloud = carry();
  EXPECT_EQ(drops_.occluded, 0u);
  std::size_t hidden_as_panel = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    hidden_as_panel += hidden_from_segmented(moved_ * cloud.points[i]) && cloud.labels[i] == kPanel;
  }
  EXPECT_GT(hidden_as_panel, 50u);
}

TEST_F(LabelCarryingTest, RelativePoseOfTheOpticalFramesFromTheBodyPoses) {
  // A world point seen from two body poses through a mounted camera: (1) takes its coordinates
  // in the current optical frame to those in the segmented one.
  Eigen::Isometry3f mount = Eigen::Isometry3f::Identity();
  mount.linear() = optical_to_flu();
  mount.translation() = Eigen::Vector3f(0.3f, 0.0f, 1.5f);
  Eigen::Isometry3f body_s = Eigen::Isometry3f::Identity();
  body_s.translation() = Eigen::Vector3f(100.0f, -50.0f, 2.0f);
  body_s.linear() = Eigen::AngleAxisf(0.3f, Eigen::Vector3f::UnitZ()).toRotationMatrix();
  Eigen::Isometry3f body_t = body_s;
  body_t.translation() += Eigen::Vector3f(0.5f, 0.2f, 0.0f);
  body_t.linear() = Eigen::AngleAxisf(0.4f, Eigen::Vector3f::UnitZ()).toRotationMatrix();
  const Eigen::Vector3f world(110.0f, -47.0f, 0.5f);
  const Eigen::Vector3f in_s = (body_s * mount).inverse() * world;
  const Eigen::Vector3f in_t = (body_t * mount).inverse() * world;
  EXPECT_LT((perception::segmented_from_current(body_s, body_t, mount) * in_t - in_s).norm(),
            1e-4f);
}

TEST_F(LabelCarryingTest, ImagesOfAnotherSizeThrow) {
  const cv::Mat small(kHeight / 2, kWidth / 2, CV_32FC1, cv::Scalar(1.0f));
  EXPECT_THROW(cloud_from_carried_labels(small, segmented_.segmentation, segmented_.depth_m, moved_,
                                         k_, body_from_optical_, options_, carry_, drops_),
               std::invalid_argument);
}

}  // namespace
}  // namespace semap::perception
