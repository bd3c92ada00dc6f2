#include "semap/drivers/stream_log.hpp"

#include <array>
#include <cstring>
#include <stdexcept>

#include "semap/drivers/frame_convert.hpp"

namespace semap::drivers {
namespace {

constexpr std::array<char, 8> kMagic{'S', 'E', 'M', 'A', 'P', 'L', 'O', 'G'};
constexpr std::uint32_t kVersion = 1;

void store_u32(std::uint8_t* out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
void store_i64(std::uint8_t* out, std::int64_t v) {
  const auto u = static_cast<std::uint64_t>(v);
  for (int i = 0; i < 8; ++i) out[i] = static_cast<std::uint8_t>(u >> (8 * i));
}
std::uint32_t load_u32(const std::uint8_t* in) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | in[i];
  return v;
}
std::int64_t load_i64(const std::uint8_t* in) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | in[i];
  return static_cast<std::int64_t>(v);
}

// 0 for compressed formats, whose rows are not in the record.
std::uint32_t bytes_per_pixel(common::PixelFormat format) {
  switch (format) {
    case common::PixelFormat::kGrey:
      return 1;
    case common::PixelFormat::kYuyv:
    case common::PixelFormat::kZ16:
      return 2;
    case common::PixelFormat::kBgr24:
      return 3;
    case common::PixelFormat::kMjpeg:
      return 0;
  }
  return 0;
}

// Fixed part of a frame record after the stamp: sequence, fourcc, width, height, stride, length.
constexpr std::size_t kFrameFields = 6;

std::vector<std::uint8_t> stream_log_header(StreamLogKind kind) {
  std::vector<std::uint8_t> header(16);
  std::memcpy(header.data(), kMagic.data(), kMagic.size());
  store_u32(header.data() + 8, static_cast<std::uint32_t>(kind));
  store_u32(header.data() + 12, kVersion);
  return header;
}

}  // namespace

StreamLogWriter::StreamLogWriter(const std::filesystem::path& path, StreamLogKind kind,
                                 std::chrono::steady_clock::duration retry_after)
    : kind_(kind), file_(path, stream_log_header(kind), retry_after) {}

bool StreamLogWriter::write_bytes(common::Stamp stamp, std::span<const std::uint8_t> bytes) {
  if (kind_ != StreamLogKind::kBytes || bytes.size() > kStreamLogMaxChunk) return false;
  std::array<std::uint8_t, 12> head{};
  store_i64(head.data(), stamp.ns);
  store_u32(head.data() + 8, static_cast<std::uint32_t>(bytes.size()));
  return file_.append(head, bytes);
}

bool StreamLogWriter::write_frame(const common::ImageFrame& frame) {
  if (kind_ != StreamLogKind::kFrames || frame.data.size() > kStreamLogMaxFrame) return false;
  std::array<std::uint8_t, 8 + 4 * kFrameFields> head{};
  store_i64(head.data(), frame.stamp.ns);
  const std::array<std::uint32_t, kFrameFields> fields{
      frame.sequence, to_fourcc(frame.format),
      frame.width,    frame.height,
      frame.stride,   static_cast<std::uint32_t>(frame.data.size())};
  for (std::size_t i = 0; i < fields.size(); ++i) store_u32(head.data() + 8 + 4 * i, fields[i]);
  return file_.append(head, frame.data);
}

StreamLogReader::StreamLogReader(std::istream& in, std::string name, StreamLogKind kind)
    : in_(in), name_(std::move(name)), kind_(kind) {
  std::array<std::uint8_t, 16> header{};
  if (!read(header.data(), header.size(), "header", true)) {
    if (error_.empty()) fail("header", "empty log");
    return;
  }
  if (std::memcmp(header.data(), kMagic.data(), kMagic.size()) != 0) {
    fail("header", "not a semap stream log (no SEMAPLOG magic)");
  } else if (load_u32(header.data() + 8) != static_cast<std::uint32_t>(kind)) {
    fail("kind",
         std::string("expected a log of ") + (kind == StreamLogKind::kBytes ? "bytes" : "frames"));
  } else if (const std::uint32_t version = load_u32(header.data() + 12); version != kVersion) {
    fail("version", std::to_string(version) + " is not 1");
  }
}

