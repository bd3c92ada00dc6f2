#pragma once

#include <cstdint>
#include <optional>
#include <span>

#include "semap/common/map_grid.hpp"

namespace semap::common {

// The Dirichlet posterior of one S-BKI / S-CSM cell, alpha^k = prior + evidence^k, read in place
// from wherever the evidence lives (the map's blocks, a received block; valid while it does).
// The one reader of a cell's evidence: the map, its exports and the DDS blocks all use it.
class CellPosterior {
 public:
  CellPosterior(std::span<const float> evidence, float prior, bool observed);

  int num_classes() const { return static_cast<int>(evidence_.size()); }
  bool observed() const { return observed_; }
  float alpha(int k) const { return prior_ + evidence_[static_cast<std::size_t>(k)]; }
  float alpha_sum() const;

  // E[theta^k] = alpha^k / sum alpha.
  float mean(int k) const;
  // Var[theta^k] = mean (1 - mean) / (sum alpha + 1).
  float variance(int k) const;
  // (alpha^k - 1) / (sum alpha - K), defined only when every alpha^j > 1.
  std::optional<float> mode(int k) const;
  // Class with the largest alpha; the lowest index wins ties.
  int argmax() const;
  // Unknown if never observed, or if unknown_variance > 0 and the argmax class's variance
  // exceeds it; otherwise free when the argmax is class 0, else occupied.
  CellState state(float unknown_variance = 0.0f) const;
  // argmax, or -1 when the state is unknown.
  int label(float unknown_variance = 0.0f) const;

  // state(), argmax() and variance(argmax()) from one pass over the classes (equal to them):
  // what a map publishes per cell.
  struct Summary {
    CellState state = CellState::kUnknown;
    int argmax = 0;
    float variance = 0.0f;
  };
  Summary summary(float unknown_variance = 0.0f) const;

 private:
  std::span<const float> evidence_;
  float prior_;
  bool observed_;
};

}  // namespace semap::common
