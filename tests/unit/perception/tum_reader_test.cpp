#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>
#include <opencv2/imgcodecs.hpp>

#include "dataset_test_data.hpp"
#include "semap/perception/datasets/depth_png.hpp"
#include "semap/perception/datasets/tum.hpp"
#include "semap/perception/datasets/tum_files.hpp"
#include "test_files.hpp"

namespace semap::perception::datasets {
namespace {

namespace fs = std::filesystem;
using testing::absent;
using testing::error_of;
using ::testing::HasSubstr;
using testing::real_data;
using testing::TempDir;
using testing::write_text;

// A TUM folder whose listed images are empty files: enough for everything but decoding.
void touch_listed(const fs::path& dir, const std::string& list) {
  for (const TumListEntry& e : parse_tum_list(list, "list").entries) {
    fs::create_directories((dir / e.file).parent_path());
    write_text(dir / e.file, "");
  }
}

void write_tum(const fs::path& dir, const std::string& rgb, const std::string& depth,
               const std::string& truth) {
  write_text(dir / "rgb.txt", rgb);
  write_text(dir / "depth.txt", depth);
  write_text(dir / "groundtruth.txt", truth);
  touch_listed(dir, rgb);
  touch_listed(dir, depth);
}

// The ground truth of the synthetic folders, samples 80 ms apart: at rest at the origin at
// 0.96 s, then from 1.04 s 0.2 m along x and turned 90 degrees about z.
const std::string kTruth =
    "# timestamp tx ty tz qx qy qz qw\n"
    "0.96 0 0 0 0 0 0 1\n"
    "1.04 0.2 0 0 0 0 0.7071068 0.7071068\n"
    "1.12 0.2 0 0 0 0 0.7071068 0.7071068\n";

std::vector<std::string> where_of(const std::vector<InputProblem>& problems) {
  std::vector<std::string> out;
  for (const InputProblem& p : problems) out.push_back(p.where);
  return out;
}

// The real TUM pair (fr1, Open3D's test data) in a folder of TUM's layout, read with /5000.
TEST(TumReader, RealPairInMetres) {
  const fs::path pair = real_data("tum_pair");
  if (!fs::exists(pair)) GTEST_SKIP() << absent(pair);
  const TempDir dir;
  fs::create_directories(dir / "rgb");
  fs::create_directories(dir / "depth");
  fs::create_symlink(pair / "TUM_color.png", dir / "rgb/1.000000.png");
  fs::create_symlink(pair / "TUM_depth.png", dir / "depth/1.010000.png");
  write_text(dir / "rgb.txt", "# color images\n# timestamp filename\n1.000000 rgb/1.000000.png\n");
  write_text(dir / "depth.txt", "# depth maps\n1.010000 depth/1.010000.png\n");
  write_text(dir / "groundtruth.txt", kTruth);

  const RgbdSequence sequence = read_tum(dir.path());
  ASSERT_EQ(sequence.frames.size(), 1u);
  EXPECT_TRUE(sequence.problems.empty());
  EXPECT_EQ(sequence.depth_units_per_metre, 5000.0);
  EXPECT_FALSE(sequence.intrinsics);
  const RgbdFrame& frame = sequence.frames[0];
  EXPECT_EQ(frame.stamp_s, 1.0);
  EXPECT_EQ(frame.colour, dir / "rgb/1.000000.png");
  EXPECT_EQ(frame.depth, dir / "depth/1.010000.png");
  // Halfway between the two ground-truth poses: 0.1 m along x, 45 degrees about z.
  EXPECT_TRUE(frame.world_from_camera.translation().isApprox(Eigen::Vector3d(0.1, 0, 0), 1e-9));
  const Eigen::AngleAxisd turn(frame.world_from_camera.linear());
  EXPECT_NEAR(turn.angle(), std::numbers::pi / 4, 1e-6);
  EXPECT_NEAR(turn.axis().z(), 1.0, 1e-9);

  const cv::Mat raw = cv::imread(frame.depth.string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(raw.type(), CV_16UC1);
  const cv::Mat metres = read_depth_metres(frame.depth, sequence.depth_units_per_metre);
  ASSERT_EQ(metres.type(), CV_32FC1);
  ASSERT_EQ(metres.size(), cv::Size(640, 480));
  std::vector<float> valid;
  for (int v = 0; v < raw.rows; ++v) {
    for (int u = 0; u < raw.cols; ++u) {
      const std::uint16_t r = raw.at<std::uint16_t>(v, u);
      EXPECT_FLOAT_EQ(metres.at<float>(v, u), static_cast<float>(r / 5000.0))
          << "pixel " << u << "," << v;
      if (r != 0) valid.push_back(metres.at<float>(v, u));
    }
  }
  ASSERT_GT(valid.size(), raw.total() / 2) << "most pixels of a Kinect frame have depth";
  std::nth_element(valid.begin(), valid.begin() + valid.size() / 2, valid.end());
  const float median = valid[valid.size() / 2];
  std::cout << "TUM pair: " << valid.size() << " pixels with depth, median " << median << " m\n";
  // An office scene from a hand-held Kinect: its median depth lies at room scale. With the
  // Redwood scale (1/1000) it would be five times larger, 5-25 m.
  EXPECT_GT(median, 0.5f);
  EXPECT_LT(median, 5.0f);
}

TEST(TumReader, MissingFileIsAnError) {
  const TempDir dir;
  write_text(dir / "rgb.txt", "");
  write_text(dir / "groundtruth.txt", "");
  EXPECT_THAT(error_of<DatasetError>([&] { read_tum(dir.path()); }),
              HasSubstr((dir / "depth.txt").string() + ": missing"));
}

TEST(TumReader, LineThatDoesNotParseSkipsItsFrame) {
  const TempDir dir;
  write_tum(dir.path(),
            "# color\n1.0 rgb/a.png\n1.0x rgb/b.png\n1.02 rgb/c.png extra\n1.04 rgb/d.png\n",
            "1.0 depth/a.png\n1.04 depth/d.png\n", kTruth);
  const RgbdSequence sequence = read_tum(dir.path());
  ASSERT_EQ(sequence.frames.size(), 2u);
  EXPECT_EQ(sequence.frames[0].colour, dir / "rgb/a.png");
  EXPECT_EQ(sequence.frames[1].colour, dir / "rgb/d.png");
  const std::string rgb = (dir / "rgb.txt").string();
  EXPECT_THAT(where_of(sequence.problems), ::testing::ElementsAre(rgb + ":3", rgb + ":4"));
  EXPECT_THAT(sequence.problems[0].what, HasSubstr("'1.0x' is not a number"));
  EXPECT_THAT(sequence.problems[1].what, HasSubstr("got 3 fields"));
}

TEST(TumReader, FrameWithoutDepthPartnerIsAProblem) {
  const TempDir dir;
  // 1.05 has its nearest depth frame 25 ms away, more than the 20 ms tolerance.
  write_tum(dir.path(), "1.0 rgb/a.png\n1.05 rgb/b.png\n", "1.01 depth/a.png\n1.075 depth/b.png\n",
            kTruth);
  const RgbdSequence sequence = read_tum(dir.path());
  ASSERT_EQ(sequence.frames.size(), 1u);
  ASSERT_EQ(sequence.problems.size(), 1u);
  EXPECT_EQ(sequence.problems[0].where, (dir / "rgb.txt").string() + ":2");
  EXPECT_THAT(sequence.problems[0].what, HasSubstr("no depth frame within 0.020000 s"));
  // A wider tolerance pairs it.
  TumOptions wider;
  wider.max_difference_s = 0.03;
  EXPECT_EQ(read_tum(dir.path(), wider).frames.size(), 2u);
}

TEST(TumReader, FrameOutsideTheGroundTruthIsAProblem) {
  const TempDir dir;
  write_tum(dir.path(), "0.8 rgb/a.png\n1.0 rgb/b.png\n1.3 rgb/c.png\n2.05 rgb/d.png\n",
            "0.8 depth/a.png\n1.0 depth/b.png\n1.3 depth/c.png\n2.05 depth/d.png\n",
            kTruth + "2.0 0 0 0 0 0 0 1\n2.08 0 0 0 0 0 0 1\n");
  const RgbdSequence sequence = read_tum(dir.path());
  ASSERT_EQ(sequence.frames.size(), 2u);
  EXPECT_EQ(sequence.frames[0].stamp_s, 1.0);
  EXPECT_EQ(sequence.frames[1].stamp_s, 2.05);
  ASSERT_EQ(sequence.problems.size(), 2u);
  EXPECT_THAT(sequence.problems[0].what, HasSubstr("outside the ground truth"));
  // 1.3 s falls between samples 0.88 s apart: the motion capture lost the camera there.
  EXPECT_THAT(sequence.problems[1].what, HasSubstr("gap of 0.880000 s"));
}

TEST(TumReader, ImageThatIsNotThereIsAProblem) {
  const TempDir dir;
  write_tum(dir.path(), "1.0 rgb/a.png\n1.04 rgb/b.png\n", "1.0 depth/a.png\n1.04 depth/b.png\n",
            kTruth);
  fs::remove(dir / "depth/b.png");
  const RgbdSequence sequence = read_tum(dir.path());
  EXPECT_EQ(sequence.frames.size(), 1u);
  ASSERT_EQ(sequence.problems.size(), 1u);
  EXPECT_EQ(sequence.problems[0].where, (dir / "depth.txt").string() + ":2");
  EXPECT_THAT(sequence.problems[0].what, HasSubstr("b.png: no such file"));
}

TEST(TumGroundTruth, BadLinesAreNamedAndLeftOut) {
  const TumGroundTruth truth = parse_tum_groundtruth(
      "# ground truth\n"
      "2.0 1 2 3 0 0 0 1\n"
      "1.0 0 0 0 0 0 0\n"
      "1.5 0 0 0 0 0 0 2\n"
      "1.0 0 0 0 0 0 nan 1\n"
      "1.0 4 5 6 0 0 1 0\n",
      "gt.txt");
  ASSERT_EQ(truth.poses.size(), 2u);
  EXPECT_EQ(truth.poses[0].stamp_s, 1.0);  // sorted by stamp
  EXPECT_TRUE(truth.poses[0].world_from_camera.translation().isApprox(Eigen::Vector3d(4, 5, 6)));
  EXPECT_TRUE(truth.poses[0].world_from_camera.linear().isApprox(
      Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitZ()).toRotationMatrix()));
  EXPECT_THAT(where_of(truth.problems), ::testing::ElementsAre("gt.txt:3", "gt.txt:4", "gt.txt:5"));
  EXPECT_THAT(truth.problems[1].what, HasSubstr("norm 2"));
}

TEST(TumIntrinsics, ByFreiburgSensorInTheFolderName) {
  const auto fr3 = tum_intrinsics_for("/data/rgbd_dataset_freiburg3_long_office_household/");
  ASSERT_TRUE(fr3);
  EXPECT_EQ(fr3->width, 640);
  EXPECT_FLOAT_EQ(fr3->fx, 535.4f);
  EXPECT_FLOAT_EQ(fr3->cy, 247.6f);
  const auto fr1 = tum_intrinsics_for("rgbd_dataset_freiburg1_xyz");
  ASSERT_TRUE(fr1);
  EXPECT_FLOAT_EQ(fr1->fx, 517.3f);
  EXPECT_FALSE(tum_intrinsics_for("/data/my_sequence"));
}

TEST(DepthPng, EightBitImageIsAnErrorNamingTheFile) {
  const TempDir dir;
  const fs::path png = dir / "depth.png";
  ASSERT_TRUE(cv::imwrite(png.string(), cv::Mat(4, 4, CV_8UC1, cv::Scalar(7))));
  EXPECT_THAT(error_of<DatasetError>([&] { read_depth_metres(png, 5000); }),
              HasSubstr(png.string() + ": depth image is 8-bit 1-channel"));
  const fs::path colour = dir / "colour.png";
  ASSERT_TRUE(cv::imwrite(colour.string(), cv::Mat(4, 4, CV_16UC3, cv::Scalar(7, 7, 7))));
  EXPECT_THAT(error_of<DatasetError>([&] { read_depth_metres(colour, 5000); }),
              HasSubstr("16-bit 3-channel"));
  EXPECT_THAT(error_of<DatasetError>([&] { read_depth_metres(dir / "none.png", 5000); }),
              HasSubstr("none.png: no such file"));
  write_text(dir / "text.png", "not a png");
  EXPECT_THAT(error_of<DatasetError>([&] { read_depth_metres(dir / "text.png", 5000); }),
              HasSubstr("text.png: cannot decode"));
  EXPECT_THROW(read_depth_metres(png, 0.0), std::invalid_argument);
}

TEST(DepthPng, ZeroStaysNoDepth) {
  const TempDir dir;
  cv::Mat raw(1, 3, CV_16UC1);
  raw.at<std::uint16_t>(0, 0) = 0;
  raw.at<std::uint16_t>(0, 1) = 1000;
  raw.at<std::uint16_t>(0, 2) = 65535;
  const fs::path png = dir / "d.png";
  ASSERT_TRUE(cv::imwrite(png.string(), raw));
  const cv::Mat m = read_depth_metres(png, 1000.0);
  EXPECT_EQ(m.at<float>(0, 0), 0.0f);
  EXPECT_FLOAT_EQ(m.at<float>(0, 1), 1.0f);
  EXPECT_FLOAT_EQ(m.at<float>(0, 2), 65.535f);
}

}  // namespace
}  // namespace semap::perception::datasets
