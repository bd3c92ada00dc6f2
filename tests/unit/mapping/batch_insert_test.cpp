// SemanticMap::insert(clouds, origins) must give the map and results of inserting the scans
// one by one, whatever the thread count.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cstring>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "semap/mapping/semantic_map.hpp"
#include "toy_dataset.hpp"

namespace semap::mapping {
namespace {

std::vector<common::LabeledCloud> toy_scans(int count) { return testing::toy_scans(1, count); }

std::vector<Eigen::Vector3f> origins_of(const std::vector<common::LabeledCloud>& scans) {
  std::vector<Eigen::Vector3f> origins;
  for (const auto& s : scans) origins.push_back(s.origin);
  return origins;
}

MapParams params_for(MapMethod method) {
  MapParams p;
  p.method = method;
  return p;
}

// Same blocks, and every block's evidence and observed bits equal bit for bit.
void expect_identical(const SemanticMap& a, const SemanticMap& b) {
  ASSERT_EQ(a.stats().blocks, b.stats().blocks);
  ASSERT_EQ(a.stats().scans, b.stats().scans);
  ASSERT_EQ(a.stats().rejected_points, b.stats().rejected_points);
  std::size_t compared = 0;
  a.for_each_block([&](const common::BlockIndex& index, const Block& block) {
    const Block* other = b.find_block(index);
    ASSERT_NE(other, nullptr);
    const std::vector<float> x = block.dense();
    const std::vector<float> y = other->dense();
    ASSERT_EQ(std::memcmp(x.data(), y.data(), x.size() * sizeof(float)), 0);
    for (int c = 0; c < block.num_cells(); ++c) ASSERT_EQ(block.observed(c), other->observed(c));
    ++compared;
  });
  EXPECT_EQ(compared, a.stats().blocks);
}

class BatchInsert : public ::testing::TestWithParam<MapMethod> {};

TEST_P(BatchInsert, EqualsOneByOneInsertionOnOneAndTwoThreads) {
  const auto scans = toy_scans(5);
  const auto origins = origins_of(scans);
  SemanticMap one_by_one(params_for(GetParam()));
  std::vector<InsertResult> expected;
  tbb::task_arena(1).execute([&] {
    for (const auto& s : scans) expected.push_back(one_by_one.insert(s, s.origin));
  });
  ASSERT_GT(one_by_one.stats().observed_cells, 1000u);
  for (const int threads : {1, 2}) {
    SCOPED_TRACE(threads);
    SemanticMap batch(params_for(GetParam()));
    std::vector<InsertResult> results;
    tbb::task_arena(threads).execute([&] { results = batch.insert(scans, origins); });
    expect_identical(one_by_one, batch);
    ASSERT_EQ(results.size(), expected.size());
    for (std::size_t i = 0; i < results.size(); ++i) {
      EXPECT_EQ(results[i].training_points, expected[i].training_points);
      EXPECT_EQ(results[i].hits, expected[i].hits);
      EXPECT_EQ(results[i].out_of_range, expected[i].out_of_range);
      EXPECT_EQ(results[i].rejected_points, expected[i].rejected_points);
      EXPECT_EQ(results[i].updated_blocks, expected[i].updated_blocks);
      // Each scan's own build and scatter are timed (a scan of ~3.4k points takes > 1 us).
      EXPECT_GT(results[i].phases.training, 0.0);
      EXPECT_GT(results[i].phases.scatter, 0.0);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Methods, BatchInsert, ::testing::Values(MapMethod::kBki, MapMethod::kCsm));

TEST(BatchInsert, ABadScanLeavesTheScansBeforeItInsertedAndThrows) {
  auto scans = toy_scans(4);
  scans[2].labels.pop_back();  // one label short: build_training_set throws
  const auto origins = origins_of(scans);
  SemanticMap first_two(params_for(MapMethod::kBki));
  first_two.insert(scans[0], scans[0].origin);
  first_two.insert(scans[1], scans[1].origin);
  SemanticMap batch(params_for(MapMethod::kBki));
  tbb::task_arena(2).execute(
      [&] { EXPECT_THROW(batch.insert(scans, origins), std::invalid_argument); });
  expect_identical(first_two, batch);
}

TEST(BatchInsert, AnEmptyBatchLeavesTheMapEmpty) {
  SemanticMap map(params_for(MapMethod::kBki));
  EXPECT_TRUE(
      map.insert(std::span<const common::LabeledCloud>{}, std::span<const Eigen::Vector3f>{})
          .empty());
  EXPECT_EQ(map.stats().scans, 0u);
  EXPECT_EQ(map.stats().blocks, 0u);
}

TEST(BatchInsert, RejectsAnOriginCountThatDiffersFromTheScans) {
  const auto scans = toy_scans(2);
  const std::vector<Eigen::Vector3f> one_origin{scans[0].origin};
  SemanticMap map(params_for(MapMethod::kBki));
  EXPECT_THROW(map.insert(scans, one_origin), std::invalid_argument);
  EXPECT_EQ(map.stats().scans, 0u);
}

}  // namespace
}  // namespace semap::mapping
