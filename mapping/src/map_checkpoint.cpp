#include "semap/mapping/map_checkpoint.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace semap::mapping {

MapCheckpoint::MapCheckpoint(SemanticMap& map, const CheckpointParams& params, bool load)
    : map_(map),
      params_(params),
      log_(params.path, map.params(), params.durable),
      last_(std::chrono::steady_clock::now()) {
  if (params_.resume) {
    stats_.resumed_scans = log_.committed_scans();
    if (load) stats_.resumed_blocks = log_.load_all(map_);
  } else if (log_.committed_scans() > 0) {
    // A new map appended to an old one would bring the old blocks back on the next resume.
    throw BlockLogError(params_.path.string() +
                        ": holds a map already: resume it, or move the file away");
  }
  stats_.log_bytes = log_.bytes();
  stats_.committed_scans = log_.committed_scans();
  writer_ = std::jthread([this](std::stop_token stop) { run(stop); });
}

MapCheckpoint::~MapCheckpoint() {
  writer_.request_stop();
  wake_.notify_all();
}

void MapCheckpoint::after_insert(const InsertResult& result) {
  dirty_.insert(result.updated_blocks.begin(), result.updated_blocks.end());
  poll();
}

void MapCheckpoint::poll() {
  const auto now = std::chrono::steady_clock::now();
  if (std::chrono::duration<double>(now - last_).count() < params_.interval_s) return;
  std::lock_guard lock(mutex_);
  if (pending_) return;  // the writer is still busy: these changes go in the next one
  take_retries();
  if (dirty_.empty()) return;
  batch_ = copy_dirty();
  pending_ = true;
  last_ = now;
  wake_.notify_all();
}

MapCheckpoint::Batch MapCheckpoint::copy_dirty() {
  Batch batch;
  batch.scans = map_.scans();
  batch.blocks.reserve(dirty_.size());
  for (const common::BlockIndex& index : dirty_) {
    // A block a pager moved out is already in the log, newer than any copy here.
    const Block* block = map_.find_block(index);
    if (block == nullptr) continue;
    const auto observed = block->observed_words();
    batch.blocks.push_back({index, block->dense(), {observed.begin(), observed.end()}});
  }
  dirty_.clear();
  return batch;
}

void MapCheckpoint::take_retries() {
  dirty_.insert(retry_.begin(), retry_.end());
  retry_.clear();
}

void MapCheckpoint::failed(const Batch& batch, const std::string& error) {
  std::lock_guard lock(mutex_);
  for (const BlockCopy& copy : batch.blocks) retry_.insert(copy.index);
  ++stats_.write_failures;
  stats_.failing = true;
  stats_.last_error = error;
  stats_.log_bytes = log_.bytes();
}

