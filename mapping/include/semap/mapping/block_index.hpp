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

struct BlockIndexHash {
  std::size_t operator()(const BlockIndex& b) const {
    // Multiplicative mixing of the three coordinates; cheap and well spread for grid keys.
    std::uint64_t h = static_cast<std::uint32_t>(b.x) * 0x9E3779B97F4A7C15ull;
    h ^= static_cast<std::uint32_t>(b.y) * 0xC2B2AE3D27D4EB4Full;
    h ^= static_cast<std::uint32_t>(b.z) * 0x165667B19E3779F9ull;
    return static_cast<std::size_t>(h ^ (h >> 29));
  }
};

// Floor division for negative grid coordinates (C++ `/` truncates towards zero).
inline std::int32_t floor_div(std::int32_t a, std::int32_t b) {
  const std::int32_t q = a / b;
  return (a % b != 0 && ((a < 0) != (b < 0))) ? q - 1 : q;
}

}  // namespace semap::mapping
