// Recorded stream logs (semap-onboard --record): any bytes as a log of bytes and as a log of
// frames. Records up to the first damage come out within the format's limits, a raw frame holds
// its rows, and damage leaves an error naming the log.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>

#include "semap/drivers/frame_convert.hpp"
#include "semap/drivers/stream_log.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace semap::drivers;
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  {
    std::istringstream in(bytes);
    StreamLogReader reader(in, "fuzz.log", StreamLogKind::kBytes);
    std::uint64_t records = 0;
    while (const auto chunk = reader.next_bytes()) {
      ++records;
      if (chunk->bytes.size() > kStreamLogMaxChunk) std::abort();
    }
    if (records != reader.records()) std::abort();
    if (!reader.error().empty() && reader.error().rfind("fuzz.log: ", 0) != 0) std::abort();
  }
  {
    std::istringstream in(bytes);
    StreamLogReader reader(in, "fuzz.log", StreamLogKind::kFrames);
    while (const auto frame = reader.next_frame()) {
      if (frame->width == 0 || frame->width > kStreamLogMaxSide || frame->height == 0 ||
          frame->height > kStreamLogMaxSide || frame->data.size() < expected_size(*frame)) {
        std::abort();
      }
    }
    if (!reader.error().empty() && reader.error().rfind("fuzz.log: ", 0) != 0) std::abort();
  }
  return 0;
}
