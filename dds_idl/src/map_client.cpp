#include "semap/dds_idl/map_client.hpp"

#include <fstream>
#include <numeric>
#include <stdexcept>

#include "semap/common/logging.hpp"
#include "semap/dds_idl/block_cdr.hpp"
#include "semap/dds_idl/topic_names.hpp"

namespace semap::dds_idl {

std::uint64_t MapClientCounters::rejected_total() const {
  return std::accumulate(rejected.begin(), rejected.end(), std::uint64_t{0});
}

namespace {

using ListenerPtr = std::unique_ptr<dds_listener_t, decltype(&dds_delete_listener)>;

// The listener is copied by Cyclone when the reader is created; null: no listener.
ListenerPtr block_listener(void* client, bool take_on_receive, dds_on_data_available_fn fn) {
  ListenerPtr l(take_on_receive ? dds_create_listener(client) : nullptr, &dds_delete_listener);
  if (l) dds_lset_data_available(l.get(), fn);
  return l;
}

}  // namespace

MapClient::MapClient(const Participant& participant, MapClientConfig config)
    : config_(std::move(config)),
      block_topic_(participant, topic_name(config_.ns, SemapTopic::kMapBlocks)),
      block_reader_(participant, block_topic_, topic_qos(SemapTopic::kMapBlocks),
                    block_listener(this, config_.take_on_receive, &on_data_available).get()),
      info_topic_(participant, topic_name(config_.ns, SemapTopic::kMapInfo)),
      info_reader_(participant, info_topic_, topic_qos(SemapTopic::kMapInfo)) {
  constructed_ = true;
  // Blocks whose notification came while this was still being built are taken now.
  if (config_.take_on_receive) on_data_available(block_reader_.handle(), this);
}

MapClient::~MapClient() {
  // Returns once a listener call in progress has finished.
  if (config_.take_on_receive) dds_set_listener(block_reader_.handle(), nullptr);
}

void MapClient::on_data_available(dds_entity_t, void* self) {
  auto* client = static_cast<MapClient*>(self);
  if (!client->constructed_) return;
  bool wanted = false;
  {
    const std::lock_guard lock(client->mutex_);
    // Called from Cyclone's C code: nothing may propagate out of here.
    try {
      client->take_blocks();
    } catch (const std::exception& e) {
      client->last_error_ = e.what();
      common::logger("dds.map_client")->error("taking blocks on receive: {}", e.what());
    }
    wanted = client->blocks_.size() >= client->wait_for_count_;
  }
  // Only when a waiter's count is reached: a wake-up per sample would cost the receive thread
  // as much as taking the sample.
  if (wanted) client->accepted_cv_.notify_all();
}

void MapClient::take_blocks() {
  // Serialised blocks, read by read_block_cdr: Cyclone's deserialiser and a copy skipped.
  block_reader_.take_each_cdr(
      [this](std::span<const std::uint8_t> cdr, const dds_sample_info_t&) { on_block(cdr); });
}

std::size_t MapClient::poll() {
  const std::lock_guard lock(mutex_);
  // MapInfo first: it may fix the shape the blocks are checked against.
  info_reader_.take_each([this](const msg::MapInfo& m, const dds_sample_info_t&) { on_info(m); });
  const std::uint64_t before = counters_.accepted;
  take_blocks();
  return static_cast<std::size_t>(counters_.accepted - before);
}

bool MapClient::wait_for_blocks(std::size_t count, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    poll();
    if (block_count() >= count) return true;
    const auto now = std::chrono::steady_clock::now();
    if (now >= deadline) return false;
    // At most 50 ms between polls: MapInfo is taken by poll() only.
    const auto until = std::min(deadline, now + std::chrono::milliseconds(50));
    if (config_.take_on_receive) {
      std::unique_lock lock(mutex_);
      wait_for_count_ = count;
      accepted_cv_.wait_until(lock, until, [&] { return blocks_.size() >= count; });
      wait_for_count_ = SIZE_MAX;
    } else {
      block_reader_.wait(until - now);
    }
  }
}

const MapClient::BlockMap& MapClient::blocks() const {
  if (config_.take_on_receive) {
    throw std::logic_error("MapClient::blocks() with take_on_receive: use with_blocks()");
  }
  return blocks_;
}

std::size_t MapClient::block_count() const {
  const std::lock_guard lock(mutex_);
  return blocks_.size();
}

std::optional<MapDescription> MapClient::info() const {
  const std::lock_guard lock(mutex_);
  return info_;
}

