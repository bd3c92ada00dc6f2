#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "semap/map_io/evaluation.hpp"
#include "semap/map_io/semantic_kitti_io.hpp"
#include "semap/mapping/semantic_map.hpp"

namespace semap::map_io {

// The map parameters of Gan et al. for SemanticKITTI: resolution 0.1 m, ell 0.3 m, sf2 0.1
// (their Table I as issue 19 quotes it), prior 0.001, no free samples along the beams
// (free_res 100 m, as their semantickitti.yaml) and no range limit; ds_res 0.1 m (theirs
// keeps every point; ours needs a voxel, one cell keeps about one point per cell); K = 20.
mapping::MapParams kitti_semantic_params();

// What evaluate_kitti_semantic runs.
struct KittiSemanticConfig {
  mapping::MapParams params = kitti_semantic_params();  // method replaced per map
  std::vector<mapping::MapMethod> methods{mapping::MapMethod::kCsm, mapping::MapMethod::kBki};
  // A folder of NNNNNN.label files in SemanticKITTI's format (a segmenter's output); empty:
  // the ground truth with flip_fraction of its labelled points flipped to another class.
  std::filesystem::path predictions;
  double flip_fraction = 0.3;
  std::uint64_t seed = 1;  // flips of scan i use seed + i
  std::size_t first = 0;   // scans first..last of poses.txt, both included
  std::optional<std::size_t> last;
  // Scan i is scored in the map that also holds scans i+1..i+lag (the reference
  // implementation queries each scan again after each of the next 10 inserts; the last query
  // counts). Scans within lag of the end are scored in the final map.
  std::size_t query_lag = 10;
  // > 0: each map pages like the robot's (map.memory_radius_m, mapping::MapPager): before each
  // insert, blocks farther than this from the scan's origin go to a block log in page_dir
  // (<method>.log, created, not synced) and come back when the car returns. Points scored while
  // their blocks are paged out count as unknown to the map.
  double memory_radius_m = 0.0;
  std::filesystem::path page_dir;
};

// One map's figures.
struct KittiMapResult {
  mapping::MapMethod method = mapping::MapMethod::kBki;
  mapping::ConfusionMatrix confusion{kKittiClasses};
  std::vector<double> insert_seconds;  // per inserted scan: training set and fusion
  mapping::MapStats stats;
  std::uint64_t paged_out = 0;  // blocks evicted to the log over the run (memory_radius_m)
  std::uint64_t paged_in = 0;   // and brought back
};

struct KittiSemanticResult {
  mapping::ConfusionMatrix input{kKittiClasses};  // the labels the maps were built from
  std::vector<KittiMapResult> maps;               // in config.methods' order
  std::size_t scans = 0;                          // read, inserted and scored
  std::size_t points = 0;                         // in those scans
  std::size_t unscored_points = 0;                // ground truth unlabelled (class 0): not scored
  std::size_t unlabeled_inputs = 0;  // input label 0: not inserted (class 0 is free space)
  std::size_t flipped_labels = 0;
  std::vector<std::string> bad_scans;  // scans skipped, one message each naming the file
};

// Reads scans first..last of the sequence folder (velodyne/, labels/, poses.txt, calib.txt)
// one at a time, inserts each into one map per method and scores the input labels and the
// maps at every point against the ground truth (map queries as query_lag says; a point the
// map knows nothing of, or calls free, is a miss). At most query_lag + 1 scans are held, so
// memory is the maps plus a bounded window. A scan whose files are missing or malformed is
// skipped and its KittiError kept in bad_scans. Calls progress(scans handled, scans in range)
// after each scan. Throws KittiError for an unreadable poses.txt or calib.txt and
// std::invalid_argument for a bad configuration.
KittiSemanticResult evaluate_kitti_semantic(
    const std::filesystem::path& sequence, const KittiSemanticConfig& config,
    const std::function<void(std::size_t, std::size_t)>& progress = {});

}  // namespace semap::map_io
