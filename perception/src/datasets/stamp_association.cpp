#include "semap/perception/datasets/stamp_association.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <tuple>

namespace semap::perception::datasets {

std::vector<StampPair> associate_stamps(std::span<const double> first,
                                        std::span<const double> second, double max_difference_s) {
  // The second list in stamp order, so that each first stamp finds its candidates by bisection
  // instead of associate.py's all-pairs loop.
  std::vector<std::size_t> by_stamp(second.size());
  std::iota(by_stamp.begin(), by_stamp.end(), std::size_t{0});
  std::stable_sort(by_stamp.begin(), by_stamp.end(),
                   [&](std::size_t a, std::size_t b) { return second[a] < second[b]; });

  struct Candidate {
    double difference;
    std::size_t first;
    std::size_t second;
  };
  std::vector<Candidate> candidates;
  for (std::size_t i = 0; i < first.size(); ++i) {
    const double a = first[i];
    auto it = std::lower_bound(by_stamp.begin(), by_stamp.end(), a - max_difference_s,
                               [&](std::size_t j, double stamp) { return second[j] < stamp; });
    for (; it != by_stamp.end() && second[*it] < a + max_difference_s; ++it) {
      const double difference = std::abs(a - second[*it]);
      if (difference < max_difference_s) candidates.push_back({difference, i, *it});
    }
  }
  const auto key = [&](const Candidate& c) {
    return std::tie(c.difference, first[c.first], second[c.second], c.first, c.second);
  };
  std::sort(candidates.begin(), candidates.end(),
            [&](const Candidate& x, const Candidate& y) { return key(x) < key(y); });

  std::vector<bool> first_used(first.size(), false);
  std::vector<bool> second_used(second.size(), false);
  std::vector<StampPair> pairs;
  for (const Candidate& c : candidates) {
    if (first_used[c.first] || second_used[c.second]) continue;
    first_used[c.first] = true;
    second_used[c.second] = true;
    pairs.push_back({c.first, c.second});
  }
  std::sort(pairs.begin(), pairs.end(),
            [](const StampPair& x, const StampPair& y) { return x.first < y.first; });
  return pairs;
}

}  // namespace semap::perception::datasets
