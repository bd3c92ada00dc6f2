// The Redwood / Open3D text files on any bytes; the first byte picks a .log trajectory or
// rgbd.match. Bad lines are problems named "name:line", never exceptions; every pose handed
// out is rigid, entries keep their file order.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "dataset_fuzz_checks.hpp"
#include "semap/perception/datasets/redwood_files.hpp"

namespace pd = semap::perception::datasets;
using semap::fuzz::require;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data) + 1, size - 1);
  int previous = 0;
  if (data[0] % 2 == 0) {
    const pd::RedwoodLog log = pd::parse_redwood_log(text, "odometry.log");
    semap::fuzz::require_named(log.problems, "odometry.log");
    for (const pd::RedwoodLogEntry& e : log.entries) {
      require(e.line > previous);
      previous = e.line;
      if (e.world_from_camera) semap::fuzz::require_rigid(*e.world_from_camera);
    }
  } else {
    const pd::RgbdMatch match = pd::parse_rgbd_match(text, "rgbd.match");
    semap::fuzz::require_named(match.problems, "rgbd.match");
    for (const pd::RgbdMatchEntry& e : match.entries) {
      require(e.line > previous && !e.depth.empty() && !e.colour.empty());
      previous = e.line;
    }
  }
  return 0;
}
