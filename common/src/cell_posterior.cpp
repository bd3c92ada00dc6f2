#include "semap/common/cell_posterior.hpp"

namespace semap::common {

CellPosterior::CellPosterior(std::span<const float> evidence, float prior, bool observed)
    : evidence_(evidence), prior_(prior), observed_(observed) {}

float CellPosterior::alpha_sum() const {
  float sum = 0.0f;
  for (int k = 0; k < num_classes(); ++k) sum += alpha(k);
  return sum;
}

float CellPosterior::mean(int k) const { return alpha(k) / alpha_sum(); }

float CellPosterior::variance(int k) const {
  const float m = mean(k);
  return m * (1.0f - m) / (alpha_sum() + 1.0f);
}

std::optional<float> CellPosterior::mode(int k) const {
  for (int j = 0; j < num_classes(); ++j) {
    if (!(alpha(j) > 1.0f)) return std::nullopt;
  }
  return (alpha(k) - 1.0f) / (alpha_sum() - static_cast<float>(num_classes()));
}

int CellPosterior::argmax() const {
  int best = 0;
  for (int k = 1; k < num_classes(); ++k) {
    if (evidence_[static_cast<std::size_t>(k)] > evidence_[static_cast<std::size_t>(best)]) {
      best = k;
    }
  }
  return best;
}

CellState CellPosterior::state(float unknown_variance) const {
  if (!observed_) return CellState::kUnknown;
  const int best = argmax();
  if (unknown_variance > 0.0f && variance(best) > unknown_variance) return CellState::kUnknown;
  return best == 0 ? CellState::kFree : CellState::kOccupied;
}

int CellPosterior::label(float unknown_variance) const {
  return state(unknown_variance) == CellState::kUnknown ? -1 : argmax();
}

CellPosterior::Summary CellPosterior::summary(float unknown_variance) const {
  Summary s;
  float sum = 0.0f;
  for (int k = 0; k < num_classes(); ++k) {
    const float e = evidence_[static_cast<std::size_t>(k)];
    if (e > evidence_[static_cast<std::size_t>(s.argmax)]) s.argmax = k;
    sum += prior_ + e;
  }
  const float m = alpha(s.argmax) / sum;
  s.variance = m * (1.0f - m) / (sum + 1.0f);
  if (!observed_ || (unknown_variance > 0.0f && s.variance > unknown_variance)) {
    s.state = CellState::kUnknown;
  } else {
    s.state = s.argmax == 0 ? CellState::kFree : CellState::kOccupied;
  }
  return s;
}

}  // namespace semap::common
