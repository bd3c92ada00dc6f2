#include "semap/mapping/label_noise.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <stdexcept>
#include <vector>

namespace semap::mapping {

std::size_t flip_labels(common::LabeledCloud& cloud, double fraction, int first_class,
                        int num_classes, std::uint64_t seed) {
  if (!(fraction >= 0.0 && fraction <= 1.0)) {
    throw std::invalid_argument("label noise fraction must be in [0, 1]");
  }
  if (num_classes - first_class < 2) {
    throw std::invalid_argument("label noise needs at least two candidate classes");
  }
  std::mt19937_64 rng(seed);
  std::vector<std::size_t> order(cloud.labels.size());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), rng);
  const auto flips = static_cast<std::size_t>(std::llround(fraction * order.size()));
  // Draw from the other num_classes - first_class - 1 classes, skipping the current one.
  std::uniform_int_distribution<int> pick(first_class, num_classes - 2);
  for (std::size_t n = 0; n < flips; ++n) {
    std::uint16_t& label = cloud.labels[order[n]];
    int other = pick(rng);
    if (other >= label) ++other;
    label = static_cast<std::uint16_t>(other);
  }
  return flips;
}

}  // namespace semap::mapping
