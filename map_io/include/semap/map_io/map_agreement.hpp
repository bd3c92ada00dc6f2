#pragma once

#include <cstddef>

#include "semap/mapping/layered_map.hpp"

namespace semap::map_io {

// How well `candidate` reproduces `reference` on the same grid: of the cells occupied in the
// reference, how many are occupied in the candidate with the same most probable class.
struct Agreement {
  std::size_t reference_occupied = 0;
  std::size_t candidate_occupied = 0;
  std::size_t both_occupied = 0;
  std::size_t same_class = 0;

  double fraction() const {
    return reference_occupied ? static_cast<double>(same_class) / reference_occupied : 0.0;
  }
};

// Throws std::invalid_argument unless both maps share method, classes and grid.
Agreement occupied_agreement(const mapping::LayeredMap& reference,
                             const mapping::LayeredMap& candidate);

}  // namespace semap::map_io
