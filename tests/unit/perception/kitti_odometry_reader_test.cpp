#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <iostream>

#include "dataset_test_data.hpp"
#include "semap/perception/datasets/kitti_odometry.hpp"
#include "semap/perception/datasets/velodyne_bin.hpp"
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

// Velodyne to camera 0 of sequence 00 (KITTI's calib.txt, quoted in ../shared/data/real's
// README). The P rows are a KITTI-like camera; nothing here projects with them.
const std::string kSequence00Calib =
    "P0: 718.856 0 607.1928 0 0 718.856 185.2157 0 0 0 1 0\n"
    "P1: 718.856 0 607.1928 -386.1448 0 718.856 185.2157 0 0 0 1 0\n"
    "P2: 718.856 0 607.1928 45.38225 0 718.856 185.2157 -0.1130887 0 0 1 0.003779761\n"
    "P3: 718.856 0 607.1928 -337.2877 0 718.856 185.2157 2.369057 0 0 1 0.004915215\n"
    "Tr: 4.276802385584e-04 -9.999672484946e-01 -8.084491683471e-03 -1.198459927713e-02 "
    "-7.210626507497e-03 8.081198471645e-03 -9.999413164504e-01 -5.403984729748e-02 "
    "9.999738645903e-01 4.859485810390e-04 -7.206933692422e-03 -2.921968648686e-01\n";

// The camera axes from the Velodyne's (camera z = Velodyne x, camera x = -y, camera y = -z),
// both at one point: poses convert by a plain change of axes.
const std::string kAxesCalib =
    "P0: 1 0 0 0 0 1 0 0 0 0 1 0\nP2: 1 0 0 0 0 1 0 0 0 0 1 0\nTr: 0 -1 0 0 0 0 -1 0 1 0 0 0\n";

void write_scan(const fs::path& path, const std::vector<float>& values) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(values.data()),
            static_cast<std::streamsize>(values.size() * sizeof(float)));
}

// A camera-0 pose row: identity rotation, camera moved `forward` metres along its z.
std::string forward_row(double forward) {
  return "1 0 0 0 0 1 0 0 0 0 1 " + std::to_string(forward) + "\n";
}

// Sequence 00's scan 000000 with the dataset's own poses/00.txt (found beside the sequence).
TEST(KittiOdometryReader, RealScanLiesOnTheGround) {
  const fs::path sequence_dir = real_data("kitti_odometry_00") / "sequences/00";
  if (!fs::exists(sequence_dir)) GTEST_SKIP() << absent(sequence_dir);
  const TempDir dir;
  const fs::path calib = write_text(dir / "calib.txt", kSequence00Calib);
  const KittiOdometrySequence sequence = read_kitti_odometry(sequence_dir, {}, {.calib = calib});
  EXPECT_TRUE(sequence.problems.empty()) << sequence.problems.front().text();
  ASSERT_EQ(sequence.frames.size(), 1u);
  const LidarFrame& frame = sequence.frames[0];
  EXPECT_EQ(frame.scan, sequence_dir / "velodyne/000000.bin");
  EXPECT_EQ(frame.stamp_s, 0.0);
  EXPECT_FALSE(frame.image);
  // Scan 0 defines the map frame.
  EXPECT_TRUE(frame.world_from_lidar.matrix().isApprox(Eigen::Matrix4d::Identity(), 1e-9));
  EXPECT_DOUBLE_EQ(sequence.calib.cam0_from_velo.translation().z(), -2.921968648686e-01);

  const std::vector<Eigen::Vector4f> points = read_velodyne_bin(frame.scan);
  EXPECT_EQ(points.size(), 124668u);
  std::vector<float> ground;
  for (const Eigen::Vector4f& p : points) {
    const Eigen::Vector3d world = frame.world_from_lidar * p.head<3>().cast<double>();
    if (world.x() > 5 && world.x() < 15 && std::abs(world.y()) < 2) {
      ground.push_back(static_cast<float>(world.z()));
    }
  }
  ASSERT_GT(ground.size(), 1000u);
  std::sort(ground.begin(), ground.end());
  const float median = ground[ground.size() / 2];
  const float iqr = ground[3 * ground.size() / 4] - ground[ground.size() / 4];
  std::cout << "KITTI 00 scan 0: " << points.size() << " points, " << ground.size()
            << " in front of the car, median z " << median << " m, IQR " << iqr << " m\n";
  // The HDL-64 is mounted 1.73 m above the road (KITTI's sensor setup). The car's pitch on its
  // suspension (0.2 degrees is 3.5 cm at 10 m) and the road's camber (2 % over 2 m is 4 cm)
  // move the strip's median by centimetres, hence 5 cm; a wrong frame is off by a metre
  // or more (z up inverted: +1.73; Velodyne taken for the camera frame: no ground at all).
  EXPECT_NEAR(median, -1.73f, 0.05f);
  // The strip in front of the car is road, flat to a few centimetres.
  EXPECT_LT(iqr, 0.1f);
}

