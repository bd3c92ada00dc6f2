#include "semap/map_io/evaluation.hpp"

#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "semap/map_io/label_noise.hpp"

namespace semap::map_io {

ConfusionMatrix::ConfusionMatrix(int num_classes)
    : k_(num_classes), counts_(static_cast<std::size_t>(num_classes) * (num_classes + 1), 0) {
  if (num_classes < 1) throw std::invalid_argument("confusion matrix needs at least one class");
}

void ConfusionMatrix::add(int truth, int predicted) {
  if (truth < 0 || truth >= k_) return;
  const int column = (predicted < 0 || predicted >= k_) ? k_ : predicted;
  ++counts_[static_cast<std::size_t>(truth) * (k_ + 1) + column];
  ++total_;
}

void ConfusionMatrix::merge(const ConfusionMatrix& other) {
  if (other.k_ != k_) throw std::invalid_argument("confusion matrices differ in class count");
  for (std::size_t i = 0; i < counts_.size(); ++i) counts_[i] += other.counts_[i];
  total_ += other.total_;
}

std::uint64_t ConfusionMatrix::count(int truth, int predicted) const {
  const int column = predicted < 0 ? k_ : predicted;
  return counts_[static_cast<std::size_t>(truth) * (k_ + 1) + column];
}

std::uint64_t ConfusionMatrix::truth_count(int c) const {
  const auto row = counts_.begin() + static_cast<std::ptrdiff_t>(c) * (k_ + 1);
  return std::accumulate(row, row + k_ + 1, std::uint64_t{0});
}

double ConfusionMatrix::iou(int c) const {
  const std::uint64_t tp = count(c, c), fn = truth_count(c) - tp;
  std::uint64_t fp = 0;
  for (int t = 0; t < k_; ++t) {
    if (t != c) fp += count(t, c);
  }
  const std::uint64_t denominator = tp + fp + fn;
  return denominator == 0 ? std::numeric_limits<double>::quiet_NaN()
                          : static_cast<double>(tp) / static_cast<double>(denominator);
}

double ConfusionMatrix::mean_iou(std::span<const int> classes) const {
  double sum = 0.0;
  int n = 0;
  for (const int c : classes) {
    const double v = iou(c);
    if (std::isnan(v)) continue;
    sum += v;
    ++n;
  }
  return n == 0 ? std::numeric_limits<double>::quiet_NaN() : sum / n;
}

ConfusionMatrix score_map(const mapping::SemanticMap& map,
                          std::span<const common::LabeledCloud> scans) {
  ConfusionMatrix m(map.params().num_classes);
  for (const auto& scan : scans) {
    for (std::size_t i = 0; i < scan.size(); ++i) {
      m.add(scan.labels[i], map.label_at(scan.points[i]));
    }
  }
  return m;
}

std::vector<NoiseResult> evaluate_label_noise(std::span<const common::LabeledCloud> clean,
                                              const mapping::MapParams& params,
                                              std::span<const double> noise, std::uint64_t seed) {
  // Scan points are hits, so class 0 (free) is never a true label and is not scored.
  std::vector<int> classes(static_cast<std::size_t>(params.num_classes - 1));
  std::iota(classes.begin(), classes.end(), 1);
  std::vector<NoiseResult> rows;
  for (const double fraction : noise) {
    std::vector<common::LabeledCloud> noisy(clean.begin(), clean.end());
    for (std::size_t i = 0; i < noisy.size(); ++i) {
      flip_labels(noisy[i], fraction, 1, params.num_classes, seed + i);
    }
    for (const mapping::MapMethod method : {mapping::MapMethod::kBki, mapping::MapMethod::kCsm}) {
      mapping::MapParams p = params;
      p.method = method;
      mapping::SemanticMap map(p);
      for (const auto& scan : noisy) map.insert(scan, scan.origin);
      NoiseResult row{fraction, method, score_map(map, clean), 0.0};
      row.mean_iou = row.confusion.mean_iou(classes);
      rows.push_back(std::move(row));
    }
  }
  return rows;
}

}  // namespace semap::map_io
