#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "semap/common/messages.hpp"
#include "semap/map_io/evaluation.hpp"
#include "semap/mapping/map_params.hpp"

namespace semap::map_io {

// Replaces the hard labels of round(fraction * N) randomly chosen points with a different
// class drawn uniformly from [first_class, num_classes). Deterministic for a given seed.
// Returns the number of flipped points.
std::size_t flip_labels(common::LabeledCloud& cloud, double fraction, int first_class,
                        int num_classes, std::uint64_t seed);

// A simulated noisy segmenter. For a point with true class t in [first_class, K), over the
// C = K - first_class candidate classes c in [first_class, K):
//   z_c = margin * [c == t] + sigma * n_c,   n_c ~ N(0, 1) i.i.d.          (logits)
//   y_c = exp(z_c) / sum_j exp(z_j),   y_c = 0 for c < first_class (free)  (soft label)
//   hard label = argmax_c y_c = argmax_c z_c
// The hard label is wrong with probability, a function of r = margin / sigma only,
//   e(r) = 1 - integral phi(x) Phi(x + r)^(C - 1) dx
// (the true logit is margin + sigma x; every other one must stay below it). Since
// p(z | t) is proportional to exp(margin z_t / sigma^2), softmax(margin z / sigma^2) is the
// Bayes posterior of t under a uniform class prior, so with margin = sigma^2 the soft labels
// are calibrated (P(t = c | y) = y_c).
struct SoftLabelNoise {
  double margin = 0.0;
  double sigma = 0.0;
};

// The noisy segmenter's output for one scan: the same points and origin with soft labels
// (probabilities, K floats per point, no hard labels) and with the argmax as hard labels.
struct NoisySegmentation {
  common::LabeledCloud soft;
  common::LabeledCloud hard;
  std::size_t wrong = 0;  // points whose hard label is not the true one
};

// Applies the segmenter above to the hard labels of `clean`. Deterministic for a seed (its
// own normal sampler, no std:: distribution). Throws std::invalid_argument when a label lies
// outside [first_class, num_classes), fewer than two candidate classes, or margin or sigma
// is negative or not finite.
NoisySegmentation soft_label_noise(const common::LabeledCloud& clean, SoftLabelNoise noise,
                                   int first_class, int num_classes, std::uint64_t seed);

// e(margin / sigma) above for `classes` candidate classes (numerical integral); sigma > 0.
double soft_label_error_rate(SoftLabelNoise noise, int classes);

// The calibrated segmenter (margin = sigma^2) whose argmax error rate is `error`, which must
// lie in (0, (classes - 1) / classes).
SoftLabelNoise calibrated_soft_label_noise(double error, int classes);

// One level of the soft-label study: the segmenter, its measured error rate over all scans,
// and the mIoU (classes 1..K-1, queried at the scan points against the clean labels) of the
// maps built from its hard and from its soft labels, S-BKI and S-CSM.
struct SoftLabelResult {
  double target_error = 0.0;
  SoftLabelNoise noise;
  double error = 0.0;
  double bki_hard = 0.0;
  double bki_soft = 0.0;
  double csm_hard = 0.0;
  double csm_soft = 0.0;
};

// For every error rate: the calibrated segmenter of that rate applied to every scan (seed +
// scan index), four maps built with `params` (method replaced), scored as
// evaluate_label_noise does.
std::vector<SoftLabelResult> evaluate_soft_labels(std::span<const common::LabeledCloud> clean,
                                                  const mapping::MapParams& params,
                                                  std::span<const double> error_rates,
                                                  std::uint64_t seed);

}  // namespace semap::map_io
