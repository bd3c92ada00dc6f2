#include "semap/onboard/mapping_stage.hpp"

#include <spdlog/fmt/fmt.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <filesystem>

#include "semap/common/logging.hpp"

namespace semap::onboard {

dds_idl::MapDescription describe_map(const MappingConfig& config) {
  dds_idl::MapDescription d;
  d.resolution = config.params.resolution;
  d.block_cells = static_cast<std::uint16_t>(config.params.cells_per_side());
  d.num_classes = static_cast<std::uint16_t>(config.params.num_classes);
  d.class_names = config.palette.names;
  for (const mapping::Rgb& rgb : config.palette.colors) {
    d.class_colors.push_back(std::uint32_t{rgb[0]} << 16 | std::uint32_t{rgb[1]} << 8 | rgb[2]);
  }
  return d;
}

void to_snapshot(const mapping::SemanticMap& map, const common::BlockIndex& index,
                 const mapping::Block& block, std::uint32_t version, bool with_evidence,
                 dds_idl::BlockSnapshot& out) {
  const auto& params = map.params();
  std::vector<std::uint8_t> observed(static_cast<std::size_t>(block.num_cells()));
  for (int c = 0; c < block.num_cells(); ++c) {
    observed[static_cast<std::size_t>(c)] = block.observed(c) ? 1 : 0;
  }
  dds_idl::snapshot_of_evidence(index, params.grid(), block.channels(), block.dense(), observed,
                                params.prior, params.unknown_variance, version, with_evidence, out);
}

MappingStage::MappingStage(const MappingConfig& config,
                           common::SpscRing<common::LabeledCloud>& clouds, BlockSink sink,
                           const std::filesystem::path& checkpoint_path)
    : config_(config),
      clouds_(clouds),
      sink_(std::move(sink)),
      map_(config.params, config.robot_id) {
  if (checkpoint_path.empty() || config.checkpoint_s <= 0.0) return;
  if (checkpoint_path.has_parent_path()) {
    std::filesystem::create_directories(checkpoint_path.parent_path());
  }
  if (!config.resume && std::filesystem::exists(checkpoint_path)) {
    // A new map: the previous run's checkpoint is kept beside it, not continued or deleted.
    std::filesystem::path previous = checkpoint_path;
    previous += ".previous";
    std::filesystem::rename(checkpoint_path, previous);
    common::logger("mapping")->info("previous map checkpoint moved to {}", previous.string());
  }
  const bool paged = config.memory_radius_m > 0.0;
  checkpoint_ = std::make_unique<mapping::MapCheckpoint>(
      map_,
      mapping::CheckpointParams{
          .path = checkpoint_path, .interval_s = config.checkpoint_s, .resume = config.resume},
      !paged);
  const auto log = common::logger("mapping");
  if (!checkpoint_->damage().empty()) {
    log->warn("map checkpoint: {}; resuming from the last complete checkpoint",
              checkpoint_->damage());
  }
  if (config.resume) {
    const auto stats = checkpoint_->stats();
    log->info("map resumed from {}: {} blocks of {} scans{}", checkpoint_path.string(),
              paged ? checkpoint_->log().blocks().size() : stats.resumed_blocks,
              stats.resumed_scans, paged ? " (paged in as the robot gets near)" : "");
  }
  if (paged) {
    pager_ = std::make_unique<mapping::MapPager>(map_, checkpoint_->log(), config.memory_radius_m);
  }
  write_log_ = std::make_unique<WriteFailureLog>(
      "mapping", "map checkpoint",
      fmt::format("the log keeps its last complete checkpoint; retrying every {} s, mapping "
                  "goes on",
                  config.checkpoint_s));
  stage_.figures().checkpoint = checkpoint_->stats();
  stage_.figures().map = map_.stats();
  stage_.share();
}

dds_idl::WriterHealthData checkpoint_health(const MappingStageStats& stats,
                                            const std::filesystem::path& path) {
  const auto& c = stats.checkpoint;
  const auto& p = stats.pager;
  dds_idl::WriterHealthData h;
  h.name = "map_checkpoint";
  h.path = path.string();
  h.writes = c.checkpoints;
  // The checkpoint and the pager write the same log; a failing checkpoint says more.
  h.failures = c.write_failures + p.write_failures;
  h.failing = c.failing || p.failing;
  h.last_error = c.failing || p.last_error.empty() ? c.last_error : p.last_error;
  return h;
}

void MappingStage::note_writes() {
  if (!checkpoint_) return;
  auto& f = stage_.figures();
  f.checkpoint = checkpoint_->stats();
  if (pager_) f.pager = pager_->stats();
  const auto health = checkpoint_health(f, {});
  write_log_->update(health.failures, health.failing, health.last_error);
}

MappingStage::~MappingStage() { stop(); }

void MappingStage::start(std::vector<int> cpus) {
  stage_.start([this](std::stop_token stop) { run(stop); }, "mapping", std::move(cpus));
}

void MappingStage::stop() {
  if (stage_.stop() && checkpoint_) {
    checkpoint_->flush();
    note_writes();
    stage_.share();
  }
}

void MappingStage::record_map_frame(const mapping::MapFrame& frame) {
  if (checkpoint_ && !checkpoint_->frame()) checkpoint_->set_frame(frame);
}

const mapping::SemanticMap& MappingStage::map() {
  if (!pager_) return map_;
  if (!full_map_) {
    full_map_ = std::make_unique<mapping::SemanticMap>(config_.params, config_.robot_id);
    checkpoint_->log().load_all(*full_map_);
  }
  return *full_map_;
}

MappingStageStats MappingStage::stats() const { return stage_.stats(); }

void MappingStage::run(std::stop_token stop) {
  tbb::task_arena arena(config_.threads);
  if (config_.resume && sink_) {
    // Subscribers get the resumed map before anything new.
    // With a pager, they are all in the log: published once, then paged out of DDS too.
    std::vector<common::BlockIndex> resumed;
    if (pager_) {
      resumed = checkpoint_->log().blocks();
      sink_(resumed, resumed);
    } else {
      map_.for_each_block([&](const common::BlockIndex& index, const mapping::Block&) {
        resumed.push_back(index);
      });
      sink_(resumed, {});
    }
  }
  common::LabeledCloud cloud;
  int idle = 0;
  // Asked to stop, it first maps what the ring still holds (perception has stopped).
  while (true) {
    if (!clouds_.try_pop(cloud)) {
      if (stop.stop_requested()) break;
      if (checkpoint_) checkpoint_->poll();
      // A standing robot's checkpoint retries are reported too, about twice a second.
      if (checkpoint_ && ++idle % 500 == 0) {
        note_writes();
        stage_.share();
      }
      // Short: a cloud's wait here is part of its latency into the map.
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      continue;
    }
    arena.execute([&] { insert(cloud); });
  }
  stage_.figures().map = map_.stats();
  stage_.share();
}

void MappingStage::insert(const common::LabeledCloud& cloud) {
  // A cloud older than one already mapped was held from before the heading was known
  // (PerceptionStage): late on purpose, it would only hide the live latency.
  const bool live = cloud.stamp >= newest_mapped_;
  const auto t0 = std::chrono::steady_clock::now();
  if (live) taken_age_.record(common::seconds_between(common::Stamp::now(), cloud.stamp));
  mapping::InsertResult result;
  std::vector<common::BlockIndex> paged_out;
  std::chrono::steady_clock::time_point locked;
  {
    std::unique_lock lock(map_mutex_);
    locked = std::chrono::steady_clock::now();
    if (pager_) paged_out = pager_->update(cloud.origin);
    result = map_.insert(cloud, cloud.origin);
    if (pager_) {
      pager_->after_insert(result);
      // A block the insert reached right after its eviction is back in memory: DDS keeps it.
      std::erase_if(paged_out,
                    [&](const common::BlockIndex& i) { return map_.find_block(i) != nullptr; });
    }
    for (const auto& index : result.updated_blocks) ++versions_[index];
  }
  // The cloud's cells are in the map, readable by the publisher: what follows (the
  // checkpoint's copy, the figures, telling the publisher) delays only the next cloud.
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (live) {
    newest_mapped_ = cloud.stamp;
    latency_.record(common::seconds_between(common::Stamp::now(), cloud.stamp));
    lock_wait_.record(std::chrono::duration<double>(locked - t0).count());
  }
  if (checkpoint_) checkpoint_->after_insert(result);
  insert_time_.record(seconds);
  stage_.figures().scans++;
  stage_.figures().points += cloud.size();
  stage_.figures().blocks_changed += result.updated_blocks.size();
  stage_.figures().insert_seconds_total += seconds;
  stage_.figures().insert_seconds_max = std::max(stage_.figures().insert_seconds_max, seconds);
  // Counting the map's cells walks every block: twice a second is enough for the figures.
  if (std::chrono::steady_clock::now() - stats_taken_ >= std::chrono::milliseconds(500)) {
    stage_.figures().map = map_.stats();
    stats_taken_ = std::chrono::steady_clock::now();
  }
  note_writes();
  if (sink_) sink_(result.updated_blocks, paged_out);
  stage_.share();
}

void MappingStage::for_each_block(const std::function<void(const common::BlockIndex&)>& f) const {
  std::vector<common::BlockIndex> indices;
  {
    std::shared_lock lock(map_mutex_);
    map_.for_each_block(
        [&](const common::BlockIndex& index, const mapping::Block&) { indices.push_back(index); });
  }
  for (const auto& index : indices) f(index);
}

bool MappingStage::read(const common::BlockIndex& index, dds_idl::BlockSnapshot& out) const {
  return read_block(index, true, out);
}

bool MappingStage::read_cells(const common::BlockIndex& index, dds_idl::BlockSnapshot& out) const {
  return read_block(index, false, out);
}

bool MappingStage::read_block(const common::BlockIndex& index, bool with_evidence,
                              dds_idl::BlockSnapshot& out) const {
  std::shared_lock lock(map_mutex_);
  const auto version = versions_.find(index);
  const std::uint32_t v = version == versions_.end() ? 0 : version->second;
  if (const mapping::Block* block = map_.find_block(index)) {
    to_snapshot(map_, index, *block, v, with_evidence, out);
    return true;
  }
  // Paged out: the log holds its latest state.
  std::vector<float> evidence;
  std::vector<std::uint64_t> observed_words;
  if (!pager_ || !checkpoint_->log().read(index, evidence, observed_words)) return false;
  std::vector<std::uint8_t> observed(static_cast<std::size_t>(config_.params.cells_per_block()));
  for (std::size_t c = 0; c < observed.size(); ++c) {
    observed[c] = (observed_words[c / 64] >> (c % 64)) & 1u;
  }
  dds_idl::snapshot_of_evidence(index, config_.params.grid(), config_.params.num_classes, evidence,
                                observed, config_.params.prior, config_.params.unknown_variance, v,
                                with_evidence, out);
  return true;
}

mapping::Costmap MappingStage::build_costmap(const mapping::CostmapParams& p,
                                             const Eigen::Vector2d& centre) const {
  std::shared_lock lock(map_mutex_);
  return mapping::build_costmap(map_, p, centre);
}

mapping::CostmapUpdate MappingStage::update_costmap(
    mapping::Costmap& costmap, const mapping::CostmapParams& p,
    std::span<const common::BlockIndex> changed) const {
  std::shared_lock lock(map_mutex_);
  return mapping::update_costmap(costmap, map_, p, changed);
}

}  // namespace semap::onboard