MapClientCounters MapClient::counters() const {
  const std::lock_guard lock(mutex_);
  return counters_;
}

std::string MapClient::last_error() const {
  const std::lock_guard lock(mutex_);
  return last_error_;
}

void MapClient::on_info(const msg::MapInfo& m) {
  try {
    MapDescription d = from_msg(m);
    BlockLimits& l = config_.limits;
    const bool conflicts = (l.num_classes != 0 && l.num_classes != d.num_classes) ||
                           (l.block_cells != 0 && l.block_cells != d.block_cells) ||
                           (l.resolution > 0.0f && l.resolution != d.resolution);
    if (conflicts) {
      throw std::runtime_error("MapInfo: shape (" + std::to_string(d.num_classes) + " classes, " +
                               std::to_string(d.block_cells) +
                               " cells) differs from the expected one");
    }
    l.num_classes = d.num_classes;
    l.block_cells = d.block_cells;
    l.resolution = d.resolution;
    info_ = std::move(d);
    ++counters_.infos;
  } catch (const std::exception& e) {
    ++counters_.infos_rejected;
    last_error_ = e.what();
    common::logger("dds.map_client")->warn("{}", last_error_);
  }
}

void MapClient::on_block(std::span<const std::uint8_t> cdr) {
  common::Stamp stamp;
  BlockCheck c = read_block_cdr(cdr, scratch_, stamp);
  if (c.ok()) c = check_block(scratch_, config_.limits);
  if (!c.ok()) {
    ++counters_.rejected[static_cast<std::size_t>(c.reason)];
    last_error_ = std::move(c.error);
    common::logger("dds.map_client")->warn("rejected {}", last_error_);
    return;
  }
  BlockLimits& l = config_.limits;
  // Without MapInfo the first valid block fixes the shape of the map.
  if (l.num_classes == 0) l.num_classes = scratch_.num_classes;
  if (l.block_cells == 0) l.block_cells = scratch_.block_cells;
  if (l.resolution <= 0.0f) l.resolution = scratch_.resolution;

  const common::BlockIndex index = scratch_.index;
  auto [it, inserted] = blocks_.try_emplace(index);
  if (!inserted && it->second.version > scratch_.version) {
    ++counters_.stale;
    return;
  }
  std::swap(it->second, scratch_);
  changed_.insert(index);
  ++counters_.accepted;
}

std::vector<common::BlockIndex> MapClient::take_changed() {
  const std::lock_guard lock(mutex_);
  std::vector<common::BlockIndex> changed(changed_.begin(), changed_.end());
  changed_.clear();
  return changed;
}

CellQuery MapClient::query(const Eigen::Vector3f& p) const {
  const std::lock_guard lock(mutex_);
  const BlockLimits& l = config_.limits;
  if (l.resolution <= 0.0f || l.block_cells == 0) return {};
  // The robot's own point -> cell -> block function, so a query near a block face reads the
  // cell the robot filled.
  const common::MapGrid grid(l.resolution, l.block_cells);
  const common::CellIndex cell_index = grid.cell_of(p);
  const common::BlockIndex index = grid.block_of(cell_index);
  const auto it = blocks_.find(index);
  if (it == blocks_.end()) return {};
  const BlockSnapshot& b = it->second;
  const auto cell = static_cast<std::size_t>(grid.local_index(cell_index, index));
  return {true, b.state[cell], b.argmax_class[cell], b.variance[cell]};
}

void MapClient::save_pcd(const std::filesystem::path& path) const {
  const std::lock_guard lock(mutex_);
  std::size_t n = 0;
  for (const auto& [index, b] : blocks_) {
    for (common::CellState s : b.state) n += s == common::CellState::kOccupied;
  }
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path.string());
  out << "# .PCD v0.7 - semap map received over DDS\nVERSION 0.7\n"
      << "FIELDS x y z class variance\nSIZE 4 4 4 2 4\nTYPE F F F U F\nCOUNT 1 1 1 1 1\n"
      << "WIDTH " << n << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << n << "\nDATA ascii\n";
  for (const auto& [index, b] : blocks_) {
    for (std::size_t i = 0; i < b.state.size(); ++i) {
      if (b.state[i] != common::CellState::kOccupied) continue;
      const Eigen::Vector3f c = b.cell_center(i);
      out << c.x() << ' ' << c.y() << ' ' << c.z() << ' ' << b.argmax_class[i] << ' '
          << b.variance[i] << '\n';
    }
  }
  if (!out) throw std::runtime_error("error writing " + path.string());
}

}  // namespace semap::dds_idl
