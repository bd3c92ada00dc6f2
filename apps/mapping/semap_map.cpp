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

#include "logodds_mode.hpp"
#include "map_options.hpp"
#include "semap/common/logging.hpp"
#include "semap/map_io/pcd_io.hpp"
#include "semap/mapping/map_params.hpp"
#include "semap/mapping/semantic_map.hpp"

int main(int argc, char** argv) {
  CLI::App app{"Build a semantic map (S-BKI or S-CSM) from labelled PCD scans"};
  semap::apps::MapOptions options;
  int threads = 0;
  std::string out_voxels, query_out, log_level = "warn";
  std::vector<std::string> scans;
  semap::apps::add_map_options(app, options);
  app.add_option("--threads", threads, "worker threads (default: all cores)");
  app.add_option("--out-voxels", out_voxels, "CSV x,y,z,label of occupied cell centres");
  app.add_option("--query-out", query_out, "map class (or -1) at every input point");
  app.add_option("--log-level", log_level, "trace..off");
  semap::apps::LogOddsRun logodds_run;
  app.add_option("--save", logodds_run.save_path, "write the map as .smap (any method)");
  app.add_option("--robot-id", logodds_run.robot, "source id of this robot's evidence in .smap");
  app.add_option("scans", scans, "PCD scans, inserted in order")->required();
  CLI11_PARSE(app, argc, argv);
  semap::common::setup_logging(log_level);

  try {
    // The log-odds map reads the shared grid flags from the S-BKI parameters.
    const bool logodds = options.method == "logodds";
    if (logodds) options.method = "bki";
    const semap::mapping::MapParams params = semap::apps::resolve_map_params(app, options);
    std::unique_ptr<tbb::global_control> limit;
    if (threads > 0) {
      limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                    static_cast<std::size_t>(threads));
    }
    std::vector<semap::common::LabeledCloud> clouds;
    for (const auto& path : scans) clouds.push_back(semap::map_io::read_pcd(path).cloud);

    if (logodds) {
      logodds_run.out_voxels = out_voxels;
      logodds_run.query_out = query_out;
      semap::apps::run_logodds(params, clouds, logodds_run);
      return 0;
    }
    semap::mapping::SemanticMap map(params, logodds_run.robot);
    std::vector<Eigen::Vector3f> origins;
    for (const auto& cloud : clouds) origins.push_back(cloud.origin);
    std::size_t rejected = 0;
    const auto start = std::chrono::steady_clock::now();
    // In the order given; the batch builds the next scans' training sets while one is fused.
    for (const auto& result : map.insert(clouds, origins)) rejected += result.rejected_points;
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    if (!out_voxels.empty()) {
      std::ofstream out(out_voxels);
      if (!out) throw std::runtime_error(out_voxels + ": cannot create");
      out << "x,y,z,label\n";
      map.for_each_cell([&](const Eigen::Vector3f& c, const semap::common::CellPosterior& cell) {
        if (cell.state(params.unknown_variance) == semap::common::CellState::kOccupied) {
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
    if (!logodds_run.save_path.empty()) {
      semap::mapping::write_smap(logodds_run.save_path, map.layers());
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
