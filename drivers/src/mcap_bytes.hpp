#pragma once
// Little-endian fields of MCAP records: appending them to a buffer and reading them from one
// with every length checked against the bytes left, plus the CRC-32 the format uses.
#include <zlib.h>

#include <cstdint>
#include <cstring>
#include <map>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "semap/drivers/mcap_records.hpp"

namespace semap::drivers::mcap {

// Bad bytes in a record: `field` names it as "Record.field", `at` is the byte of the field
// within the bytes being read (the reader turns it into a file offset).
class FormatError : public std::runtime_error {
 public:
  FormatError(const std::string& field, std::uint64_t at, const std::string& what)
      : std::runtime_error(field + ": " + what), at_(at) {}
  std::uint64_t at() const { return at_; }

 private:
  std::uint64_t at_;
};

// zlib's crc32 is the IEEE CRC-32 of the specification; chained over parts like one buffer.
inline std::uint32_t crc32_update(std::uint32_t crc, std::span<const std::uint8_t> bytes) {
  // zlib takes a uInt length: feed huge spans in pieces.
  while (!bytes.empty()) {
    const std::size_t n = std::min<std::size_t>(bytes.size(), 1u << 30);
    crc = static_cast<std::uint32_t>(::crc32(crc, bytes.data(), static_cast<uInt>(n)));
    bytes = bytes.subspan(n);
  }
  return crc;
}

inline void put_u8(Bytes& out, std::uint8_t v) { out.push_back(v); }
inline void put_le(Bytes& out, std::uint64_t v, int size) {
  for (int i = 0; i < size; ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}
inline void put_u16(Bytes& out, std::uint16_t v) { put_le(out, v, 2); }
inline void put_u32(Bytes& out, std::uint32_t v) { put_le(out, v, 4); }
inline void put_u64(Bytes& out, std::uint64_t v) { put_le(out, v, 8); }
inline void put_bytes(Bytes& out, std::span<const std::uint8_t> bytes) {
  out.insert(out.end(), bytes.begin(), bytes.end());
}
inline void put_string(Bytes& out, std::string_view s) {
  put_u32(out, static_cast<std::uint32_t>(s.size()));
  out.insert(out.end(), s.begin(), s.end());
}
inline void put_string_map(Bytes& out, const StringMap& map) {
  std::size_t size = 0;
  for (const auto& [key, value] : map) size += 8 + key.size() + value.size();
  put_u32(out, static_cast<std::uint32_t>(size));
  for (const auto& [key, value] : map) {
    put_string(out, key);
    put_string(out, value);
  }
}

// Starts a record: opcode and a length to be set by end_record once the content is in.
inline std::size_t begin_record(Bytes& out, Opcode op) {
  put_u8(out, static_cast<std::uint8_t>(op));
  put_u64(out, 0);
  return out.size();
}
inline void end_record(Bytes& out, std::size_t content_start) {
  const std::uint64_t length = out.size() - content_start;
  for (int i = 0; i < 8; ++i) {
    out[content_start - 8 + static_cast<std::size_t>(i)] =
        static_cast<std::uint8_t>(length >> (8 * i));
  }
}

// Reads the fields of one record's content front to back. A field that does not fit in what
// is left throws FormatError naming "<record>.<field>"; unread bytes at the end (fields of a
// newer version, padding) are ignored by the callers.
class ByteReader {
 public:
  ByteReader(std::span<const std::uint8_t> bytes, const char* record)
      : bytes_(bytes), record_(record) {}

  std::uint8_t u8(const char* field) { return static_cast<std::uint8_t>(le(field, 1)); }
  std::uint16_t u16(const char* field) { return static_cast<std::uint16_t>(le(field, 2)); }
  std::uint32_t u32(const char* field) { return static_cast<std::uint32_t>(le(field, 4)); }
  std::uint64_t u64(const char* field) { return le(field, 8); }

  // `n` bytes; a shortfall is reported at `start`, where the field (with its length) began.
  std::span<const std::uint8_t> take(const char* field, std::uint64_t n) {
    return take_from(at_, field, n);
  }
  std::string string(const char* field) {
    const auto raw = prefixed(field, 4);
    return {raw.begin(), raw.end()};
  }
  Bytes bytes32(const char* field) { return to_bytes(prefixed(field, 4)); }
  Bytes bytes64(const char* field) { return to_bytes(prefixed(field, 8)); }
  // A field of `length_size` bytes of length and then that many bytes.
  std::span<const std::uint8_t> prefixed(const char* field, int length_size) {
    const std::size_t start = at_;
    return take_from(start, field, le(field, length_size));
  }
  std::span<const std::uint8_t> rest() { return take("rest", left()); }

  StringMap string_map(const char* field) {
    ByteReader entries(prefixed(field, 4), record_);
    entries.base_ = base_ + at_ - entries.bytes_.size();
    StringMap out;
    while (entries.left() > 0) {
      std::string key = entries.string(field);
      out[std::move(key)] = entries.string(field);
    }
    return out;
  }
  ChannelCounts u16_u64_map(const char* field) {
    ByteReader entries(prefixed(field, 4), record_);
    entries.base_ = base_ + at_ - entries.bytes_.size();
    ChannelCounts out;
    while (entries.left() > 0) {
      const std::uint16_t key = entries.u16(field);
      out[key] = entries.u64(field);
    }
    return out;
  }

  std::size_t left() const { return bytes_.size() - at_; }
  std::size_t position() const { return at_; }

 private:
  std::span<const std::uint8_t> take_from(std::size_t start, const char* field, std::uint64_t n) {
    if (n > left()) {
      throw FormatError(std::string(record_) + "." + field, base_ + start,
                        "needs " + std::to_string(n) + " bytes, " + std::to_string(left()) +
                            " left in the record");
    }
    const auto out = bytes_.subspan(at_, static_cast<std::size_t>(n));
    at_ += static_cast<std::size_t>(n);
    return out;
  }
  std::uint64_t le(const char* field, int size) {
    const auto raw = take(field, static_cast<std::uint64_t>(size));
    std::uint64_t v = 0;
    for (int i = size - 1; i >= 0; --i) v = (v << 8) | raw[static_cast<std::size_t>(i)];
    return v;
  }
  static Bytes to_bytes(std::span<const std::uint8_t> raw) { return {raw.begin(), raw.end()}; }

  std::span<const std::uint8_t> bytes_;
  const char* record_;
  std::size_t at_ = 0;
  std::size_t base_ = 0;  // where bytes_ starts in the record (for a map's entries)
};

}  // namespace semap::drivers::mcap
