#include "semap/mapping/evidence_grid.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <vector>

#include "semap/mapping/semantic_map.hpp"
#include "semap/mapping/smap_io.hpp"
#include "toy_dataset.hpp"

namespace semap::mapping {
namespace {

using ::testing::HasSubstr;

// Block side 2 (8 cells) of 3 channels: 24 floats.
std::vector<float> ramp(float start) {
  std::vector<float> values(24);
  std::iota(values.begin(), values.end(), start);
  return values;
}

std::vector<float> evidence_of(const EvidenceGrid& grid, const common::BlockIndex& key) {
  const Block* block = grid.find_block(key);
  if (block == nullptr) return {};
  return block->dense();
}

TEST(EvidenceGrid, PutReplacesAddAddsAndNonZeroCellsAreObserved) {
  EvidenceGrid grid(2, 3);
  std::vector<float> one_cell(24, 0.0f);
  one_cell[3 * 5 + 1] = 2.0f;  // cell 5, channel 1
  grid.add_block({1, -2, 3}, one_cell);
  grid.add_block({1, -2, 3}, one_cell);
  const Block* block = grid.find_block({1, -2, 3});
  ASSERT_NE(block, nullptr);
  std::vector<float> cell(3);
  block->read_cell(5, cell);
  EXPECT_EQ(cell[1], 4.0f);
  EXPECT_EQ(block->num_observed(), 1);
  EXPECT_TRUE(block->observed(5));

  grid.put_block({1, -2, 3}, ramp(-1.0f));  // cell 0 channel 0 is zero, the rest is not
  EXPECT_EQ(evidence_of(grid, {1, -2, 3}), ramp(-1.0f));
  EXPECT_EQ(grid.find_block({1, -2, 3})->num_observed(), 8);
  grid.put_block({1, -2, 3}, std::vector<float>(24, 0.0f));
  EXPECT_EQ(grid.find_block({1, -2, 3})->num_observed(), 0);
  EXPECT_EQ(grid.size(), 1u);
}

TEST(EvidenceGrid, CellWritesCreateTheBlockAndMarkTheCell) {
  EvidenceGrid grid(2, 3);
  std::vector<float> cell(3, 1.0f);
  EXPECT_FALSE(grid.read_cell(common::CellIndex(-1, 0, 0), cell));
  EXPECT_EQ(cell, std::vector<float>(3, 0.0f));
  grid.set_cell(common::CellIndex(-1, 0, 0), std::vector<float>{0.0f, 0.0f, 7.0f});  // local x 1
  const Block* block = grid.find_block({-1, 0, 0});
  ASSERT_NE(block, nullptr);
  EXPECT_TRUE(block->observed(1));
  EXPECT_EQ(block->num_observed(), 1);
  EXPECT_TRUE(grid.read_cell(common::CellIndex(-1, 0, 0), cell));
  EXPECT_EQ(cell[2], 7.0f);
  EXPECT_TRUE(grid.read_cell(common::CellIndex(-2, 0, 0), cell));
  EXPECT_EQ(cell[2], 0.0f);
}

TEST(EvidenceGrid, EvictedBlocksComeBackExactlyAndFreeTheirEntries) {
  EvidenceGrid grid(2, 3);
  grid.put_block({0, 0, 0}, ramp(1.0f));
  grid.put_block({5, 0, 0}, ramp(100.0f));
  const std::vector<std::uint64_t> observed(grid.find_block({0, 0, 0})->observed_words().begin(),
                                            grid.find_block({0, 0, 0})->observed_words().end());
  const std::size_t bytes = grid.bytes();

  EXPECT_TRUE(grid.evict({0, 0, 0}));
  EXPECT_FALSE(grid.evict({0, 0, 0}));
  EXPECT_EQ(grid.find_block({0, 0, 0}), nullptr);
  EXPECT_EQ(grid.size(), 1u);
  EXPECT_EQ(grid.evicted(), 1u);
  EXPECT_EQ(grid.keys(), (std::vector<common::BlockIndex>{{5, 0, 0}}));

  // The evicted block's entries are freed: a new empty block costs less than they did.
  grid.block_at({9, 9, 9});
  EXPECT_EQ(evidence_of(grid, {9, 9, 9}), std::vector<float>(24, 0.0f));
  EXPECT_LT(grid.bytes(), bytes);

  grid.restore_block({0, 0, 0}, ramp(1.0f), observed);
  EXPECT_EQ(evidence_of(grid, {0, 0, 0}), ramp(1.0f));
  EXPECT_EQ(grid.evicted(), 0u);
  EXPECT_EQ(evidence_of(grid, {5, 0, 0}), ramp(100.0f));
}

TEST(EvidenceGrid, CopiesAreEqualAndIndependent) {
  EvidenceGrid grid(2, 3);
  grid.put_block({0, 1, 0}, ramp(1.0f));
  grid.put_block({-4, 1, 0}, ramp(2.0f));
  grid.set_updates(7);
  EvidenceGrid copy = grid;
  EXPECT_TRUE(copy == grid);
  std::vector<float> cell(3);
  copy.read_cell(common::CellIndex(0, 2, 0), cell);
  cell[0] += 1.0f;
  copy.set_cell(common::CellIndex(0, 2, 0), cell);
  EXPECT_FALSE(copy == grid);
  EXPECT_EQ(evidence_of(grid, {0, 1, 0}), ramp(1.0f));
  copy = grid;
  EXPECT_TRUE(copy == grid);
  copy.set_updates(8);
  EXPECT_FALSE(copy == grid);
}

TEST(EvidenceGrid, BadBlocksAreRefusedWithTheReason) {
  EvidenceGrid grid(2, 3);
  try {
    grid.put_block({1 << 20, 0, 0}, ramp(0.0f));
    FAIL() << "a block beyond the table's range was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("(1048576, 0, 0) beyond"));
  }
  EXPECT_THROW(grid.block_at({0, -(1 << 20) - 1, 0}), std::invalid_argument);
  try {
    grid.add_block({0, 0, 0}, std::vector<float>(23));
    FAIL() << "a short block was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("23 floats, expected 24"));
  }
  EXPECT_EQ(grid.size(), 0u);
  EXPECT_EQ(grid.find_block({1 << 20, 0, 0}), nullptr);
}

// The live S-BKI map is its robot's layer: saving reads the blocks the insert wrote, and the
// saved file is that layer.
TEST(EvidenceGrid, TheLiveMapIsItsRobotsLayer) {
  MapParams params;
  params.num_classes = 4;
  SemanticMap map(params, 4);
  for (const auto& scan : testing::toy_scans(1, 3)) map.insert(scan, scan.origin);

  ASSERT_EQ(map.layers().layers().size(), 1u);
  EXPECT_EQ(map.layers().find_layer(4), &map.grid());
  EXPECT_EQ(map.grid().updates(), 3u);
  EXPECT_EQ(map.scans(), 3u);
  EXPECT_EQ(map.layers().params(), params);

  const SmapReadResult read = decode_smap(encode_smap(map.layers()), "live.smap");
  ASSERT_TRUE(read.complete);
  EXPECT_TRUE(read.map == map.layers());
  std::size_t blocks = 0;
  map.for_each_block([&](const common::BlockIndex& key, const Block& block) {
    const Block* saved = read.map.find_layer(4)->find_block(key);
    ASSERT_NE(saved, nullptr);
    EXPECT_EQ(saved->dense(), block.dense());
    ++blocks;
  });
  EXPECT_GT(blocks, 100u);
  EXPECT_EQ(read.blocks, blocks);
}

}  // namespace
}  // namespace semap::mapping
