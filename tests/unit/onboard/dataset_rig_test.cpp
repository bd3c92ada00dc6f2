// The robot's perception and mapping stages on real RGB-D frames (Redwood, Open3D's test data)
// played by the DatasetRig: the map built from frames 0-3 must hold frame 4's depth points where
// frame 4's pose puts them.
#include "semap/onboard/dataset_rig.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <thread>
#include <tuple>

#include "semap/map_io/map_export.hpp"
#include "semap/onboard/pipeline.hpp"
#include "semap/perception/datasets/depth_png.hpp"
#include "semap/perception/datasets/kitti_odometry.hpp"
#include "semap/perception/datasets/redwood.hpp"

namespace semap::onboard {
namespace {

namespace datasets = perception::datasets;

std::filesystem::path redwood_dir() {
  return std::filesystem::path(SEMAP_SHARED_DATA_DIR) / "real" / "redwood";
}

OnboardConfig geometry_config(const datasets::RgbdSequence& sequence) {
  OnboardConfig c;
  c.map.params.resolution = 0.05f;
  c.map.params.ell = 0.15f;
  c.map.params.free_res = 0.1f;
  c.map.params.ds_res = 0.05f;
  c.map.params.max_range = 5.0f;
  c.map.params.num_classes = 2;
  c.map.palette = mapping::ClassPalette::defaults(2);
  c.map.checkpoint_s = 0.0;
  c.dds.enabled = false;
  c.costmap.reset();
  c.segmenter.kind = SegmenterConfig::Kind::kGeometry;
  c.depth.points.max_range = 5.0f;
  c.camera.intrinsics = *sequence.intrinsics;
  c.depth.depth_scale = static_cast<float>(1.0 / sequence.depth_units_per_metre);
  return c;
}

// Maps `sequence`'s frames 0..last through the pipeline; returns the occupied cells.
std::vector<map_io::OccupiedCell> map_frames(datasets::RgbdSequence sequence, std::size_t last) {
  const OnboardConfig config = geometry_config(sequence);
  DatasetSelection selection;
  selection.last = last;
  Pipeline pipeline(config, [&](const SensorRings& rings) {
    return std::make_unique<DatasetRig>(std::move(sequence), "redwood",
                                        config.camera.body_from_optical(), selection, rings);
  });
  pipeline.start();
  while (!pipeline.finished()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  pipeline.stop();
  EXPECT_EQ(pipeline.mapping().scans, last + 1);
  return map_io::occupied_cells(pipeline.map().layers());
}

// Share of the frame's depth points (every 4th pixel) that lie within one cell of an occupied
// cell once placed with `world_from_camera`.
double share_near_occupied(const std::vector<map_io::OccupiedCell>& cells, double resolution,
                           const datasets::RgbdSequence& sequence, const datasets::RgbdFrame& frame,
                           const Eigen::Isometry3d& world_from_camera) {
  using Key = std::tuple<long, long, long>;
  const auto key = [&](const Eigen::Vector3d& p) {
    return Key{std::lround(std::floor(p.x() / resolution)),
               std::lround(std::floor(p.y() / resolution)),
               std::lround(std::floor(p.z() / resolution))};
  };
  std::set<Key> occupied;
  for (const auto& c : cells) occupied.insert(key(c.centre));
  const cv::Mat depth = datasets::read_depth_metres(frame.depth, sequence.depth_units_per_metre);
  const auto& k = *sequence.intrinsics;
  std::size_t points = 0, near = 0;
  for (int v = 0; v < depth.rows; v += 4) {
    for (int u = 0; u < depth.cols; u += 4) {
      const float z = depth.at<float>(v, u);
      if (!(z > 0.0f) || z > 5.0f) continue;
      const Eigen::Vector3d optical((u - k.cx) / k.fx * z, (v - k.cy) / k.fy * z, z);
      const auto [x, y, w] = key(world_from_camera * optical);
      ++points;
      bool found = false;
      for (long dx = -1; dx <= 1 && !found; ++dx) {
        for (long dy = -1; dy <= 1 && !found; ++dy) {
          for (long dz = -1; dz <= 1 && !found; ++dz) {
            found = occupied.count(Key{x + dx, y + dy, w + dz}) > 0;
          }
        }
      }
      near += found ? 1 : 0;
    }
  }
  return points ? static_cast<double>(near) / static_cast<double>(points) : 0.0;
}

TEST(DatasetRig, RedwoodFramesAgreeWithTheMapOfTheFramesBefore) {
  if (!std::filesystem::exists(redwood_dir())) {
    GTEST_SKIP() << redwood_dir() << " is absent (../shared/data/real, see its README.md)";
  }
  const datasets::RgbdSequence sequence = datasets::read_redwood(redwood_dir());
  ASSERT_EQ(sequence.frames.size(), 5u);
  ASSERT_TRUE(sequence.intrinsics);
  const auto& frame4 = sequence.frames[4];

  const auto with_poses = map_frames(sequence, 3);
  const double posed =
      share_near_occupied(with_poses, 0.05, sequence, frame4, frame4.world_from_camera);

  // A pose-convention error: frames 0-3 mapped with camera-from-world instead.
  datasets::RgbdSequence inverted = sequence;
  for (auto& f : inverted.frames) f.world_from_camera = f.world_from_camera.inverse();
  const auto with_inverted = map_frames(inverted, 3);
  const double wrong =
      share_near_occupied(with_inverted, 0.05, sequence, frame4, frame4.world_from_camera);
  // Identity poses: frames 0-3 mapped where the camera's motion is ignored.
  datasets::RgbdSequence unposed = sequence;
  for (auto& f : unposed.frames) f.world_from_camera = Eigen::Isometry3d::Identity();
  const auto with_identity = map_frames(unposed, 3);
  const double identity =
      share_near_occupied(with_identity, 0.05, sequence, frame4, frame4.world_from_camera);

  std::printf("frame 4 near the map of frames 0-3: %.3f with poses, %.3f inverted, %.3f identity\n",
              posed, wrong, identity);
  EXPECT_GE(posed, 0.90);
  EXPECT_LT(identity, posed - 0.10);
  EXPECT_LT(wrong, posed - 0.10);
}

// KITTI odometry sequence 00's first scan, mapped whole (no image) through the pipeline: the
// road in front of the car lies where the Velodyne's mount, 1.73 m above it, puts it.
TEST(DatasetRig, KittiScanPutsTheRoadBelowTheVelodyneMount) {
  const auto root = std::filesystem::path(SEMAP_SHARED_DATA_DIR) / "real" / "kitti_odometry_00";
  if (!std::filesystem::exists(root)) {
    GTEST_SKIP() << root << " is absent (../shared/data/real, see its README.md)";
  }
  // Tr of sequence 00 as its README quotes it; P2 does not matter for whole scans.
  const auto calib = std::filesystem::path(::testing::TempDir()) / "kitti00_calib.txt";
  std::ofstream(calib)
      << "P2: 718.856 0 607.1928 45.38225 0 718.856 185.2157 -0.1130887 0 0 1 0.003779761\n"
         "Tr: 4.276802385584e-04 -9.999672484946e-01 -8.084491683471e-03 -1.198459927713e-02 "
         "-7.210626507497e-03 8.081198471645e-03 -9.999413164504e-01 -5.403984729748e-02 "
         "9.999738645903e-01 4.859485810390e-04 -7.206933692422e-03 -2.921968648686e-01\n";
  const auto sequence =
      datasets::read_kitti_odometry(root / "sequences" / "00", {}, {.calib = calib});
  ASSERT_EQ(sequence.frames.size(), 1u);

  OnboardConfig config;
  auto& p = config.map.params;
  p.resolution = 0.1f;
  p.block_depth = 3;
  p.ell = 0.3f;
  p.ds_res = 0.1f;
  p.free_res = 2.0f;
  p.max_range = 30.0f;
  p.num_classes = 2;
  config.map.palette = mapping::ClassPalette::defaults(2);
  config.map.checkpoint_s = 0.0;
  config.dds.enabled = false;
  config.costmap.reset();
  config.segmenter.kind = SegmenterConfig::Kind::kGeometry;
  config.depth.source = DepthSource::kLidar;
  config.depth.points.max_range = 30.0f;
  Pipeline pipeline(config, [&](const SensorRings& rings) {
    return std::make_unique<DatasetRig>(sequence, "kitti 00", Eigen::Isometry3f::Identity(),
                                        DatasetSelection{}, rings);
  });
  pipeline.start();
  while (!pipeline.finished()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  pipeline.stop();
  ASSERT_EQ(pipeline.mapping().scans, 1u);
  const auto perception = pipeline.perception();
  ASSERT_TRUE(perception);
  // Every one of the 124,668 points is in the cloud or counted (beyond 30 m).
  EXPECT_EQ(perception->points + perception->dropped.out_of_range, 124668u);

  // In each column of cells 5-15 m ahead within 2 m of the centre line, the most probable
  // occupied cell: the kernel (ell 0.3) spreads a surface's evidence a few cells up and down,
  // fading with distance, so the surface is where the probability peaks.
  std::map<std::pair<long, long>, map_io::OccupiedCell> peak;
  for (const auto& cell : map_io::occupied_cells(pipeline.map().layers())) {
    const auto& c = cell.centre;
    if (c.x() < 5 || c.x() > 15 || std::abs(c.y()) > 2) continue;
    const std::pair<long, long> column{std::lround(c.x() * 10), std::lround(c.y() * 10)};
    const auto [it, added] = peak.emplace(column, cell);
    if (!added && cell.probability > it->second.probability) it->second = cell;
  }
  ASSERT_GT(peak.size(), 500u);
  std::vector<double> heights;
  for (const auto& [column, cell] : peak) heights.push_back(cell.centre.z());
  std::nth_element(heights.begin(), heights.begin() + heights.size() / 2, heights.end());
  const double road = heights[heights.size() / 2];
  std::printf("KITTI 00 scan 0 mapped: road 5-15 m ahead at z = %.3f m (%zu columns)\n", road,
              heights.size());
  // Within a cell and a half (0.15 m) of -1.73 m. A flipped z axis would put it at +1.73 m,
  // the camera frame taken for the LiDAR's would leave no road ahead at all.
  EXPECT_NEAR(road, -1.73, 0.15);
}

}  // namespace
}  // namespace semap::onboard
