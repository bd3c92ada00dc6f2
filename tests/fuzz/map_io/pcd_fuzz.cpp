// Feeds arbitrary bytes to the PCD parser: it must either return a consistent cloud or throw
// PcdError, never crash, hang or over-allocate.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "semap/map_io/pcd_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    const auto scan = semap::map_io::parse_pcd(bytes, "fuzz.pcd");
    const auto& c = scan.cloud;
    const bool consistent =
        c.has_probabilities()
            ? c.probabilities.size() == c.points.size() * c.num_classes && c.labels.empty()
            : c.labels.size() == c.points.size();
    if (!consistent) std::abort();
  } catch (const semap::map_io::PcdError&) {
  }
  return 0;
}
