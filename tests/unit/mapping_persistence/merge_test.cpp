#include <gtest/gtest.h>

#include <cmath>

#include "semap/mapping/logodds_map.hpp"
#include "semap/mapping/map_merge.hpp"
#include "test_maps.hpp"

namespace semap::mapping {
namespace {

Eigen::Isometry3d rotated_translated() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(1.23, -0.71, 0.35);
  return T;
}

// One robot's map built from random beams.
LayeredMap robot_map(SourceId robot, std::uint32_t seed) {
  LayeredMap map = testing::random_logodds_map(seed);
  LayeredMap only(map.params());
  only.set_layer(robot, *map.find_layer(1));
  return only;
}

TEST(Merge, IdentityMergeAddsOccupancyAndLabelLogOdds) {
  LayeredMap a = robot_map(1, 11);
  const LayeredMap b = robot_map(2, 12);
  const LayeredMap a_before = a;
  const MergeReport report = merge_into(a, b, Eigen::Isometry3d::Identity());
  EXPECT_EQ(report.layers_added, 1u);
  const LogOddsModel model(a.params().logodds);
  std::size_t checked = 0;
  std::vector<float> fa(5), fb(5), fm(5);
  for (const common::BlockIndex& key : b.block_keys()) {
    for (int c = 0; c < 64; c += 5) {
      const common::CellIndex cell = cell_of_local(key, c, a.params().cells_per_side());
      const bool ka = a_before.fused(cell, fa);
      const bool kb = b.fused(cell, fb);
      ASSERT_EQ(a.fused(cell, fm), ka || kb);
      EXPECT_FLOAT_EQ(fm[0], model.clamp(fa[0] + fb[0]));
      for (int k = 1; k < 5; ++k) EXPECT_NEAR(fm[k], fa[k] + fb[k], 1e-5);
      checked += ka && kb;
    }
  }
  EXPECT_GT(checked, 10u);  // the maps overlap, so the sums were really exercised
}

TEST(Merge, MergingTheSameMapTwiceChangesNothing) {
  LayeredMap a = robot_map(1, 21);
  const LayeredMap b = robot_map(2, 22);
  const Eigen::Isometry3d T_ab = rotated_translated();
  merge_into(a, b, T_ab);
  const LayeredMap once = a;
  const MergeReport again = merge_into(a, b, T_ab);
  EXPECT_EQ(again.layers_kept, 1u);
  EXPECT_EQ(again.layers_added + again.layers_replaced, 0u);
  EXPECT_EQ(a, once);
}

TEST(Merge, AIntoBThenBBackIntoAChangesNothing) {
  LayeredMap a = robot_map(1, 31);
  LayeredMap b = robot_map(2, 32);
  const Eigen::Isometry3d T_ab = rotated_translated();
  merge_into(b, a, T_ab.inverse());  // B now holds A's evidence in B's frame
  merge_into(a, b, T_ab);            // A gets B's own layer; its own copy of A is kept
  const LayeredMap a_merged = a;
  merge_into(b, a, T_ab.inverse());
  merge_into(a, b, T_ab);
  EXPECT_EQ(a, a_merged);
  // A's own evidence never went through a lossy round trip.
  EXPECT_EQ(*a.find_layer(1), *robot_map(1, 31).find_layer(1));
}

TEST(Merge, NewerCopyOfASourceReplacesTheOlderOne) {
  LayeredMap a = robot_map(1, 41);
  LayeredMap b(a.params());
  EvidenceGrid newer = *a.find_layer(1);
  testing::set_channel(newer, {0, 0, 0}, 0, 1.0f);
  newer.set_updates(newer.updates() + 1);
  b.set_layer(1, newer);
  const MergeReport report = merge_into(a, b, Eigen::Isometry3d::Identity());
  EXPECT_EQ(report.layers_replaced, 1u);
  EXPECT_EQ(*a.find_layer(1), newer);
}

TEST(Merge, ResamplingMovesEvidenceWithTheTransform) {
  MapParams p = testing::small_logodds_params();
  LayeredMap b(p);
  // A single labelled cell in B's frame.
  const Eigen::Vector3d in_b(0.45, 0.15, 0.05);
  testing::set_channel(b.layer(2), p.grid().cell_of(in_b), 0, 2.0f);
  testing::set_channel(b.layer(2), p.grid().cell_of(in_b), 3, 5.0f);
  b.layer(2).set_updates(1);
  LayeredMap a(p);
  const Eigen::Isometry3d T_ab = rotated_translated();
  merge_into(a, b, T_ab);
  // The evidence appears where T_ab puts the cell centre, and only around there.
  const Eigen::Vector3d centre_b = p.grid().cell_centre(p.grid().cell_of(in_b)).cast<double>();
  const common::CellIndex expected = p.grid().cell_of(Eigen::Vector3d(T_ab * centre_b));
  std::vector<float> f(5);
  ASSERT_TRUE(a.fused(expected, f));
  EXPECT_FLOAT_EQ(f[0], 2.0f);
  EXPECT_FLOAT_EQ(f[3], 5.0f);
  std::size_t cells = 0;
  a.find_layer(2)->for_each_block([&](const common::BlockIndex&, const Block& block) {
    const std::vector<float> evidence = block.dense();
    for (std::size_t i = 0; i < evidence.size(); i += 5) cells += evidence[i] != 0.0f;
  });
  EXPECT_GE(cells, 1u);
  EXPECT_LE(cells, 3u);  // nearest-neighbour resampling of one cell touches at most a few
}

TEST(Merge, DirichletMapsAddEvidence) {
  MapParams p;
  p.method = MapMethod::kBki;
  p.num_classes = 3;
  p.prior = 0.5f;
  LayeredMap a(p);
  LayeredMap b(p);
  const common::CellIndex cell(3, -1, 2);
  // alpha_A = (0.5, 2.5, 0.5), alpha_B = (1.5, 0.5, 3.5).
  testing::set_channel(a.layer(1), cell, 1, 2.0f);
  testing::set_channel(b.layer(2), cell, 0, 1.0f);
  testing::set_channel(b.layer(2), cell, 2, 3.0f);
  a.layer(1).set_updates(1);
  b.layer(2).set_updates(1);
  merge_into(a, b, Eigen::Isometry3d::Identity());
  merge_into(a, b, Eigen::Isometry3d::Identity());
  std::vector<float> alpha(3);
  ASSERT_TRUE(a.fused(cell, alpha));
  // alpha_A + alpha_B - alpha_0, once.
  EXPECT_FLOAT_EQ(alpha[0], 0.5f + 1.5f - 0.5f);
  EXPECT_FLOAT_EQ(alpha[1], 2.5f + 0.5f - 0.5f);
  EXPECT_FLOAT_EQ(alpha[2], 0.5f + 3.5f - 0.5f);
}

TEST(Merge, RejectsIncompatibleMaps) {
  LayeredMap a(testing::small_logodds_params());
  MapParams other = testing::small_logodds_params();
  other.num_classes = 7;
  EXPECT_THROW(merge_into(a, LayeredMap(other), Eigen::Isometry3d::Identity()),
               std::invalid_argument);
}

}  // namespace
}  // namespace semap::mapping
