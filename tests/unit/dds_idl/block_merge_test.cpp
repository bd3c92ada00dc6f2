#include "semap/dds_idl/block_merge.hpp"

#include <gtest/gtest.h>

namespace semap::dds_idl {
namespace {

TEST(BlockMerge, EvidenceAddsWithThePriorCountedOnce) {
  // Two classes: 0 = free, 1 = occupied class. Prior 0.5 per class in each robot's evidence.
  BlockSnapshot a = BlockSnapshot::empty({0, 0, 0}, 0.1f, 1, 2, true);
  BlockSnapshot b = a;
  a.version = 2;
  b.version = 5;
  a.evidence = {0.5f + 3.0f, 0.5f + 1.0f};
  b.evidence = {0.5f + 0.0f, 0.5f + 4.0f};
  const BlockSnapshot m = merge_blocks({&a, &b}, {0, 0.5f, 1e-6f});
  ASSERT_EQ(m.evidence.size(), 2u);
  EXPECT_FLOAT_EQ(m.evidence[0], 3.5f);
  EXPECT_FLOAT_EQ(m.evidence[1], 5.5f);
  EXPECT_EQ(m.argmax_class[0], 1);
  EXPECT_EQ(m.state[0], CellState::kOccupied);
  const float s = 9.0f;
  EXPECT_FLOAT_EQ(m.variance[0], 5.5f * (s - 5.5f) / (s * s * (s + 1.0f)));
  EXPECT_EQ(m.version, 7u);
}

TEST(BlockMerge, CellsWithOnlyThePriorStayUnknownAndFreeWinsWhenStrongest) {
  BlockSnapshot a = BlockSnapshot::empty({0, 0, 0}, 0.1f, 1, 2, true);
  BlockSnapshot b = a;
  a.evidence = {1.0f, 1.0f};  // prior only
  b.evidence = {1.0f, 1.0f};
  EXPECT_EQ(merge_blocks({&a, &b}, {0, 1.0f, 1e-6f}).state[0], CellState::kUnknown);
  b.evidence = {4.0f, 1.0f};
  const BlockSnapshot m = merge_blocks({&a, &b}, {0, 1.0f, 1e-6f});
  EXPECT_EQ(m.state[0], CellState::kFree);
  EXPECT_EQ(m.argmax_class[0], 0);
}

TEST(BlockMerge, WithoutEvidenceTheMoreCertainKnownCellWins) {
  BlockSnapshot a = BlockSnapshot::empty({1, 2, 3}, 0.1f, 2, 4, false);
  BlockSnapshot b = a;
  a.state[0] = CellState::kOccupied;
  a.argmax_class[0] = 2;
  a.variance[0] = 0.2f;
  b.state[0] = CellState::kOccupied;
  b.argmax_class[0] = 3;
  b.variance[0] = 0.1f;
  b.state[1] = CellState::kFree;
  b.variance[1] = 0.5f;
  const BlockSnapshot m = merge_blocks({&a, &b}, {});
  EXPECT_EQ(m.argmax_class[0], 3);
  EXPECT_FLOAT_EQ(m.variance[0], 0.1f);
  EXPECT_EQ(m.state[1], CellState::kFree);  // unknown in a, known in b
  EXPECT_EQ(m.state[2], CellState::kUnknown);
  EXPECT_FALSE(m.has_evidence());
}

TEST(BlockMerge, RefusesMixedShapes) {
  const BlockSnapshot a = BlockSnapshot::empty({0, 0, 0}, 0.1f, 2, 4, false);
  const BlockSnapshot b = BlockSnapshot::empty({0, 0, 0}, 0.1f, 2, 5, false);
  const BlockSnapshot c = BlockSnapshot::empty({0, 0, 1}, 0.1f, 2, 4, false);
  EXPECT_THROW(merge_blocks({&a, &b}, {}), std::invalid_argument);
  EXPECT_THROW(merge_blocks({&a, &c}, {}), std::invalid_argument);
  EXPECT_THROW(merge_blocks({}, {}), std::invalid_argument);
}

}  // namespace
}  // namespace semap::dds_idl
