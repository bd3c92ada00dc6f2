#include "semap/mapping/logodds_map.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "semap/mapping/ray_traversal.hpp"

namespace semap::mapping {
namespace {

MapParams logodds_params(int classes = 5) {
  MapParams p;
  p.method = MapMethod::kLogOdds;
  p.resolution = 0.1f;
  p.num_classes = classes;
  return p;
}

common::LabeledCloud beam(const Eigen::Vector3f& origin, const Eigen::Vector3f& end,
                          std::uint16_t label) {
  common::LabeledCloud cloud;
  cloud.origin = origin;
  cloud.points = {end};
  cloud.labels = {label};
  return cloud;
}

// Yue et al.'s single-voxel experiment: six observations of "road" at p ~ 0.98.
TEST(LogOddsMap, SingleVoxelRoadProbabilityRisesOthersFall) {
  constexpr int kClasses = 5;
  constexpr int kRoad = 2;
  LogOddsMap map(logodds_params(kClasses), 1);
  common::LabeledCloud cloud;
  cloud.origin = Eigen::Vector3f(0.05f, 0.05f, 0.05f);
  cloud.points = {Eigen::Vector3f(1.05f, 0.05f, 0.05f)};
  cloud.num_classes = kClasses;
  cloud.probabilities.assign(kClasses, 0.02f / (kClasses - 1));
  cloud.probabilities[kRoad] = 0.98f;
  const common::CellIndex voxel =
      common::MapGrid(0.1f, 1).cell_of(Eigen::Vector3d(1.05, 0.05, 0.05));

  std::vector<double> previous = map.class_probabilities(voxel);
  for (double p : previous) EXPECT_NEAR(p, 1.0 / kClasses, 1e-6);
  for (int update = 0; update < 6; ++update) {
    map.insert(cloud);
    const std::vector<double> now = map.class_probabilities(voxel);
    for (int c = 0; c < kClasses; ++c) {
      if (c == kRoad) {
        EXPECT_GT(now[c], previous[c]) << "update " << update;
      } else {
        EXPECT_LT(now[c], previous[c]) << "update " << update << " class " << c;
      }
    }
    double sum = 0.0;
    for (double p : now) sum += p;
    EXPECT_NEAR(sum, 1.0, 1e-9);
    previous = now;
  }
  EXPECT_GT(previous[kRoad], 0.999999);
  const CellSummary s = map.summary(voxel);
  EXPECT_EQ(s.label, kRoad);
  EXPECT_TRUE(s.occupied);
}

TEST(LogOddsMap, FirstUpdateMatchesBayesRule) {
  LogOddsMap map(logodds_params(3), 1);
  common::LabeledCloud cloud;
  cloud.points = {Eigen::Vector3f(0.55f, 0.05f, 0.05f)};
  cloud.num_classes = 3;
  cloud.probabilities = {0.2f, 0.5f, 0.3f};
  map.insert(cloud);
  map.insert(cloud);
  // Two identical measurements from a uniform prior: p(c) proportional to p(c|z)^2.
  const double norm = 0.04 + 0.25 + 0.09;
  const auto p =
      map.class_probabilities(common::MapGrid(0.1f, 1).cell_of(Eigen::Vector3d(0.55, 0.05, 0.05)));
  EXPECT_NEAR(p[0], 0.04 / norm, 1e-5);
  EXPECT_NEAR(p[1], 0.25 / norm, 1e-5);
  EXPECT_NEAR(p[2], 0.09 / norm, 1e-5);
}

TEST(LogOddsMap, OccupancyFollowsOctomapHitMissAndClamping) {
  LogOddsMap map(logodds_params(), 7);
  const auto cloud = beam({0.05f, 0.05f, 0.05f}, {1.05f, 0.05f, 0.05f}, 1);
  map.insert(cloud);
  EXPECT_NEAR(map.occupancy_probability({10, 0, 0}), 0.7, 1e-5);
  for (int x = 0; x < 10; ++x) EXPECT_NEAR(map.occupancy_probability({x, 0, 0}), 0.4, 1e-5);
  EXPECT_FALSE(map.summary({11, 0, 0}).known);
  EXPECT_FALSE(map.summary({5, 1, 0}).known);
  for (int i = 0; i < 30; ++i) map.insert(cloud);
  EXPECT_NEAR(map.occupancy_probability({10, 0, 0}), 0.97, 1e-5);
  EXPECT_NEAR(map.occupancy_probability({3, 0, 0}), 0.12, 1e-5);
  EXPECT_EQ(map.summary({10, 0, 0}).label, 1);
  EXPECT_FALSE(map.summary({3, 0, 0}).occupied);
  EXPECT_EQ(map.layers().find_layer(7)->updates(), 31u);
}

TEST(LogOddsMap, CellHitAndCrossedInOneScanCountsAsHit) {
  LogOddsMap map(logodds_params(), 1);
  common::LabeledCloud cloud;
  cloud.origin = Eigen::Vector3f(0.05f, 0.05f, 0.05f);
  // The second beam passes through the cell the first ends in.
  cloud.points = {{0.55f, 0.05f, 0.05f}, {1.05f, 0.05f, 0.05f}};
  cloud.labels = {1, 2};
  map.insert(cloud);
  EXPECT_NEAR(map.occupancy_probability({5, 0, 0}), 0.7, 1e-5);
  EXPECT_NEAR(map.occupancy_probability({4, 0, 0}), 0.4, 1e-5);
}

TEST(LogOddsMap, BeamsBeyondMaxRangeOnlyClearSpace) {
  MapParams p = logodds_params();
  p.logodds.max_range = 0.5;
  LogOddsMap map(p, 1);
  map.insert(beam({0.05f, 0.05f, 0.05f}, {2.05f, 0.05f, 0.05f}, 1));
  EXPECT_FALSE(map.summary({20, 0, 0}).known);
  EXPECT_NEAR(map.occupancy_probability({3, 0, 0}), 0.4, 1e-5);
  EXPECT_FALSE(map.summary({6, 0, 0}).known);
}

TEST(LogOddsMap, CountsBadPointsAndSkipsThem) {
  LogOddsMap map(logodds_params(4), 1);
  common::LabeledCloud cloud;
  cloud.points = {{0.55f, 0.05f, 0.05f},
                  {std::nanf(""), 0.0f, 0.0f},
                  {0.05f, 0.55f, 0.05f},
                  {90.0f, 0.05f, 0.05f}};
  cloud.labels = {1, 1, 9, 2};
  const LogOddsInsertResult r = map.insert(cloud);
  EXPECT_EQ(r.rejected, 2u);
  EXPECT_EQ(r.out_of_range, 1u);
  EXPECT_EQ(r.hit_cells, 1u);
  EXPECT_GT(r.free_cells, 100u);
  EXPECT_FALSE(map.summary_at({0.05, 0.55, 0.05}).occupied);
}

// Cells beyond the block table's +-2^20 blocks are bad points, not a crash; a scan taken from
// such an origin leaves the map as it was.
TEST(LogOddsMap, PointsAndOriginsBeyondTheGridAreRejected) {
  LogOddsMap map(logodds_params(4), 1);
  common::LabeledCloud cloud;
  cloud.points = {{0.55f, 0.05f, 0.05f}, {1e9f, 0.0f, 0.0f}};
  cloud.labels = {1, 1};
  EXPECT_EQ(map.insert(cloud).rejected, 1u);
  const std::size_t blocks = map.layers().resident_blocks();
  cloud.origin = {0.0f, -3e8f, 0.0f};
  EXPECT_EQ(map.insert(cloud).rejected, 2u);
  EXPECT_EQ(map.layers().resident_blocks(), blocks);
}

TEST(LogOddsMap, RejectsCloudWithMismatchedLabels) {
  LogOddsMap map(logodds_params(), 1);
  common::LabeledCloud cloud;
  cloud.points = {{1.0f, 0.0f, 0.0f}};
  EXPECT_THROW(map.insert(cloud), std::invalid_argument);
  MapParams bki = logodds_params();
  bki.method = MapMethod::kBki;
  EXPECT_THROW(LogOddsMap(bki, 1), std::invalid_argument);
}

TEST(RayTraversal, VisitsFaceConnectedCellsUpToTheEndCell) {
  const Eigen::Vector3d from(0.03, -0.17, 0.41);
  const Eigen::Vector3d to(2.71, 1.33, -0.92);
  std::vector<common::CellIndex> cells;
  traverse_ray(from, to, 0.1, [&](const common::CellIndex& c) { cells.push_back(c); });
  ASSERT_FALSE(cells.empty());
  EXPECT_EQ(cells.front(), common::MapGrid(0.1f, 1).cell_of(from));
  const common::CellIndex end = common::MapGrid(0.1f, 1).cell_of(to);
  EXPECT_EQ((end - cells.back()).cwiseAbs().sum(), 1);
  for (std::size_t i = 1; i < cells.size(); ++i) {
    EXPECT_EQ((cells[i] - cells[i - 1]).cwiseAbs().sum(), 1) << "step " << i;
  }
  EXPECT_EQ(static_cast<int>(cells.size()), (end - cells.front()).cwiseAbs().sum());
}

TEST(RayTraversal, NegativeAxisRay) {
  std::vector<common::CellIndex> cells;
  traverse_ray({0.05, 0.05, 0.05}, {-0.45, 0.05, 0.05}, 0.1,
               [&](const common::CellIndex& c) { cells.push_back(c); });
  ASSERT_EQ(cells.size(), 5u);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(cells[i], common::CellIndex(-i, 0, 0));
}

}  // namespace
}  // namespace semap::mapping
