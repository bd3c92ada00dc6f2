#pragma once

// Internal to semap_mapping.

#include <cstdint>

namespace semap::mapping::detail {

// std::floor/ceil need SSE4.1 to be one instruction; on plain x86-64 they are a dozen. These
// are exact for |x| < 2^31, which the callers' range checks guarantee.
inline std::int32_t fast_floor(float x) {
  const auto i = static_cast<std::int32_t>(x);
  return i - static_cast<std::int32_t>(x < static_cast<float>(i));
}
inline std::int32_t fast_ceil(float x) {
  const auto i = static_cast<std::int32_t>(x);
  return i + static_cast<std::int32_t>(x > static_cast<float>(i));
}

}  // namespace semap::mapping::detail
