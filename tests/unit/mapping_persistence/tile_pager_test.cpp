#include "semap/mapping/tile_pager.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "semap/mapping/logodds_map.hpp"
#include "semap/mapping/smap_io.hpp"

namespace semap::mapping {
namespace {

class TilePagerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("tile_pager_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
};

LayeredMapParams pager_params() {
  LayeredMapParams p;
  p.method = MapMethod::kLogOdds;
  p.resolution = 0.2;
  p.block_depth = 3;  // 4 cells, 0.8 m per block side
  p.num_classes = 4;
  p.logodds.max_range = 3.0;
  return p;
}

// A ring of beams from 1 m above the ground hitting the ground (class by position) and a
// few posts (class 3) within 3 m.
common::LabeledCloud scan_at(const Eigen::Vector3f& robot) {
  common::LabeledCloud cloud;
  cloud.origin = robot + Eigen::Vector3f(0.0f, 0.0f, 1.0f);
  for (int i = 0; i < 72; ++i) {
    const float angle = static_cast<float>(i) * 0.0873f;
    for (const float r : {1.0f, 2.0f, 2.8f}) {
      const Eigen::Vector3f p =
          robot + Eigen::Vector3f(r * std::cos(angle), r * std::sin(angle), 0.0f);
      cloud.points.push_back(p);
      cloud.labels.push_back(std::fmod(std::floor(p.x() / 5.0f), 2.0f) == 0.0f ? 1 : 2);
    }
  }
  return cloud;
}

// Out along y = 0 and back along y = 1.5: the return revisits (and restores) blocks.
std::vector<Eigen::Vector3f> path() {
  std::vector<Eigen::Vector3f> poses;
  for (float x = 0.0f; x <= 120.0f; x += 1.0f) poses.emplace_back(x, 0.0f, 0.0f);
  for (float x = 120.0f; x >= 0.0f; x -= 1.0f) poses.emplace_back(x, 1.5f, 0.0f);
  return poses;
}

TEST_F(TilePagerTest, LongRunStaysUnderBudgetAndLosesNoEvidence) {
  // Radius 3 m max range + block diagonal (1.4 m) + margin; with the eviction hysteresis the
  // resident set is the blocks within ~5.3 m of the robot.
  constexpr double kRadius = 4.5;
  // A disc of ~5.3 m radius holds ~140 ground blocks of 0.8 m, plus the few blocks above the
  // ground near the robot that the descending beams cross; 200 leaves a margin.
  constexpr std::size_t kBudget = 200;  // layer blocks resident at any time

  LogOddsMap reference(pager_params(), 1);
  LogOddsMap paged(pager_params(), 1);
  // Not durable: fsync per tile would make this test take a minute on a busy disk; the
  // durable path is the same code with fsync and is covered by the .smap tests.
  TileStore store(dir_ / "tiles", pager_params(), false);
  TilePager pager(paged.layers(), store, kRadius);
  std::size_t max_resident = 0;
  for (const Eigen::Vector3f& pose : path()) {
    const auto cloud = scan_at(pose);
    reference.insert(cloud);
    pager.update(cloud.origin.cast<double>());
    paged.insert(cloud);
    max_resident = std::max(max_resident, paged.layers().resident_blocks());
  }
  const std::size_t total = reference.layers().resident_blocks();
  std::printf(
      "blocks in the full map %zu, max resident %zu (budget %zu), evicted %zu, "
      "restored %zu\n",
      total, max_resident, kBudget, pager.stats().evicted, pager.stats().restored);
  EXPECT_LE(max_resident, kBudget);
  EXPECT_GE(total, 10 * kBudget);          // the run covers more than ten budgets of map
  EXPECT_GT(pager.stats().restored, 50u);  // the return trip really read tiles back
  // Nothing lost or changed: resident blocks plus tiles are exactly the unpaged map.
  EXPECT_EQ(pager.full_map(), reference.layers());

  // After a restart the tiles are found again.
  TileStore reopened(dir_ / "tiles", pager_params());
  EXPECT_EQ(reopened.size(), store.size());
}

TEST_F(TilePagerTest, DamagedTileIsReportedWithItsFile) {
  LogOddsMap map(pager_params(), 1);
  map.insert(scan_at(Eigen::Vector3f::Zero()));
  TileStore store(dir_ / "tiles", pager_params());
  TilePager pager(map.layers(), store, 1.0);
  pager.update(Eigen::Vector3d(100.0, 0.0, 0.0));
  ASSERT_GT(store.size(), 0u);
  const common::BlockIndex key = *store.keys().begin();
  std::filesystem::resize_file(store.tile_path(key), 40);
  try {
    store.restore(map.layers(), key);
    FAIL();
  } catch (const SmapError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr(store.tile_path(key).string()));
  }
}

}  // namespace
}  // namespace semap::mapping
