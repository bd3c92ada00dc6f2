// The robot's map and a DDS client put every point in the same cell, also on and within
// 0.1 mm of block faces, at several resolutions: both go through common::MapGrid. (A client
// computing floor(p / block size) instead sends some of these points to the neighbouring block.)
#include <gtest/gtest.h>

#include <random>

#include "dds_fixture.hpp"
#include "semap/dds_idl/map_client.hpp"
#include "semap/dds_idl/map_publisher.hpp"
#include "semap/mapping/semantic_map.hpp"
#include "semap/onboard/mapping_stage.hpp"

namespace semap::dds_idl::testing {
namespace {

constexpr int kClasses = 3;

// Points on the faces between blocks along each axis, at the float next to each face on either
// side, and uniformly within 0.1 mm of it.
std::vector<Eigen::Vector3f> points_at_block_faces(const common::MapGrid& grid, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> inside(-2.0f, 2.0f);
  std::uniform_real_distribution<float> near(-1e-4f, 1e-4f);
  std::vector<Eigen::Vector3f> points;
  // Faces up to a few hundred metres out, where float rounding of p / block size and of
  // p * (1 / resolution) part ways most often.
  for (int face = -300; face <= 300; face += 7) {
    const float at = static_cast<float>(face) * grid.block_size();
    std::vector<float> coordinates{at, std::nextafter(at, -1e9f), std::nextafter(at, 1e9f)};
    for (int i = 0; i < 20; ++i) coordinates.push_back(at + near(rng));
    for (const float c : coordinates) {
      for (int axis = 0; axis < 3; ++axis) {
        Eigen::Vector3f p(inside(rng), inside(rng), inside(rng));
        p[axis] = c;
        points.push_back(p);
      }
    }
  }
  return points;
}

TEST_F(DdsTest, RobotAndClientAgreeOnTheCellOfPointsAtBlockFaces) {
  Participant participant(test_domain());
  std::size_t checked = 0;
  for (const float resolution : {0.1f, 0.2f, 0.25f, 0.3f}) {
    mapping::MapParams params;
    params.method = mapping::MapMethod::kCsm;  // a point's evidence stays in its own cell
    params.resolution = resolution;
    params.block_depth = 3;
    params.num_classes = kClasses;
    const mapping::MapParams& p = params;
    mapping::SemanticMap map(p);
    const auto points = points_at_block_faces(p.grid(), static_cast<unsigned>(resolution * 1000));
    // Neighbouring points get different classes, so reading the cell next door shows.
    mapping::TrainingSet training;
    training.num_classes = kClasses;
    for (std::size_t i = 0; i < points.size(); ++i) {
      training.points.push_back(points[i]);
      training.labels.push_back(1 + static_cast<int>(i % 2));
    }
    training.num_hits = training.points.size();
    map.insert(training);

    const std::string ns = unique_ns("grid");
    MapDescription description;
    description.resolution = resolution;
    description.block_cells = static_cast<std::uint16_t>(p.cells_per_side());
    description.num_classes = kClasses;
    SnapshotStore publisher_blocks;
    MapPublisher publisher(participant, {ns, "map", 20.0, 0.0}, description, publisher_blocks);
    std::size_t blocks = 0;
    map.for_each_block([&](const common::BlockIndex& index, const mapping::Block& block) {
      BlockSnapshot snapshot;
      onboard::to_snapshot(map, index, block, 1, true, snapshot);
      publisher.changed(publisher_blocks.put(std::move(snapshot)));
      ++blocks;
    });
    publisher.publish_changed(common::Stamp::now());
    MapClient client(participant, {ns, {}});
    ASSERT_TRUE(client.wait_for_blocks(blocks, seconds(15)))
        << "resolution " << resolution << ": got " << client.blocks().size() << " of " << blocks;

    for (const Eigen::Vector3f& point : points) {
      const auto robot = map.query(point);
      ASSERT_TRUE(robot.has_value());
      const CellQuery client_cell = client.query(point);
      ASSERT_TRUE(client_cell.known_block) << point.transpose() << " at " << resolution;
      EXPECT_EQ(client_cell.state, robot->state()) << point.transpose() << " at " << resolution;
      EXPECT_EQ(client_cell.cls, robot->argmax()) << point.transpose() << " at " << resolution;
      ++checked;
    }
  }
  EXPECT_EQ(checked, 4u * 86u * 23u * 3u);
}

}  // namespace
}  // namespace semap::dds_idl::testing
