#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace semap::mapping {

// Counts of predicted against true classes over K classes, with one more column for "no
// label": a map that knows nothing at a point (label -1) or a segmenter that left a pixel
// unlabelled. A true class outside [0, K) is not counted (SemanticKITTI's unlabelled points,
// sky); a prediction outside [0, K) goes to the no-label column and is a miss of the true class.
class ConfusionMatrix {
 public:
  // The no-label column's name in count(); any prediction outside [0, K) reads it too.
  static constexpr int kNoLabel = -1;

  // Throws std::invalid_argument for fewer than one class.
  explicit ConfusionMatrix(int num_classes);

  // Counts `n` points (pixels, cells) of true class `truth` predicted as `predicted`.
  void add(int truth, int predicted, std::uint64_t n = 1);
  // Adds another matrix's counts (a thread's, a scan's); throws std::invalid_argument when
  // the class counts differ.
  void merge(const ConfusionMatrix& other);

  int num_classes() const { return k_; }
  // `truth` in [0, K).
  std::uint64_t count(int truth, int predicted) const;
  std::uint64_t total() const { return total_; }
  // Counted with true class c, whatever was predicted.
  std::uint64_t truth_count(int c) const;
  // A copy without the counts of true class c, e.g. without the true free cells of a map:
  // the errors on its surfaces alone.
  ConfusionMatrix without_true_class(int c) const;

  // TP / (TP + FP + FN); NaN when the class appears neither in truth nor in predictions.
  double iou(int c) const;
  // Mean of iou(c) over `classes`, skipping NaN entries.
  double mean_iou(std::span<const int> classes) const;

  // Scoring over the classes the truth has (truth_count(c) > 0), as the SemanticKITTI
  // benchmark averages a sequence: a class that was only ever predicted, never true, is not
  // scored. iou(c) when the truth has c, NaN otherwise.
  double iou_if_present(int c) const;
  // Mean of iou(c) over the classes c in [first_class, K) the truth has; NaN when it has none.
  double mean_iou_of_present(int first_class) const;

 private:
  std::size_t cell(int truth, int predicted) const;

  int k_;
  std::vector<std::uint64_t> counts_;  // k_ rows, k_ + 1 columns (last: no label)
  std::uint64_t total_ = 0;
};

}  // namespace semap::mapping
