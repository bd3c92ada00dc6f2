#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>

#include "dataset_test_data.hpp"
#include "semap/perception/datasets/depth_png.hpp"
#include "semap/perception/datasets/redwood.hpp"
#include "semap/perception/datasets/redwood_files.hpp"
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

// One .log entry: metadata `i i i+1` and a pure translation.
std::string log_entry(int i, double tx, const std::string& first_row_rest = "0 0") {
  return std::to_string(i) + " " + std::to_string(i) + " " + std::to_string(i + 1) + "\n" + "1 " +
         first_row_rest + " " + std::to_string(tx) + "\n0 1 0 0\n0 0 1 0\n0 0 0 1\n";
}

TEST(RedwoodReader, RealFramesWithOdometryPoses) {
  const fs::path dir = real_data("redwood");
  if (!fs::exists(dir)) GTEST_SKIP() << absent(dir);
  const RgbdSequence sequence = read_redwood(dir);
  EXPECT_TRUE(sequence.problems.empty()) << sequence.problems.front().text();
  ASSERT_EQ(sequence.frames.size(), 5u);
  EXPECT_EQ(sequence.depth_units_per_metre, 1000.0);
  ASSERT_TRUE(sequence.intrinsics);
  EXPECT_EQ(sequence.intrinsics->width, 640);
  EXPECT_EQ(sequence.intrinsics->height, 480);
  EXPECT_FLOAT_EQ(sequence.intrinsics->fx, 525.0f);
  EXPECT_FLOAT_EQ(sequence.intrinsics->fy, 525.0f);
  EXPECT_FLOAT_EQ(sequence.intrinsics->cx, 319.5f);
  EXPECT_FLOAT_EQ(sequence.intrinsics->cy, 239.5f);
  for (std::size_t i = 0; i < 5; ++i) {
    const RgbdFrame& frame = sequence.frames[i];
    EXPECT_EQ(frame.colour.filename(), "0000" + std::to_string(i) + ".jpg");
    EXPECT_EQ(frame.depth.filename(), "0000" + std::to_string(i) + ".png");
    EXPECT_DOUBLE_EQ(frame.stamp_s, static_cast<double>(i) / 30.0);
  }
  // odometry.log's first and last matrices, camera to world.
  EXPECT_TRUE(sequence.frames[0].world_from_camera.matrix().isApprox(
      (Eigen::Matrix4d() << 1, 0, 0, 2, 0, 1, 0, 2, 0, 0, 1, -0.3, 0, 0, 0, 1).finished()));
  const Eigen::Isometry3d& last = sequence.frames[4].world_from_camera;
  EXPECT_TRUE(last.translation().isApprox(Eigen::Vector3d(2.00124, 1.90487, -0.305411), 1e-9));
  EXPECT_NEAR(last.linear()(1, 2), 0.0486137, 1e-6);
  EXPECT_NEAR(last.linear()(2, 1), -0.048614, 1e-6);

  const cv::Mat depth = read_depth_metres(sequence.frames[4].depth, 1000.0);
  std::vector<float> valid;
  for (auto it = depth.begin<float>(); it != depth.end<float>(); ++it) {
    if (*it > 0.0f) valid.push_back(*it);
  }
  ASSERT_GT(valid.size(), depth.total() / 2);
  std::nth_element(valid.begin(), valid.begin() + valid.size() / 2, valid.end());
  const float median = valid[valid.size() / 2];
  std::cout << "Redwood frame 4: " << valid.size() << " pixels with depth, median " << median
            << " m\n";
  // An indoor scene at a PrimeSense's range (0.5 to about 5 m).
  EXPECT_GT(median, 0.5f);
  EXPECT_LT(median, 5.0f);
}

// A copy of the real folder's layout with images linked, and a trajectory of our own.
class RedwoodCopy : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(real_)) GTEST_SKIP() << absent(real_);
    for (const char* sub : {"color", "depth"})
      fs::create_directory_symlink(real_ / sub, dir_ / sub);
    fs::copy_file(real_ / "camera_primesense.json", dir_ / "camera_primesense.json");
  }
  const fs::path real_ = real_data("redwood");
  const TempDir dir_;
};

