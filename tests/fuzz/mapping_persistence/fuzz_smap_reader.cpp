// Feeds arbitrary bytes to the .smap reader, strict and salvaging: it must either return a map
// or throw SmapError, never crash, hang or allocate without bound.
#include <cstddef>
#include <cstdint>
#include <span>

#include "semap/mapping/smap_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> bytes(data, size);
  for (const bool salvage : {false, true}) {
    try {
      const auto result = semap::mapping::decode_smap(bytes, "fuzz", {.salvage = salvage});
      // A map that was accepted re-encodes to a file that is accepted again.
      const auto again =
          semap::mapping::decode_smap(semap::mapping::encode_smap(result.map), "fuzz-reencoded");
      if (!(again.map == result.map)) __builtin_trap();
    } catch (const semap::mapping::SmapError&) {
    }
  }
  return 0;
}
