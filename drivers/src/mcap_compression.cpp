#include "semap/drivers/mcap_compression.hpp"

#include <lz4frame.h>
#include <zstd.h>

#include <memory>

#include "mcap_bytes.hpp"

namespace semap::drivers::mcap {
namespace {

[[noreturn]] void bad_records(const std::string& what) {
  throw FormatError("Chunk.records", 0, what);
}

void compress_zstd(std::span<const std::uint8_t> in, Bytes& out, int level) {
  const std::size_t start = out.size();
  out.resize(start + ZSTD_compressBound(in.size()));
  const std::size_t n =
      ZSTD_compress(out.data() + start, out.size() - start, in.data(), in.size(), level);
  // Only a bug (a bound too small, a bad level) can make this fail.
  if (ZSTD_isError(n)) throw std::logic_error(std::string("zstd: ") + ZSTD_getErrorName(n));
  out.resize(start + n);
}

void compress_lz4(std::span<const std::uint8_t> in, Bytes& out) {
  LZ4F_preferences_t prefs{};
  prefs.frameInfo.contentSize = in.size();  // lets readers check the size before inflating
  const std::size_t start = out.size();
  out.resize(start + LZ4F_compressFrameBound(in.size(), &prefs));
  const std::size_t n =
      LZ4F_compressFrame(out.data() + start, out.size() - start, in.data(), in.size(), &prefs);
  if (LZ4F_isError(n)) throw std::logic_error(std::string("lz4: ") + LZ4F_getErrorName(n));
  out.resize(start + n);
}

Bytes decompress_zstd(std::span<const std::uint8_t> in, std::uint64_t size) {
  Bytes out(static_cast<std::size_t>(size));
  const std::size_t n = ZSTD_decompress(out.data(), out.size(), in.data(), in.size());
  if (ZSTD_isError(n)) bad_records(std::string("zstd: ") + ZSTD_getErrorName(n));
  if (n != size) {
    bad_records("zstd data holds " + std::to_string(n) + " bytes, uncompressed_size says " +
                std::to_string(size));
  }
  return out;
}

Bytes decompress_lz4(std::span<const std::uint8_t> in, std::uint64_t size) {
  LZ4F_dctx* raw = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&raw, LZ4F_VERSION))) {
    throw std::bad_alloc();
  }
  const std::unique_ptr<LZ4F_dctx, decltype(&LZ4F_freeDecompressionContext)> dctx(
      raw, &LZ4F_freeDecompressionContext);
  Bytes out(static_cast<std::size_t>(size));
  std::size_t in_at = 0;
  std::size_t out_at = 0;
  std::size_t hint = 0;  // 0 once a frame is complete
  // A file may hold several frames back to back; each call goes on where the last stopped.
  while (in_at < in.size()) {
    std::size_t out_n = out.size() - out_at;
    std::size_t in_n = in.size() - in_at;
    hint =
        LZ4F_decompress(dctx.get(), out.data() + out_at, &out_n, in.data() + in_at, &in_n, nullptr);
    if (LZ4F_isError(hint)) bad_records(std::string("lz4: ") + LZ4F_getErrorName(hint));
    in_at += in_n;
    out_at += out_n;
    // No progress: the frame wants more output room than uncompressed_size leaves.
    if (in_n == 0 && out_n == 0) {
      bad_records("lz4 data holds more than uncompressed_size " + std::to_string(size) + " bytes");
    }
  }
  if (hint != 0) bad_records("lz4 frame cut short or longer than uncompressed_size");
  if (out_at != size) {
    bad_records("lz4 data holds " + std::to_string(out_at) + " bytes, uncompressed_size says " +
                std::to_string(size));
  }
  return out;
}

}  // namespace

std::string_view compression_name(Compression compression) {
  switch (compression) {
    case Compression::kNone:
      return "";
    case Compression::kLz4:
      return "lz4";
    case Compression::kZstd:
      return "zstd";
  }
  return "";
}

void compress(Compression compression, std::span<const std::uint8_t> in, Bytes& out, int level) {
  switch (compression) {
    case Compression::kNone:
      put_bytes(out, in);
      return;
    case Compression::kLz4:
      compress_lz4(in, out);
      return;
    case Compression::kZstd:
      compress_zstd(in, out, level);
      return;
  }
}

Bytes decompress(const std::string& compression, std::span<const std::uint8_t> in,
                 std::uint64_t uncompressed_size) {
  if (compression.empty()) {
    if (in.size() != uncompressed_size) {
      bad_records("uncompressed records hold " + std::to_string(in.size()) +
                  " bytes, uncompressed_size says " + std::to_string(uncompressed_size));
    }
    return {in.begin(), in.end()};
  }
  if (compression == "zstd") return decompress_zstd(in, uncompressed_size);
  if (compression == "lz4") return decompress_lz4(in, uncompressed_size);
  throw FormatError("Chunk.compression", 0, "unknown compression '" + compression + "'");
}

}  // namespace semap::drivers::mcap
