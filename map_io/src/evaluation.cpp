#include "semap/map_io/evaluation.hpp"

#include <numeric>

#include "semap/map_io/label_noise.hpp"

namespace semap::map_io {

mapping::ConfusionMatrix score_map(const mapping::SemanticMap& map,
                                   std::span<const common::LabeledCloud> scans) {
  mapping::ConfusionMatrix m(map.params().num_classes);
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
