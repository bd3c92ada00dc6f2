#include "semap/drivers/mcap_stream_reader.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "mcap_bytes.hpp"
#include "mcap_record_codec.hpp"
#include "semap/drivers/mcap_compression.hpp"

namespace semap::drivers::mcap {
namespace {

std::string hex32(std::uint32_t v) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%08x", v);
  return text;
}

std::uint64_t load_u64(const std::uint8_t* in) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | in[i];
  return v;
}

// The records a chunk may hold: the spec names these three; private ones are skipped.
bool allowed_in_chunk(std::uint8_t opcode) {
  const auto op = static_cast<Opcode>(opcode);
  return op == Opcode::kSchema || op == Opcode::kChannel || op == Opcode::kMessage ||
         opcode > static_cast<std::uint8_t>(Opcode::kDataEnd);
}

}  // namespace

McapStreamReader::McapStreamReader(std::span<const std::uint8_t> bytes, std::string name,
                                   McapReaderOptions options)
    : name_(std::move(name)), options_(options), bytes_(bytes), size_(bytes.size()) {}

McapStreamReader::McapStreamReader(const std::filesystem::path& path, McapReaderOptions options)
    : name_(path.string()), options_(options) {
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  struct stat st {};
  if (fd_ < 0 || ::fstat(fd_, &st) != 0) {
    fail(0, std::string("cannot open: ") + std::strerror(errno));
    return;
  }
  size_ = static_cast<std::uint64_t>(st.st_size);
}

McapStreamReader::~McapStreamReader() {
  if (fd_ >= 0) ::close(fd_);
}

std::optional<Record> McapStreamReader::next() {
  if (status_ != McapReadStatus::kReading) return std::nullopt;
  if (chunk_at_ < chunk_records_.size()) return next_in_chunk();
  return next_top_level();
}

std::optional<Record> McapStreamReader::next_in_chunk() {
  in_chunk_ = true;
  record_offset_ = chunk_offset_;
  offset_in_chunk_ = chunk_at_;
  const std::string where = "in the Chunk, record at byte " + std::to_string(chunk_at_) + ": ";
  const std::size_t left = chunk_records_.size() - chunk_at_;
  if (left < kRecordHeadSize) {
    fail(chunk_offset_, where + "record head needs 9 bytes, " + std::to_string(left) + " left");
    return std::nullopt;
  }
  const std::uint8_t opcode = chunk_records_[chunk_at_];
  const std::uint64_t length = load_u64(&chunk_records_[chunk_at_ + 1]);
  if (opcode == 0 || !allowed_in_chunk(opcode)) {
    fail(chunk_offset_, where + "opcode: a " + opcode_name(opcode) + " record (" +
                            std::to_string(opcode) + ") cannot be in a chunk");
    return std::nullopt;
  }
  if (length > left - kRecordHeadSize) {
    fail(chunk_offset_, where + opcode_name(opcode) + " record needs " + std::to_string(length) +
                            " bytes, " + std::to_string(left - kRecordHeadSize) +
                            " left in the chunk");
    return std::nullopt;
  }
  const auto content = std::span<const std::uint8_t>(chunk_records_)
                           .subspan(chunk_at_ + kRecordHeadSize, static_cast<std::size_t>(length));
  chunk_at_ += kRecordHeadSize + static_cast<std::size_t>(length);
  try {
    return decode_record(opcode, content);
  } catch (const FormatError& e) {
    fail(chunk_offset_, where + e.what());
    return std::nullopt;
  }
}

std::optional<Record> McapStreamReader::next_top_level() {
  in_chunk_ = false;
  if (!started_ && offset_ == 0) {
    std::uint8_t magic[kMagic.size()] = {};
    const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(size_, kMagic.size()));
    if (!read(0, n, magic)) return std::nullopt;
    if (!std::equal(magic, magic + n, kMagic.begin())) {
      fail(0, "magic: not an MCAP file (or not major version 0)");
      return std::nullopt;
    }
    if (n < kMagic.size()) {
      truncate(0, "the file ends inside the magic");
      return std::nullopt;
    }
    data_crc_ = crc32_update(0, kMagic);
    offset_ = kMagic.size();
  }
  record_offset_ = offset_;
  const std::uint64_t left = size_ - offset_;
  if (left < kRecordHeadSize) {
    truncate(offset_, left == 0 ? "the file ends without a Footer"
                                : "record head needs 9 bytes, " + std::to_string(left) + " left");
    return std::nullopt;
  }
  std::uint8_t head[kRecordHeadSize];
  if (!read(offset_, kRecordHeadSize, head)) return std::nullopt;
  const std::uint8_t opcode = head[0];
  const std::uint64_t length = load_u64(head + 1);
  if (opcode == 0) {
    fail(offset_, "opcode: 0 is not a record");
    return std::nullopt;
  }
  if (length > left - kRecordHeadSize) {
    truncate(offset_, std::string(opcode_name(opcode)) + " record needs " + std::to_string(length) +
                          " bytes, " + std::to_string(left - kRecordHeadSize) + " left");
    return std::nullopt;
  }
  const auto op = static_cast<Opcode>(opcode);
  if (started_ == (op == Opcode::kHeader)) {
    fail(offset_,
         started_ ? "a second Header record"
                  : std::string("the first record is a ") + opcode_name(opcode) + ", not a Header");
    return std::nullopt;
  }
  started_ = true;
  content_.resize(static_cast<std::size_t>(length));
  if (!read(offset_ + kRecordHeadSize, content_.size(), content_.data())) return std::nullopt;
  const std::uint32_t crc_before = data_crc_;
  if (!data_ended_) data_crc_ = crc32_update(crc32_update(data_crc_, head), content_);
  offset_ += kRecordHeadSize + length;
  try {
    switch (op) {
      case Opcode::kChunk:
        return read_chunk(content_);
      case Opcode::kAttachment: {
        std::span<const std::uint8_t> covered;
        Attachment a = decode_attachment(content_, covered);
        const std::uint32_t crc = crc32_update(0, covered);
        if (options_.validate_crcs && a.crc != 0 && a.crc != crc) {
          fail(record_offset_, "Attachment.crc: " + hex32(a.crc) + ", content gives " + hex32(crc));
          return std::nullopt;
        }
        return a;
      }
      case Opcode::kDataEnd: {
        Record r = decode_record(opcode, content_);
        const std::uint32_t stored = std::get<DataEnd>(r).data_section_crc;
        if (options_.validate_crcs && stored != 0 && stored != crc_before) {
          fail(record_offset_, "DataEnd.data_section_crc: " + hex32(stored) +
                                   ", data section gives " + hex32(crc_before));
          return std::nullopt;
        }
        data_ended_ = true;
        return r;
      }
      case Opcode::kFooter: {
        Record r = decode_record(opcode, content_);
        check_footer(std::get<Footer>(r));
        if (status_ == McapReadStatus::kError) return std::nullopt;
        return r;
      }
      default:
        return decode_record(opcode, content_);
    }
  } catch (const FormatError& e) {
    fail(record_offset_ + kRecordHeadSize + e.at(), e.what());
    return std::nullopt;
  }
}

