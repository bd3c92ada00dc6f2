#include "semap/map_io/semantic_kitti_io.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace semap::map_io {
namespace {

namespace fs = std::filesystem;

// Writes a two-scan sequence in the SemanticKITTI layout.
class KittiFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("semap_kitti_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
            "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_ / "velodyne");
    fs::create_directories(dir_ / "labels");
    // Tr swaps axes like the real calibration (velodyne x forward -> camera z forward).
    std::ofstream(dir_ / "calib.txt") << "P0: 1 0 0 0 0 1 0 0 0 0 1 0\n"
                                         "Tr: 0 -1 0 0 0 0 -1 0 1 0 0 0\n";
    // Camera moves 2 m along its z (forward) between the scans.
    std::ofstream(dir_ / "poses.txt") << "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1 2\n";
    for (int s = 0; s < 2; ++s) {
      const float pts[2][4] = {{1, 0, 0, 0.5f}, {0, 2, -1, 0.1f}};
      const std::string name = "00000" + std::to_string(s);
      std::ofstream(dir_ / "velodyne" / (name + ".bin"), std::ios::binary)
          .write(reinterpret_cast<const char*>(pts), sizeof(pts));
      // Upper 16 bits carry the instance id and must be ignored.
      const std::uint32_t labels[2] = {(7u << 16) | 10u, 40u};
      std::ofstream(dir_ / "labels" / (name + ".label"), std::ios::binary)
          .write(reinterpret_cast<const char*>(labels), sizeof(labels));
    }
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(KittiFiles, ReadsScansIntoTheWorldFrameWithLearningLabels) {
  const KittiSequence seq(dir_);
  ASSERT_EQ(seq.size(), 2u);
  const auto scan = seq.scan(1);
  ASSERT_EQ(scan.size(), 2u);
  EXPECT_EQ(scan.labels[0], 1);  // raw 10 = car
  EXPECT_EQ(scan.labels[1], 9);  // raw 40 = road
  // Velodyne (1,0,0) is camera (0,0,1); the second camera pose is 2 m further along z.
  EXPECT_TRUE(scan.points[0].isApprox(Eigen::Vector3f(0, 0, 3), 1e-6f));
  EXPECT_TRUE(scan.points[1].isApprox(Eigen::Vector3f(-2, 1, 2), 1e-6f));
  EXPECT_TRUE(scan.origin.isApprox(Eigen::Vector3f(0, 0, 2), 1e-6f));
}

TEST(KittiLearningMap, MapsOfficialIdsAndIgnoresInstanceBits) {
  EXPECT_EQ(kitti_learning_map(10), 1);
  EXPECT_EQ(kitti_learning_map(252), 1);  // moving car
  EXPECT_EQ(kitti_learning_map(81), 19);
  EXPECT_EQ(kitti_learning_map(70), 15);
  EXPECT_EQ(kitti_learning_map((123u << 16) | 50u), 13);
  EXPECT_EQ(kitti_learning_map(1), 0);
  EXPECT_EQ(kitti_learning_map(12345), 0);
  EXPECT_STREQ(kitti_class_names()[13], "building");
}

// Found by kitti_readers_fuzz (UBSan: memcpy from an empty file into the empty vector's null
// pointer); an empty label file holds no labels (an empty scan: kitti_odometry_reader_test).
TEST_F(KittiFiles, EmptyLabelFileGivesNothing) {
  std::ofstream(dir_ / "empty.label", std::ios::binary).flush();
  EXPECT_TRUE(read_kitti_labels(dir_ / "empty.label").empty());
}

TEST_F(KittiFiles, MalformedFilesNameFileAndLine) {
  std::ofstream(dir_ / "poses.txt") << "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0\n";
  try {
    KittiSequence seq(dir_);
    FAIL() << "expected KittiError";
  } catch (const KittiError& e) {
    EXPECT_NE(std::string(e.what()).find("poses.txt:2: expected 12 numbers"), std::string::npos);
  }
  std::ofstream(dir_ / "velodyne" / "000000.bin", std::ios::binary) << "12345";
  std::ofstream(dir_ / "labels" / "000001.label", std::ios::binary) << "1234";
  std::ofstream(dir_ / "poses.txt") << "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1 2\n";
  const KittiSequence seq(dir_);
  try {
    seq.scan(0);
    FAIL() << "expected KittiError";
  } catch (const KittiError& e) {
    EXPECT_NE(std::string(e.what()).find("000000.bin: size 5 bytes is not a multiple of 16"),
              std::string::npos)
        << e.what();
  }
  try {
    seq.scan(1);
    FAIL() << "expected KittiError";
  } catch (const KittiError& e) {
    EXPECT_NE(std::string(e.what()).find("1 labels for 2 points"), std::string::npos);
  }
  EXPECT_THROW(seq.scan(5), KittiError);
}

}  // namespace
}  // namespace semap::map_io
