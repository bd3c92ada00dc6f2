// Runs build/bin/semap-dataset kitti-raw on simulated drives written in the KITTI raw layout: the
// filter beats its GNSS, the map holds the street's classes where the street has them, and bad
// input is named with exit status 2.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include "semap/map_io/map_export.hpp"
#include "semap/mapping/smap_io.hpp"
#include "semap/perception/sim_classes.hpp"
#include "sim_kitti_raw_drive.hpp"
#include "support/cli_run.hpp"

namespace semap::map_io {
namespace {

namespace fs = std::filesystem;
using test_support::CliResult;

const fs::path kKittiCalib = fs::path(SEMAP_SHARED_DATA_DIR) / "kitti/2011_09_26";

CliResult run(const std::string& args) { return test_support::run_cli(SEMAP_DATASET_EXE, args); }

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// The number after `key` in the output (NaN when absent).
double figure(const std::string& out, const std::string& key) {
  const auto at = out.find(key);
  if (at == std::string::npos) return std::nan("");
  return std::stod(out.substr(at + key.size()));
}

fs::path temp_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() /
                       ("semap_dataset_kitti_raw_" + name + "_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string args_for(const bench::SimKittiRawDrive& d, const fs::path& out) {
  return "kitti-raw --drive " + d.drive_dir.string() + " --labels " + d.labels_dir.string() +
         " --num-classes 8 --out " + out.string();
}

class KittiRawCliDrive : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = new fs::path(temp_dir("drive"));
    bench::SimKittiRawOptions o;
    o.duration_s = 22.0;  // 2 s at rest, 200 scans
    o.azimuths = 600;
    drive_ = new bench::SimKittiRawDrive(bench::write_sim_kitti_raw_drive(*root_, kKittiCalib, o));
  }
  static void TearDownTestSuite() {
    fs::remove_all(*root_);
    delete drive_;
    delete root_;
  }
  static fs::path* root_;
  static bench::SimKittiRawDrive* drive_;
};
fs::path* KittiRawCliDrive::root_ = nullptr;
bench::SimKittiRawDrive* KittiRawCliDrive::drive_ = nullptr;

TEST_F(KittiRawCliDrive, FilterBeatsGnssAndTheMapHoldsTheStreet) {
  const fs::path out = *root_ / "out";
  const CliResult r =
      run(args_for(*drive_, out) +
          " --filter both --gnss-sigma 1.5 --threads 2 --progress-seconds 0.000001");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(has(r.out, "white noise sigma 1.50 m per axis")) << r.out;
  // Raw fixes of sigma 1.5 per axis miss by about 1.5 sqrt(3) = 2.6 m; the filters must stay
  // within half of that (about 0.9 m on this drive).
  const double gnss = figure(r.out, "GNSS  ATE ");
  EXPECT_GT(gnss, 2.3) << r.out;
  EXPECT_LT(figure(r.out, "InEKF ATE "), 0.5 * gnss) << r.out;
  EXPECT_LT(figure(r.out, "ESKF  ATE "), 0.5 * gnss) << r.out;
  EXPECT_LT(figure(r.out, "heading_rmse "), 2.0) << r.out;
  EXPECT_TRUE(has(r.out, "semap-dataset kitti-raw: ")) << r.out;  // the progress line
  EXPECT_TRUE(has(r.out, "label_ms (segmentation + projection) median")) << r.out;
  EXPECT_TRUE(has(r.out, "insert_ms median")) << r.out;
  EXPECT_GT(figure(r.out, "out_of_image "), 0.0) << r.out;  // the points behind the camera
  for (const char* file :
       {"trajectory.csv", "top_view.png", "map.smap", "map.ply", "map_top_down.png"}) {
    EXPECT_TRUE(fs::is_regular_file(out / file)) << file;
  }

  // Occupied cells carry the class of the street's surface at their centre.
  const auto read = mapping::read_smap(out / "map.smap");
  const auto cells = occupied_cells(read.map);
  ASSERT_GT(cells.size(), 1000u);
  const sim::SimWorld world = bench::sim_kitti_raw_world(*drive_);
  const Eigen::Vector3d lift(0.0, 0.0, 0.93);
  std::map<int, std::size_t> seen;
  std::size_t agree = 0;
  std::size_t known = 0;
  for (const auto& c : cells) {
    ++seen[c.label];
    const auto truth = world.class_at((c.centre + lift).cast<float>(), 0.3f);
    if (truth == 0) continue;  // free in the world: a pose error moved the cell
    ++known;
    agree += truth == c.label ? 1 : 0;
  }
  ASSERT_GT(known, cells.size() / 2);
  EXPECT_GT(static_cast<double>(agree) / static_cast<double>(known), 0.8) << agree << "/" << known;
  EXPECT_GT(seen[1], 100u);  // road
  EXPECT_GT(seen[3], 100u);  // building
  // Below the car half-way through the drive the map says road.
  const Eigen::Vector3d under =
      drive_->simulation.truth[drive_->simulation.truth.size() / 2].state.position;
  std::map<int, int> below;
  for (const auto& c : cells) {
    if ((c.centre.head<2>() - under.head<2>()).norm() < 1.5) ++below[c.label];
  }
  EXPECT_GT(below[1], below[3] + below[4] + below[5]) << below[1];
}

