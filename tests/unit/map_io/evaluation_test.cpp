#include "semap/map_io/evaluation.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "../mapping/toy_dataset.hpp"
#include "semap/map_io/label_noise.hpp"

namespace semap::map_io {
namespace {

using namespace semap::mapping;

TEST(LabelNoise, FlipsTheRequestedFractionToOtherClasses) {
  common::LabeledCloud c;
  c.points.resize(1000);
  c.labels.assign(1000, 2);
  common::LabeledCloud noisy = c;
  EXPECT_EQ(flip_labels(noisy, 0.3, 1, 4, 42), 300u);
  int changed = 0;
  for (std::size_t i = 0; i < c.labels.size(); ++i) {
    if (noisy.labels[i] != c.labels[i]) {
      ++changed;
      EXPECT_TRUE(noisy.labels[i] == 1 || noisy.labels[i] == 3);
    }
  }
  EXPECT_EQ(changed, 300);
  common::LabeledCloud again = c;
  flip_labels(again, 0.3, 1, 4, 42);
  EXPECT_EQ(again.labels, noisy.labels);
  EXPECT_THROW(flip_labels(again, 1.5, 1, 4, 1), std::invalid_argument);
}

TEST(Evaluation, BkiFillsTheGapBetweenSparseHitsThatCsmLeavesUnknown) {
  // Hits every 0.3 m along a line; the cells in between get no point.
  TrainingSet t;
  t.num_classes = 3;
  for (int i = 0; i < 10; ++i) {
    t.points.emplace_back(0.05f + 0.3f * static_cast<float>(i), 0.05f, 0.05f);
    t.labels.push_back(2);
  }
  t.num_hits = t.points.size();
  MapParams p;
  p.num_classes = 3;
  SemanticMap bki(p);
  p.method = MapMethod::kCsm;
  SemanticMap csm(p);
  bki.insert(t);
  csm.insert(t);
  const Eigen::Vector3f gap(0.25f, 0.05f, 0.05f);
  EXPECT_EQ(bki.label_at(gap), 2);
  EXPECT_EQ(csm.label_at(gap), -1);
}

TEST(Evaluation, BkiBeatsCsmOnTheToyDatasetAtEveryNoiseLevel) {
  const std::vector<common::LabeledCloud> scans = mapping::testing::toy_scans(1, 12);
  const std::vector<double> noise{0.0, 0.3, 0.5};
  const auto rows = evaluate_label_noise(scans, MapParams{}, noise, 1);
  ASSERT_EQ(rows.size(), 6u);
  for (std::size_t i = 0; i < rows.size(); i += 2) {
    ASSERT_EQ(rows[i].method, MapMethod::kBki);
    ASSERT_EQ(rows[i + 1].method, MapMethod::kCsm);
    EXPECT_GT(rows[i].mean_iou, rows[i + 1].mean_iou) << "noise " << rows[i].noise;
  }
  // More noise, worse maps.
  EXPECT_GT(rows[0].mean_iou, rows[2].mean_iou);
  EXPECT_GT(rows[2].mean_iou, rows[4].mean_iou);
  EXPECT_GT(rows[0].mean_iou, 0.85);
}

}  // namespace
}  // namespace semap::map_io
