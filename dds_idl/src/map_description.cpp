#include "semap/dds_idl/map_description.hpp"

#include <cmath>
#include <stdexcept>

#include "semap/dds_idl/converters.hpp"

namespace semap::dds_idl {

MapInfoMessage::MapInfoMessage(const MapDescription& d, common::Stamp stamp,
                               const std::string& frame_id) {
  msg_.header_.stamp_ = to_msg_time(stamp);
  msg_.header_.frame_id_ = const_cast<char*>(frame_id.c_str());
  msg_.resolution_ = d.resolution;
  msg_.block_cells_ = d.block_cells;
  msg_.num_classes_ = d.num_classes;
  for (const auto& n : d.class_names) names_.push_back(const_cast<char*>(n.c_str()));
  msg_.class_names_ = borrow_sequence<dds_sequence_string>(names_.data(), names_.size());
  msg_.class_colors_ = borrow_sequence<dds_sequence_unsigned_long>(
      const_cast<std::uint32_t*>(d.class_colors.data()), d.class_colors.size());
  msg_.min_bound_ = {d.min_bound.x(), d.min_bound.y(), d.min_bound.z()};
  msg_.max_bound_ = {d.max_bound.x(), d.max_bound.y(), d.max_bound.z()};
  msg_.num_blocks_ = d.num_blocks;
  msg_.sequence_ = d.sequence;
}

MapDescription from_msg(const msg::MapInfo& m) {
  if (!std::isfinite(m.resolution_) || m.resolution_ <= 0.0f) {
    throw std::runtime_error("MapInfo: resolution " + std::to_string(m.resolution_));
  }
  if (m.block_cells_ == 0 || m.block_cells_ > 64) {
    throw std::runtime_error("MapInfo: block_cells " + std::to_string(m.block_cells_));
  }
  if (m.num_classes_ == 0) throw std::runtime_error("MapInfo: num_classes 0");
  if (m.class_names_._length != 0 && m.class_names_._length != m.num_classes_) {
    throw std::runtime_error("MapInfo: class_names has " + std::to_string(m.class_names_._length) +
                             " entries for " + std::to_string(m.num_classes_) + " classes");
  }
  if (m.class_colors_._length != 0 && m.class_colors_._length != m.num_classes_) {
    throw std::runtime_error("MapInfo: class_colors has " +
                             std::to_string(m.class_colors_._length) + " entries for " +
                             std::to_string(m.num_classes_) + " classes");
  }
  MapDescription d;
  d.resolution = m.resolution_;
  d.block_cells = m.block_cells_;
  d.num_classes = m.num_classes_;
  for (std::uint32_t i = 0; i < m.class_names_._length; ++i) {
    d.class_names.emplace_back(m.class_names_._buffer[i] ? m.class_names_._buffer[i] : "");
  }
  d.class_colors.assign(m.class_colors_._buffer, m.class_colors_._buffer + m.class_colors_._length);
  d.min_bound = {m.min_bound_.x_, m.min_bound_.y_, m.min_bound_.z_};
  d.max_bound = {m.max_bound_.x_, m.max_bound_.y_, m.max_bound_.z_};
  d.num_blocks = m.num_blocks_;
  d.sequence = m.sequence_;
  return d;
}

}  // namespace semap::dds_idl
