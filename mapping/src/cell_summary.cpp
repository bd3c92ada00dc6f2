#include "semap/mapping/cell_summary.hpp"

#include <algorithm>
#include <numeric>

#include "semap/common/cell_posterior.hpp"
#include "semap/mapping/logodds.hpp"

namespace semap::mapping {

std::vector<double> class_probabilities(const MapParams& params, std::span<const float> fused) {
  std::vector<double> p(static_cast<std::size_t>(params.num_classes));
  if (params.method == MapMethod::kLogOdds) {
    LogOddsModel::probabilities(fused.subspan(1), p);
    return p;
  }
  const double sum = std::accumulate(fused.begin(), fused.end(), 0.0);
  for (std::size_t c = 0; c < p.size(); ++c) p[c] = fused[c] / sum;
  return p;
}

CellSummary summarize(const MapParams& params, std::span<const float> fused) {
  CellSummary s;
  const std::vector<double> p = class_probabilities(params, fused);
  const auto best = std::max_element(p.begin(), p.end());
  s.label = static_cast<int>(best - p.begin());
  s.probability = static_cast<float>(*best);
  if (params.method == MapMethod::kLogOdds) {
    s.known = std::any_of(fused.begin(), fused.end(), [](float v) { return v != 0.0f; });
    s.occupancy = static_cast<float>(sigmoid(fused[0]));
    s.occupied = fused[0] > 0.0f;
    s.variance = s.probability * (1.0f - s.probability);
    return s;
  }
  // S-BKI / S-CSM: fused channels are alpha = alpha_0 + evidence, read with a zero prior, and
  // cells more uncertain than the map's own threshold are unknown, as on the robot.
  const float prior = params.prior;
  const common::CellPosterior cell(
      fused, 0.0f, std::any_of(fused.begin(), fused.end(), [&](float v) { return v > prior; }));
  const common::CellState state = cell.state(params.unknown_variance);
  s.known = state != common::CellState::kUnknown;
  s.occupied = state == common::CellState::kOccupied;
  s.occupancy = static_cast<float>(1.0 - p[0]);
  s.variance = cell.variance(s.label);
  return s;
}

}  // namespace semap::mapping
