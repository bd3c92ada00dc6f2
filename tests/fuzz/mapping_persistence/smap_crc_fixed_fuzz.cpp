// The .smap reader past its CRCs: the input is a .smap file whose CRC32s (header, each layer
// record, each block record, whole file) are recomputed before decoding, following the
// lengths the (mutated) file itself announces, so mutations of counts, keys, parameters and
// evidence reach the decoder instead of stopping at the first CRC. The reader, strict and
// salvaging, returns a map or throws SmapError; an accepted map re-encodes to a file that
// decodes to the same map; salvage never reports more blocks than the map holds, and a file
// the strict reader accepts is salvaged complete, to the same map; an accepted header holds
// finite parameters.
#include <zlib.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <span>
#include <vector>

#include "semap/mapping/smap_io.hpp"

namespace {

// Walks the layout of mapping/src/smap_io.cpp and rewrites every CRC32 it reaches; stops at
// the first field that does not fit.
class CrcFixer {
 public:
  explicit CrcFixer(std::vector<std::uint8_t>& bytes) : b_(bytes) {}

  void run() {
    // Header: magic(8) version(4) method(1) depth(1) classes(2) channels(4) resolution(8)
    // prior(8) parameter count(4), parameters (name length(2) name value(8)), layers(4), CRC.
    if (!skip(8 + 4 + 1 + 1 + 2 + 4 + 8 + 8)) return;
    std::uint32_t params = 0;
    if (!get(params)) return;
    for (std::uint32_t i = 0; i < params && i < 256; ++i) {
      std::uint16_t length = 0;
      if (!get(length) || !skip(length) || !skip(8)) return;
    }
    std::uint32_t layers = 0;
    if (!get(layers) || !put_crc(0)) return;
    std::uint32_t total = 0;
    for (std::uint32_t layer = 0; layer < layers; ++layer) {
      // Layer: tag(4) source(4) updates(8) block count(4), CRC.
      const std::size_t start = at_;
      std::uint32_t blocks = 0;
      if (!skip(16) || !get(blocks) || !put_crc(start)) return;
      for (std::uint32_t block = 0; block < blocks; ++block) {
        // Block: tag(4) x y z(12) value count(4) values(4 each), CRC.
        const std::size_t block_start = at_;
        std::uint32_t count = 0;
        if (!skip(16) || !get(count) || !skip(std::size_t{count} * 4) || !put_crc(block_start)) {
          return;
        }
        ++total;
      }
    }
    // Footer: tag(4) total(4), CRC of the whole file.
    (void)total;
    if (skip(8)) put_crc(0);
  }

 private:
  bool skip(std::size_t n) {
    if (n > b_.size() - at_) return false;
    at_ += n;
    return true;
  }
  template <typename T>
  bool get(T& value) {
    if (sizeof(T) > b_.size() - at_) return false;
    std::memcpy(&value, b_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return true;
  }
  bool put_crc(std::size_t from) {
    if (4 > b_.size() - at_) return false;
    const auto crc =
        static_cast<std::uint32_t>(::crc32(0L, b_.data() + from, static_cast<uInt>(at_ - from)));
    std::memcpy(b_.data() + at_, &crc, 4);
    at_ += 4;
    return true;
  }

  std::vector<std::uint8_t>& b_;
  std::size_t at_ = 0;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace mp = semap::mapping;
  std::vector<std::uint8_t> bytes(data, data + size);
  CrcFixer(bytes).run();
  std::optional<mp::SmapReadResult> strict;
  try {
    strict = mp::decode_smap(bytes, "fuzz", {.salvage = false});
    const auto again = mp::decode_smap(mp::encode_smap(strict->map), "fuzz-reencoded");
    if (!(again.map == strict->map)) std::abort();
    // An accepted header gives finite parameters (the floats are read from doubles).
    const mp::MapParams& p = strict->map.params();
    for (const float v : {p.resolution, p.prior, p.sf2, p.ell, p.free_res, p.ds_res, p.max_range,
                          p.unknown_variance}) {
      if (!std::isfinite(v)) std::abort();
    }
  } catch (const mp::SmapError&) {
  }
  try {
    const auto salvaged = mp::decode_smap(bytes, "fuzz", {.salvage = true});
    std::size_t held = 0;
    for (const auto& [source, grid] : salvaged.map.layers()) held += grid.size();
    if (salvaged.blocks != held) std::abort();
    if (strict && (!salvaged.complete || !(salvaged.map == strict->map))) std::abort();
    if (salvaged.complete != salvaged.problem.empty()) std::abort();
  } catch (const mp::SmapError&) {
    // Salvage still refuses a file whose header is unreadable.
  }
  return 0;
}