Record McapStreamReader::read_chunk(std::span<const std::uint8_t> content) {
  std::span<const std::uint8_t> records;
  Chunk chunk = decode_chunk(content, records);
  if (chunk.uncompressed_size > options_.max_chunk_size) {
    throw FormatError("Chunk.uncompressed_size", 16,
                      std::to_string(chunk.uncompressed_size) + " bytes exceed the reader's " +
                          std::to_string(options_.max_chunk_size));
  }
  chunk_records_ = decompress(chunk.compression, records, chunk.uncompressed_size);
  if (options_.validate_crcs && chunk.uncompressed_crc != 0) {
    const std::uint32_t crc = crc32_update(0, chunk_records_);
    if (crc != chunk.uncompressed_crc) {
      chunk_records_.clear();
      throw FormatError("Chunk.uncompressed_crc", 24,
                        hex32(chunk.uncompressed_crc) + ", records give " + hex32(crc));
    }
  }
  chunk_at_ = 0;
  chunk_offset_ = record_offset_;
  return chunk;
}

void McapStreamReader::check_footer(const Footer& footer) {
  const std::uint64_t footer_at = record_offset_;
  if (footer.summary_start > footer_at) {
    throw FormatError("Footer.summary_start", 0,
                      std::to_string(footer.summary_start) + " is past the Footer");
  }
  if (footer.summary_offset_start > footer_at) {
    throw FormatError("Footer.summary_offset_start", 8,
                      std::to_string(footer.summary_offset_start) + " is past the Footer");
  }
  if (options_.validate_crcs && footer.summary_crc != 0) {
    // From the summary (or the Footer when there is none) through summary_offset_start.
    std::uint64_t at = footer.summary_start != 0 ? footer.summary_start : footer_at;
    const std::uint64_t end = footer_at + kRecordHeadSize + 16;
    std::uint32_t crc = 0;
    std::uint8_t piece[64 * 1024];
    while (at < end) {
      const auto n = static_cast<std::size_t>(std::min<std::uint64_t>(sizeof piece, end - at));
      if (!read(at, n, piece)) return;
      crc = crc32_update(crc, {piece, n});
      at += n;
    }
    if (crc != footer.summary_crc) {
      throw FormatError("Footer.summary_crc", 16,
                        hex32(footer.summary_crc) + ", summary gives " + hex32(crc));
    }
  }
  const std::uint64_t left = size_ - offset_;
  std::uint8_t magic[kMagic.size()] = {};
  const auto n = static_cast<std::size_t>(std::min<std::uint64_t>(left, kMagic.size()));
  if (!read(offset_, n, magic)) return;
  if (!std::equal(magic, magic + n, kMagic.begin())) {
    fail(offset_, "magic: the Footer is not followed by the closing magic");
  } else if (n < kMagic.size()) {
    truncate(offset_, "the file ends inside the closing magic");
  } else if (left > kMagic.size()) {
    fail(offset_ + kMagic.size(),
         std::to_string(left - kMagic.size()) + " bytes after the closing magic");
  } else {
    offset_ += kMagic.size();
    status_ = McapReadStatus::kEnd;
  }
}

bool McapStreamReader::read(std::uint64_t at, std::size_t n, std::uint8_t* out) {
  if (fd_ < 0) {
    if (n > 0) std::memcpy(out, bytes_.data() + at, n);
    return true;
  }
  std::size_t done = 0;
  while (done < n) {
    const ssize_t got = ::pread(fd_, out + done, n - done, static_cast<off_t>(at + done));
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) {
      fail(at + done, std::string("read: ") + std::strerror(errno));
      return false;
    }
    if (got == 0) {  // the file shrank while being read
      truncate(at + done, "the file ends while being read");
      return false;
    }
    done += static_cast<std::size_t>(got);
  }
  return true;
}

void McapStreamReader::fail(std::uint64_t at, const std::string& what) {
  status_ = McapReadStatus::kError;
  error_ = name_ + ": byte " + std::to_string(at) + ": " + what;
}

void McapStreamReader::truncate(std::uint64_t at, const std::string& what) {
  status_ = McapReadStatus::kTruncated;
  truncated_at_ = at;
  error_ = name_ + ": truncated at byte " + std::to_string(at) + ": " + what;
}

}  // namespace semap::drivers::mcap