// The real poses/00.txt for two scans: between them the car drives 0.86 m straight ahead,
// which the map frame must show as the Velodyne's +x.
TEST(KittiOdometryReader, RealPosesDriveAlongVelodyneX) {
  const fs::path real = real_data("kitti_odometry_00");
  if (!fs::exists(real)) GTEST_SKIP() << absent(real);
  const TempDir dir;
  fs::create_directory(dir / "velodyne");
  for (const char* scan : {"000000.bin", "000001.bin"}) {
    fs::create_symlink(real / "sequences/00/velodyne/000000.bin", dir / "velodyne" / scan);
  }
  fs::create_symlink(real / "sequences/00/times.txt", dir / "times.txt");
  write_text(dir / "calib.txt", kSequence00Calib);
  const KittiOdometrySequence sequence = read_kitti_odometry(dir.path(), real / "poses/00.txt");
  ASSERT_EQ(sequence.frames.size(), 2u);
  EXPECT_NEAR(sequence.frames[1].stamp_s, 0.1037359, 1e-12);
  const Eigen::Isometry3d& second = sequence.frames[1].world_from_lidar;
  std::cout << "KITTI 00 scan 1 in the map: " << second.translation().transpose() << "\n";
  // Row 2 of poses/00.txt moves camera 0 by (-0.0469, -0.0284, 0.8587): 0.8605 m, almost all
  // along the camera's z (forward); the Velodyne sits 0.3 m from the camera and the car turns
  // by 0.1 degrees, so its own path differs by under a millimetre.
  EXPECT_NEAR(second.translation().norm(), 0.8605, 1e-3);
  EXPECT_GT(second.translation().x(), 0.85);
  EXPECT_LT(std::abs(second.translation().z()), 0.05);
  EXPECT_GT(second.linear()(2, 2), 0.9999);  // z stays up
}

TEST(KittiOdometryReader, BadRowsAndNamesCostTheirScansOnly) {
  const TempDir dir;
  fs::create_directories(dir / "velodyne");
  fs::create_directories(dir / "image_2");
  for (const char* scan : {"000000", "000001", "000002", "000003", "000004", "notes"}) {
    write_scan(dir / "velodyne" / (std::string(scan) + ".bin"), {1, 2, 3, 0.5f});
  }
  write_text(dir / "image_2/000000.png", "");
  write_text(dir / "calib.txt", kAxesCalib);
  const fs::path times = write_text(dir / "times.txt", "0.0\n0.1\nabc\n0.3\n0.4\n");
  // Row 0 is not the identity: the map frame is still scan 0's Velodyne frame.
  const fs::path poses =
      write_text(dir / "poses.txt", forward_row(1.0) + "1 0 0 0 0 1 0 0 0 0 1\n" +
                                        forward_row(2.0) + forward_row(3.0));
  const KittiOdometrySequence sequence = read_kitti_odometry(dir.path());
  ASSERT_EQ(sequence.frames.size(), 2u);
  EXPECT_EQ(sequence.frames[0].scan, dir / "velodyne/000000.bin");
  EXPECT_EQ(sequence.frames[0].image, dir / "image_2/000000.png");
  EXPECT_TRUE(sequence.frames[0].world_from_lidar.matrix().isApprox(Eigen::Matrix4d::Identity()));
  const LidarFrame& third = sequence.frames[1];
  EXPECT_EQ(third.scan, dir / "velodyne/000003.bin");
  EXPECT_FALSE(third.image);
  EXPECT_DOUBLE_EQ(third.stamp_s, 0.3);
  EXPECT_TRUE(third.world_from_lidar.translation().isApprox(Eigen::Vector3d(2, 0, 0), 1e-12));
  EXPECT_TRUE(third.world_from_lidar.linear().isIdentity(1e-12));

  ASSERT_EQ(sequence.problems.size(), 4u);
  EXPECT_EQ(sequence.problems[0].where, times.string() + ":3");
  EXPECT_EQ(sequence.problems[1].where, poses.string() + ":2");
  EXPECT_THAT(sequence.problems[1].what, HasSubstr("expected 12 numbers"));
  EXPECT_EQ(sequence.problems[2].where, (dir / "velodyne/000004.bin").string());
  EXPECT_THAT(sequence.problems[2].what, HasSubstr("no row 4 in " + poses.string() + " (4 rows)"));
  EXPECT_EQ(sequence.problems[3].where, (dir / "velodyne/notes.bin").string());
}

