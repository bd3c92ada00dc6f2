#include "semap/map_io/label_noise.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace semap::map_io {

namespace {

// Standard normal draws by the Box-Muller transform on mt19937_64's raw output, so the
// sequence for a seed does not depend on the standard library's distributions.
class NormalSampler {
 public:
  explicit NormalSampler(std::uint64_t seed) : rng_(seed) {}

  double operator()() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double radius = std::sqrt(-2.0 * std::log(uniform()));
    const double angle = 2.0 * std::numbers::pi * uniform();
    spare_ = radius * std::sin(angle);
    has_spare_ = true;
    return radius * std::cos(angle);
  }

 private:
  // Uniform in (0, 1): 53 random bits, offset by half a step.
  double uniform() { return (static_cast<double>(rng_() >> 11) + 0.5) * 0x1.0p-53; }

  std::mt19937_64 rng_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

double normal_cdf(double x) { return 0.5 * std::erfc(-x / std::numbers::sqrt2); }

}  // namespace

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

NoisySegmentation soft_label_noise(const common::LabeledCloud& clean, SoftLabelNoise noise,
                                   int first_class, int num_classes, std::uint64_t seed) {
  if (num_classes - first_class < 2 || first_class < 0) {
    throw std::invalid_argument("soft label noise needs at least two candidate classes");
  }
  if (!(std::isfinite(noise.margin) && std::isfinite(noise.sigma) && noise.margin >= 0.0 &&
        noise.sigma >= 0.0)) {
    throw std::invalid_argument("soft label noise needs finite margin >= 0 and sigma >= 0");
  }
  if (clean.labels.size() != clean.size()) {
    throw std::invalid_argument("soft label noise needs one hard label per point");
  }
  const auto k = static_cast<std::size_t>(num_classes);
  const auto first = static_cast<std::size_t>(first_class);
  NoisySegmentation out;
  for (common::LabeledCloud* cloud : {&out.soft, &out.hard}) {
    cloud->stamp = clean.stamp;
    cloud->origin = clean.origin;
    cloud->points = clean.points;
    cloud->num_classes = static_cast<std::uint16_t>(num_classes);
  }
  out.soft.probabilities.assign(clean.size() * k, 0.0f);
  out.hard.labels.resize(clean.size());
  NormalSampler normal(seed);
  std::vector<double> z(k);
  for (std::size_t i = 0; i < clean.size(); ++i) {
    const std::size_t truth = clean.labels[i];
    if (truth < first || truth >= k) {
      throw std::invalid_argument("label " + std::to_string(truth) + " outside [" +
                                  std::to_string(first_class) + ", " + std::to_string(num_classes) +
                                  ")");
    }
    // Logits; the argmax keeps the lowest class on a tie.
    std::size_t best = first;
    for (std::size_t c = first; c < k; ++c) {
      z[c] = (c == truth ? noise.margin : 0.0) + noise.sigma * normal();
      if (z[c] > z[best]) best = c;
    }
    const double top = z[best];
    double sum = 0.0;
    for (std::size_t c = first; c < k; ++c) {
      z[c] = std::exp(z[c] - top);
      sum += z[c];
    }
    float* y = out.soft.probabilities.data() + i * k;
    for (std::size_t c = first; c < k; ++c) y[c] = static_cast<float>(z[c] / sum);
    out.hard.labels[i] = static_cast<std::uint16_t>(best);
    if (best != truth) ++out.wrong;
  }
  return out;
}

double soft_label_error_rate(SoftLabelNoise noise, int classes) {
  if (!(noise.sigma > 0.0) || classes < 2) {
    throw std::invalid_argument("soft label error rate needs sigma > 0 and two classes");
  }
  // Composite Simpson rule over x in [-12, 12] of phi(x) (1 - Phi(x + r)^(C - 1)); the
  // tails beyond contribute below 1e-30.
  const double r = noise.margin / noise.sigma;
  constexpr int kSteps = 4800;  // even
  constexpr double kLo = -12.0, kHi = 12.0, kStep = (kHi - kLo) / kSteps;
  double sum = 0.0;
  for (int s = 0; s <= kSteps; ++s) {
    const double x = kLo + kStep * s;
    const double f = std::exp(-0.5 * x * x) / std::sqrt(2.0 * std::numbers::pi) *
                     (1.0 - std::pow(normal_cdf(x + r), classes - 1));
    sum += f * (s == 0 || s == kSteps ? 1.0 : (s % 2 == 1 ? 4.0 : 2.0));
  }
  return sum * kStep / 3.0;
}

SoftLabelNoise calibrated_soft_label_noise(double error, int classes) {
  if (classes < 2 || !(error > 0.0 && error < static_cast<double>(classes - 1) / classes)) {
    throw std::invalid_argument("argmax error rate must lie in (0, (C - 1) / C)");
  }
  // e(r) falls from (C - 1) / C at r = 0 towards 0; bisect for r = margin / sigma = sigma.
  double lo = 0.0, hi = 40.0;
  for (int iteration = 0; iteration < 100; ++iteration) {
    const double mid = 0.5 * (lo + hi);
    if (soft_label_error_rate({mid * mid, mid}, classes) > error) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  const double r = 0.5 * (lo + hi);
  return {r * r, r};
}

std::vector<SoftLabelResult> evaluate_soft_labels(std::span<const common::LabeledCloud> clean,
                                                  const mapping::MapParams& params,
                                                  std::span<const double> error_rates,
                                                  std::uint64_t seed) {
  // Scan points are hits: classes 1..K-1 are the candidates and the scored classes.
  std::vector<int> classes(static_cast<std::size_t>(params.num_classes - 1));
  std::iota(classes.begin(), classes.end(), 1);
  const auto miou = [&](mapping::MapMethod method, const std::vector<common::LabeledCloud>& scans) {
    mapping::MapParams p = params;
    p.method = method;
    mapping::SemanticMap map(p);
    for (const auto& scan : scans) map.insert(scan, scan.origin);
    return score_map(map, clean).mean_iou(classes);
  };
  std::vector<SoftLabelResult> rows;
  for (const double error : error_rates) {
    SoftLabelResult row;
    row.target_error = error;
    row.noise = calibrated_soft_label_noise(error, params.num_classes - 1);
    std::vector<common::LabeledCloud> soft, hard;
    std::size_t wrong = 0, points = 0;
    for (std::size_t i = 0; i < clean.size(); ++i) {
      NoisySegmentation s = soft_label_noise(clean[i], row.noise, 1, params.num_classes, seed + i);
      wrong += s.wrong;
      points += clean[i].size();
      soft.push_back(std::move(s.soft));
      hard.push_back(std::move(s.hard));
    }
    row.error = points == 0 ? 0.0 : static_cast<double>(wrong) / static_cast<double>(points);
    row.bki_hard = miou(mapping::MapMethod::kBki, hard);
    row.bki_soft = miou(mapping::MapMethod::kBki, soft);
    row.csm_hard = miou(mapping::MapMethod::kCsm, hard);
    row.csm_soft = miou(mapping::MapMethod::kCsm, soft);
    rows.push_back(row);
  }
  return rows;
}

}  // namespace semap::map_io
