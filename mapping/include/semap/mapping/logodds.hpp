#pragma once

#include <algorithm>
#include <cmath>
#include <span>

#include "semap/mapping/map_params.hpp"

namespace semap::mapping {

inline float logit(double p) { return static_cast<float>(std::log(p / (1.0 - p))); }
inline double sigmoid(double l) { return 1.0 / (1.0 + std::exp(-l)); }

// The measurement model of the log-odds map: OctoMap's occupancy update
// l <- clamp(l + l_hit|l_miss), and the Bayesian label update of Yue et al.
//   l_t(c) = l(c|z_t) + l_{t-1}(c),  l(c|z) = log p(c|z) - log P(c),
// i.e. the label state is a categorical distribution whose log (up to a per-voxel constant)
// accumulates the measurement log-likelihood ratios against the prior P(c) = 1/K; the class
// probabilities are the softmax of log P(c) + l_t(c).
class LogOddsModel {
 public:
  explicit LogOddsModel(const LogOddsParams& params)
      : hit_(logit(params.prob_hit)),
        miss_(logit(params.prob_miss)),
        min_(logit(params.clamp_min)),
        max_(logit(params.clamp_max)),
        spread_(static_cast<float>(params.label_spread)),
        confidence_(params.label_confidence) {}

  float hit() const { return hit_; }
  float miss() const { return miss_; }
  float clamp(float l) const { return std::clamp(l, min_, max_); }

  // Adds one class measurement (probabilities p(c|z), K values) to the label log-odds.
  void add_label_probabilities(std::span<float> labels, std::span<const float> p) const {
    const double log_prior = -std::log(static_cast<double>(labels.size()));
    for (std::size_t c = 0; c < labels.size(); ++c) {
      const double pc = std::clamp(static_cast<double>(p[c]), 1e-6, 1.0);
      labels[c] += static_cast<float>(std::log(pc) - log_prior);
    }
    normalise(labels);
  }

  // Adds a hard-label measurement: `label_confidence` for the observed class, the rest spread.
  void add_hard_label(std::span<float> labels, std::size_t label) const {
    const auto k = static_cast<double>(labels.size());
    const double log_prior = -std::log(k);
    const double other = k > 1.0 ? (1.0 - confidence_) / (k - 1.0) : 1.0;
    for (std::size_t c = 0; c < labels.size(); ++c) {
      labels[c] += static_cast<float>(std::log(c == label ? confidence_ : other) - log_prior);
    }
    normalise(labels);
  }

  // Softmax of log P(c) + l(c); the uniform prior cancels.
  static void probabilities(std::span<const float> labels, std::span<double> out) {
    const float top = *std::max_element(labels.begin(), labels.end());
    double sum = 0.0;
    for (std::size_t c = 0; c < labels.size(); ++c) {
      out[c] = std::exp(static_cast<double>(labels[c] - top));
      sum += out[c];
    }
    for (double& v : out) v /= sum;
  }

 private:
  // Softmax is invariant to a per-voxel shift, so shifting the best class to 0 and bounding the
  // others keeps the floats small without changing any probability beyond the spread.
  void normalise(std::span<float> labels) const {
    const float top = *std::max_element(labels.begin(), labels.end());
    for (float& l : labels) l = std::max(l - top, -spread_);
  }

  float hit_;
  float miss_;
  float min_;
  float max_;
  float spread_;
  double confidence_;
};

}  // namespace semap::mapping
