// The closing demo of issue 7 as a test: the toy dataset split between two robots, robot B
// mapping in its own frame, merged back and compared with one robot mapping all 12 scans.
#include <gtest/gtest.h>

#include <cstdio>

#include "semap/map_io/map_agreement.hpp"
#include "semap/mapping/cloud_transform.hpp"
#include "semap/mapping/logodds_map.hpp"
#include "semap/mapping/map_merge.hpp"
#include "semap/mapping/semantic_map.hpp"
#include "toy_data.hpp"

namespace semap::map_io {
namespace {

using namespace semap::mapping;

// Robot B's frame: a general rotation and a translation that is no multiple of the cell size.
Eigen::Isometry3d t_b_world() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.5236, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(2.013, -1.347, 0.518);
  return T;
}

LayeredMap logodds_map(const std::vector<common::LabeledCloud>& scans, SourceId robot,
                       const Eigen::Isometry3d& T) {
  LogOddsMap map(mapping::testing::toy_logodds_params(), robot);
  for (const auto& scan : scans) map.insert(transform_cloud(scan, T.cast<float>()));
  return map.layers();
}

class ToySplit : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    first_ = new std::vector<common::LabeledCloud>(mapping::testing::toy_scans(1, 6));
    second_ = new std::vector<common::LabeledCloud>(mapping::testing::toy_scans(7, 12));
  }
  static void TearDownTestSuite() {
    delete first_;
    delete second_;
  }
  static std::vector<common::LabeledCloud> all() {
    auto scans = *first_;
    scans.insert(scans.end(), second_->begin(), second_->end());
    return scans;
  }
  static std::vector<common::LabeledCloud>* first_;
  static std::vector<common::LabeledCloud>* second_;
};
std::vector<common::LabeledCloud>* ToySplit::first_ = nullptr;
std::vector<common::LabeledCloud>* ToySplit::second_ = nullptr;

TEST_F(ToySplit, MergedLogOddsMapAgreesWithSingleRobotMap) {
  const Eigen::Isometry3d identity = Eigen::Isometry3d::Identity();
  const LayeredMap single = logodds_map(all(), 1, identity);

  // Without a transform the merge differs from the single map only through clamping, which
  // OctoMap applies per robot here and once over all scans in the single map.
  LayeredMap same_frame = logodds_map(*first_, 1, identity);
  merge_into(same_frame, logodds_map(*second_, 2, identity), identity);
  const Agreement exact = occupied_agreement(single, same_frame);

  // Robot B maps in its own frame; merging resamples its grid into A's.
  LayeredMap merged = logodds_map(*first_, 1, identity);
  const LayeredMap b = logodds_map(*second_, 2, t_b_world());
  merge_into(merged, b, t_b_world().inverse());
  const Agreement moved = occupied_agreement(single, merged);

  // The cost of expressing a map in another grid at all: the single-robot map built in B's
  // frame and resampled into A's, with no merging involved.
  LayeredMap resampled_only(single.params());
  merge_into(resampled_only, logodds_map(all(), 1, t_b_world()), t_b_world().inverse());
  const Agreement grid_only = occupied_agreement(single, resampled_only);

  std::printf("single-robot occupied cells: %zu\n", exact.reference_occupied);
  std::printf("baseline, all 12 scans mapped in B's frame and resampled: agreement %.4f\n",
              grid_only.fraction());
  std::printf("same frame: merged occupied %zu, same class %zu, agreement %.4f\n",
              exact.candidate_occupied, exact.same_class, exact.fraction());
  std::printf(
      "B shifted (yaw 30 deg, t=(2.013,-1.347,0.518)): merged occupied %zu, same class "
      "%zu (of %zu occupied in both), agreement %.4f\n",
      moved.candidate_occupied, moved.same_class, moved.both_occupied, moved.fraction());
  RecordProperty("agreement_same_frame", std::to_string(exact.fraction()));
  RecordProperty("agreement_transformed", std::to_string(moved.fraction()));
  EXPECT_GT(exact.reference_occupied, 5000u);
  EXPECT_GE(exact.fraction(), 0.98);
  // Half of the evidence went through the resampling, so the expected agreement is about the
  // mean of the same-frame merge (1.0) and the resampling baseline (0.69 measured): ~0.85;
  // 0.80 leaves room for the clamping and free-space interplay, and anything lower means the
  // merge itself lost or misplaced evidence.
  EXPECT_GE(grid_only.fraction(), 0.6);
  EXPECT_GE(moved.fraction(), 0.80);
  EXPECT_GE(moved.fraction(), grid_only.fraction());
  // Where both maps call a cell occupied, the classes agree: the loss is occupancy aliasing of
  // thin surfaces between rotated grids, not label errors.
  EXPECT_GE(static_cast<double>(moved.same_class) / moved.both_occupied, 0.99);
}

// S-BKI evidence is a sum over scans, so merging the two robots' maps (their own layers, as
// saved) is exact, and merging one twice changes nothing.
TEST_F(ToySplit, MergedBkiMapEqualsSingleRobotMap) {
  const MapParams toy = mapping::testing::toy_logodds_params();
  MapParams p;
  p.resolution = 0.1f;
  p.block_depth = toy.block_depth;
  p.num_classes = 4;
  SemanticMap single(p);
  SemanticMap robot_a(p, 1);
  SemanticMap robot_b(p, 2);
  for (const auto& scan : *first_) {
    single.insert(scan, scan.origin);
    robot_a.insert(scan, scan.origin);
  }
  for (const auto& scan : *second_) {
    single.insert(scan, scan.origin);
    robot_b.insert(scan, scan.origin);
  }
  LayeredMap merged = robot_a.layers();
  merge_into(merged, robot_b.layers(), Eigen::Isometry3d::Identity());
  merge_into(merged, robot_b.layers(), Eigen::Isometry3d::Identity());
  ASSERT_EQ(merged.layers().size(), 2u);
  const common::MapGrid grid = p.grid();
  std::vector<float> alpha(4);
  std::size_t cells = 0;
  single.for_each_cell([&](const Eigen::Vector3f& centre, const common::CellPosterior& expected) {
    ASSERT_TRUE(merged.fused(grid.cell_of(centre), alpha));
    for (int k = 0; k < 4; ++k) {
      EXPECT_NEAR(alpha[k], expected.alpha(k), 1e-3f * (1.0f + expected.alpha(k)));
    }
    ++cells;
  });
  EXPECT_GT(cells, 1000u);
  // No cell is known to the merged map that the single robot never saw.
  std::size_t merged_known = 0;
  for (const common::BlockIndex& key : merged.block_keys()) {
    for (int c = 0; c < grid.cells_per_block(); ++c) {
      merged_known += merged.fused(grid.cell_of_local(key, c), alpha) ? 1 : 0;
    }
  }
  EXPECT_EQ(merged_known, cells);
}

}  // namespace
}  // namespace semap::map_io
