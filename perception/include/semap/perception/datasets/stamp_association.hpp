#pragma once

#include <cstddef>
#include <span>
#include <vector>

namespace semap::perception::datasets {

struct StampPair {
  std::size_t first = 0;   // index into the first list
  std::size_t second = 0;  // index into the second list
};

// Pairs two lists of stamps (seconds) as TUM RGB-D's associate.py does: every pair closer than
// `max_difference_s` (strictly) is a candidate; candidates are taken in order of increasing
// difference (ties: earlier first stamp, then earlier second stamp), each stamp used at most
// once. The lists need not be sorted; stamps must be finite. Returns the pairs ordered by `first`.
std::vector<StampPair> associate_stamps(std::span<const double> first,
                                        std::span<const double> second, double max_difference_s);

}  // namespace semap::perception::datasets
