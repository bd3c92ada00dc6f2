#include "semap/mapping/confusion_matrix.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace semap::mapping {
namespace {

TEST(ConfusionMatrix, IouCountsNoLabelAsAMiss) {
  ConfusionMatrix m(3);
  m.add(1, 1);
  m.add(1, 1);
  m.add(1, 2);  // FN for 1, FP for 2
  m.add(2, 2);
  m.add(2, ConfusionMatrix::kNoLabel);  // FN for 2
  m.add(7, 1);                          // true class outside [0, K): not counted
  EXPECT_EQ(m.total(), 5u);
  EXPECT_DOUBLE_EQ(m.iou(1), 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(m.iou(2), 1.0 / 3.0);
  EXPECT_TRUE(std::isnan(m.iou(0)));
  const std::vector<int> classes{0, 1, 2};
  EXPECT_DOUBLE_EQ(m.mean_iou(classes), 0.5);
}

// A segmenter's "no label" (0xFFFF) and a map's unknown (-1) land in the same column, which
// count() reads under kNoLabel or K alike.
TEST(ConfusionMatrix, EveryPredictionOutsideTheClassesIsNoLabel) {
  ConfusionMatrix m(4);
  m.add(1, -1);
  m.add(1, 4);
  m.add(1, 0xFFFF);
  m.add(1, 1);
  EXPECT_EQ(m.count(1, ConfusionMatrix::kNoLabel), 3u);
  EXPECT_EQ(m.count(1, 4), 3u);
  EXPECT_EQ(m.count(1, 1), 1u);
  EXPECT_EQ(m.truth_count(1), 4u);
  EXPECT_DOUBLE_EQ(m.iou(1), 0.25);
}

TEST(ConfusionMatrix, AddsCountsOfManyPointsAtOnce) {
  ConfusionMatrix once(3);
  once.add(2, 1, 5);
  once.add(1, ConfusionMatrix::kNoLabel, 2);
  ConfusionMatrix one_by_one(3);
  for (int i = 0; i < 5; ++i) one_by_one.add(2, 1);
  for (int i = 0; i < 2; ++i) one_by_one.add(1, ConfusionMatrix::kNoLabel);
  EXPECT_EQ(once.total(), 7u);
  for (int t = 0; t < 3; ++t) {
    for (int p = 0; p <= 3; ++p) EXPECT_EQ(once.count(t, p), one_by_one.count(t, p)) << t << p;
  }
}

// Four classes, 0 free. Class 3 is predicted once but never true.
ConfusionMatrix with_a_class_only_predicted() {
  ConfusionMatrix m(4);
  m.add(1, 1, 3);
  m.add(1, 3);  // FN for 1, FP for 3
  m.add(2, 2);
  m.add(0, 2);  // a free cell called 2: FP for 2
  return m;
}

TEST(ConfusionMatrix, ScoresOnlyTheClassesTheTruthHasWhenAsked) {
  const ConfusionMatrix m = with_a_class_only_predicted();
  EXPECT_DOUBLE_EQ(m.iou(3), 0.0);
  EXPECT_TRUE(std::isnan(m.iou_if_present(3)));
  EXPECT_DOUBLE_EQ(m.iou_if_present(1), 0.75);  // 3 / (3 + 1)
  EXPECT_DOUBLE_EQ(m.iou_if_present(2), 0.5);   // 1 / (1 + 1)
  EXPECT_DOUBLE_EQ(m.mean_iou_of_present(1), (0.75 + 0.5) / 2);
  // The other average counts the class only predicted as 0.
  const std::vector<int> classes{1, 2, 3};
  EXPECT_DOUBLE_EQ(m.mean_iou(classes), (0.75 + 0.5 + 0.0) / 3);
  // From class 0 on the free cells count too: one, predicted as 2.
  EXPECT_DOUBLE_EQ(m.mean_iou_of_present(0), (0.0 + 0.75 + 0.5) / 3);
  EXPECT_TRUE(std::isnan(ConfusionMatrix(4).mean_iou_of_present(1)));
}

TEST(ConfusionMatrix, WithoutATrueClassDropsItsRowOnly) {
  const ConfusionMatrix m = with_a_class_only_predicted();
  const ConfusionMatrix surfaces = m.without_true_class(0);
  EXPECT_EQ(surfaces.total(), m.total() - 1);
  EXPECT_EQ(surfaces.truth_count(0), 0u);
  EXPECT_EQ(surfaces.count(1, 1), 3u);
  EXPECT_DOUBLE_EQ(surfaces.iou(2), 1.0);  // the free cell called 2 is gone
  EXPECT_DOUBLE_EQ(m.iou(2), 0.5);         // the original is unchanged
}

}  // namespace
}  // namespace semap::mapping
