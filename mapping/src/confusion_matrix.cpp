#include "semap/mapping/confusion_matrix.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace semap::mapping {

namespace {

int checked_class_count(int num_classes) {
  if (num_classes < 1) throw std::invalid_argument("confusion matrix needs at least one class");
  return num_classes;
}

}  // namespace

ConfusionMatrix::ConfusionMatrix(int num_classes)
    : k_(checked_class_count(num_classes)),
      counts_(static_cast<std::size_t>(k_) * static_cast<std::size_t>(k_ + 1), 0) {}

std::size_t ConfusionMatrix::cell(int truth, int predicted) const {
  const int column = (predicted < 0 || predicted >= k_) ? k_ : predicted;
  return static_cast<std::size_t>(truth) * static_cast<std::size_t>(k_ + 1) +
         static_cast<std::size_t>(column);
}

void ConfusionMatrix::add(int truth, int predicted, std::uint64_t n) {
  if (truth < 0 || truth >= k_) return;
  counts_[cell(truth, predicted)] += n;
  total_ += n;
}

void ConfusionMatrix::merge(const ConfusionMatrix& other) {
  if (other.k_ != k_) throw std::invalid_argument("confusion matrices differ in class count");
  for (std::size_t i = 0; i < counts_.size(); ++i) counts_[i] += other.counts_[i];
  total_ += other.total_;
}

std::uint64_t ConfusionMatrix::count(int truth, int predicted) const {
  return counts_[cell(truth, predicted)];
}

std::uint64_t ConfusionMatrix::truth_count(int c) const {
  const auto row = counts_.begin() + static_cast<std::ptrdiff_t>(cell(c, 0));
  return std::accumulate(row, row + k_ + 1, std::uint64_t{0});
}

ConfusionMatrix ConfusionMatrix::without_true_class(int c) const {
  ConfusionMatrix out = *this;
  out.total_ -= truth_count(c);
  const auto row = out.counts_.begin() + static_cast<std::ptrdiff_t>(cell(c, 0));
  std::fill(row, row + k_ + 1, std::uint64_t{0});
  return out;
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

double ConfusionMatrix::iou_if_present(int c) const {
  return truth_count(c) > 0 ? iou(c) : std::numeric_limits<double>::quiet_NaN();
}

double ConfusionMatrix::mean_iou_of_present(int first_class) const {
  std::vector<int> present;
  for (int c = first_class; c < k_; ++c) {
    if (truth_count(c) > 0) present.push_back(c);
  }
  return mean_iou(present);
}

}  // namespace semap::mapping
