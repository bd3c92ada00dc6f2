// semap-map: builds an S-BKI or S-CSM map from PCD scans, writes occupied voxels and the
// map's class at every input point, and prints the insertion time.
#include <tbb/global_control.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <exception>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "semap/common/config.hpp"
#include "semap/common/logging.hpp"
#include "semap/mapping/map_params.hpp"
#include "semap/mapping/pcd_io.hpp"
#include "semap/mapping/semantic_map.hpp"

namespace {

using semap::mapping::MapParams;

// Config file values first, then flags given on the command line override them.
MapParams resolve_params(const CLI::App& app, const std::string& config_path,
                         const MapParams& flags) {
  MapParams p;
  if (!config_path.empty()) {
    const auto root = semap::common::ConfigSection::load_file(config_path);
    const auto section = root.has("map") ? root.section("map") : root;
    p = semap::mapping::map_params_from_config(section, p);
    section.finish();
    root.finish();
  }
  auto given = [&](const char* flag) { return app.count(flag) > 0; };
  if (given("--method")) p.method = flags.method;
  if (given("--resolution")) p.resolution = flags.resolution;
  if (given("--block-depth")) p.block_depth = flags.block_depth;
  if (given("--num-classes")) p.num_classes = flags.num_classes;
  if (given("--sf2")) p.sf2 = flags.sf2;
  if (given("--ell")) p.ell = flags.ell;
  if (given("--prior")) p.prior = flags.prior;
  if (given("--free-res")) p.free_res = flags.free_res;
  if (given("--ds-res")) p.ds_res = flags.ds_res;
  if (given("--max-range")) p.max_range = flags.max_range;
  if (given("--unknown-variance")) p.unknown_variance = flags.unknown_variance;
  p.validate();
  return p;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Build a semantic map (S-BKI or S-CSM) from labelled PCD scans"};
  MapParams flags;
  std::string method = "bki";
  int threads = 0;
  std::string out_voxels, query_out, config_path, log_level = "warn";
  std::vector<std::string> scans;
  app.add_option("--method", method, "bki or csm")->check(CLI::IsMember({"bki", "csm"}));
  app.add_option("--resolution", flags.resolution, "cell size, m");
  app.add_option("--block-depth", flags.block_depth, "block holds (2^(depth-1))^3 cells");
  app.add_option("--num-classes", flags.num_classes, "K, class 0 = free");
  app.add_option("--sf2", flags.sf2, "kernel scale");
  app.add_option("--ell", flags.ell, "kernel length scale, m");
  app.add_option("--prior", flags.prior, "Dirichlet prior per class");
  app.add_option("--free-res", flags.free_res, "free-space sample spacing, m");
  app.add_option("--ds-res", flags.ds_res, "training-data downsampling voxel, m");
  app.add_option("--max-range", flags.max_range, "drop hits farther than this, m (<= 0: keep)");
  app.add_option("--unknown-variance", flags.unknown_variance,
                 "report cells unknown above this argmax variance (0: off)");
  app.add_option("--threads", threads, "worker threads (default: all cores)");
  app.add_option("--out-voxels", out_voxels, "CSV x,y,z,label of occupied cell centres");
  app.add_option("--query-out", query_out, "map class (or -1) at every input point");
  app.add_option("--config", config_path, "YAML with map parameters (flags override)");
  app.add_option("--log-level", log_level, "trace..off");
  app.add_option("scans", scans, "PCD scans, inserted in order")->required();
  CLI11_PARSE(app, argc, argv);
  semap::common::setup_logging(log_level);

  try {
    flags.method = semap::mapping::method_from_string(method);
    const MapParams params = resolve_params(app, config_path, flags);
    std::unique_ptr<tbb::global_control> limit;
    if (threads > 0) {
      limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                    static_cast<std::size_t>(threads));
    }
    std::vector<semap::common::LabeledCloud> clouds;
    for (const auto& path : scans) clouds.push_back(semap::mapping::read_pcd(path).cloud);

    semap::mapping::SemanticMap map(params);
    std::size_t rejected = 0;
    const auto start = std::chrono::steady_clock::now();
    for (const auto& cloud : clouds) rejected += map.insert(cloud, cloud.origin).rejected_points;
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    if (!out_voxels.empty()) {
      std::ofstream out(out_voxels);
      if (!out) throw std::runtime_error(out_voxels + ": cannot create");
      out << "x,y,z,label\n";
      map.for_each_cell([&](const Eigen::Vector3f& c, const semap::mapping::CellPosterior& cell) {
        if (cell.state(params.unknown_variance) == semap::mapping::CellState::kOccupied) {
          out << c.x() << ',' << c.y() << ',' << c.z() << ',' << cell.argmax() << '\n';
        }
      });
    }
    if (!query_out.empty()) {
      std::ofstream out(query_out);
      if (!out) throw std::runtime_error(query_out + ": cannot create");
      for (const auto& cloud : clouds) {
        for (const auto& p : cloud.points) out << map.label_at(p) << '\n';
      }
    }
    const auto stats = map.stats();
    std::printf("method %s\nscans %zu\nrejected_points %zu\nblocks %zu\ncells %zu\n",
                semap::mapping::to_string(params.method).c_str(), clouds.size(), rejected,
                stats.blocks, stats.cells);
    std::printf("observed_cells %zu\nbytes_per_cell %.2f\n", stats.observed_cells,
                stats.bytes_per_cell());
    std::printf("insert_seconds %.6f\n", seconds);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "semap-map: %s\n", e.what());
    return 1;
  }
  return 0;
}
