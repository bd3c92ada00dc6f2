#include "semap/drivers/mcap_writer.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "mcap_bytes.hpp"
#include "mcap_record_codec.hpp"

namespace semap::drivers::mcap {
namespace {

constexpr std::size_t kMaxIds = 65535;  // ids are u16 and 0 is reserved

[[noreturn]] void throw_write_error(const std::filesystem::path& path, const char* call,
                                    int error) {
  throw McapWriteError(path.string() + ": " + call + ": " + std::strerror(error), error);
}

}  // namespace

McapWriter::McapWriter(std::filesystem::path path, McapWriterOptions options)
    : path_(std::move(path)), options_(std::move(options)) {
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) throw_write_error(path_, "cannot create", errno);
  Bytes start(kMagic.begin(), kMagic.end());
  encode(start, Header{options_.profile, "semap " SEMAP_VERSION});
  try {
    append(start);
  } catch (...) {
    ::close(fd_);
    throw;
  }
}

McapWriter::~McapWriter() {
  try {
    close();
  } catch (const std::exception&) {
    // The file ends after its last whole chunk; close() reports this to callers that ask.
  }
  if (fd_ >= 0) ::close(fd_);
}

std::uint16_t McapWriter::add_schema(std::string name, std::string encoding,
                                     std::span<const std::uint8_t> data) {
  if (schemas_.size() >= kMaxIds) throw std::length_error("MCAP: more than 65535 schemas");
  const auto id = static_cast<std::uint16_t>(schemas_.size() + 1);
  schemas_.push_back(Schema{id, std::move(name), std::move(encoding), {data.begin(), data.end()}});
  return id;
}

std::uint16_t McapWriter::add_channel(std::uint16_t schema_id, std::string topic,
                                      std::string message_encoding, StringMap metadata) {
  if (channels_.size() >= kMaxIds) throw std::length_error("MCAP: more than 65535 channels");
  if (schema_id > schemas_.size()) {
    throw std::invalid_argument("MCAP channel '" + topic + "': no schema " +
                                std::to_string(schema_id));
  }
  const auto id = static_cast<std::uint16_t>(channels_.size() + 1);
  channels_.push_back(
      Channel{id, schema_id, std::move(topic), std::move(message_encoding), std::move(metadata)});
  return id;
}

void McapWriter::ensure_channel_in_chunk(std::uint16_t channel_id) {
  if (file_channels_.contains(channel_id) || chunk_channels_.contains(channel_id)) return;
  const Channel& channel = channels_[channel_id - 1u];
  const std::uint16_t schema_id = channel.schema_id;
  if (schema_id != 0 && !file_schemas_.contains(schema_id) && !chunk_schemas_.contains(schema_id)) {
    encode(chunk_records_, schemas_[schema_id - 1u]);
    chunk_schemas_.insert(schema_id);
  }
  encode(chunk_records_, channel);
  chunk_channels_.insert(channel_id);
}

void McapWriter::write(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time_ns,
                       std::uint64_t publish_time_ns, std::span<const std::uint8_t> data) {
  if (closed_) throw std::logic_error(path_.string() + ": MCAP write after close");
  if (channel_id == 0 || channel_id > channels_.size()) {
    throw std::invalid_argument(path_.string() + ": MCAP write on unknown channel " +
                                std::to_string(channel_id));
  }
  ensure_channel_in_chunk(channel_id);
  const std::uint64_t offset = chunk_records_.size();
  encode_message(chunk_records_, channel_id, sequence, log_time_ns, publish_time_ns, data);
  auto index = std::find_if(chunk_indexes_.begin(), chunk_indexes_.end(),
                            [&](const MessageIndex& m) { return m.channel_id == channel_id; });
  if (index == chunk_indexes_.end()) {
    index = chunk_indexes_.insert(chunk_indexes_.end(), MessageIndex{channel_id, {}});
  }
  index->records.emplace_back(log_time_ns, offset);
  chunk_start_time_ = chunk_messages_ == 0 ? log_time_ns : std::min(chunk_start_time_, log_time_ns);
  chunk_end_time_ = chunk_messages_ == 0 ? log_time_ns : std::max(chunk_end_time_, log_time_ns);
  ++chunk_messages_;
  const bool full = chunk_records_.size() >= options_.chunk_size;
  const bool long_enough = options_.chunk_duration_ns != 0 &&
                           chunk_end_time_ - chunk_start_time_ >= options_.chunk_duration_ns;
  if (full || long_enough) write_chunk();
}

void McapWriter::flush() {
  if (!closed_) write_chunk();
}

