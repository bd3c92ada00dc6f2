// read_block_cdr parses the serialised bytes of a map block taken from the network before any
// other check (MapClient skips Cyclone's deserialiser), so any bytes must give a verdict without
// crashing or reading out of bounds; what it accepts then goes through check_block, as in
// MapClient.
#include <cstdint>
#include <span>

#include "semap/dds_idl/block_cdr.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace semap::dds_idl;
  static BlockSnapshot block;  // reused as MapClient reuses its scratch block
  semap::common::Stamp stamp;
  const BlockCheck framing = read_block_cdr(std::span(data, size), block, stamp);
  if (framing.ok()) {
    (void)check_block(block, {});
  } else if (framing.error.empty() || framing.reason != BlockReject::kMalformed) {
    __builtin_trap();  // every rejection must say why
  }
  return 0;
}
