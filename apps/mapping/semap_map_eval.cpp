// semap-map-eval: label-noise robustness of S-BKI against S-CSM. Flips a fraction of the
// scans' labels, builds both maps from the noisy scans, queries them at every scan point and
// prints the mIoU against the clean labels per noise level.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "map_options.hpp"
#include "semap/common/logging.hpp"
#include "semap/mapping/evaluation.hpp"
#include "semap/mapping/pcd_io.hpp"
#include "semap/mapping/semantic_map.hpp"

int main(int argc, char** argv) {
  using namespace semap::mapping;
  CLI::App app{"mIoU of S-BKI and S-CSM maps under label noise"};
  semap::apps::MapOptions options;
  std::vector<double> noise{0.0, 0.3, 0.5};
  std::uint64_t seed = 1;
  std::vector<std::string> scans;
  semap::apps::add_map_options(app, options);
  app.add_option("--noise", noise, "fractions of flipped labels")->delimiter(',');
  app.add_option("--seed", seed, "random seed of the label flips");
  app.add_option("scans", scans, "labelled PCD scans")->required();
  CLI11_PARSE(app, argc, argv);
  semap::common::setup_logging("warn");
  try {
    const MapParams base = semap::apps::resolve_map_params(app, options);
    std::vector<semap::common::LabeledCloud> clean;
    for (const auto& path : scans) clean.push_back(read_pcd(path).cloud);
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
  } catch (const std::exception& e) {
    std::fprintf(stderr, "semap-map-eval: %s\n", e.what());
    return 1;
  }
  return 0;
}