void McapWriter::write_chunk() {
  if (chunk_records_.empty()) return;
  Chunk chunk;
  // A chunk of Schema and Channel records only has no time span; readers that use the index
  // (@mcap/core) reject one that claims the last chunk's times without message indexes.
  chunk.message_start_time = chunk_messages_ > 0 ? chunk_start_time_ : 0;
  chunk.message_end_time = chunk_messages_ > 0 ? chunk_end_time_ : 0;
  chunk.uncompressed_size = chunk_records_.size();
  chunk.uncompressed_crc = crc32_update(0, chunk_records_);
  chunk.compression = compression_name(options_.compression);
  scratch_.clear();
  if (options_.compression == Compression::kNone) {
    encode_chunk(scratch_, chunk, chunk_records_);
  } else {
    compressed_.clear();
    compress(options_.compression, chunk_records_, compressed_, options_.zstd_level);
    encode_chunk(scratch_, chunk, compressed_);
  }

  ChunkIndex entry;
  entry.message_start_time = chunk.message_start_time;
  entry.message_end_time = chunk.message_end_time;
  entry.chunk_start_offset = file_size_;
  entry.chunk_length = scratch_.size();
  entry.compression = chunk.compression;
  entry.compressed_size =
      options_.compression == Compression::kNone ? chunk_records_.size() : compressed_.size();
  entry.uncompressed_size = chunk.uncompressed_size;
  for (const MessageIndex& index : chunk_indexes_) {
    entry.message_index_offsets[index.channel_id] = file_size_ + scratch_.size();
    encode(scratch_, index);
  }
  entry.message_index_length = scratch_.size() - entry.chunk_length;

  // The open chunk is over whether or not it reaches the file.
  const std::uint64_t messages = chunk_messages_;
  const std::vector<MessageIndex> indexes = std::move(chunk_indexes_);
  const std::set<std::uint16_t> schemas = std::move(chunk_schemas_);
  const std::set<std::uint16_t> channels = std::move(chunk_channels_);
  chunk_records_.clear();
  chunk_indexes_.clear();
  chunk_schemas_.clear();
  chunk_channels_.clear();
  chunk_messages_ = 0;
  try {
    append(scratch_);
  } catch (const McapWriteError&) {
    messages_lost_ += messages;
    throw;
  }
  file_schemas_.insert(schemas.begin(), schemas.end());
  file_channels_.insert(channels.begin(), channels.end());
  if (messages > 0) {
    const bool first = stats_.message_count == 0;
    stats_.message_start_time = first
                                    ? entry.message_start_time
                                    : std::min(stats_.message_start_time, entry.message_start_time);
    stats_.message_end_time =
        first ? entry.message_end_time : std::max(stats_.message_end_time, entry.message_end_time);
  }
  stats_.message_count += messages;
  for (const MessageIndex& index : indexes) {
    stats_.channel_message_counts[index.channel_id] += index.records.size();
  }
  ++stats_.chunk_count;
  chunk_index_.push_back(std::move(entry));
  if (options_.sync_each_chunk && ::fdatasync(fd_) != 0)
    throw_write_error(path_, "fdatasync", errno);
}

void McapWriter::append(std::span<const std::uint8_t> bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::pwrite(fd_, bytes.data() + done, bytes.size() - done,
                               static_cast<off_t>(file_size_ + done));
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    const int error = n == 0 ? ENOSPC : errno;
    // Cut the torn part off again: the file keeps ending after a whole chunk. A file that
    // cannot be cut (a device such as /dev/full) has nothing whole to keep anyway.
    if (done > 0) (void)::ftruncate(fd_, static_cast<off_t>(file_size_));
    throw_write_error(path_, "write", error);
  }
  data_crc_ = crc32_update(data_crc_, bytes);
  file_size_ += bytes.size();
}

void McapWriter::close() {
  if (closed_) return;
  closed_ = true;
  // A declared channel without messages is still listed, so a reader sees every topic.
  for (const Channel& channel : channels_) ensure_channel_in_chunk(channel.id);
  write_chunk();
  write_summary_and_footer();
  if (options_.sync_each_chunk && ::fdatasync(fd_) != 0)
    throw_write_error(path_, "fdatasync", errno);
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) throw_write_error(path_, "close", errno);
}

void McapWriter::write_summary_and_footer() {
  Bytes out;
  encode(out, DataEnd{data_crc_});
  const std::size_t summary = out.size();  // where the summary starts in `out`
  std::vector<SummaryOffset> groups;
  // Appends one group of summary records and its Summary Offset.
  const auto group = [&](Opcode op, auto&& write_records) {
    const std::size_t start = out.size();
    write_records();
    if (out.size() > start) {
      groups.push_back(
          SummaryOffset{static_cast<std::uint8_t>(op), file_size_ + start, out.size() - start});
    }
  };
  group(Opcode::kSchema, [&] {
    for (const std::uint16_t id : file_schemas_) encode(out, schemas_[id - 1u]);
  });
  group(Opcode::kChannel, [&] {
    for (const std::uint16_t id : file_channels_) encode(out, channels_[id - 1u]);
  });
  stats_.schema_count = static_cast<std::uint16_t>(file_schemas_.size());
  stats_.channel_count = static_cast<std::uint32_t>(file_channels_.size());
  group(Opcode::kStatistics, [&] { encode(out, stats_); });
  group(Opcode::kChunkIndex, [&] {
    for (const ChunkIndex& entry : chunk_index_) encode(out, entry);
  });
  const std::size_t offsets = out.size();
  for (const SummaryOffset& g : groups) encode(out, g);

  const std::size_t footer = out.size();
  encode(out, Footer{file_size_ + summary, file_size_ + offsets, 0});
  // The summary CRC covers the summary through the footer's summary_offset_start field.
  const std::size_t crc_end = footer + kRecordHeadSize + 16;
  const std::uint32_t crc =
      crc32_update(0, std::span<const std::uint8_t>(out).subspan(summary, crc_end - summary));
  for (int i = 0; i < 4; ++i)
    out[crc_end + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(crc >> (8 * i));
  out.insert(out.end(), kMagic.begin(), kMagic.end());
  append(out);
}

}  // namespace semap::drivers::mcap
