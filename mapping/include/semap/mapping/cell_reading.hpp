#pragma once

#include <utility>
#include <vector>

#include "semap/common/cell_posterior.hpp"

namespace semap::mapping {

namespace detail {
struct EvidenceCopy {
  std::vector<float> values;
};
}  // namespace detail

// One cell read out of a map: a copy of its evidence (blocks store cells sparsely, so there is
// no dense row to view in place) and the posterior over that copy. Movable, not copyable: a
// move keeps the vector's buffer, which the posterior views.
class CellReading : private detail::EvidenceCopy, public common::CellPosterior {
 public:
  CellReading(std::vector<float> evidence, float prior, bool observed)
      : detail::EvidenceCopy{std::move(evidence)}, common::CellPosterior(values, prior, observed) {}
  CellReading(const CellReading&) = delete;
  CellReading& operator=(const CellReading&) = delete;
  CellReading(CellReading&&) noexcept = default;
  CellReading& operator=(CellReading&&) noexcept = default;
  ~CellReading() = default;
};

}  // namespace semap::mapping
