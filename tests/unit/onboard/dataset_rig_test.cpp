// The robot's perception and mapping stages on real RGB-D frames (Redwood, Open3D's test data)
// played by the DatasetRig: the map built from frames 0-3 must hold frame 4's depth points where
// frame 4's pose puts them.
#include "semap/onboard/dataset_rig.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <set>
#include <thread>
#include <tuple>

#include "semap/map_io/map_export.hpp"
#include "semap/onboard/pipeline.hpp"
#include "semap/perception/datasets/depth_png.hpp"
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

}  // namespace
}  // namespace semap::onboard
