#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numeric>

#include "projection_fixtures.hpp"
#include "semap/perception/depth_cloud.hpp"

namespace semap::perception {
namespace {

using fixtures::label_at;
using fixtures::make_segmentation;
using fixtures::probability_at;
using ::testing::AllOf;
using ::testing::HasSubstr;

constexpr int kClasses = 5;

PinholeIntrinsics small_camera(int width, int height, float f) {
  PinholeIntrinsics k;
  k.width = width;
  k.height = height;
  k.fx = f;
  k.fy = f;
  k.cx = (static_cast<float>(width) - 1.0f) / 2.0f;
  k.cy = (static_cast<float>(height) - 1.0f) / 2.0f;
  return k;
}

Eigen::Isometry3f camera_on_mast() {
  Eigen::Isometry3f body_from_optical = Eigen::Isometry3f::Identity();
  body_from_optical.linear() = optical_to_flu();
  body_from_optical.translation() = Eigen::Vector3f(0.2f, -0.1f, 1.2f);
  return body_from_optical;
}

// A tilted plane n . p = d (optical frame) rendered as z-depth, z = d / (n . ray), must come
// back onto the same plane in the body frame.
TEST(CloudFromDepth, TiltedPlaneLandsOnPlane) {
  const PinholeIntrinsics k = small_camera(64, 48, 40.0f);
  const Eigen::Vector3f n = Eigen::Vector3f(0.2f, -0.3f, 1.0f).normalized();
  const float d = 3.0f;
  cv::Mat depth(48, 64, CV_32FC1);
  for (int v = 0; v < 48; ++v) {
    for (int u = 0; u < 64; ++u) {
      depth.at<float>(v, u) = d / n.dot(k.ray(static_cast<float>(u), static_cast<float>(v)));
    }
  }
  const Segmentation seg = make_segmentation(64, 48, kClasses, false);
  const Eigen::Isometry3f body_from_optical = camera_on_mast();
  DropCounts drops;
  const auto cloud = cloud_from_depth(depth, seg, k, body_from_optical, PointOptions{}, drops);

  ASSERT_EQ(cloud.size(), 64u * 48u);
  EXPECT_EQ(drops.total(), 0u);
  EXPECT_EQ(cloud.num_classes, kClasses);
  EXPECT_TRUE(cloud.origin.isApprox(body_from_optical.translation()));
  const Eigen::Vector3f n_body = body_from_optical.linear() * n;
  const float d_body = d + n_body.dot(body_from_optical.translation());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    EXPECT_NEAR(n_body.dot(cloud.points[i]), d_body, 1e-3f) << "point " << i;
    // Row-major order: point i came from pixel (i % 64, i / 64).
    const int u = static_cast<int>(i % 64);
    const int v = static_cast<int>(i / 64);
    EXPECT_EQ(cloud.labels[i], label_at(u, v, kClasses));
  }
  // The principal ray goes straight ahead: body x.
  const Eigen::Vector3f centre = body_from_optical.inverse() * cloud.points[24 * 64 + 32];
  EXPECT_NEAR(centre.x(), 0.5f / 40.0f * centre.z(), 1e-4f);
}

// 8x6 pixels with stride 2 visits 4x3 = 12: each is a point or one counted drop.
TEST(CloudFromDepth, StrideAndEveryDropReasonCountedExactly) {
  const PinholeIntrinsics k = small_camera(8, 6, 4.0f);
  cv::Mat depth(6, 8, CV_32FC1, cv::Scalar(2.0f));
  Segmentation seg = make_segmentation(8, 6, kClasses, false);
  depth.at<float>(0, 0) = 0.0f;                                     // no return
  depth.at<float>(0, 2) = std::numeric_limits<float>::quiet_NaN();  // no return
  depth.at<float>(0, 4) = 100.0f;                                   // beyond max_range
  // z below max_range but the corner ray is longer: range, not z, is compared.
  depth.at<float>(4, 0) = 4.5f;
  seg.labels.at<std::uint16_t>(0, 6) = kNoLabel;
  seg.confidence.at<float>(2, 2) = 0.1f;
  // Pixels the stride skips are neither points nor drops.
  depth.at<float>(1, 1) = 0.0f;
  seg.labels.at<std::uint16_t>(1, 3) = kNoLabel;

  PointOptions options;
  options.stride = 2;
  options.max_range = 5.0f;
  options.min_confidence = 0.5f;
  DropCounts drops;
  const auto cloud = cloud_from_depth(depth, seg, k, Eigen::Isometry3f::Identity(), options, drops);
  EXPECT_EQ(drops.no_depth, 2u);
  EXPECT_EQ(drops.out_of_range, 2u);
  EXPECT_EQ(drops.no_label, 1u);
  EXPECT_EQ(drops.low_confidence, 1u);
  EXPECT_EQ(drops.out_of_image, 0u);
  EXPECT_EQ(cloud.size(), 12u - 6u);
  for (std::size_t i = 0; i < cloud.size(); ++i) EXPECT_NEAR(cloud.points[i].z(), 2.0f, 1e-6f);

  // Drops add up over frames.
  cloud_from_depth(depth, seg, k, Eigen::Isometry3f::Identity(), options, drops);
  EXPECT_EQ(drops.total(), 12u);
}

TEST(DepthMetres, ScalesZ16AndKeepsNoReturn) {
  const cv::Mat z16 = (cv::Mat_<std::uint16_t>(2, 2) << 0, 1000, 65535, 1);
  const cv::Mat m = depth_metres(z16, 0.001f);
  ASSERT_EQ(m.type(), CV_32FC1);
  EXPECT_EQ(m.at<float>(0, 0), 0.0f);
  EXPECT_NEAR(m.at<float>(0, 1), 1.0f, 1e-6f);
  EXPECT_NEAR(m.at<float>(1, 0), 65.535f, 1e-4f);
  EXPECT_NEAR(m.at<float>(1, 1), 0.001f, 1e-9f);
  EXPECT_THROW(depth_metres(cv::Mat(2, 2, CV_32FC1), 0.001f), std::invalid_argument);
  EXPECT_THROW(depth_metres(z16, 0.0f), std::invalid_argument);
}

TEST(CloudFromDepth, CopiesSoftLabelsPerPoint) {
  const PinholeIntrinsics k = small_camera(10, 7, 8.0f);
  const cv::Mat depth(7, 10, CV_32FC1, cv::Scalar(1.5f));
  const Segmentation seg = make_segmentation(10, 7, kClasses, true);
  PointOptions options;
  options.stride = 3;
  DropCounts drops;
  const auto cloud = cloud_from_depth(depth, seg, k, camera_on_mast(), options, drops);
  ASSERT_EQ(cloud.size(), 4u * 3u);
  EXPECT_TRUE(cloud.labels.empty());
  ASSERT_EQ(cloud.probabilities.size(), cloud.size() * kClasses);
  std::size_t i = 0;
  for (int v = 0; v < 7; v += 3) {
    for (int u = 0; u < 10; u += 3, ++i) {
      const float* p = cloud.probabilities.data() + i * kClasses;
      for (int c = 0; c < kClasses; ++c) {
        EXPECT_EQ(p[c], probability_at(u, v, c, kClasses)) << "pixel " << u << "," << v;
      }
      EXPECT_NEAR(std::accumulate(p, p + kClasses, 0.0f), 1.0f, 1e-5f);
    }
  }
}

TEST(CloudFromDepth, HardLabelsWhenSoftIsOff) {
  const PinholeIntrinsics k = small_camera(10, 7, 8.0f);
  const cv::Mat depth(7, 10, CV_32FC1, cv::Scalar(1.5f));
  const Segmentation seg = make_segmentation(10, 7, kClasses, true);
  PointOptions options;
  options.soft_labels = false;
  DropCounts drops;
  const auto cloud = cloud_from_depth(depth, seg, k, camera_on_mast(), options, drops);
  ASSERT_EQ(cloud.size(), 70u);
  EXPECT_FALSE(cloud.has_probabilities());
  ASSERT_EQ(cloud.labels.size(), 70u);
  EXPECT_EQ(cloud.labels[13], label_at(3, 1, kClasses));
}

TEST(CloudFromDepth, SizeMismatchNamesBothSizes) {
  const PinholeIntrinsics k = small_camera(8, 6, 4.0f);
  const cv::Mat depth(6, 8, CV_32FC1, cv::Scalar(1.0f));
  DropCounts drops;
  const auto message = [&](const cv::Mat& d, const Segmentation& s, const PinholeIntrinsics& i) {
    try {
      cloud_from_depth(d, s, i, Eigen::Isometry3f::Identity(), PointOptions{}, drops);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_THAT(message(depth, make_segmentation(8, 5, kClasses, false), k),
              AllOf(HasSubstr("depth 8x6"), HasSubstr("segmentation 8x5")));
  EXPECT_THAT(message(depth, make_segmentation(8, 6, kClasses, false), small_camera(9, 6, 4.0f)),
              AllOf(HasSubstr("depth 8x6"), HasSubstr("intrinsics 9x6")));
}

TEST(CloudFromDepth, RejectsBrokenSegmentations) {
  const PinholeIntrinsics k = small_camera(8, 6, 4.0f);
  const cv::Mat depth(6, 8, CV_32FC1, cv::Scalar(1.0f));
  DropCounts drops;
  const auto throws_naming = [&](const Segmentation& s, const char* what) {
    try {
      cloud_from_depth(depth, s, k, Eigen::Isometry3f::Identity(), PointOptions{}, drops);
    } catch (const std::invalid_argument& e) {
      EXPECT_THAT(e.what(), HasSubstr(what));
      return;
    }
    ADD_FAILURE() << "no error for " << what;
  };
  Segmentation free_space_hit = make_segmentation(8, 6, kClasses, false);
  free_space_hit.labels.at<std::uint16_t>(2, 3) = 0;
  throws_naming(free_space_hit, "labels(3, 2) = 0");
  Segmentation wrong_k = make_segmentation(8, 6, kClasses, true);
  wrong_k.num_classes = kClasses + 1;
  throws_naming(wrong_k, "probabilities");
  Segmentation no_confidence = make_segmentation(8, 6, kClasses, false);
  no_confidence.confidence = cv::Mat();
  throws_naming(no_confidence, "confidence");
}

}  // namespace
}  // namespace semap::perception
