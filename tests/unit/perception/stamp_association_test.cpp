#include "semap/perception/datasets/stamp_association.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <tuple>
#include <vector>

namespace semap::perception::datasets {
namespace {

using Pairs = std::vector<std::pair<std::size_t, std::size_t>>;

Pairs associate(const std::vector<double>& first, const std::vector<double>& second,
                double max_difference) {
  Pairs out;
  for (const StampPair& p : associate_stamps(first, second, max_difference)) {
    out.emplace_back(p.first, p.second);
  }
  return out;
}

// associate.py line by line: every pair closer than the tolerance, sorted as Python sorts the
// tuples (difference, a, b), taken greedily.
Pairs associate_py(const std::vector<double>& first, const std::vector<double>& second,
                   double max_difference) {
  std::vector<std::tuple<double, double, double, std::size_t, std::size_t>> candidates;
  for (std::size_t i = 0; i < first.size(); ++i) {
    for (std::size_t j = 0; j < second.size(); ++j) {
      const double d = std::abs(first[i] - second[j]);
      if (d < max_difference) candidates.emplace_back(d, first[i], second[j], i, j);
    }
  }
  std::sort(candidates.begin(), candidates.end());
  std::set<std::size_t> used_first, used_second;
  Pairs out;
  for (const auto& [d, a, b, i, j] : candidates) {
    if (used_first.count(i) || used_second.count(j)) continue;
    used_first.insert(i);
    used_second.insert(j);
    out.emplace_back(i, j);
  }
  std::sort(out.begin(), out.end());
  return out;
}

TEST(StampAssociation, SmallestDifferenceFirstEachStampOnce) {
  // Depth frame 0 is 23 ms after colour 0 and 8 ms before colour 1: it goes to colour 1, and
  // colour 0 stays alone, though depth 0 is also its nearest frame.
  EXPECT_EQ(associate({0.0, 0.03125}, {0.0234375}, 0.05), (Pairs{{1, 0}}));
  // Everyone paired when the nearest neighbours are mutual.
  EXPECT_EQ(associate({0.0, 0.033, 0.066}, {0.004, 0.031, 0.07}, 0.02),
            (Pairs{{0, 0}, {1, 1}, {2, 2}}));
}

TEST(StampAssociation, ToleranceIsStrict) {
  // Stamps chosen so the differences are exact in binary.
  EXPECT_TRUE(associate({1.0}, {1.015625}, 0.015625).empty());
  EXPECT_EQ(associate({1.0}, {1.015625}, 0.015626), (Pairs{{0, 0}}));
  EXPECT_EQ(associate({1.0}, {0.984375}, 0.015626), (Pairs{{0, 0}}));
  EXPECT_TRUE(associate({1.0}, {}, 1.0).empty());
  EXPECT_TRUE(associate({}, {1.0}, 1.0).empty());
}

TEST(StampAssociation, EqualDifferencesGoToTheEarlierStamp) {
  // Depth 0.5 is 0.25 from both colour frames; Python's tuple order gives it to colour 0.25.
  EXPECT_EQ(associate({0.75, 0.25}, {0.5}, 0.3), (Pairs{{1, 0}}));
}

TEST(StampAssociation, UnsortedListsPairLikeSortedOnes) {
  EXPECT_EQ(associate({0.066, 0.0, 0.033}, {0.031, 0.07, 0.004}, 0.02),
            (Pairs{{0, 1}, {1, 2}, {2, 0}}));
}

TEST(StampAssociation, SameAsAssociatePyOnRandomStreams) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.012, 0.012);
  std::bernoulli_distribution dropped(0.1);
  for (int trial = 0; trial < 50; ++trial) {
    // Two 30 Hz streams with jitter and dropped frames, as a Kinect records them.
    std::vector<double> colour, depth;
    for (int k = 0; k < 200; ++k) {
      if (!dropped(rng)) colour.push_back(k / 30.0 + jitter(rng));
      if (!dropped(rng)) depth.push_back(k / 30.0 + 0.005 + jitter(rng));
    }
    std::shuffle(depth.begin(), depth.end(), rng);
    ASSERT_EQ(associate(colour, depth, 0.02), associate_py(colour, depth, 0.02))
        << "trial " << trial;
  }
}

}  // namespace
}  // namespace semap::perception::datasets
