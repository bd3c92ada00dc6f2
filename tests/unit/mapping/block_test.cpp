#include "semap/mapping/block.hpp"

#include <gtest/gtest.h>

#include <random>
#include <stdexcept>
#include <vector>

#include "semap/mapping/block_delta.hpp"

namespace semap::mapping {
namespace {

// The dense block Block used to be: K floats per cell, a bit per cell. Every sparse write is
// mirrored here and the two are compared through every reader.
struct DenseBlock {
  int cells;
  int channels;
  std::vector<float> values;
  std::vector<bool> observed;
  DenseBlock(int side, int k)
      : cells(side * side * side),
        channels(k),
        values(static_cast<std::size_t>(cells * k), 0.0f),
        observed(static_cast<std::size_t>(cells), false) {}
  float& at(int cell, int channel) {
    return values[static_cast<std::size_t>(cell * channels + channel)];
  }
};

void expect_same(const Block& block, const DenseBlock& dense) {
  ASSERT_EQ(block.dense(), dense.values);
  std::vector<float> cell(static_cast<std::size_t>(dense.channels));
  int observed = 0;
  std::size_t non_zero = 0;
  for (int c = 0; c < dense.cells; ++c) {
    EXPECT_EQ(block.observed(c), dense.observed[static_cast<std::size_t>(c)]) << "cell " << c;
    observed += dense.observed[static_cast<std::size_t>(c)] ? 1 : 0;
    block.read_cell(c, cell);
    for (int k = 0; k < dense.channels; ++k) {
      const float want = dense.values[static_cast<std::size_t>(c * dense.channels + k)];
      ASSERT_EQ(cell[static_cast<std::size_t>(k)], want) << "cell " << c << " channel " << k;
      non_zero += want != 0.0f ? 1 : 0;
    }
  }
  EXPECT_EQ(block.num_observed(), observed);
  // Only non-zero channels are stored (every value here is the sum of positive adds).
  EXPECT_EQ(block.num_entries(), non_zero);
}

TEST(Block, SparseCellsReadAsTheDenseBlockThroughPlainAndDeltaWrites) {
  constexpr int kSide = 8;
  constexpr int kClasses = 20;
  Block block(kSide, kClasses);
  DenseBlock dense(kSide, kClasses);
  BlockDelta delta(kSide, kClasses);
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> any_cell(0, kSide * kSide * kSide - 1);
  std::uniform_int_distribution<int> few_classes(0, 3);  // a cell sees few classes
  std::uniform_real_distribution<float> weight(0.01f, 1.0f);
  for (int round = 0; round < 30; ++round) {
    // A scan's worth through a delta: the engine's way in.
    for (int i = 0; i < 40; ++i) {
      const int c = any_cell(rng);
      const int k = (c + few_classes(rng)) % kClasses;
      const float w = weight(rng);
      delta.cell(c)[k] += w;
      delta.mark(c);
      delta.mark_channel(k);
    }
    // The delta sums first, then adds to the block (the engine's order of additions).
    for (int c = 0; c < dense.cells; ++c) {
      if (!((delta.marked()[static_cast<std::size_t>(c / 64)] >> (c % 64)) & 1u)) continue;
      dense.observed[static_cast<std::size_t>(c)] = true;
      for (int k = 0; k < kClasses; ++k) dense.at(c, k) += delta.cell(c)[k];
    }
    block.add(delta);
    // The plain update's way in, one entry at a time, some of them zero.
    for (int i = 0; i < 10; ++i) {
      const int c = any_cell(rng);
      const int k = (c + few_classes(rng)) % kClasses;
      const float w = i % 5 == 0 ? 0.0f : weight(rng);
      block.add(c, k, w);
      dense.at(c, k) += w;
      dense.observed[static_cast<std::size_t>(c)] = true;
    }
    expect_same(block, dense);
  }
  // The delta is zeroed and unmarked by the merge.
  for (const std::uint64_t word : delta.marked()) EXPECT_EQ(word, 0u);
  for (int c = 0; c < dense.cells; ++c) {
    for (int k = 0; k < kClasses; ++k) ASSERT_EQ(delta.cell(c)[k], 0.0f);
  }
}

TEST(Block, ACellMarkedWithoutWeightIsObservedAndHoldsNothing) {
  Block block(4, 5);
  BlockDelta delta(4, 5);
  delta.mark(9);
  block.add(delta);
  EXPECT_TRUE(block.observed(9));
  EXPECT_EQ(block.num_observed(), 1);
  EXPECT_EQ(block.num_entries(), 0u);
  std::vector<float> cell(5, 1.0f);
  block.read_cell(9, cell);
  EXPECT_EQ(cell, std::vector<float>(5, 0.0f));
}

TEST(Block, SetCellReplacesOneCellAndLeavesItsNeighbours) {
  Block block(2, 3);
  block.add(3, 1, 2.0f);
  block.add(4, 0, 5.0f);
  block.add(4, 2, 6.0f);
  block.add(5, 2, 7.0f);
  const std::vector<float> values{0.0f, -1.5f, 0.0f};
  block.set_cell(4, values);
  std::vector<float> cell(3);
  block.read_cell(4, cell);
  EXPECT_EQ(cell, values);
  block.read_cell(3, cell);
  EXPECT_EQ(cell, (std::vector<float>{0.0f, 2.0f, 0.0f}));
  block.read_cell(5, cell);
  EXPECT_EQ(cell, (std::vector<float>{0.0f, 0.0f, 7.0f}));
  EXPECT_EQ(block.num_entries(), 3u);
  EXPECT_THROW(block.set_cell(4, std::vector<float>(2)), std::invalid_argument);
}

TEST(Block, DenseEvidenceComesBackAsItWentOut) {
  Block block(2, 3);
  std::vector<float> evidence(24, 0.0f);
  evidence[3 * 2 + 0] = 1.0f;
  evidence[3 * 7 + 2] = 4.0f;
  block.add_evidence(evidence);
  EXPECT_EQ(block.dense(), evidence);
  EXPECT_EQ(block.num_observed(), 2);
  // restore keeps cells observed that hold nothing, as a checkpoint wrote them.
  Block restored(2, 3);
  std::vector<std::uint64_t> observed(block.observed_words().begin(), block.observed_words().end());
  observed[0] |= 1u << 5;  // observed, all zero
  restored.restore(block.dense(), observed);
  EXPECT_EQ(restored.dense(), evidence);
  EXPECT_TRUE(restored.observed(5));
  EXPECT_EQ(restored.num_observed(), 3);
  // assign replaces: cells it leaves at zero are no longer observed.
  std::vector<float> other(24, 0.0f);
  other[3 * 1 + 1] = 3.0f;
  restored.assign(other);
  EXPECT_EQ(restored.dense(), other);
  EXPECT_EQ(restored.num_observed(), 1);
  EXPECT_THROW(restored.add_evidence(std::vector<float>(23)), std::invalid_argument);
}

TEST(Block, SparseContentCostsAFractionOfTheDenseBytes) {
  // 1 cell in 12 observed with two of 20 classes: a LiDAR block at 0.1 m.
  Block block(8, 20);
  for (int c = 0; c < 512; c += 12) {
    block.add(c, 0, 1.0f);
    block.add(c, 1 + c % 19, 0.5f);
  }
  const std::size_t dense_bytes = 512 * 20 * sizeof(float);
  EXPECT_LT(block.bytes() * 10, dense_bytes);
}

}  // namespace
}  // namespace semap::mapping
