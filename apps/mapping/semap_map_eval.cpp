// semap-map-eval: label-noise robustness of S-BKI against S-CSM. Flips a fraction of the
// scans' labels, builds both maps from the noisy scans, queries them at every scan point and
// prints the mIoU against the clean labels per noise level. With --soft: a simulated,
// calibrated noisy segmenter instead (see soft_label_noise), and the mIoU of the maps built
// from its argmax (hard) labels against those built from its probabilities (soft labels).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <span>
#include <string>
#include <vector>

#include "map_options.hpp"
#include "semap/common/logging.hpp"
#include "semap/map_io/evaluation.hpp"
#include "semap/map_io/label_noise.hpp"
#include "semap/map_io/pcd_io.hpp"
#include "semap/mapping/semantic_map.hpp"

namespace {

using namespace semap::map_io;
using namespace semap::mapping;

void print_label_noise(std::span<const semap::common::LabeledCloud> clean, const MapParams& base,
                       std::span<const double> noise, std::uint64_t seed) {
  std::printf("%-6s %-5s %8s", "noise", "map", "mIoU");
  for (int c = 1; c < base.num_classes; ++c) std::printf("  IoU_%-3d", c);
  std::printf("  %8s\n", "unknown");
  for (const NoiseResult& row : evaluate_label_noise(clean, base, noise, seed)) {
    std::uint64_t unknown = 0;
    std::printf("%-6.2f %-5s %8.4f", row.noise, to_string(row.method).c_str(), row.mean_iou);
    for (int c = 1; c < base.num_classes; ++c) {
      std::printf("  %7.4f", row.confusion.iou(c));
      unknown += row.confusion.count(c, -1);
    }
    std::printf("  %8.4f\n",
                static_cast<double>(unknown) / static_cast<double>(row.confusion.total()));
  }
}

void print_soft_labels(std::span<const semap::common::LabeledCloud> clean, const MapParams& base,
                       std::span<const double> errors, std::uint64_t seed) {
  std::printf("%-7s %8s %8s %8s  %8s %8s  %8s %8s\n", "target", "sigma", "margin", "error",
              "bki_hard", "bki_soft", "csm_hard", "csm_soft");
  for (const SoftLabelResult& row : evaluate_soft_labels(clean, base, errors, seed)) {
    std::printf("%-7.3f %8.4f %8.4f %8.4f  %8.4f %8.4f  %8.4f %8.4f\n", row.target_error,
                row.noise.sigma, row.noise.margin, row.error, row.bki_hard, row.bki_soft,
                row.csm_hard, row.csm_soft);
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"mIoU of S-BKI and S-CSM maps under label noise"};
  semap::apps::MapOptions options;
  std::vector<double> noise{0.0, 0.3, 0.5};
  std::vector<double> soft_errors{0.001, 0.1, 0.3, 0.5};
  bool soft = false;
  std::uint64_t seed = 1;
  std::vector<std::string> scans;
  semap::apps::add_map_options(app, options);
  // One comma-separated value each, so that the scans after them stay positional.
  app.add_option("--noise", noise, "fractions of flipped labels")
      ->delimiter(',')
      ->allow_extra_args(false);
  app.add_flag("--soft", soft, "soft-vs-hard study with a simulated calibrated segmenter");
  app.add_option("--soft-error", soft_errors, "argmax error rates of the segmenter (--soft)")
      ->delimiter(',')
      ->allow_extra_args(false);
  app.add_option("--seed", seed, "random seed of the label noise");
  app.add_option("scans", scans, "labelled PCD scans")->required();
  CLI11_PARSE(app, argc, argv);
  semap::common::setup_logging("warn");
  try {
    const MapParams base = semap::apps::resolve_map_params(app, options);
    std::vector<semap::common::LabeledCloud> clean;
    for (const auto& path : scans) clean.push_back(read_pcd(path).cloud);
    if (soft) {
      print_soft_labels(clean, base, soft_errors, seed);
    } else {
      print_label_noise(clean, base, noise, seed);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "semap-map-eval: %s\n", e.what());
    return 1;
  }
  return 0;
}
