#include "semap/common/cell_posterior.hpp"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace semap::common {
namespace {

TEST(CellPosterior, MeanVarianceModeMatchTheDirichletClosedForms) {
  const std::vector<float> evidence{1.0f, 4.0f, 2.5f, 0.5f};
  const float prior = 1.5f;
  const CellPosterior cell(evidence, prior, true);
  const float sum = 4 * prior + 8.0f;
  EXPECT_FLOAT_EQ(cell.alpha_sum(), sum);
  for (int k = 0; k < 4; ++k) {
    const float a = prior + evidence[static_cast<std::size_t>(k)];
    EXPECT_FLOAT_EQ(cell.mean(k), a / sum);
    EXPECT_FLOAT_EQ(cell.variance(k), (a / sum) * (1 - a / sum) / (sum + 1));
    ASSERT_TRUE(cell.mode(k).has_value());
    EXPECT_FLOAT_EQ(*cell.mode(k), (a - 1) / (sum - 4));
  }
  EXPECT_EQ(cell.argmax(), 1);
  EXPECT_EQ(cell.state(), CellState::kOccupied);
  EXPECT_EQ(cell.label(), 1);
}

TEST(CellPosterior, ModeIsUndefinedWhenAnAlphaIsAtMostOne) {
  const std::vector<float> evidence{0.0f, 3.0f};
  const CellPosterior cell(evidence, 0.001f, true);
  EXPECT_FALSE(cell.mode(0).has_value());
}

TEST(CellPosterior, StatesUnknownFreeOccupied) {
  const std::vector<float> none{0, 0, 0};
  EXPECT_EQ(CellPosterior(none, 0.001f, false).state(), CellState::kUnknown);
  EXPECT_EQ(CellPosterior(none, 0.001f, false).label(), -1);
  const std::vector<float> free{5, 1, 0};
  EXPECT_EQ(CellPosterior(free, 0.001f, true).state(), CellState::kFree);
  const std::vector<float> occupied{1, 0, 5};
  EXPECT_EQ(CellPosterior(occupied, 0.001f, true).state(), CellState::kOccupied);
}

TEST(CellPosterior, VarianceThresholdTurnsUncertainCellsUnknown) {
  const std::vector<float> weak{0.0f, 0.2f};  // little evidence: large variance
  const CellPosterior cell(weak, 0.1f, true);
  const float var = cell.variance(1);
  EXPECT_EQ(cell.state(var * 0.5f), CellState::kUnknown);
  EXPECT_EQ(cell.state(var * 2.0f), CellState::kOccupied);
  EXPECT_EQ(cell.state(0.0f), CellState::kOccupied);  // off by default
}

// The one-pass summary the map publishes equals the separate calls, ties and unobserved
// cells included, with and without a variance threshold.
TEST(CellPosterior, SummaryEqualsStateArgmaxAndVariance) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> small(0, 3);
  std::uniform_real_distribution<float> real(0.0f, 5.0f);
  for (int trial = 0; trial < 2000; ++trial) {
    std::vector<float> e(static_cast<std::size_t>(1 + trial % 20));
    for (float& v : e) v = trial % 2 ? static_cast<float>(small(rng)) : real(rng);  // ties too
    const CellPosterior post(e, 0.001f, trial % 7 != 0);
    for (const float threshold : {0.0f, 0.05f}) {
      const auto s = post.summary(threshold);
      EXPECT_EQ(s.argmax, post.argmax());
      EXPECT_EQ(s.state, post.state(threshold));
      EXPECT_EQ(s.variance, post.variance(post.argmax()));
    }
  }
}

}  // namespace
}  // namespace semap::common
