// Open3D's intrinsic JSON parser on any bytes: camera intrinsics a projection can use, or a
// DatasetError that names the file; no other exception, crash or hang.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "dataset_fuzz_checks.hpp"
#include "semap/perception/datasets/redwood_files.hpp"

namespace pd = semap::perception::datasets;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view json(reinterpret_cast<const char*>(data), size);
  try {
    semap::fuzz::require_usable(pd::parse_open3d_intrinsics(json, "camera.json"));
  } catch (const pd::DatasetError& e) {
    semap::fuzz::require(std::string_view(e.what()).rfind("camera.json", 0) == 0);
  }
  return 0;
}
