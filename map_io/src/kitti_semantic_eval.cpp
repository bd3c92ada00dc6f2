#include "semap/map_io/kitti_semantic_eval.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <chrono>
#include <deque>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <utility>

#include "semap/map_io/label_noise.hpp"
#include "semap/mapping/block_log.hpp"
#include "semap/mapping/map_checkpoint.hpp"

namespace semap::map_io {

namespace {

// A scan kept until its maps are queried: world points and true classes.
struct PendingScan {
  std::vector<Eigen::Vector3f> points;
  std::vector<std::uint16_t> truth;
};

// SemanticKITTI's benchmark ignores unlabelled points; mapping::ConfusionMatrix ignores truth -1.
int scored_truth(std::uint16_t truth) { return truth == 0 ? -1 : truth; }

mapping::ConfusionMatrix score_map_at(const mapping::SemanticMap& map, const PendingScan& scan) {
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, scan.points.size(), 4096),
      mapping::ConfusionMatrix(kKittiClasses),
      [&](const tbb::blocked_range<std::size_t>& range, mapping::ConfusionMatrix m) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
          m.add(scored_truth(scan.truth[i]), map.label_at(scan.points[i]));
        }
        return m;
      },
      [](mapping::ConfusionMatrix a, const mapping::ConfusionMatrix& b) {
        a.merge(b);
        return a;
      });
}

// The segmenter's labels of scan `index` through the learning map, one per point.
std::vector<std::uint16_t> predicted_labels(const std::filesystem::path& folder, std::size_t index,
                                            std::size_t points) {
  const auto path = folder / kitti_frame_name(index, ".label");
  const std::vector<std::uint32_t> raw = read_kitti_labels(path);
  if (raw.size() != points) {
    throw KittiError(path.string() + ": " + std::to_string(raw.size()) + " labels for " +
                     std::to_string(points) + " points in the scan");
  }
  std::vector<std::uint16_t> labels(raw.size());
  for (std::size_t i = 0; i < raw.size(); ++i) labels[i] = kitti_learning_map(raw[i]);
  return labels;
}

// The ground truth with `fraction` of its labelled points flipped to another class 1..19.
std::vector<std::uint16_t> flipped_truth(const std::vector<std::uint16_t>& truth, double fraction,
                                         std::uint64_t seed, std::size_t& flipped) {
  common::LabeledCloud labelled;
  for (const std::uint16_t label : truth) {
    if (label != 0) labelled.labels.push_back(label);
  }
  flipped += flip_labels(labelled, fraction, 1, kKittiClasses, seed);
  std::vector<std::uint16_t> labels = truth;
  std::size_t next = 0;
  for (std::uint16_t& label : labels) {
    if (label != 0) label = labelled.labels[next++];
  }
  return labels;
}

void check(const KittiSemanticConfig& config) {
  config.params.validate_semantic();
  if (config.params.num_classes != kKittiClasses) {
    throw std::invalid_argument("SemanticKITTI maps need num_classes 20, not " +
                                std::to_string(config.params.num_classes));
  }
  if (config.methods.empty()) throw std::invalid_argument("no map method to evaluate");
  for (const mapping::MapMethod method : config.methods) {
    if (method == mapping::MapMethod::kLogOdds) {
      throw std::invalid_argument("the SemanticKITTI evaluation runs S-BKI and S-CSM only");
    }
  }
  if (!(config.flip_fraction >= 0.0 && config.flip_fraction <= 1.0)) {
    throw std::invalid_argument("flip fraction must be in [0, 1]");
  }
  if (!(config.memory_radius_m >= 0.0)) {
    throw std::invalid_argument("memory radius must be >= 0 m");
  }
  if (config.memory_radius_m > 0.0 && config.page_dir.empty()) {
    throw std::invalid_argument("a memory radius needs a folder for the block logs");
  }
}

}  // namespace

mapping::MapParams kitti_semantic_params() {
  mapping::MapParams p;
  p.resolution = 0.1f;
  // Storage only (maps are the same for any depth): with ell 0.3 on LiDAR scans, 4^3-cell
  // blocks insert faster and allocate half the cells of 8^3 ones (docs/kitti.md).
  p.block_depth = 3;
  p.num_classes = kKittiClasses;
  p.sf2 = 0.1f;
  p.ell = 0.3f;
  p.prior = 0.001f;
  p.free_res = 100.0f;
  p.ds_res = 0.1f;
  p.max_range = -1.0f;
  return p;
}