void StreamLogReader::fail(const std::string& field, const std::string& what) {
  if (!error_.empty()) return;
  error_ = name_ + ": ";
  if (field == "header" || field == "kind" || field == "version") {
    error_ += field + ": " + what;
  } else {
    error_ += "record " + std::to_string(records_ + 1) + " at byte " +
              std::to_string(record_start_) + ": " + field + ": " + what;
  }
}

bool StreamLogReader::read(void* out, std::size_t len, const char* field, bool first) {
  if (!error_.empty()) return false;
  in_.read(static_cast<char*>(out), static_cast<std::streamsize>(len));
  const auto got = static_cast<std::size_t>(in_.gcount());
  offset_ += got;
  if (got == len) return true;
  if (!(first && got == 0)) {
    fail(field, "truncated (" + std::to_string(got) + " of " + std::to_string(len) + " bytes)");
  }
  return false;
}

std::optional<ByteChunk> StreamLogReader::next_bytes() {
  if (kind_ != StreamLogKind::kBytes) return std::nullopt;
  record_start_ = offset_;
  std::array<std::uint8_t, 12> head{};
  if (!read(head.data(), head.size(), "stamp", true)) return std::nullopt;
  ByteChunk chunk;
  chunk.stamp = common::Stamp(load_i64(head.data()));
  const std::uint32_t length = load_u32(head.data() + 8);
  if (length > kStreamLogMaxChunk) {
    fail("length", std::to_string(length) + " beyond " + std::to_string(kStreamLogMaxChunk));
    return std::nullopt;
  }
  chunk.bytes.resize(length);
  if (!read(chunk.bytes.data(), length, "bytes")) return std::nullopt;
  ++records_;
  return chunk;
}

std::optional<common::ImageFrame> StreamLogReader::next_frame() {
  if (kind_ != StreamLogKind::kFrames) return std::nullopt;
  record_start_ = offset_;
  std::array<std::uint8_t, 8 + 4 * kFrameFields> head{};
  if (!read(head.data(), head.size(), "stamp", true)) return std::nullopt;
  common::ImageFrame frame;
  frame.stamp = common::Stamp(load_i64(head.data()));
  frame.sequence = load_u32(head.data() + 8);
  const std::uint32_t fourcc = load_u32(head.data() + 12);
  frame.width = load_u32(head.data() + 16);
  frame.height = load_u32(head.data() + 20);
  frame.stride = load_u32(head.data() + 24);
  const std::uint32_t length = load_u32(head.data() + 28);
  const auto format = from_fourcc(fourcc);
  if (!format) {
    fail(
        "fourcc", "0x" + [&] {
          char hex[9];
          std::snprintf(hex, sizeof(hex), "%08x", fourcc);
          return std::string(hex);
        }() + " is not a pixel format semap reads");
    return std::nullopt;
  }
  frame.format = *format;
  if (frame.width == 0 || frame.width > kStreamLogMaxSide) {
    fail("width", std::to_string(frame.width) + " outside 1.." + std::to_string(kStreamLogMaxSide));
    return std::nullopt;
  }
  if (frame.height == 0 || frame.height > kStreamLogMaxSide) {
    fail("height",
         std::to_string(frame.height) + " outside 1.." + std::to_string(kStreamLogMaxSide));
    return std::nullopt;
  }
  if (length > kStreamLogMaxFrame) {
    fail("length", std::to_string(length) + " beyond " + std::to_string(kStreamLogMaxFrame));
    return std::nullopt;
  }
  frame.data.resize(length);
  if (!read(frame.data.data(), length, "data")) return std::nullopt;
  // A raw frame must hold its rows; a shorter one would be read past its end downstream.
  if (const std::uint32_t row = bytes_per_pixel(frame.format) * frame.width; frame.stride < row) {
    fail("stride",
         std::to_string(frame.stride) + " below the row's " + std::to_string(row) + " bytes");
    return std::nullopt;
  }
  if (const std::size_t need = expected_size(frame); length < need) {
    fail("length", std::to_string(length) + " below stride x height " + std::to_string(need));
    return std::nullopt;
  }
  ++records_;
  return frame;
}

}  // namespace semap::drivers