TEST_F(KittiRawCliDrive, ScanRangeAndPacketNoise) {
  const CliResult r = run(args_for(*drive_, *root_ / "out_range") +
                          " --gnss-sigma packet --first 40 --last 59 --threads 1");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(has(r.out, "scans 20 mapped 20")) << r.out;
  EXPECT_TRUE(has(r.out, "the packet's pos_accuracy")) << r.out;
  EXPECT_FALSE(has(r.out, "ESKF")) << r.out;
}

// The shipped network (trained on the simulated camera) segments image_02; its probabilities
// go into the map as soft labels, and the ground below the car comes out as road.
TEST(KittiRawCliSegmenter, ModelCardLabelsTheCameraImages) {
  const fs::path root = temp_dir("segmenter");
  bench::SimKittiRawOptions o;
  o.duration_s = 6.0;
  o.azimuths = 300;
  o.beams = 32;
  o.colour_images = true;
  const auto drive = bench::write_sim_kitti_raw_drive(root, kKittiCalib, o);
  const fs::path card = fs::path(SEMAP_SOURCE_DIR) / "models/semap-seg.yaml";
  const CliResult r = run("kitti-raw --drive " + drive.drive_dir.string() + " --segmenter " +
                          card.string() + " --out " + (root / "out").string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(has(r.out, "dnn segmenter: ")) << r.out;
  EXPECT_EQ(figure(r.out, "soft_labelled "), figure(r.out, "mapped ")) << r.out;
  const auto cells = occupied_cells(mapping::read_smap(root / "out/map.smap").map);
  const Eigen::Vector3d under = drive.simulation.truth.back().state.position;
  std::map<int, int> below;
  for (const auto& c : cells) {
    if ((c.centre.head<2>() - under.head<2>()).norm() < 1.5) ++below[c.label];
  }
  EXPECT_GT(below[1], below[3] + below[4] + below[5]) << below[1];
  fs::remove(drive.image_dir / "0000000020.png");
  const CliResult missing = run("kitti-raw --drive " + drive.drive_dir.string() + " --segmenter " +
                                card.string() + " --out " + (root / "out").string());
  EXPECT_EQ(missing.status, 2) << missing.out;
  EXPECT_TRUE(has(missing.out, "image_02/data/0000000020.png: missing image")) << missing.out;
  fs::remove_all(root);
}

// A small drive of its own per case, broken in one way.
class KittiRawCliBadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = temp_dir(::testing::UnitTest::GetInstance()->current_test_info()->name());
    bench::SimKittiRawOptions o;
    o.duration_s = 5.0;
    o.azimuths = 90;
    o.beams = 16;
    drive_ = bench::write_sim_kitti_raw_drive(root_, kKittiCalib, o);
  }
  void TearDown() override { fs::remove_all(root_); }
  void expect_error(const std::string& part) {
    const CliResult r = run(args_for(drive_, root_ / "out"));
    EXPECT_EQ(r.status, 2) << r.out;
    EXPECT_TRUE(has(r.out, part)) << r.out;
  }
  fs::path root_;
  bench::SimKittiRawDrive drive_;
};

TEST_F(KittiRawCliBadInput, RunsWhenIntact) {
  const CliResult r = run(args_for(drive_, root_ / "out"));
  EXPECT_EQ(r.status, 0) << r.out;
}

TEST_F(KittiRawCliBadInput, MissingCalibrationKey) {
  std::ofstream(drive_.calib_dir / "calib_velo_to_cam.txt") << "R: 1 0 0 0 1 0 0 0 1\n";
  expect_error("calib_velo_to_cam.txt");
  expect_error("'T'");
}

TEST_F(KittiRawCliBadInput, ScanSizeNotAMultipleOf16) {
  const fs::path bin = drive_.drive_dir / "velodyne_points/data/0000000030.bin";
  fs::resize_file(bin, fs::file_size(bin) - 4);
  expect_error("0000000030.bin: size");
  expect_error("not a multiple of 16");
}

TEST_F(KittiRawCliBadInput, MissingLabelImage) {
  fs::remove(drive_.labels_dir / "0000000031.png");
  expect_error("0000000031.png: missing image");
}

TEST_F(KittiRawCliBadInput, UnreadableOxts) {
  std::ofstream(drive_.drive_dir / "oxts/data/0000000005.txt") << "49.0 8.4 oops\n";
  expect_error("0000000005.txt:1");
  fs::remove_all(drive_.drive_dir / "oxts");
  expect_error("oxts/timestamps.txt: cannot open");
}

TEST_F(KittiRawCliBadInput, NeitherSegmenterNorLabels) {
  const CliResult r = run("kitti-raw --drive " + drive_.drive_dir.string());
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_TRUE(has(r.out, "--segmenter or --labels")) << r.out;
}

}  // namespace
}  // namespace semap::map_io