TEST(KittiOdometryReader, MissingFilesAreErrors) {
  const TempDir dir;
  fs::create_directories(dir / "velodyne");
  write_text(dir / "times.txt", "0\n");
  write_text(dir / "poses.txt", forward_row(0));
  EXPECT_THAT(error_of<DatasetError>([&] { read_kitti_odometry(dir.path()); }),
              HasSubstr((dir / "calib.txt").string() + ": missing"));
  write_text(dir / "calib.txt", "P2: 1 0 0 0 0 1 0 0 0 0 1 0\n");
  EXPECT_THAT(error_of<DatasetError>([&] { read_kitti_odometry(dir.path()); }),
              HasSubstr("no key 'Tr' or 'Tr_velo_to_cam'"));
  write_text(dir / "calib.txt", kAxesCalib);
  write_text(dir / "poses.txt", "1 0 0 0 0 1 0 0 0 0 1 x\n" + forward_row(1));
  EXPECT_THAT(error_of<DatasetError>([&] { read_kitti_odometry(dir.path()); }),
              HasSubstr((dir / "poses.txt").string() + ":1: the first pose defines the map frame"));
  fs::remove(dir / "poses.txt");
  EXPECT_THAT(error_of<DatasetError>([&] { read_kitti_odometry(dir.path()); }),
              HasSubstr("the ground-truth poses of camera 0"));
}

TEST(KittiOdometryCalib, ObjectLayoutWithRectification) {
  const Eigen::Matrix3d r0 = Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitX()).toRotationMatrix();
  std::ostringstream text;
  text.precision(17);
  text << "P0: 700 0 600 0 0 700 180 0 0 0 1 0\nP2: 700 0 600 45 0 700 180 0 0 0 1 0\nR0_rect:";
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) text << ' ' << r0(r, c);
  }
  text << "\nTr_velo_to_cam: 0 -1 0 0.1 0 0 -1 -0.2 1 0 0 -0.3\nTr_imu_to_velo: 1 0 0 0 0 1 0 0 0 "
          "0 1 0\n";
  const KittiOdometryCalib calib =
      KittiOdometryCalib::from_text(KittiCalibText(text.str(), "calib.txt"));
  EXPECT_TRUE(calib.r0_rect.isApprox(r0, 1e-12));
  EXPECT_TRUE(calib.cam0_from_velo.translation().isApprox(Eigen::Vector3d(0.1, -0.2, -0.3)));
  EXPECT_TRUE(calib.rect_from_velo().matrix().isApprox(
      (Eigen::Isometry3d(r0) * calib.cam0_from_velo).matrix()));
  // Projection as KITTI's devkit writes it: P2 R0_rect Tr_velo_to_cam.
  const KittiCameraCalibration camera = calib.camera2({1242, 375});
  EXPECT_EQ(camera.image_size, cv::Size(1242, 375));
  Eigen::Matrix4d rect = Eigen::Matrix4d::Identity();
  rect.topLeftCorner<3, 3>() = r0;
  const Eigen::Matrix<double, 3, 4> expected = calib.p2 * rect * calib.cam0_from_velo.matrix();
  EXPECT_TRUE(camera.image_from_lidar().isApprox(expected.cast<float>()));

  EXPECT_THAT(error_of<CalibrationError>([] {
                KittiOdometryCalib::from_text(KittiCalibText(
                    "P2: 1 0 0 0 0 1 0 0 0 0 1 0\nTr: 2 0 0 0 0 2 0 0 0 0 2 0\n", "c.txt"));
              }),
              HasSubstr("c.txt: key 'Tr': not a rigid transform"));
}

TEST(VelodyneBin, TruncatedFileIsAnErrorNamingIt) {
  const TempDir dir;
  const fs::path bin = dir / "000007.bin";
  write_scan(bin, {1, 2, 3, 0.25f, -4, 5.5f, 6, 1});
  const std::vector<Eigen::Vector4f> points = read_velodyne_bin(bin);
  ASSERT_EQ(points.size(), 2u);
  EXPECT_EQ(points[1], Eigen::Vector4f(-4, 5.5f, 6, 1));
  fs::resize_file(bin, 17);
  EXPECT_THAT(error_of<DatasetError>([&] { read_velodyne_bin(bin); }),
              HasSubstr(bin.string() + ": size 17 bytes is not a multiple of 16"));
  EXPECT_THAT(error_of<DatasetError>([&] { read_velodyne_bin(dir / "none.bin"); }),
              HasSubstr("none.bin: cannot open"));
  fs::resize_file(bin, 0);
  EXPECT_TRUE(read_velodyne_bin(bin).empty());
}

}  // namespace
}  // namespace semap::perception::datasets
