#include "semap/mapping/semantic_map.hpp"

#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "semap/mapping/bki_update.hpp"
#include "tile_inserter.hpp"

namespace semap::mapping {

SemanticMap::SemanticMap(const MapParams& params, SourceId robot)
    : params_((params.validate_semantic(), params)),
      layers_(params),
      robot_(robot),
      grid_(&layers_.layer(robot)),
      inserter_(std::make_unique<detail::TileInserter>(params)) {}

SemanticMap::~SemanticMap() = default;
SemanticMap::SemanticMap(SemanticMap&&) noexcept = default;
SemanticMap& SemanticMap::operator=(SemanticMap&&) noexcept = default;

namespace {

// The training set of a scan and the wall time its build took.
struct TimedTraining {
  TrainingSet training;
  double seconds = 0;
};

TimedTraining build_timed(const common::LabeledCloud& cloud, const Eigen::Vector3f& origin,
                          const MapParams& params) {
  const auto start = std::chrono::steady_clock::now();
  TimedTraining built{build_training_set(cloud, origin, params)};
  built.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return built;
}

}  // namespace

InsertResult SemanticMap::insert(const common::LabeledCloud& cloud, const Eigen::Vector3f& origin) {
  const TimedTraining built = build_timed(cloud, origin, params_);
  InsertResult result = fuse_scan(built.training, nullptr);
  result.phases.training = built.seconds;
  return result;
}

std::vector<InsertResult> SemanticMap::insert(std::span<const common::LabeledCloud> clouds,
                                              std::span<const Eigen::Vector3f> origins) {
  if (clouds.size() != origins.size()) {
    throw std::invalid_argument(std::to_string(clouds.size()) + " clouds but " +
                                std::to_string(origins.size()) + " origins");
  }
  // A scan's training set and tile plan (neither depends on the map), or the exception the
  // build threw: kept until the serial stage reaches that scan, so the scans before it are
  // fused first.
  struct Prepared {
    TimedTraining timed;
    detail::TilePlan plan;
    std::exception_ptr error;
  };
  // Every Prepared object, owned here; the pipeline passes plain pointers between its stages
  // (TBB's own copies of a non-trivial item would outlive the pipeline). A fused scan's object
  // goes back to `spare` for reuse, so its plan's buffers are not reallocated.
  std::mutex pool_mutex;
  std::vector<std::unique_ptr<Prepared>> pool;
  std::vector<Prepared*> spare;
  std::vector<InsertResult> results;
  results.reserve(clouds.size());
  std::size_t next = 0;
  // One scan in the serial stage and one being prepared per further thread; more would only
  // hold training sets in memory (the order of fusion, hence the map, does not depend on it).
  const auto scans_in_flight =
      static_cast<std::size_t>(tbb::this_task_arena::max_concurrency()) + 1;
  tbb::parallel_pipeline(
      scans_in_flight,
      tbb::make_filter<void, std::size_t>(tbb::filter_mode::serial_in_order,
                                          [&](tbb::flow_control& control) -> std::size_t {
                                            if (next == clouds.size()) {
                                              control.stop();
                                              return 0;
                                            }
                                            return next++;
                                          }) &
          tbb::make_filter<std::size_t, Prepared*>(
              tbb::filter_mode::parallel,
              [&](std::size_t scan) {
                Prepared* prepared = nullptr;
                {
                  std::lock_guard lock(pool_mutex);
                  if (spare.empty()) {
                    pool.push_back(std::make_unique<Prepared>());
                    prepared = pool.back().get();
                  } else {
                    prepared = spare.back();
                    spare.pop_back();
                  }
                }
                try {
                  prepared->timed = build_timed(clouds[scan], origins[scan], params_);
                  if (params_.engine == Engine::kTiled) {
                    inserter_->plan(prepared->timed.training, prepared->plan);
                  }
                } catch (...) {
                  prepared->error = std::current_exception();
                }
                return prepared;
              }) &
          tbb::make_filter<Prepared*, void>(
              tbb::filter_mode::serial_in_order, [&](Prepared* prepared) {
                if (prepared->error) std::rethrow_exception(prepared->error);
                results.push_back(
                    fuse_scan(prepared->timed.training,
                              params_.engine == Engine::kTiled ? &prepared->plan : nullptr));
                results.back().phases.training = prepared->timed.seconds;
                std::lock_guard lock(pool_mutex);
                spare.push_back(prepared);
              }));
  return results;
}

InsertResult SemanticMap::insert(const TrainingSet& training) { return fuse(training, nullptr); }

InsertResult SemanticMap::fuse_scan(const TrainingSet& training, detail::TilePlan* plan) {
  InsertResult result = fuse(training, plan);
  result.rejected_points += training.rejected;
  result.out_of_range = training.out_of_range;
  rejected_ += training.rejected;
  return result;
}

InsertResult SemanticMap::fuse(const TrainingSet& training, detail::TilePlan* plan) {
  if (training.num_classes != params_.num_classes) {
    throw std::invalid_argument("training set has " + std::to_string(training.num_classes) +
                                " classes, map has " + std::to_string(params_.num_classes));
  }
  InsertResult result;
  result.training_points = training.size();
  result.hits = training.num_hits;
  const BlockAt block_at = [this](const common::BlockIndex& index) -> Block& {
    return grid_->block_at(index);
  };
  const detail::BlockFind find = [this](const common::BlockIndex& index) {
    return grid_->find_block(index);
  };
  if (params_.engine == Engine::kPlain) {
    const auto start = std::chrono::steady_clock::now();
    UpdateResult updated = plain_update(training, params_, block_at);
    result.phases.scatter =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    result.rejected_points = updated.rejected_points;
    result.updated_blocks = std::move(updated.updated_blocks);
  } else {
    detail::TileInsertResult fused = plan != nullptr
                                         ? inserter_->apply(*plan, training, block_at, find)
                                         : inserter_->insert(training, block_at, find);
    result.rejected_points = fused.rejected_points;
    result.phases = fused.phases;
    result.updated_blocks = std::move(fused.updated_blocks);
  }
  rejected_ += result.rejected_points;
  result.blocks_updated = result.updated_blocks.size();
  grid_->set_updates(grid_->updates() + 1);
  return result;
}

common::BlockIndex SemanticMap::block_of(const Eigen::Vector3f& point) const {
  return params_.grid().block_of(point);
}

Eigen::Vector3f SemanticMap::cell_center(const common::BlockIndex& block, int cell) const {
  const common::MapGrid grid = params_.grid();
  return grid.cell_centre(grid.cell_of_local(block, cell));
}

std::optional<CellReading> SemanticMap::query(const Eigen::Vector3f& point) const {
  if (!detail::mappable(point, 1.0f / params_.resolution)) return std::nullopt;
  const common::MapGrid grid = params_.grid();
  const common::CellIndex cell = grid.cell_of(point);
  const common::BlockIndex index = grid.block_of(cell);
  const Block* block = find_block(index);
  if (block == nullptr) return std::nullopt;
  const int c = grid.local_index(cell, index);
  std::vector<float> evidence(static_cast<std::size_t>(block->channels()));
  block->read_cell(c, evidence);
  return CellReading(std::move(evidence), params_.prior, block->observed(c));
}

int SemanticMap::label_at(const Eigen::Vector3f& point) const {
  const auto cell = query(point);
  return cell ? cell->label(params_.unknown_variance) : -1;
}

MapStats SemanticMap::stats() const {
  MapStats s;
  s.blocks = grid_->size();
  s.evicted_blocks = grid_->evicted();
  s.scans = scans();
  s.rejected_points = rejected_;
  s.bytes = grid_->bytes();
  for_each_block([&](const common::BlockIndex&, const Block& block) {
    s.cells += static_cast<std::size_t>(block.num_cells());
    s.observed_cells += static_cast<std::size_t>(block.num_observed());
  });
  return s;
}

}  // namespace semap::mapping
