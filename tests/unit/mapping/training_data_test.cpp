#include "semap/mapping/training_data.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <tuple>

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

// A scan large enough for the parallel build (sharded voxel grouping): hits and free samples
// must come out exactly as one serial pass makes them, which this test does directly.
TEST(TrainingData, LargeScanEqualsTheSerialDefinition) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> coord(-6.0f, 6.0f);
  std::uniform_int_distribution<int> label(1, 3);
  common::LabeledCloud cloud;
  for (int i = 0; i < 60000; ++i) {
    cloud.points.emplace_back(coord(rng), coord(rng), coord(rng) * 0.2f);
    cloud.labels.push_back(static_cast<std::uint16_t>(label(rng)));
  }
  const Eigen::Vector3f origin(0.05f, 0.05f, 0.05f);
  MapParams p = params();
  p.free_res = 0.3f;
  const TrainingSet set = build_training_set(cloud, origin, p);

  // Voxels in order of first occurrence; sums in input order.
  using Key = std::tuple<int, int, int>;
  const auto key = [](const Eigen::Vector3f& v) {
    const float inv = 1.0f / 0.1f;
    return Key{static_cast<int>(std::floor(v.x() * inv)), static_cast<int>(std::floor(v.y() * inv)),
               static_cast<int>(std::floor(v.z() * inv))};
  };
  struct Voxel {
    Eigen::Vector3f sum = Eigen::Vector3f::Zero();
    std::uint32_t count = 0;
    std::array<float, 4> votes{};
  };
  std::map<Key, std::size_t> index;
  std::vector<Voxel> hits;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const auto [it, fresh] = index.try_emplace(key(cloud.points[i]), hits.size());
    if (fresh) hits.emplace_back();
    Voxel& v = hits[it->second];
    v.sum += cloud.points[i];
    ++v.count;
    v.votes[cloud.labels[i]] += 1.0f;
  }
  ASSERT_EQ(set.num_hits, hits.size());
  ASSERT_GT(hits.size(), 30000u);
  std::vector<Eigen::Vector3f> hit_points;
  for (std::size_t h = 0; h < hits.size(); ++h) {
    const Eigen::Vector3f c = hits[h].sum / static_cast<float>(hits[h].count);
    hit_points.push_back(c);
    ASSERT_EQ(set.points[h], c) << h;
    const auto& votes = hits[h].votes;
    ASSERT_EQ(set.labels[h], std::max_element(votes.begin(), votes.end()) - votes.begin()) << h;
  }
  // Free samples: the origin, then every free_res along each downsampled hit's beam.
  index.clear();
  std::vector<Voxel> free;
  const auto add = [&](const Eigen::Vector3f& q) {
    const auto [it, fresh] = index.try_emplace(key(q), free.size());
    if (fresh) free.emplace_back();
    free[it->second].sum += q;
    ++free[it->second].count;
  };
  add(origin);
  for (const Eigen::Vector3f& hit : hit_points) {
    const Eigen::Vector3f ray = hit - origin;
    const float length = ray.norm();
    if (!(length > p.free_res)) continue;
    const Eigen::Vector3f dir = ray / length;
    const int samples = static_cast<int>(std::floor((length - p.free_res) / p.free_res));
    for (int s = 1; s <= samples; ++s) add(origin + dir * (p.free_res * static_cast<float>(s)));
  }
  ASSERT_EQ(set.size(), hits.size() + free.size());
  ASSERT_GT(free.size(), 30000u);
  for (std::size_t f = 0; f < free.size(); ++f) {
    ASSERT_EQ(set.points[hits.size() + f], free[f].sum / static_cast<float>(free[f].count)) << f;
    ASSERT_EQ(set.labels[hits.size() + f], 0);
  }
}

}  // namespace
}  // namespace semap::mapping