KittiSemanticResult evaluate_kitti_semantic(
    const std::filesystem::path& folder, const KittiSemanticConfig& config,
    const std::function<void(std::size_t, std::size_t)>& progress) {
  check(config);
  const KittiSequence sequence(folder);
  if (sequence.size() == 0) throw KittiError((folder / "poses.txt").string() + ": no poses");
  const std::size_t last = std::min(config.last.value_or(sequence.size() - 1), sequence.size() - 1);
  if (config.first > last) {
    throw std::invalid_argument("scan range " + std::to_string(config.first) + ".." +
                                std::to_string(last) + " is empty (" +
                                std::to_string(sequence.size()) + " poses)");
  }
  KittiSemanticResult result;
  std::vector<mapping::SemanticMap> maps;
  for (const mapping::MapMethod method : config.methods) {
    mapping::MapParams p = config.params;
    p.method = method;
    maps.emplace_back(p);
    result.maps.push_back(KittiMapResult{method, mapping::ConfusionMatrix(kKittiClasses), {}, {}});
  }
  // Built once the maps stop moving in their vector: pagers hold references to them.
  std::vector<std::unique_ptr<mapping::BlockLog>> logs;
  std::vector<std::unique_ptr<mapping::MapPager>> pagers;
  if (config.memory_radius_m > 0.0) {
    std::filesystem::create_directories(config.page_dir);
    for (mapping::SemanticMap& map : maps) {
      const auto path = config.page_dir / (mapping::to_string(map.params().method) + ".log");
      std::filesystem::remove(path);
      logs.push_back(std::make_unique<mapping::BlockLog>(path, map.params(), false));
      pagers.push_back(
          std::make_unique<mapping::MapPager>(map, *logs.back(), config.memory_radius_m));
    }
  }
  std::deque<PendingScan> pending;
  const auto score_oldest = [&] {
    for (std::size_t m = 0; m < maps.size(); ++m) {
      result.maps[m].confusion.merge(score_map_at(maps[m], pending.front()));
    }
    pending.pop_front();
  };
  const std::size_t total = last - config.first + 1;
  for (std::size_t index = config.first; index <= last; ++index) {
    common::LabeledCloud cloud;
    std::vector<std::uint16_t> input;
    try {
      cloud = sequence.scan(index);
      input = config.predictions.empty()
                  ? flipped_truth(cloud.labels, config.flip_fraction, config.seed + index,
                                  result.flipped_labels)
                  : predicted_labels(config.predictions, index, cloud.size());
    } catch (const KittiError& e) {
      result.bad_scans.emplace_back(e.what());
      if (progress) progress(index - config.first + 1, total);
      continue;
    }
    // The maps take the labelled points; the input row scores every point.
    common::LabeledCloud mappable;
    mappable.num_classes = kKittiClasses;
    mappable.origin = cloud.origin;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      result.input.add(scored_truth(cloud.labels[i]), input[i]);
      result.unscored_points += cloud.labels[i] == 0 ? 1 : 0;
      if (input[i] == 0) {
        ++result.unlabeled_inputs;
        continue;
      }
      mappable.points.push_back(cloud.points[i]);
      mappable.labels.push_back(input[i]);
    }
    for (std::size_t m = 0; m < maps.size(); ++m) {
      if (!pagers.empty()) pagers[m]->update(mappable.origin);
      const auto start = std::chrono::steady_clock::now();
      const mapping::InsertResult inserted = maps[m].insert(mappable, mappable.origin);
      result.maps[m].insert_seconds.push_back(
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
      if (!pagers.empty()) pagers[m]->after_insert(inserted);
    }
    ++result.scans;
    result.points += cloud.size();
    pending.push_back({std::move(cloud.points), std::move(cloud.labels)});
    if (pending.size() > config.query_lag) score_oldest();
    if (progress) progress(index - config.first + 1, total);
  }
  while (!pending.empty()) score_oldest();
  for (std::size_t m = 0; m < maps.size(); ++m) {
    result.maps[m].stats = maps[m].stats();
    if (!pagers.empty()) {
      result.maps[m].paged_out = pagers[m]->stats().evicted;
      result.maps[m].paged_in = pagers[m]->stats().restored;
    }
  }
  return result;
}

}  // namespace semap::map_io
