// The one-line intrinsics file parser (`fx fy cx cy [width height]`) on any bytes: camera
// intrinsics a projection can use, or a DatasetError that names the file.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "dataset_fuzz_checks.hpp"
#include "semap/perception/datasets/intrinsics_text.hpp"

namespace pd = semap::perception::datasets;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    semap::fuzz::require_usable(pd::parse_intrinsics_text(text, "intrinsics.txt"));
  } catch (const pd::DatasetError& e) {
    semap::fuzz::require(std::string_view(e.what()).rfind("intrinsics.txt", 0) == 0);
  }
  return 0;
}