TEST_F(RedwoodCopy, PoseLineThatDoesNotParseSkipsItsFrame) {
  const fs::path log = write_text(dir_ / "odometry.log", log_entry(0, 0) + log_entry(1, 0.1) +
                                                             log_entry(2, 0.2, "0 zero") +
                                                             log_entry(3, 0.3) + log_entry(4, 0.4));
  const RgbdSequence sequence = read_redwood(dir_.path());
  ASSERT_EQ(sequence.frames.size(), 4u);
  EXPECT_EQ(sequence.frames[2].colour.filename(), "00003.jpg");
  EXPECT_NEAR(sequence.frames[2].world_from_camera.translation().x(), 0.3, 1e-12);
  ASSERT_EQ(sequence.problems.size(), 1u);
  EXPECT_EQ(sequence.problems[0].where, log.string() + ":12");
  EXPECT_THAT(sequence.problems[0].what, HasSubstr("frame 2: value 'zero' is not a number"));
}

TEST_F(RedwoodCopy, FramesAndPosesThatDoNotMatch) {
  write_text(dir_ / "odometry.log", log_entry(0, 0) + log_entry(1, 0.1) + log_entry(2, 0.2));
  const RgbdSequence few = read_redwood(dir_.path());
  EXPECT_EQ(few.frames.size(), 3u);
  ASSERT_EQ(few.problems.size(), 2u);
  EXPECT_THAT(few.problems[0].what, HasSubstr("frame 3 has no pose"));
  EXPECT_EQ(few.problems[1].where, (dir_ / "color/00004.jpg").string());

  std::string six;
  for (int i = 0; i < 6; ++i) six += log_entry(i, 0.1 * i);
  const fs::path log = write_text(dir_ / "odometry.log", six);
  const RgbdSequence many = read_redwood(dir_.path());
  EXPECT_EQ(many.frames.size(), 5u);
  ASSERT_EQ(many.problems.size(), 1u);
  EXPECT_EQ(many.problems[0].where, log.string() + ":26");
  EXPECT_THAT(many.problems[0].what, HasSubstr("pose of frame 5 has no colour and depth image"));
}

TEST_F(RedwoodCopy, RgbdMatchPairsTheFrames) {
  // The match file decides which images make frame i: here only two, in reverse.
  write_text(dir_ / "rgbd.match",
             "depth/00003.png color/00003.jpg\ndepth/00001.png color/00001.jpg\n");
  write_text(dir_ / "odometry.log", log_entry(0, 0) + log_entry(1, 0.1));
  const RgbdSequence sequence = read_redwood(dir_.path());
  EXPECT_TRUE(sequence.problems.empty());
  ASSERT_EQ(sequence.frames.size(), 2u);
  EXPECT_EQ(sequence.frames[0].colour, dir_ / "color/00003.jpg");
  EXPECT_EQ(sequence.frames[0].depth, dir_ / "depth/00003.png");
  EXPECT_EQ(sequence.frames[1].colour, dir_ / "color/00001.jpg");

  write_text(dir_ / "rgbd.match", "depth/00003.png color/00009.jpg\nonly-one-file\n");
  const RgbdSequence broken = read_redwood(dir_.path());
  EXPECT_TRUE(broken.frames.empty());
  ASSERT_EQ(broken.problems.size(), 3u);
  EXPECT_EQ(broken.problems[0].where, (dir_ / "rgbd.match").string() + ":2");
  EXPECT_EQ(broken.problems[1].where, (dir_ / "rgbd.match").string() + ":1");
  EXPECT_THAT(broken.problems[1].what,
              HasSubstr("no such file: " + (dir_ / "color/00009.jpg").string()));
  EXPECT_THAT(broken.problems[2].what, HasSubstr("pose of frame 1 has no colour and depth image"));
}

TEST_F(RedwoodCopy, TrajectoryMustBeNamedWithoutOdometryLog) {
  fs::copy_file(real_ / "trajectory.log", dir_ / "trajectory.log");
  EXPECT_THAT(
      error_of<DatasetError>([&] { read_redwood(dir_.path()); }),
      HasSubstr((dir_ / "odometry.log").string() + ": missing; name the frames' trajectory"));
  RedwoodOptions options;
  options.trajectory = dir_ / "trajectory.log";
  const RgbdSequence sequence = read_redwood(dir_.path(), options);
  EXPECT_EQ(sequence.frames.size(), 5u);
}

