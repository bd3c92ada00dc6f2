#pragma once

// semap-map --method logodds: the log-odds semantic map (Yue et al.) built from the same scans
// and flags as S-BKI (resolution, block depth, classes, max range), with the same outputs.
#include <chrono>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "semap/map_io/map_export.hpp"
#include "semap/mapping/logodds_map.hpp"
#include "semap/mapping/map_params.hpp"
#include "semap/mapping/smap_io.hpp"

namespace semap::apps {

struct LogOddsRun {
  std::string out_voxels;  // CSV x,y,z,label of occupied cell centres
  std::string query_out;   // class (or -1 where not occupied) at every input point
  std::string save_path;   // .smap
  mapping::SourceId robot = 1;
};

// The S-BKI parameters as a log-odds map's: the same grid and classes, the S-BKI max range
// (when set) as the log-odds one.
inline mapping::MapParams logodds_params(const mapping::MapParams& bki) {
  mapping::MapParams p = bki;
  p.method = mapping::MapMethod::kLogOdds;
  if (bki.max_range > 0.0f) p.logodds.max_range = bki.max_range;
  return p;
}

inline void run_logodds(const mapping::MapParams& params,
                        const std::vector<common::LabeledCloud>& clouds, const LogOddsRun& run) {
  mapping::LogOddsMap map(logodds_params(params), run.robot);
  const auto start = std::chrono::steady_clock::now();
  std::size_t rejected = 0;
  for (const auto& cloud : clouds) rejected += map.insert(cloud).rejected;
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const auto cells = map_io::occupied_cells(map.layers());
  if (!run.out_voxels.empty()) {
    std::ofstream out(run.out_voxels);
    if (!out) throw std::runtime_error(run.out_voxels + ": cannot create");
    out << "x,y,z,label\n";
    for (const auto& c : cells) {
      out << c.centre.x() << ',' << c.centre.y() << ',' << c.centre.z() << ',' << c.label << '\n';
    }
  }
  if (!run.query_out.empty()) {
    std::ofstream out(run.query_out);
    if (!out) throw std::runtime_error(run.query_out + ": cannot create");
    for (const auto& cloud : clouds) {
      for (const auto& p : cloud.points) {
        const auto s = map.summary_at(p.cast<double>());
        out << (s.known && s.occupied ? s.label : -1) << '\n';
      }
    }
  }
  if (!run.save_path.empty()) mapping::write_smap(run.save_path, map.layers());
  std::printf(
      "method logodds\nscans %zu\nrejected_points %zu\nblocks %zu\noccupied_cells %zu\n"
      "insert_seconds %.6f\n",
      clouds.size(), rejected, map.layers().resident_blocks(), cells.size(), seconds);
}

}  // namespace semap::apps
