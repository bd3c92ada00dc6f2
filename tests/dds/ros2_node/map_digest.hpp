#pragma once

// What the ROS 2 reader test compares, computed the same way on both sides: the reader over the
// map cloud and costmap it assembled from the wire, the test over the robot's map.
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

namespace semap::ros2_check {

// A cell of the map cloud: its centre in millimetres (the cloud carries cell centres as
// float32, so both sides round the same floats) and its class.
using CellKey = std::array<std::int32_t, 3>;
using CloudCells = std::map<CellKey, std::uint16_t>;

inline CellKey cell_key(float x, float y, float z) {
  return {static_cast<std::int32_t>(std::lround(x * 1000.0f)),
          static_cast<std::int32_t>(std::lround(y * 1000.0f)),
          static_cast<std::int32_t>(std::lround(z * 1000.0f))};
}

class Fnv1a {
 public:
  void add(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) h_ = (h_ ^ p[i]) * 0x100000001b3ULL;
  }
  template <typename T>
  void add(const T& value) {
    add(&value, sizeof value);
  }
  std::string hex() const {
    char s[17];
    std::snprintf(s, sizeof s, "%016llx", static_cast<unsigned long long>(h_));
    return s;
  }

 private:
  std::uint64_t h_ = 0xcbf29ce484222325ULL;
};

// "<cells> <digest>" of a cloud, in cell order.
inline std::string cloud_digest(const CloudCells& cells) {
  Fnv1a h;
  for (const auto& [key, cls] : cells) {
    h.add(key);
    h.add(cls);
  }
  return std::to_string(cells.size()) + " " + h.hex();
}

// "<width> <height> <digest>" of a grid: origin in millimetres and the cells, row-major.
inline std::string grid_digest(std::uint32_t width, std::uint32_t height, double origin_x,
                               double origin_y, const std::vector<std::int8_t>& data) {
  Fnv1a h;
  h.add(static_cast<std::int64_t>(std::llround(origin_x * 1000.0)));
  h.add(static_cast<std::int64_t>(std::llround(origin_y * 1000.0)));
  h.add(data.data(), data.size());
  return std::to_string(width) + " " + std::to_string(height) + " " + h.hex();
}

}  // namespace semap::ros2_check
