#pragma once

#include <cstddef>
#include <cstdint>

namespace semap::mapping {

// Integer coordinates of a block (or of a cell or voxel on its own grid).
struct BlockIndex {
  std::int32_t x = 0;
  std::int32_t y = 0;
  std::int32_t z = 0;

  friend bool operator==(const BlockIndex&, const BlockIndex&) = default;
};

// Floor division for negative grid coordinates (C++ `/` truncates towards zero).
inline std::int32_t floor_div(std::int32_t a, std::int32_t b) {
  const std::int32_t q = a / b;
  return (a % b != 0 && ((a < 0) != (b < 0))) ? q - 1 : q;
}

}  // namespace semap::mapping
