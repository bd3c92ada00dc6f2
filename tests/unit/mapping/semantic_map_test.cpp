#include "semap/mapping/semantic_map.hpp"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstring>
#include <map>
#include <random>
#include <tuple>

#include "toy_dataset.hpp"

namespace semap::mapping {
namespace {

TrainingSet single_point(const Eigen::Vector3f& p, std::int32_t label, int k) {
  TrainingSet t;
  t.num_classes = k;
  t.points = {p};
  t.labels = {label};
  t.num_hits = 1;
  return t;
}

MapParams bki_params(int k = 4) {
  MapParams p;
  p.num_classes = k;
  return p;
}

// Evidence of every allocated cell, keyed by its centre rounded to the grid.
using CellKey = std::tuple<int, int, int>;
std::map<CellKey, std::vector<float>> all_cells(const SemanticMap& map) {
  std::map<CellKey, std::vector<float>> out;
  map.for_each_block([&](const common::BlockIndex& index, const Block& block) {
    for (int c = 0; c < block.num_cells(); ++c) {
      const Eigen::Vector3f centre = map.cell_center(index, c);
      const CellKey key{static_cast<int>(std::floor(centre.x() / map.params().resolution)),
                        static_cast<int>(std::floor(centre.y() / map.params().resolution)),
                        static_cast<int>(std::floor(centre.z() / map.params().resolution))};
      std::vector<float> e(static_cast<std::size_t>(block.channels()));
      block.read_cell(c, e);
      out[key] = e;
    }
  });
  return out;
}

TEST(SemanticMap, SinglePointAddsKernelTimesYToCellsWithinEll) {
  const MapParams params = bki_params();
  SemanticMap map(params);
  const Eigen::Vector3f p(0.537f, -0.212f, 0.049f);  // off the grid, near a block corner
  map.insert(single_point(p, 2, 4));
  const SparseKernel kernel(params.sf2, params.ell);
  int inside = 0;
  map.for_each_block([&](const common::BlockIndex& index, const Block& block) {
    for (int c = 0; c < block.num_cells(); ++c) {
      const double d = (map.cell_center(index, c) - p).cast<double>().norm();
      std::vector<float> e(static_cast<std::size_t>(block.channels()));
      block.read_cell(c, e);
      EXPECT_NEAR(e[2], kernel(d), 1e-5 * params.sf2);
      EXPECT_EQ(e[0], 0.0f);
      EXPECT_EQ(e[1], 0.0f);
      EXPECT_EQ(e[3], 0.0f);
      if (std::abs(d - params.ell) > 1e-4) {
        EXPECT_EQ(block.observed(c), d < params.ell) << "d = " << d;
      }
      inside += d < params.ell ? 1 : 0;
    }
  });
  // Every cell centre within ell got evidence: count them independently on the grid.
  int expected = 0;
  for (int x = -10; x <= 10; ++x) {
    for (int y = -10; y <= 10; ++y) {
      for (int z = -10; z <= 10; ++z) {
        const Eigen::Vector3f c =
            (Eigen::Vector3f(x, y, z) + Eigen::Vector3f::Constant(0.5f)) * 0.1f;
        const Eigen::Vector3f centre = c + Eigen::Vector3f(0.5f, -0.2f, 0.0f);
        if ((centre - p).norm() < params.ell) {
          ++expected;
          const auto cell = map.query(centre);
          ASSERT_TRUE(cell.has_value());
          EXPECT_TRUE(cell->observed());
        }
      }
    }
  }
  EXPECT_EQ(inside, expected);
  EXPECT_GT(expected, 100);  // about 4/3 pi 3^3 cells
}

TEST(SemanticMap, SoftLabelAddsKernelTimesProbabilityVector) {
  const MapParams params = bki_params(3);
  SemanticMap map(params);
  TrainingSet t = single_point(Eigen::Vector3f(0.03f, 0.07f, 0.02f), TrainingSet::kSoft, 3);
  t.probabilities = {0.2f, 0.5f, 0.3f};
  map.insert(t);
  const SparseKernel kernel(params.sf2, params.ell);
  const Eigen::Vector3f centre(0.15f, 0.05f, 0.05f);
  const auto cell = map.query(centre);
  ASSERT_TRUE(cell.has_value());
  const double w = kernel((centre - t.points[0]).cast<double>().norm());
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(cell->alpha(k) - params.prior, w * t.probabilities[static_cast<std::size_t>(k)],
                1e-5 * params.sf2);
  }
}

TEST(SemanticMap, CsmEqualsPerCellCounts) {
  MapParams params = bki_params(5);
  params.method = MapMethod::kCsm;
  SemanticMap map(params);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> coord(-1.0f, 1.0f);
  std::uniform_int_distribution<int> label(0, 4);
  TrainingSet t;
  t.num_classes = 5;
  std::map<CellKey, std::vector<float>> counts;
  for (int i = 0; i < 3000; ++i) {
    const Eigen::Vector3f p(coord(rng), coord(rng), coord(rng) * 0.2f);
    const int l = label(rng);
    t.points.push_back(p);
    t.labels.push_back(l);
    const CellKey key{static_cast<int>(std::floor(p.x() / 0.1f)),
                      static_cast<int>(std::floor(p.y() / 0.1f)),
                      static_cast<int>(std::floor(p.z() / 0.1f))};
    auto& c = counts[key];
    c.resize(5, 0.0f);
    c[static_cast<std::size_t>(l)] += 1.0f;
  }
  t.num_hits = t.points.size();
  map.insert(t);
  map.insert(t);  // incremental: a second scan adds the same counts again
  const auto cells = all_cells(map);
  std::size_t observed = 0;
  for (const auto& [key, evidence] : cells) {
    const auto it = counts.find(key);
    for (int k = 0; k < 5; ++k) {
      const float expected =
          it == counts.end() ? 0.0f : 2.0f * it->second[static_cast<std::size_t>(k)];
      EXPECT_EQ(evidence[static_cast<std::size_t>(k)], expected);
    }
    observed += it != counts.end();
  }
  EXPECT_EQ(observed, counts.size());
  EXPECT_EQ(map.stats().observed_cells, counts.size());
}

TEST(SemanticMap, TwoClassCsmIsTheBinaryCountingSensorModel) {
  MapParams params = bki_params(2);
  params.method = MapMethod::kCsm;
  params.prior = 0.5f;
  SemanticMap map(params);
  // One cell: 7 hits (class 1) and 3 pass-throughs (class 0).
  TrainingSet t;
  t.num_classes = 2;
  for (int i = 0; i < 10; ++i) {
    t.points.emplace_back(0.01f * static_cast<float>(i), 0.05f, 0.05f);
    t.labels.push_back(i < 7 ? 1 : 0);
  }
  t.num_hits = 7;
  map.insert(t);
  const auto cell = map.query(Eigen::Vector3f(0.05f, 0.05f, 0.05f));
  ASSERT_TRUE(cell.has_value());
  // Counting sensor model: p(occupied) = (hits + a0) / (hits + misses + 2 a0).
  EXPECT_FLOAT_EQ(cell->mean(1), (7.0f + 0.5f) / (10.0f + 1.0f));
  EXPECT_EQ(cell->state(), common::CellState::kOccupied);
}

std::vector<common::LabeledCloud> toy_scans(int count) { return testing::toy_scans(1, count); }

SemanticMap build_with_threads(const std::vector<common::LabeledCloud>& scans, MapMethod method,
                               int threads) {
  MapParams params = bki_params();
  params.method = method;
  SemanticMap map(params);
  tbb::task_arena arena(threads);
  arena.execute([&] {
    for (const auto& s : scans) map.insert(s, s.origin);
  });
  return map;
}

class ThreadInvariance : public ::testing::TestWithParam<MapMethod> {};

TEST_P(ThreadInvariance, MultiThreadedEqualsSingleThreadedBitForBit) {
  const auto scans = toy_scans(3);
  const SemanticMap one = build_with_threads(scans, GetParam(), 1);
  const SemanticMap two = build_with_threads(scans, GetParam(), 2);
  ASSERT_EQ(one.stats().blocks, two.stats().blocks);
  ASSERT_GT(one.stats().observed_cells, 1000u);
  std::size_t compared = 0;
  one.for_each_block([&](const common::BlockIndex& index, const Block& a) {
    const Block* b = two.find_block(index);
    ASSERT_NE(b, nullptr);
    const std::vector<float> x = a.dense();
    const std::vector<float> y = b->dense();
    ASSERT_EQ(std::memcmp(x.data(), y.data(), x.size() * sizeof(float)), 0);
    for (int c = 0; c < a.num_cells(); ++c) ASSERT_EQ(a.observed(c), b->observed(c));
    ++compared;
  });
  EXPECT_EQ(compared, one.stats().blocks);
}

INSTANTIATE_TEST_SUITE_P(Methods, ThreadInvariance,
                         ::testing::Values(MapMethod::kBki, MapMethod::kCsm));

TEST(SemanticMap, AddingBlockEvidenceMergesMaps) {
  const auto scans = toy_scans(2);
  const MapParams params = bki_params();
  SemanticMap both(params), first(params), second(params);
  for (const auto& s : scans) both.insert(s, s.origin);
  first.insert(scans[0], scans[0].origin);
  second.insert(scans[1], scans[1].origin);
  second.for_each_block([&](const common::BlockIndex& index, const Block& b) {
    first.add_evidence(index, b.dense());
  });
  EXPECT_EQ(first.stats().blocks, both.stats().blocks);
  EXPECT_EQ(first.stats().observed_cells, both.stats().observed_cells);
  both.for_each_block([&](const common::BlockIndex& index, const Block& b) {
    const Block* m = first.find_block(index);
    ASSERT_NE(m, nullptr);
    const std::vector<float> merged = m->dense();
    const std::vector<float> want = b.dense();
    for (std::size_t i = 0; i < want.size(); ++i) {
      ASSERT_NEAR(merged[i], want[i], 1e-4f * (1.0f + want[i]));
    }
  });
}

TEST(SemanticMap, ToyMapIsMostlyRightAndCompact) {
  const auto scans = toy_scans(12);
  SemanticMap map(bki_params());
  for (const auto& s : scans) map.insert(s, s.origin);
  std::size_t right = 0, total = 0;
  for (const auto& s : scans) {
    for (std::size_t i = 0; i < s.size(); ++i) {
      right += map.label_at(s.points[i]) == s.labels[i];
      ++total;
    }
  }
  EXPECT_GT(static_cast<double>(right) / total, 0.8);
  const MapStats stats = map.stats();
  EXPECT_LE(stats.bytes_per_cell(), 4.0 * 4 + 16);
  EXPECT_EQ(stats.scans, 12u);
}

TEST(SemanticMap, BadPointsAreCountedNotFatal) {
  SemanticMap map(bki_params());
  common::LabeledCloud c;
  c.points = {{std::nanf(""), 0, 0}, {0.5f, 0.5f, 0.5f}, {0.4f, 0.4f, 0.4f}};
  c.labels = {1, 7, 2};
  const InsertResult r = map.insert(c, Eigen::Vector3f::Zero());
  EXPECT_EQ(r.rejected_points, 2u);
  EXPECT_EQ(r.hits, 1u);
  EXPECT_EQ(map.stats().rejected_points, 2u);
  EXPECT_EQ(map.label_at(Eigen::Vector3f(0.45f, 0.45f, 0.45f)), 2);
  EXPECT_EQ(map.label_at(Eigen::Vector3f(50.0f, 0.0f, 0.0f)), -1);
  EXPECT_FALSE(map.query(Eigen::Vector3f(std::nanf(""), 0, 0)).has_value());
}

TEST(SemanticMap, CellCentresLieInTheirBlock) {
  const SemanticMap map(bki_params());
  for (const common::BlockIndex b :
       {common::BlockIndex{0, 0, 0}, common::BlockIndex{-1, 2, -3}, common::BlockIndex{7, -8, 0}}) {
    for (const int cell : {0, 5, 63}) {
      EXPECT_EQ(map.block_of(map.cell_center(b, cell)), b) << cell;
    }
  }
  // Negative coordinates floor towards minus infinity.
  EXPECT_EQ(map.block_of(Eigen::Vector3f(-0.01f, 0.39f, 0.41f)), (common::BlockIndex{-1, 0, 1}));
}

TEST(SemanticMap, RejectsBadParameters) {
  MapParams p;
  p.resolution = 0.0f;
  EXPECT_THROW(SemanticMap{p}, std::invalid_argument);
  p = MapParams{};
  p.block_depth = 9;
  EXPECT_THROW(SemanticMap{p}, std::invalid_argument);
}

}  // namespace
}  // namespace semap::mapping
