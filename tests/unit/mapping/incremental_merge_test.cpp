#include "semap/mapping/incremental_merge.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <random>
#include <unordered_set>

#include "semap/mapping/map_merge.hpp"

namespace semap::mapping {
namespace {

MapParams params(float resolution, int cells) {
  MapParams p;
  p.method = MapMethod::kBki;
  p.resolution = resolution;
  p.block_depth = std::countr_zero(static_cast<unsigned>(cells)) + 1;
  p.num_classes = 2;
  p.prior = 0.001f;
  return p;
}

bool contains(const std::vector<common::BlockIndex>& keys, const common::BlockIndex& k) {
  return std::find(keys.begin(), keys.end(), k) != keys.end();
}

Eigen::Isometry3d random_pose(std::mt19937& rng) {
  std::uniform_real_distribution<double> angle(-3.2, 3.2);
  std::uniform_real_distribution<double> shift(-5.0, 5.0);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(angle(rng), Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(angle(rng) / 4, Eigen::Vector3d::UnitY()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(shift(rng), shift(rng), shift(rng));
  return T;
}

std::vector<float> random_block(std::size_t floats, std::mt19937& rng) {
  std::uniform_int_distribution<int> value(-3, 4);  // about a third of the cells stay empty
  std::vector<float> b(floats);
  for (float& v : b) v = static_cast<float>(std::max(0, value(rng)));
  return b;
}

TEST(IncrementalMerge, TouchedBlocksOfAnAlignedShiftAreExact) {
  const auto p = params(0.25f, 4);
  EXPECT_EQ(touched_blocks({2, -1, 3}, p, p, Eigen::Isometry3d::Identity()),
            (std::vector<common::BlockIndex>{{2, -1, 3}}));
  EXPECT_EQ(source_blocks({2, -1, 3}, p, p, Eigen::Isometry3d::Identity()),
            (std::vector<common::BlockIndex>{{2, -1, 3}}));
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(2.0, 0.0, -1.0);  // two blocks in x, one down
  EXPECT_EQ(touched_blocks({0, 0, 0}, p, p, T), (std::vector<common::BlockIndex>{{2, 0, -1}}));
  EXPECT_EQ(source_blocks({2, 0, -1}, p, p, T), (std::vector<common::BlockIndex>{{0, 0, 0}}));
  T.translation() = Eigen::Vector3d(0.5, 0.0, 0.0);  // half a block: two each way
  EXPECT_EQ(touched_blocks({0, 0, 0}, p, p, T),
            (std::vector<common::BlockIndex>{{0, 0, 0}, {1, 0, 0}}));
  EXPECT_EQ(source_blocks({0, 0, 0}, p, p, T),
            (std::vector<common::BlockIndex>{{-1, 0, 0}, {0, 0, 0}}));
}

// Whatever the transform, every block resample_layer writes from a source block is in
// touched_blocks, and that source block is in source_blocks of each of them.
TEST(IncrementalMerge, BlockRangesCoverWhatResamplingWrites) {
  const auto p = params(0.2f, 4);
  std::mt19937 rng(3);
  for (int trial = 0; trial < 40; ++trial) {
    const Eigen::Isometry3d T = random_pose(rng);
    const common::BlockIndex key{trial % 5 - 2, trial % 3, -1};
    EvidenceGrid layer(p.cells_per_side(), p.channels());
    layer.put_block(key, std::vector<float>(layer.block_floats(), 1.0f));
    const auto written = resample_layer(layer, p, p, T);
    const auto touched = touched_blocks(key, p, p, T);
    ASSERT_GT(written.size(), 0u);
    for (const auto& k : written.keys()) {
      EXPECT_TRUE(contains(touched, k)) << "trial " << trial;
      EXPECT_TRUE(contains(source_blocks(k, p, p, T), key)) << "trial " << trial;
    }
  }
}

// A robot's layer changes in a few blocks; re-merging only the blocks they reach gives the
// same fused map as merge_into of the whole new layer.
TEST(IncrementalMerge, RemergingChangedBlocksEqualsMergeIntoTheWholeLayer) {
  const auto p = params(0.2f, 4);
  std::mt19937 rng(11);
  for (int trial = 0; trial < 12; ++trial) {
    const Eigen::Isometry3d T = trial == 0 ? Eigen::Isometry3d::Identity() : random_pose(rng);
    LayeredMap robot(p);
    auto& layer = robot.layer(2);
    for (int x = -2; x <= 2; ++x) {
      for (int y = 0; y <= 2; ++y) {
        layer.put_block({x, y, 0}, random_block(layer.block_floats(), rng));
      }
    }
    layer.set_updates(1);
    LayeredMap fused(p);
    fused.layer(1).put_block({0, 0, 0}, random_block(layer.block_floats(), rng));  // robot 1
    merge_into(fused, robot, T);

    // Three blocks change (one of them new, one emptied), and the incremental update runs.
    const std::vector<common::BlockIndex> changed{{0, 1, 0}, {3, 0, 0}, {-2, 2, 0}};
    for (const auto& k : changed) layer.put_block(k, random_block(layer.block_floats(), rng));
    layer.put_block({-2, 2, 0}, std::vector<float>(layer.block_floats(), 0.0f));
    layer.set_updates(2);
    std::unordered_set<common::BlockIndex, common::BlockIndexHash> targets;
    for (const auto& k : changed) {
      for (const auto& t : touched_blocks(k, p, p, T)) targets.insert(t);
    }
    remerge_blocks(fused, 2, layer, p, {targets.begin(), targets.end()}, T);

    LayeredMap expected(p);
    expected.layer(1) = *fused.find_layer(1);
    merge_into(expected, robot, T);
    ASSERT_TRUE(*fused.find_layer(2) == *expected.find_layer(2)) << "trial " << trial;
    EXPECT_TRUE(fused == expected) << "trial " << trial;
  }
}

}  // namespace
}  // namespace semap::mapping
