// read_map_cloud: a PointCloud2 built from the input (field count, names, offsets, types and
// counts, width, height, point_step, endianness, data) is read or refused with
// std::runtime_error naming "PointCloud2"; an accepted cloud has width * height points, each
// point's bytes read back from its own 24-byte record, never beyond data (ASan), and the
// width * height * point_step product must not wrap into a "matching" length.
// Input: field count (1 byte, % 9), per field a name (length byte + bytes), offset (uint32),
// datatype (1 byte), count (uint32); height, width, point_step (uint32), is_bigendian (1 byte),
// then the data bytes.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "fuzz_input.hpp"
#include "semap/dds_idl/map_cloud.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace semap::dds_idl;
  semap::fuzz::FuzzInput in(data, size);
  const std::size_t field_count = in.take<std::uint8_t>() % 9;
  std::vector<std::string> names;
  std::vector<msg::PointField> fields(field_count);
  for (std::size_t i = 0; i < field_count; ++i) names.push_back(in.take_string(12));
  for (std::size_t i = 0; i < field_count; ++i) {
    fields[i].name_ = names[i].data();
    fields[i].offset_ = in.take<std::uint32_t>();
    fields[i].datatype_ = in.take<std::uint8_t>();
    fields[i].count_ = in.take<std::uint32_t>();
  }
  msg::PointCloud2 m{};
  m.fields_._length = m.fields_._maximum = static_cast<std::uint32_t>(field_count);
  m.fields_._buffer = fields.data();
  m.height_ = in.take<std::uint32_t>();
  m.width_ = in.take<std::uint32_t>();
  m.point_step_ = in.take<std::uint32_t>();
  m.is_bigendian_ = (in.take<std::uint8_t>() & 1) != 0;
  const auto rest = in.rest();
  std::vector<std::uint8_t> bytes(rest.begin(), rest.end());
  m.data_._length = m.data_._maximum = static_cast<std::uint32_t>(bytes.size());
  m.data_._buffer = bytes.data();
  m.row_step_ = m.width_ * m.point_step_;

  std::vector<CloudPoint> points;
  try {
    points = read_map_cloud(m);
  } catch (const std::runtime_error& e) {
    if (std::string(e.what()).rfind("PointCloud2", 0) != 0) std::abort();
    return 0;
  }
  if (points.size() != static_cast<std::uint64_t>(m.width_) * m.height_) std::abort();
  if (points.size() * MapCloud::kPointStep != bytes.size()) std::abort();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::uint8_t* p = bytes.data() + i * MapCloud::kPointStep;
    std::uint16_t cls = 0;
    std::memcpy(&cls, p + 20, 2);
    if (points[i].cls != cls || std::memcmp(points[i].position.data(), p, 12) != 0) std::abort();
  }
  return 0;
}
