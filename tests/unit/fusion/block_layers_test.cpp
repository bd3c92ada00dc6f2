#include "semap/fusion/block_layers.hpp"

#include <gtest/gtest.h>

#include <algorithm>

namespace semap::fusion {
namespace {

dds_idl::MapDescription shape(float resolution, std::uint16_t cells, std::uint16_t classes) {
  dds_idl::MapDescription d;
  d.resolution = resolution;
  d.block_cells = cells;
  d.num_classes = classes;
  return d;
}

TEST(BlockLayers, ParamsFollowTheDescription) {
  const auto p = map_params_of(shape(0.2f, 8, 5), mapping::MapMethod::kBki, 0.01);
  EXPECT_EQ(p.cells_per_side(), 8);
  EXPECT_EQ(p.block_depth, 4);
  EXPECT_EQ(p.channels(), 5);
  EXPECT_FLOAT_EQ(p.resolution, 0.2f);
  EXPECT_THROW(map_params_of(shape(0.2f, 6, 5), mapping::MapMethod::kBki, 0.01),
               std::invalid_argument);
  EXPECT_THROW(map_params_of(shape(0.2f, 8, 5), mapping::MapMethod::kLogOdds, 0.01),
               std::invalid_argument);
}

TEST(BlockLayers, EvidenceRoundTripsThroughALayeredMap) {
  const auto p = map_params_of(shape(0.1f, 4, 3), mapping::MapMethod::kBki, 0.5);
  auto block = dds_idl::BlockSnapshot::empty({1, -2, 0}, 0.1f, 4, 3, true);
  for (std::size_t i = 0; i < block.evidence.size(); ++i) {
    block.evidence[i] = static_cast<float>(i % 7);
  }
  mapping::LayeredMap map(p);
  map.layer(1).put_block(block.index, evidence_block(block, p));
  map.layer(2).put_block(block.index, evidence_block(block, p));
  const auto fused = fused_snapshot(map, block.index, 9);
  ASSERT_TRUE(fused);
  EXPECT_EQ(fused->version, 9u);
  EXPECT_EQ(fused->index, block.index);
  for (std::size_t cell = 0; cell < block.cell_count(); ++cell) {
    // Two layers: the evidence adds, the prior (0.5) is not in the published increments.
    for (std::size_t k = 0; k < 3; ++k) {
      EXPECT_FLOAT_EQ(fused->evidence[cell * 3 + k], 2.0f * block.evidence[cell * 3 + k]);
    }
    const auto* e = &block.evidence[cell * 3];
    const bool observed = e[0] + e[1] + e[2] > 0.0f;
    const auto best = static_cast<std::uint16_t>(std::max_element(e, e + 3) - e);
    EXPECT_EQ(fused->state[cell], !observed   ? common::CellState::kUnknown
                                  : best == 0 ? common::CellState::kFree
                                              : common::CellState::kOccupied)
        << cell;
    if (observed) {
      EXPECT_EQ(fused->argmax_class[cell], best) << cell;
    }
  }
  EXPECT_FALSE(fused_snapshot(map, {5, 5, 5}, 1));
  auto plain = dds_idl::BlockSnapshot::empty({0, 0, 0}, 0.1f, 4, 3, false);
  EXPECT_THROW(evidence_block(plain, p), std::invalid_argument);
}

}  // namespace
}  // namespace semap::fusion
