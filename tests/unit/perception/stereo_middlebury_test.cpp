// The stereo path on a real rectified pair with ground truth: Middlebury 2006 "Aloe"
// (../shared/data/real/middlebury_aloe, its README: 1282x1110, rows aligned, aloeGT.png 8-bit
// disparity of the left image in pixels, 0 = unknown, x_right = x_left - d). StereoDepth with
// its default options computes depth; with fx and baseline of our choosing the disparity comes
// back as d = fx B / Z, which the test scores against the ground truth: the bad-pixel rate, the
// share of known ground-truth pixels where |d - gt| > 2 px or no disparity came out.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "dataset_test_data.hpp"
#include "semap/perception/stereo_depth.hpp"

namespace semap::perception {
namespace {

namespace fs = std::filesystem;

// No metric calibration comes with the pair: any focal length and baseline give the same
// disparity back (d = fx B / Z = fx B / (fx B / d)); these are only plausible numbers.
constexpr float kFocal = 1000.0f;
constexpr float kBaseline = 0.1f;
constexpr double kBadThresholdPx = 2.0;

struct Score {
  double bad = 0.0;        // share of known pixels: |d - gt| > 2 px, or no disparity
  double bad_found = 0.0;  // the same over the known pixels that have a disparity
  double found = 0.0;      // share of known pixels with a disparity
};

// `disparity`: CV_32FC1 in pixels, <= 0 where there is none; `gt`: CV_8UC1, 0 = unknown.
// `reach` > 0: only pixels the search range can match (gt < reach, column >= reach).
Score score(const cv::Mat& disparity, const cv::Mat& gt, int reach = 0) {
  std::size_t known = 0;
  std::size_t found = 0;
  std::size_t bad = 0;
  std::size_t bad_found = 0;
  for (int v = 0; v < gt.rows; ++v) {
    for (int u = 0; u < gt.cols; ++u) {
      const int g = gt.at<std::uint8_t>(v, u);
      if (g == 0 || (reach > 0 && (g >= reach || u < reach))) continue;
      ++known;
      const float d = disparity.at<float>(v, u);
      if (d <= 0.0f) {
        ++bad;
        continue;
      }
      ++found;
      if (std::abs(d - g) > kBadThresholdPx) {
        ++bad;
        ++bad_found;
      }
    }
  }
  Score s;
  s.bad = static_cast<double>(bad) / static_cast<double>(known);
  s.bad_found = found > 0 ? static_cast<double>(bad_found) / static_cast<double>(found) : 1.0;
  s.found = static_cast<double>(found) / static_cast<double>(known);
  return s;
}

// Mean |left(u, v) - right(u - s gt, v)| over known pixels that stay in the image: the
// photometric error of the ground truth read at scale `s`.
double warp_error(const cv::Mat& left, const cv::Mat& right, const cv::Mat& gt, double s) {
  double sum = 0.0;
  std::size_t n = 0;
  for (int v = 0; v < gt.rows; ++v) {
    for (int u = 0; u < gt.cols; ++u) {
      const int g = gt.at<std::uint8_t>(v, u);
      const int ur = u - static_cast<int>(std::lround(s * g));
      if (g == 0 || ur < 0) continue;
      sum += std::abs(left.at<std::uint8_t>(v, u) - right.at<std::uint8_t>(v, ur));
      ++n;
    }
  }
  return sum / static_cast<double>(n);
}

TEST(StereoMiddlebury, AloeBadPixelRate) {
  const fs::path dir = testing::real_data("middlebury_aloe");
  if (!fs::exists(dir)) GTEST_SKIP() << testing::absent(dir);
  const cv::Mat left = cv::imread((dir / "aloeL.jpg").string(), cv::IMREAD_COLOR);
  const cv::Mat right = cv::imread((dir / "aloeR.jpg").string(), cv::IMREAD_COLOR);
  const cv::Mat gt = cv::imread((dir / "aloeGT.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(left.empty() || right.empty() || gt.empty()) << dir;
  ASSERT_EQ(left.size(), cv::Size(1282, 1110));
  ASSERT_EQ(right.size(), left.size());
  ASSERT_EQ(gt.size(), left.size());
  ASSERT_EQ(gt.type(), CV_8UC1);

  cv::Mat left_grey;
  cv::Mat right_grey;
  cv::cvtColor(left, left_grey, cv::COLOR_BGR2GRAY);
  cv::cvtColor(right, right_grey, cv::COLOR_BGR2GRAY);
  // The ground truth is at the images' scale: read as pixels it matches the right image far
  // better than at half or double scale.
  const double e1 = warp_error(left_grey, right_grey, gt, 1.0);
  const double e_half = warp_error(left_grey, right_grey, gt, 0.5);
  const double e_double = warp_error(left_grey, right_grey, gt, 2.0);
  double gt_max = 0.0;
  cv::minMaxLoc(gt, nullptr, &gt_max);
  std::printf(
      "aloe ground truth: max %.0f px; mean |L - R| along it %.1f, at half %.1f, at double %.1f\n",
      gt_max, e1, e_half, e_double);
  EXPECT_LT(2.0 * e1, e_half);
  EXPECT_LT(2.0 * e1, e_double);

  // The stereo path: one side-by-side frame, images already rectified (no remap, identity
  // rotation), StereoDepth's default options.
  StereoCalibration calib;
  calib.half_size = left.size();
  calib.rectified.width = left.cols;
  calib.rectified.height = left.rows;
  calib.rectified.fx = kFocal;
  calib.rectified.fy = kFocal;
  calib.rectified.cx = 0.5f * static_cast<float>(left.cols - 1);
  calib.rectified.cy = 0.5f * static_cast<float>(left.rows - 1);
  calib.baseline_m = kBaseline;
  StereoDepth stereo(calib);
  cv::Mat frame;
  cv::hconcat(left, right, frame);
  const StereoFrame out = stereo.compute(frame);
  cv::Mat disparity(out.depth.size(), CV_32FC1, cv::Scalar(0));
  for (int v = 0; v < disparity.rows; ++v) {
    for (int u = 0; u < disparity.cols; ++u) {
      const float z = out.depth.at<float>(v, u);
      if (z > 0.0f) disparity.at<float>(v, u) = kFocal * kBaseline / z;
    }
  }
  const Score sgbm = score(disparity, gt);

  // Baselines through the same scoring: OpenCV's plain block matcher (StereoBM, same search
  // range, its default 21-pixel window) and the best constant, the median ground truth.
  const StereoOptions defaults;
  cv::Mat bm16;
  cv::StereoBM::create(defaults.num_disparities, 21)->compute(left_grey, right_grey, bm16);
  cv::Mat bm;
  bm16.convertTo(bm, CV_32F, 1.0 / 16.0);
  const Score block = score(bm, gt);
  std::vector<std::uint8_t> known;
  for (auto it = gt.begin<std::uint8_t>(); it != gt.end<std::uint8_t>(); ++it) {
    if (*it > 0) known.push_back(*it);
  }
  std::nth_element(known.begin(), known.begin() + known.size() / 2, known.end());
  const Score constant =
      score(cv::Mat(gt.size(), CV_32FC1, cv::Scalar(known[known.size() / 2])), gt);

  // The same over the pixels the default search range can match at all: ground truth below
  // num_disparities and a column at or beyond it (SGBM gives the left num_disparities columns
  // no disparity). Aloe reaches 211 px; 4 % of its known pixels lie beyond 128 px and 10 % in
  // the left band, so the whole-image rate counts 14 points that no matcher with these options
  // could get.
  const Score sgbm_reach = score(disparity, gt, defaults.num_disparities);
  const Score block_reach = score(bm, gt, defaults.num_disparities);

  std::printf(
      "aloe bad pixels (|d - gt| > 2 px or no disparity), over known pixels; within reach:\n");
  std::printf(
      "  StereoDepth (SGBM)  %5.1f %%  %5.1f %%  (%.1f %% of known pixels found, %.1f %% of "
      "its disparities bad)\n",
      100 * sgbm.bad, 100 * sgbm_reach.bad, 100 * sgbm.found, 100 * sgbm.bad_found);
  std::printf("  StereoBM, 21 px     %5.1f %%  %5.1f %%  (%.1f %% found)\n", 100 * block.bad,
              100 * block_reach.bad, 100 * block.found);
  std::printf("  constant %3d px     %5.1f %%\n", known[known.size() / 2], 100 * constant.bad);

  // Bounds: measured (OpenCV 4.6, Debian 12, x86-64) 25.3 % over known pixels and 13.1 %
  // within reach, the same with 1, 2 and 8 OpenCV threads. The margins (about 5 and 3 points)
  // leave room for another OpenCV build's SIMD paths or JPEG decoder, not for a real loss: the
  // plain block matcher scores 35.4 % / 24.7 % and the best constant 89 % in this very test, so
  // depth that regressed to block-matching quality, or halves swapped, a wrong disparity scale
  // or a shifted column would fail.
  constexpr double kMaxBad = 0.30;
  constexpr double kMaxBadWithinReach = 0.16;
  EXPECT_LE(sgbm.bad, kMaxBad);
  EXPECT_LE(sgbm_reach.bad, kMaxBadWithinReach);
  // The bounds tell the stereo path from the naive baselines (else they would prove nothing).
  EXPECT_GT(block.bad, kMaxBad);
  EXPECT_GT(block_reach.bad, kMaxBadWithinReach);
  EXPECT_GT(constant.bad, kMaxBad);
}

}  // namespace
}  // namespace semap::perception
