#include "semap/onboard/costmap_output.hpp"

#include <chrono>
#include <vector>

#include "semap/dds_idl/converters.hpp"
#include "semap/dds_idl/topic_names.hpp"

namespace semap::onboard {

namespace {

template <typename Seq>
Seq borrow_cells(const std::vector<std::int8_t>& cells) {
  // int8 cells travel as octets (-1 as 0xFF): same bytes.
  return dds_idl::borrow_sequence<Seq>(
      reinterpret_cast<std::uint8_t*>(const_cast<std::int8_t*>(cells.data())), cells.size());
}

}  // namespace

void to_msg(const mapping::Costmap& costmap, common::Stamp stamp, const std::string& frame_id,
            dds_idl::msg::OccupancyGrid& out) {
  out = {};
  dds_idl::set_header(stamp, frame_id, out.header_);
  out.info_.map_load_time_ = out.header_.stamp_;
  out.info_.resolution_ = static_cast<float>(costmap.resolution);
  out.info_.width_ = static_cast<std::uint32_t>(costmap.width);
  out.info_.height_ = static_cast<std::uint32_t>(costmap.height);
  out.info_.origin_.position_ = {costmap.origin_x(), costmap.origin_y(), 0.0};
  out.info_.origin_.orientation_ = {0.0, 0.0, 0.0, 1.0};
  out.data_ = borrow_cells<dds_sequence_octet>(costmap.data);
}

void to_msg(const mapping::CostmapUpdate& update, common::Stamp stamp, const std::string& frame_id,
            dds_idl::msg::OccupancyGridUpdate& out) {
  out = {};
  dds_idl::set_header(stamp, frame_id, out.header_);
  out.x_ = update.x;
  out.y_ = update.y;
  out.width_ = static_cast<std::uint32_t>(update.width);
  out.height_ = static_cast<std::uint32_t>(update.height);
  out.data_ = borrow_cells<dds_sequence_octet>(update.data);
}

CostmapOutput::CostmapOutput(const dds_idl::Participant& participant, const std::string& ns,
                             std::string frame_id, const CostmapConfig& config,
                             const CostmapSource& source)
    : frame_id_(std::move(frame_id)),
      config_(config),
      source_(source),
      grid_topic_(participant, dds_idl::topic_name(ns, dds_idl::SemapTopic::kCostmap),
                  dds_idl::topic_qos(dds_idl::SemapTopic::kCostmap)),
      grid_writer_(participant, grid_topic_, dds_idl::topic_qos(dds_idl::SemapTopic::kCostmap)),
      update_topic_(participant, dds_idl::topic_name(ns, dds_idl::SemapTopic::kCostmapUpdates),
                    dds_idl::topic_qos(dds_idl::SemapTopic::kCostmapUpdates)),
      update_writer_(participant, update_topic_,
                     dds_idl::topic_qos(dds_idl::SemapTopic::kCostmapUpdates)) {}

void CostmapOutput::changed(const common::BlockIndex& block) { pending_.insert(block); }

bool CostmapOutput::needs_rebuild(const Eigen::Vector2d& robot) const {
  if (!costmap_ || config_.params.whole_map()) return true;
  const Eigen::Vector2d off = (robot - centre_).cwiseAbs();
  return off.x() > config_.params.width_m / 4 || off.y() > config_.params.height_m / 4;
}

void CostmapOutput::spin_once(common::Stamp now, const std::optional<Eigen::Vector2d>& robot) {
  if (now < next_ || !robot) return;
  next_ = now + 1.0 / config_.publish_hz;
  const auto start = std::chrono::steady_clock::now();
  std::optional<mapping::CostmapUpdate> update;
  if (needs_rebuild(*robot)) {
    centre_ = *robot;
    costmap_ = source_.build_costmap(config_.params, centre_);
    ++counters_.rebuilds;
  } else if (!pending_.empty()) {
    const std::vector<common::BlockIndex> changed(pending_.begin(), pending_.end());
    update = source_.update_costmap(*costmap_, config_.params, changed);
  }
  pending_.clear();
  counters_.last_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (update && !update->empty()) {
    dds_idl::msg::OccupancyGridUpdate m;
    to_msg(*update, now, frame_id_, m);
    update_writer_.write(m);
    ++counters_.updates_written;
  }
  // The whole grid every round as well: it is what a late joiner gets.
  dds_idl::msg::OccupancyGrid grid;
  to_msg(*costmap_, now, frame_id_, grid);
  grid_writer_.write(grid);
  ++counters_.grids_written;
}

}  // namespace semap::onboard
