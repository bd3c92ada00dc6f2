// Serial byte stream (NMEA and UBX interleaved): framer, parsers and fix builder over arbitrary
// bytes fed in chunks whose sizes come from the input itself.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "semap/firmware_bridge/gnss_stream_decoder.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using semap::firmware_bridge::GnssStreamDecoder;
  GnssStreamDecoder decoder;
  std::vector<semap::common::GnssFix> fixes;
  std::size_t pos = 0;
  std::int64_t t = 0;
  while (pos < size) {
    const std::size_t chunk = 1 + data[pos] % 97;
    const std::size_t n = chunk < size - pos ? chunk : size - pos;
    decoder.feed({data + pos, n}, semap::common::Stamp(++t), fixes);
    pos += n;
  }
  const auto& c = decoder.counters();
  if (c.bytes != size || c.garbage_bytes > size || c.fixes != fixes.size()) std::abort();
  return 0;
}
