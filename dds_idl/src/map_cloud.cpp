#include "semap/dds_idl/map_cloud.hpp"

#include <bit>
#include <cstring>
#include <stdexcept>

#include "semap/dds_idl/converters.hpp"

namespace semap::dds_idl {

namespace {

struct FieldSpec {
  std::uint32_t offset;
  std::uint8_t datatype;
};
constexpr std::array<FieldSpec, 6> kFields{{
    {0, sensor_msgs_msg_dds__PointField_Constants_FLOAT32_},
    {4, sensor_msgs_msg_dds__PointField_Constants_FLOAT32_},
    {8, sensor_msgs_msg_dds__PointField_Constants_FLOAT32_},
    {12, sensor_msgs_msg_dds__PointField_Constants_FLOAT32_},
    {16, sensor_msgs_msg_dds__PointField_Constants_FLOAT32_},
    {20, sensor_msgs_msg_dds__PointField_Constants_UINT16_},
}};
constexpr std::uint32_t kGrey = 0x808080;

static_assert(std::endian::native == std::endian::little, "MapCloud writes little-endian clouds");

}  // namespace

MapCloud::MapCloud(std::string frame_id, std::vector<std::uint32_t> class_colors)
    : frame_id_(std::move(frame_id)), class_colors_(std::move(class_colors)) {
  for (std::size_t i = 0; i < fields_.size(); ++i) {
    fields_[i].name_ = names_[i].data();
    fields_[i].offset_ = kFields[i].offset;
    fields_[i].datatype_ = kFields[i].datatype;
    fields_[i].count_ = 1;
  }
}

void MapCloud::add(const Eigen::Vector3f& p, std::uint16_t cls, float variance) {
  std::array<std::uint8_t, kPointStep> point{};
  const std::uint32_t rgb = cls == kRemovedClass         ? 0
                            : cls < class_colors_.size() ? class_colors_[cls] & 0xFFFFFF
                                                         : kGrey;
  std::memcpy(point.data(), p.data(), 12);
  std::memcpy(point.data() + 12, &rgb, 4);
  std::memcpy(point.data() + 16, &variance, 4);
  std::memcpy(point.data() + 20, &cls, 2);
  data_.insert(data_.end(), point.begin(), point.end());
}

void MapCloud::add_occupied(const BlockSnapshot& block) {
  for (std::size_t i = 0; i < block.state.size(); ++i) {
    if (block.state[i] == common::CellState::kOccupied) {
      add(block.cell_center(i), block.argmax_class[i], block.variance[i]);
    }
  }
}

void MapCloud::add_changed(const BlockSnapshot& block, std::vector<std::uint16_t>& sent) {
  sent.resize(block.state.size(), kRemovedClass);
  for (std::size_t i = 0; i < block.state.size(); ++i) {
    const std::uint16_t now =
        block.state[i] == common::CellState::kOccupied ? block.argmax_class[i] : kRemovedClass;
    if (now == sent[i]) continue;
    add(block.cell_center(i), now, now == kRemovedClass ? 0.0f : block.variance[i]);
    sent[i] = now;
  }
}

const msg::PointCloud2& MapCloud::message(common::Stamp stamp) {
  msg_.header_.stamp_ = to_msg_time(stamp);
  msg_.header_.frame_id_ = frame_id_.data();
  msg_.height_ = 1;
  msg_.width_ = static_cast<std::uint32_t>(size());
  msg_.fields_ = borrow_sequence<dds_sequence_sensor_msgs_msg_dds__PointField_>(fields_.data(),
                                                                                fields_.size());
  msg_.is_bigendian_ = false;
  msg_.point_step_ = kPointStep;
  msg_.row_step_ = static_cast<std::uint32_t>(data_.size());
  msg_.data_ = borrow_sequence<dds_sequence_uint8>(data_.data(), data_.size());
  msg_.is_dense_ = true;
  return msg_;
}

std::vector<CloudPoint> read_map_cloud(const msg::PointCloud2& m) {
  const std::array<const char*, 6> names{"x", "y", "z", "rgb", "variance", "class"};
  if (m.fields_._length != names.size()) {
    throw std::runtime_error("PointCloud2: expected 6 fields, got " +
                             std::to_string(m.fields_._length));
  }
  for (std::size_t i = 0; i < names.size(); ++i) {
    const auto& f = m.fields_._buffer[i];
    if (std::strcmp(f.name_, names[i]) != 0 || f.offset_ != kFields[i].offset ||
        f.datatype_ != kFields[i].datatype || f.count_ != 1) {
      throw std::runtime_error(std::string("PointCloud2: field ") + names[i] +
                               " has another layout");
    }
  }
  const std::size_t n = static_cast<std::size_t>(m.width_) * m.height_;
  // Divided, not multiplied: width * height * point_step may wrap.
  if (m.is_bigendian_ || m.point_step_ != MapCloud::kPointStep ||
      m.data_._length % MapCloud::kPointStep != 0 || m.data_._length / MapCloud::kPointStep != n) {
    throw std::runtime_error("PointCloud2: point_step/data length/endianness mismatch");
  }
  std::vector<CloudPoint> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t* p = m.data_._buffer + i * MapCloud::kPointStep;
    std::memcpy(out[i].position.data(), p, 12);
    std::memcpy(&out[i].rgb, p + 12, 4);
    std::memcpy(&out[i].variance, p + 16, 4);
    std::memcpy(&out[i].cls, p + 20, 2);
  }
  return out;
}

}  // namespace semap::dds_idl
