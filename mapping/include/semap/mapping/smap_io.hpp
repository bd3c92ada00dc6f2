#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "semap/mapping/layered_map.hpp"

namespace semap::mapping {

// A .smap file that cannot be read; the message names the file, the byte offset and, past the
// header, the layer and block where reading stopped.
class SmapError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct SmapReadOptions {
  // Return the blocks read before the first damaged one instead of throwing. The header must
  // still be intact; the result says what was lost.
  bool salvage = false;
};

struct SmapReadResult {
  explicit SmapReadResult(LayeredMap loaded) : map(std::move(loaded)) {}

  LayeredMap map;
  bool complete = true;  // false: salvaged, `problem` says where and why reading stopped
  std::string problem;
  std::size_t blocks = 0;  // blocks loaded over all layers
};

inline constexpr std::uint32_t kSmapVersion = 1;

// The .smap layout (little-endian; docs/map-files.md): magic, version, header with method,
// resolution, block depth, classes and named parameters, header CRC32; per evidence layer a
// record (source robot, update count, block count, CRC32) followed by its blocks (key, dense
// floats, CRC32); a footer with the block total and the CRC32 of the whole file.
std::vector<std::uint8_t> encode_smap(const LayeredMap& map);
// `name` is used in error messages (usually the file path).
SmapReadResult decode_smap(std::span<const std::uint8_t> bytes, const std::string& name,
                           const SmapReadOptions& options = {});

// Crash-safe write (see write_file_atomically).
void write_smap(const std::filesystem::path& path, const LayeredMap& map);
SmapReadResult read_smap(const std::filesystem::path& path, const SmapReadOptions& options = {});

}  // namespace semap::mapping
