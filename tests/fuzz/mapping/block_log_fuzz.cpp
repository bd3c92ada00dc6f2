// Feeds arbitrary bytes to the block log reader (what a robot reads back from its checkpoint at
// start): it must either describe the records up to the last commit or throw BlockLogError,
// never crash, hang or read outside the bytes.
#include <cstddef>
#include <cstdint>
#include <span>

#include "semap/mapping/block_log.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  semap::mapping::MapParams params;
  params.num_classes = 3;
  params.block_depth = 2;
  try {
    const auto scan = semap::mapping::scan_block_log({data, size}, params, "fuzz");
    if (scan.end > size) __builtin_trap();
    for (const auto& [index, entry] : scan.blocks) {
      if (entry.offset + entry.bytes > scan.end) __builtin_trap();
    }
  } catch (const semap::mapping::BlockLogError&) {
  }
  return 0;
}
