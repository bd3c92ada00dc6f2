#include "semap/dds_idl/map_publisher.hpp"

#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

#include "semap/dds_idl/block_codec.hpp"
#include "semap/dds_idl/topic_names.hpp"

namespace semap::dds_idl {

namespace {

common::Stamp after(common::Stamp now, double hz) {
  return hz > 0.0 ? now + 1.0 / hz : common::Stamp(INT64_MAX);
}

}  // namespace

common::BlockIndex SnapshotStore::put(BlockSnapshot block) {
  const common::BlockIndex index = block.index;
  blocks_.insert_or_assign(index, std::move(block));
  return index;
}

void SnapshotStore::for_each_block(const std::function<void(const common::BlockIndex&)>& f) const {
  for (const auto& [index, block] : blocks_) f(index);
}

bool SnapshotStore::read(const common::BlockIndex& index, BlockSnapshot& out) const {
  const auto it = blocks_.find(index);
  if (it == blocks_.end()) return false;
  out = it->second;  // vector copy-assignment keeps out's buffers
  return true;
}

MapPublisher::MapPublisher(const Participant& participant, MapPublisherConfig config,
                           MapDescription description, const BlockSource& source)
    : config_(std::move(config)),
      description_(std::move(description)),
      block_topic_(participant, topic_name(config_.ns, SemapTopic::kMapBlocks)),
      block_writer_(participant, block_topic_, topic_qos(SemapTopic::kMapBlocks)),
      info_topic_(participant, topic_name(config_.ns, SemapTopic::kMapInfo)),
      info_writer_(participant, info_topic_, topic_qos(SemapTopic::kMapInfo)),
      cloud_topic_(participant, topic_name(config_.ns, SemapTopic::kMapCloud)),
      cloud_writer_(participant, cloud_topic_, topic_qos(SemapTopic::kMapCloud)),
      cloud_(config_.frame_id, description_.class_colors),
      updates_topic_(participant, topic_name(config_.ns, SemapTopic::kMapCloudUpdates)),
      updates_writer_(participant, updates_topic_, topic_qos(SemapTopic::kMapCloudUpdates)),
      updates_(config_.frame_id, description_.class_colors),
      source_(source) {
  if (config_.blocks_hz <= 0.0) throw std::invalid_argument("MapPublisher: blocks_hz must be > 0");
  if (description_.num_classes == 0) {
    throw std::invalid_argument("MapPublisher: num_classes must be > 0");
  }
}

void MapPublisher::check_shape(const BlockSnapshot& block) const {
  const std::size_t cells = block.cell_count();
  const bool shape_ok =
      block.resolution == description_.resolution &&
      block.block_cells == description_.block_cells &&
      block.num_classes == description_.num_classes && block.state.size() == cells &&
      block.argmax_class.size() == cells && block.variance.size() == cells &&
      (block.evidence.empty() || block.evidence.size() == cells * block.num_classes);
  if (!shape_ok) {
    throw std::invalid_argument("MapPublisher: block " + std::to_string(block.index.x) + "," +
                                std::to_string(block.index.y) + "," +
                                std::to_string(block.index.z) + " differs from the map's shape");
  }
}

void MapPublisher::changed(const common::BlockIndex& index) {
  changed_.insert(index);
  updates_due_ = true;
}

void MapPublisher::forget(const common::BlockIndex& index) { forgotten_.insert(index); }

void MapPublisher::spin_updates(common::Stamp now) {
  if (now >= next_blocks_ && config_.cloud_hz > 0.0 && updates_due_) publish_cloud_updates(now);
}

std::size_t MapPublisher::spin_once(common::Stamp now) {
  std::size_t written = 0;
  if (now >= next_blocks_) {
    written = publish_changed(now);
    next_blocks_ = after(now, config_.blocks_hz);
  }
  if (now >= next_cloud_ && config_.cloud_hz > 0.0) {
    publish_cloud(now);
    next_cloud_ = after(now, config_.cloud_hz);
  }
  return written;
}

std::size_t MapPublisher::publish_changed(common::Stamp now) {
  for (const common::BlockIndex& index : changed_) {
    if (known_.insert(index).second) info_dirty_ = true;
  }
  if (info_dirty_) publish_info(now);
  if (config_.cloud_hz > 0.0 && updates_due_) publish_cloud_updates(now);
  std::size_t written = 0;
  // A round of blocks goes out as few full packets when the configuration batches writes
  // (the loopback XML does), and is flushed before returning so that nothing waits.
  for (auto it = changed_.begin(); it != changed_.end();) {
    if (!source_.read(*it, scratch_)) {  // gone from the source: subscribers keep the last
      it = changed_.erase(it);
      continue;
    }
    check_shape(scratch_);
    const BlockMessage m(scratch_, now, config_.frame_id);
    try {
      block_writer_.write_batched(m.get());
    } catch (const DdsError& e) {
      if (e.code() != DDS_RETCODE_TIMEOUT) throw;
      ++counters_.write_timeouts;
      break;
    }
    in_history_.insert(*it);
    it = changed_.erase(it);
    ++written;
  }
  block_writer_.flush();
  // A forgotten block still waiting to go out (a write timed out) is forgotten after it went.
  for (auto it = forgotten_.begin(); it != forgotten_.end();) {
    if (changed_.contains(*it)) {
      ++it;
      continue;
    }
    if (in_history_.erase(*it) > 0) {
      msg::SemanticMapBlock key{};
      key.ix_ = it->x;
      key.iy_ = it->y;
      key.iz_ = it->z;
      block_writer_.unregister(key);
      ++counters_.blocks_forgotten;
    }
    sent_classes_.erase(*it);
    it = forgotten_.erase(it);
  }
  counters_.blocks_written += written;
  if (written > 0) ++counters_.block_publications;
  return written;
}

// Before the blocks, from the cells alone: the update is a small message that planners wait
// for, the blocks carry all the evidence.
void MapPublisher::publish_cloud_updates(common::Stamp now) {
  updates_due_ = false;
  updates_.clear();
  for (const common::BlockIndex& index : changed_) {
    if (source_.read_cells(index, scratch_)) updates_.add_changed(scratch_, sent_classes_[index]);
  }
  if (updates_.size() == 0) return;
  updates_writer_.write(updates_.message(now));
  ++counters_.cloud_updates_written;
  counters_.cloud_update_points += updates_.size();
}

void MapPublisher::publish_cloud(common::Stamp now) {
  cloud_.clear();
  source_.for_each_block([&](const common::BlockIndex& index) {
    if (source_.read_cells(index, scratch_)) cloud_.add_occupied(scratch_);
  });
  cloud_writer_.write(cloud_.message(now));
  ++counters_.clouds_written;
}

void MapPublisher::publish_info(common::Stamp now) {
  if (!known_.empty()) {
    const common::MapGrid grid{description_.resolution, description_.block_cells};
    const float side = description_.resolution * static_cast<float>(description_.block_cells);
    Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
    Eigen::Vector3f hi = -lo;
    for (const common::BlockIndex& index : known_) {
      const Eigen::Vector3f origin = grid.block_origin(index);
      lo = lo.cwiseMin(origin);
      hi = hi.cwiseMax(origin + Eigen::Vector3f::Constant(side));
    }
    description_.min_bound = lo.cast<double>();
    description_.max_bound = hi.cast<double>();
  }
  description_.num_blocks = static_cast<std::uint32_t>(known_.size());
  ++description_.sequence;
  const MapInfoMessage m(description_, now, config_.frame_id);
  info_writer_.write(m.get());
  ++counters_.infos_written;
  info_dirty_ = false;
}

}  // namespace semap::dds_idl
