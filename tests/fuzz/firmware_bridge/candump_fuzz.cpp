// candump -L log reader: any bytes as a log. Records up to the first damage come out, each one
// formats back to a line that parses to the same record; damage leaves an error naming a line.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>

#include "semap/firmware_bridge/candump_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace semap::firmware_bridge;
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  CandumpReader reader(in, "fuzz.log");
  std::uint64_t records = 0;
  while (const auto record = reader.next()) {
    ++records;
    if (record->frame.len > SEMAP_CANFD_MAX_DLEN) std::abort();
    const std::string line = format_candump_line(*record);
    SemapCandumpRecord again;
    if (semap_candump_parse_line(line.data(), line.size() - 1, &again).status != SEMAP_FB_OK ||
        std::memcmp(&again, &*record, sizeof again) != 0) {
      std::abort();
    }
  }
  if (records > reader.line()) std::abort();
  if (!reader.error().empty() && reader.error().rfind("fuzz.log:", 0) != 0) std::abort();
  return 0;
}