TEST(RedwoodReader, PairsByNameWithoutRgbdMatch) {
  const TempDir dir;
  fs::create_directory(dir / "color");
  fs::create_directory(dir / "depth");
  for (const char* name : {"b.jpg", "a.png", "c.JPG", "notes.txt"})
    write_text(dir / "color" / name, "");
  for (const char* name : {"1.png", "2.png"}) write_text(dir / "depth" / name, "");
  write_text(dir / "odometry.log", log_entry(0, 0) + log_entry(1, 0.1));
  const RgbdSequence sequence = read_redwood(dir.path());
  EXPECT_FALSE(sequence.intrinsics);
  ASSERT_EQ(sequence.frames.size(), 2u);
  EXPECT_EQ(sequence.frames[0].colour, dir / "color/a.png");
  EXPECT_EQ(sequence.frames[0].depth, dir / "depth/1.png");
  EXPECT_EQ(sequence.frames[1].colour, dir / "color/b.jpg");
  ASSERT_EQ(sequence.problems.size(), 1u);
  EXPECT_EQ(sequence.problems[0].where, (dir / "color/c.JPG").string());
  EXPECT_THAT(sequence.problems[0].what, HasSubstr("no depth image"));
  fs::remove_all(dir / "depth");
  EXPECT_THAT(error_of<DatasetError>([&] { read_redwood(dir.path()); }),
              HasSubstr((dir / "depth").string() + ": missing"));
}

TEST(RedwoodLog, OneBadLineCostsOneFrame) {
  const RedwoodLog log = parse_redwood_log(
      log_entry(0, 0) +
          // Entry 1 lost its last row, entry 2 has a mirror, a stray line follows.
          "1 1 2\n1 0 0 0\n0 1 0 0\n0 0 1 0\n" + "2 2 3\n-1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n" +
          "7 7\n" + log_entry(3, 0.3) + "4 4 5\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 1 1\n",
      "t.log");
  ASSERT_EQ(log.entries.size(), 5u);
  EXPECT_TRUE(log.entries[0].world_from_camera);
  EXPECT_FALSE(log.entries[1].world_from_camera);
  EXPECT_FALSE(log.entries[2].world_from_camera);
  ASSERT_TRUE(log.entries[3].world_from_camera);
  EXPECT_NEAR(log.entries[3].world_from_camera->translation().x(), 0.3, 1e-12);
  EXPECT_FALSE(log.entries[4].world_from_camera);
  EXPECT_EQ(log.entries[3].line, 16);
  ASSERT_EQ(log.problems.size(), 4u);
  EXPECT_EQ(log.problems[0].text(), "t.log:6: frame 1: the 4x4 matrix has 3 of 4 rows");
  EXPECT_EQ(log.problems[1].text(), "t.log:11: frame 2: the 3x3 block is not a rotation");
  EXPECT_EQ(log.problems[2].where, "t.log:15");
  EXPECT_EQ(log.problems[3].text(), "t.log:25: frame 4: the last row is not 0 0 0 1");
}

TEST(Open3dIntrinsics, ColumnMajorMatrix) {
  const PinholeIntrinsics k = parse_open3d_intrinsics(
      R"({"width": 640, "height": 480, "intrinsic_matrix": [481.2, 0, 0, 0, -480, 0, 319.5, 239.5, 1]})",
      "icl.json");
  EXPECT_EQ(k.width, 640);
  EXPECT_FLOAT_EQ(k.fx, 481.2f);
  EXPECT_FLOAT_EQ(k.fy, -480.0f);  // ICL-NUIM's flipped rows, as given
  EXPECT_FLOAT_EQ(k.cx, 319.5f);
  EXPECT_FLOAT_EQ(k.cy, 239.5f);
}

TEST(Open3dIntrinsics, ErrorsNameFileAndLine) {
  const auto error = [](const std::string& json) {
    return error_of<DatasetError>([&] { parse_open3d_intrinsics(json, "cam.json"); });
  };
  // Row by row instead of column by column.
  EXPECT_THAT(error("{\"width\": 640, \"height\": 480,\n\"intrinsic_matrix\":\n"
                    "[525, 0, 319.5, 0, 525, 239.5, 0, 0, 1]}"),
              HasSubstr("cam.json:3: key 'intrinsic_matrix': the last row must be 0 0 1"));
  EXPECT_THAT(error("{\"width\": 640, \"intrinsic_matrix\": [1, 0, 0, 0, 1, 0, 0, 0, 1]}"),
              HasSubstr("cam.json:1: key 'height': required but missing"));
  EXPECT_THAT(error("{\"width\": 640.5, \"height\": 480, \"intrinsic_matrix\": []}"),
              HasSubstr("key 'width': must be whole pixels"));
  EXPECT_THAT(error("{\"width\": 640, \"height\": 480, \"intrinsic_matrix\": [1, 0, 0]}"),
              HasSubstr("expected 9 numbers, got 3"));
  EXPECT_THAT(error("{\"width\": 640,\n \"height\": [480"), HasSubstr("cam.json:"));
  EXPECT_THAT(error_of<DatasetError>([] { read_open3d_intrinsics("/nonexistent/cam.json"); }),
              HasSubstr("/nonexistent/cam.json: cannot open"));
}

}  // namespace
}  // namespace semap::perception::datasets
