#pragma once
// The chunk compressions of the MCAP registry: zstd (a standard zstd frame, via libzstd) and
// lz4 (the LZ4 *frame* format, as the reference implementations write it, via liblz4).
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "semap/drivers/mcap_records.hpp"

namespace semap::drivers::mcap {

enum class Compression { kNone, kLz4, kZstd };

// The Chunk `compression` field: "", "lz4", "zstd".
std::string_view compression_name(Compression compression);

// Appends `in` compressed to `out`. `level` is zstd's (1 is its fastest standard level); lz4
// uses its fast default.
void compress(Compression compression, std::span<const std::uint8_t> in, Bytes& out, int level);

// Decompresses a chunk's records that must come out as exactly `uncompressed_size` bytes.
// `compression` is the Chunk's field as read. Throws FormatError naming Chunk.compression
// (unknown name) or Chunk.records (damaged data, wrong size); the caller bounds
// `uncompressed_size` before calling, since that much is allocated.
Bytes decompress(const std::string& compression, std::span<const std::uint8_t> in,
                 std::uint64_t uncompressed_size);

}  // namespace semap::drivers::mcap
