#pragma once

#include <cstdint>

#include "semap/common/messages.hpp"

namespace semap::mapping {

// Replaces the hard labels of round(fraction * N) randomly chosen points with a different
// class drawn uniformly from [first_class, num_classes). Deterministic for a given seed.
// Returns the number of flipped points.
std::size_t flip_labels(common::LabeledCloud& cloud, double fraction, int first_class,
                        int num_classes, std::uint64_t seed);

}  // namespace semap::mapping