void MapCheckpoint::write(const Batch& batch) {
  const auto start = std::chrono::steady_clock::now();
  try {
    for (const BlockCopy& copy : batch.blocks) {
      log_.append(copy.index, batch.scans, copy.evidence, copy.observed);
    }
    log_.commit(batch.scans);
  } catch (const std::exception& e) {
    // Whatever went wrong (BlockLogError, or no memory for a record), the thread lives on.
    failed(batch, e.what());
    return;
  }
  std::string compact_error;
  if (log_.bytes() > compact_after_bytes_) {
    try {
      log_.compact();
    } catch (const std::exception& e) {
      compact_error = e.what();
      compact_after_bytes_ = log_.bytes() + log_.bytes() / 4;
    }
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::lock_guard lock(mutex_);
  ++stats_.checkpoints;
  stats_.blocks_written += batch.blocks.size();
  stats_.last_write_s = seconds;
  stats_.max_write_s = std::max(stats_.max_write_s, seconds);
  stats_.log_bytes = log_.bytes();
  stats_.committed_scans = batch.scans;
  // A failed compaction costs disk space, not the checkpoint: it is counted but the log is
  // up to date.
  stats_.failing = false;
  if (!compact_error.empty()) {
    ++stats_.write_failures;
    stats_.last_error = compact_error;
  }
}

void MapCheckpoint::run(std::stop_token stop) {
  std::unique_lock lock(mutex_);
  while (true) {
    wake_.wait(lock, stop, [this] { return pending_; });
    if (!pending_) return;  // stop requested
    lock.unlock();
    write(batch_);
    lock.lock();
    pending_ = false;
    batch_ = {};
    done_.notify_all();
  }
}

void MapCheckpoint::flush() {
  {
    std::unique_lock lock(mutex_);
    done_.wait(lock, [this] { return !pending_; });
    take_retries();
  }
  write(copy_dirty());
  last_ = std::chrono::steady_clock::now();
}

MapCheckpoint::Stats MapCheckpoint::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

MapPager::MapPager(SemanticMap& map, BlockLog& log, double radius_m)
    : map_(map),
      log_(log),
      radius_(radius_m),
      region_side_(static_cast<std::int32_t>(
          std::clamp(std::ceil(radius_m / map.params().grid().block_size()), 1.0, 1024.0))) {
  // A radius of zero or less would write out every block before each insert and read it
  // back right after (as a late restore): a wrong config, not a small memory budget.
  if (!(radius_m > 0.0)) throw std::invalid_argument("MapPager: radius must be positive");
  for (const common::BlockIndex& index : log_.blocks()) {
    if (map_.find_block(index) == nullptr) mark_out(index);
  }
}

common::BlockIndex MapPager::region_of(const common::BlockIndex& index) const {
  return {common::floor_div(index.x, region_side_), common::floor_div(index.y, region_side_),
          common::floor_div(index.z, region_side_)};
}

void MapPager::mark_out(const common::BlockIndex& index) {
  out_[region_of(index)].push_back(index);
  ++paged_out_;
}

bool MapPager::take_out(const common::BlockIndex& index) {
  const auto region = out_.find(region_of(index));
  if (region == out_.end()) return false;
  std::vector<common::BlockIndex>& blocks = region->second;
  const auto at = std::find(blocks.begin(), blocks.end(), index);
  if (at == blocks.end()) return false;
  *at = blocks.back();
  blocks.pop_back();
  if (blocks.empty()) out_.erase(region);
  --paged_out_;
  return true;
}

void MapPager::after_insert(const InsertResult& result) {
  for (const common::BlockIndex& index : result.updated_blocks) {
    // The insert started this block again from zero: add its evidence from the log.
    if (take_out(index)) {
      log_.load(index, map_);
      ++stats_.restored;
      ++stats_.late_restores;
    }
  }
}

std::vector<common::BlockIndex> MapPager::update(const Eigen::Vector3f& robot) {
  const common::MapGrid grid = map_.params().grid();
  const float side = grid.block_size();
  const auto distance = [&](const common::BlockIndex& index) {
    return static_cast<double>((grid.block_centre(index) - robot).norm());
  };
  std::vector<common::BlockIndex> far;
  map_.for_each_block([&](const common::BlockIndex& index, const Block&) {
    if (distance(index) > radius_ + side) far.push_back(index);
  });
  const auto scans = static_cast<std::uint64_t>(map_.scans());
  std::vector<common::BlockIndex> evicted;
  for (const common::BlockIndex& index : far) {
    const Block& block = *map_.find_block(index);
    try {
      log_.append(index, scans, block.dense(), block.observed_words());
    } catch (const BlockLogError& e) {
      // Only a block the log holds may leave memory. The rest wait for the next update: one
      // failed record per insert while the disk is full, not one per far block.
      ++stats_.write_failures;
      stats_.failing = true;
      stats_.last_error = e.what();
      break;
    }
    stats_.failing = false;
    map_.evict(index);
    mark_out(index);
    evicted.push_back(index);
    ++stats_.evicted;
  }
  // Blocks within the radius lie in the robot's region or its 26 neighbours (a region is at
  // least the radius wide).
  std::vector<common::BlockIndex> near;
  const common::BlockIndex centre = region_of(grid.block_of(grid.cell_of(robot)));
  for (std::int32_t dz = -1; dz <= 1; ++dz) {
    for (std::int32_t dy = -1; dy <= 1; ++dy) {
      for (std::int32_t dx = -1; dx <= 1; ++dx) {
        const auto region = out_.find({centre.x + dx, centre.y + dy, centre.z + dz});
        if (region == out_.end()) continue;
        for (const common::BlockIndex& index : region->second) {
          if (distance(index) <= radius_) near.push_back(index);
        }
      }
    }
  }
  for (const common::BlockIndex& index : near) {
    log_.load(index, map_);
    take_out(index);
    ++stats_.restored;
  }
  return evicted;
}

}  // namespace semap::mapping
