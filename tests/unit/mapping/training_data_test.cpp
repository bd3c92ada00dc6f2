#include "semap/mapping/training_data.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace semap::mapping {
namespace {

common::LabeledCloud cloud_of(std::vector<Eigen::Vector3f> points,
                              std::vector<std::uint16_t> labels) {
  common::LabeledCloud c;
  c.points = std::move(points);
  c.labels = std::move(labels);
  return c;
}

MapParams params() {
  MapParams p;
  p.num_classes = 4;
  p.ds_res = 0.1f;
  p.free_res = 0.5f;
  p.max_range = 0.0f;
  return p;
}

TEST(TrainingData, DownsamplesHitsToCentroidAndMajorityLabel) {
  const auto cloud = cloud_of(
      {{0.01f, 0.01f, 0.01f}, {0.03f, 0.05f, 0.01f}, {0.05f, 0.03f, 0.04f}, {0.55f, 0.01f, 0.01f}},
      {2, 3, 2, 1});
  const Eigen::Vector3f origin(0.05f, 0.05f, 0.05f);
  const TrainingSet set = build_training_set(cloud, origin, params());
  ASSERT_EQ(set.num_hits, 2u);
  EXPECT_TRUE(set.points[0].isApprox(Eigen::Vector3f(0.03f, 0.03f, 0.02f), 1e-5f));
  EXPECT_EQ(set.labels[0], 2);
  EXPECT_EQ(set.labels[1], 1);
}

TEST(TrainingData, FreeSamplesEveryFreeResUpToOneStepShortOfTheHit) {
  const Eigen::Vector3f origin(0.05f, 0.05f, 0.05f);
  const auto cloud = cloud_of({{2.05f, 0.05f, 0.05f}}, {3});
  MapParams p = params();
  const TrainingSet set = build_training_set(cloud, origin, p);
  ASSERT_EQ(set.num_hits, 1u);
  // Origin plus samples at 0.5, 1.0 and 1.5 m along the beam, all labelled free.
  ASSERT_EQ(set.size(), 5u);
  std::vector<float> xs;
  for (std::size_t i = 1; i < set.size(); ++i) {
    EXPECT_EQ(set.labels[i], 0);
    xs.push_back(set.points[i].x());
  }
  std::sort(xs.begin(), xs.end());
  EXPECT_NEAR(xs[0], 0.05f, 1e-5f);
  EXPECT_NEAR(xs[1], 0.55f, 1e-5f);
  EXPECT_NEAR(xs[2], 1.05f, 1e-5f);
  EXPECT_NEAR(xs[3], 1.55f, 1e-5f);
}

TEST(TrainingData, FreeSamplesAreDownsampled) {
  // Three beams whose hits lie in different voxels; their samples at 0.5 m fall into only
  // two voxels (y = 0.005, 0.055 share one).
  const auto cloud =
      cloud_of({{1.05f, 0.01f, 0.05f}, {1.05f, 0.11f, 0.05f}, {1.05f, 0.21f, 0.05f}}, {1, 1, 1});
  const TrainingSet set = build_training_set(cloud, Eigen::Vector3f(0.05f, 0.0f, 0.05f), params());
  EXPECT_EQ(set.num_hits, 3u);
  EXPECT_EQ(set.size(), 3u + 1u + 2u);
}

TEST(TrainingData, DropsPointsBeyondMaxRangeAndCountsBadPoints) {
  MapParams p = params();
  p.max_range = 3.0f;
  const float nan = std::nanf("");
  const auto cloud =
      cloud_of({{1, 0, 0}, {5, 0, 0}, {nan, 0, 0}, {1, 1, 0}, {1e30f, 0, 0}}, {1, 1, 1, 9, 1});
  const TrainingSet set = build_training_set(cloud, Eigen::Vector3f::Zero(), p);
  EXPECT_EQ(set.num_hits, 1u);
  EXPECT_EQ(set.out_of_range, 1u);
  EXPECT_EQ(set.rejected, 3u);  // NaN, label 9 >= K, coordinate off the grid
}

TEST(TrainingData, SoftLabelsAverageTheProbabilityVectors) {
  common::LabeledCloud c;
  c.num_classes = 4;
  c.points = {{0.01f, 0.01f, 0.01f}, {0.02f, 0.02f, 0.02f}};
  c.probabilities = {0.0f, 1.0f, 0.0f, 0.0f, 0.0f, 0.5f, 0.5f, 0.0f};
  const TrainingSet set = build_training_set(c, Eigen::Vector3f(0.05f, 0.05f, 0.05f), params());
  ASSERT_EQ(set.num_hits, 1u);
  EXPECT_EQ(set.labels[0], TrainingSet::kSoft);
  EXPECT_FLOAT_EQ(set.probabilities[1], 0.75f);
  EXPECT_FLOAT_EQ(set.probabilities[2], 0.25f);
}

TEST(TrainingData, MismatchedLabelArraysAreAnError) {
  const auto cloud = cloud_of({{1, 0, 0}, {2, 0, 0}}, {1});
  EXPECT_THROW(build_training_set(cloud, Eigen::Vector3f::Zero(), params()), std::invalid_argument);
}

}  // namespace
}  // namespace semap::mapping
