#include "mcap_record_codec.hpp"

#include <iterator>
#include <variant>

#include "mcap_bytes.hpp"

namespace semap::drivers::mcap {
namespace {

Header decode_header(ByteReader& r) {
  Header h;
  h.profile = r.string("profile");
  h.library = r.string("library");
  return h;
}

Footer decode_footer(ByteReader& r) {
  Footer f;
  f.summary_start = r.u64("summary_start");
  f.summary_offset_start = r.u64("summary_offset_start");
  f.summary_crc = r.u32("summary_crc");
  return f;
}

Schema decode_schema(ByteReader& r) {
  Schema s;
  s.id = r.u16("id");
  s.name = r.string("name");
  s.encoding = r.string("encoding");
  s.data = r.bytes32("data");
  return s;
}

Channel decode_channel(ByteReader& r) {
  Channel c;
  c.id = r.u16("id");
  c.schema_id = r.u16("schema_id");
  c.topic = r.string("topic");
  c.message_encoding = r.string("message_encoding");
  c.metadata = r.string_map("metadata");
  return c;
}

Message decode_message(ByteReader& r) {
  Message m;
  m.channel_id = r.u16("channel_id");
  m.sequence = r.u32("sequence");
  m.log_time = r.u64("log_time");
  m.publish_time = r.u64("publish_time");
  const auto data = r.rest();
  m.data.assign(data.begin(), data.end());
  return m;
}

MessageIndex decode_message_index(ByteReader& r) {
  MessageIndex m;
  m.channel_id = r.u16("channel_id");
  ByteReader entries(r.prefixed("records", 4), "MessageIndex");
  while (entries.left() > 0) {
    const std::uint64_t log_time = entries.u64("records");
    m.records.emplace_back(log_time, entries.u64("records"));
  }
  return m;
}

ChunkIndex decode_chunk_index(ByteReader& r) {
  ChunkIndex c;
  c.message_start_time = r.u64("message_start_time");
  c.message_end_time = r.u64("message_end_time");
  c.chunk_start_offset = r.u64("chunk_start_offset");
  c.chunk_length = r.u64("chunk_length");
  c.message_index_offsets = r.u16_u64_map("message_index_offsets");
  c.message_index_length = r.u64("message_index_length");
  c.compression = r.string("compression");
  c.compressed_size = r.u64("compressed_size");
  c.uncompressed_size = r.u64("uncompressed_size");
  return c;
}

AttachmentIndex decode_attachment_index(ByteReader& r) {
  AttachmentIndex a;
  a.offset = r.u64("offset");
  a.length = r.u64("length");
  a.log_time = r.u64("log_time");
  a.create_time = r.u64("create_time");
  a.data_size = r.u64("data_size");
  a.name = r.string("name");
  a.media_type = r.string("media_type");
  return a;
}

Statistics decode_statistics(ByteReader& r) {
  Statistics s;
  s.message_count = r.u64("message_count");
  s.schema_count = r.u16("schema_count");
  s.channel_count = r.u32("channel_count");
  s.attachment_count = r.u32("attachment_count");
  s.metadata_count = r.u32("metadata_count");
  s.chunk_count = r.u32("chunk_count");
  s.message_start_time = r.u64("message_start_time");
  s.message_end_time = r.u64("message_end_time");
  s.channel_message_counts = r.u16_u64_map("channel_message_counts");
  return s;
}

Metadata decode_metadata(ByteReader& r) {
  Metadata m;
  m.name = r.string("name");
  m.metadata = r.string_map("metadata");
  return m;
}

MetadataIndex decode_metadata_index(ByteReader& r) {
  MetadataIndex m;
  m.offset = r.u64("offset");
  m.length = r.u64("length");
  m.name = r.string("name");
  return m;
}

SummaryOffset decode_summary_offset(ByteReader& r) {
  SummaryOffset s;
  s.group_opcode = r.u8("group_opcode");
  s.group_start = r.u64("group_start");
  s.group_length = r.u64("group_length");
  return s;
}

}  // namespace

const char* opcode_name(std::uint8_t opcode) {
  static constexpr const char* kNames[] = {
      "Header",     "Footer",       "Schema",        "Channel",       "Message",
      "Chunk",      "MessageIndex", "ChunkIndex",    "Attachment",    "AttachmentIndex",
      "Statistics", "Metadata",     "MetadataIndex", "SummaryOffset", "DataEnd"};
  static_assert(std::size(kNames) + 1 == std::variant_size_v<Record>);
  return opcode >= 1 && opcode <= std::size(kNames) ? kNames[opcode - 1] : "Unknown";
}

Chunk decode_chunk(std::span<const std::uint8_t> content, std::span<const std::uint8_t>& records) {
  ByteReader r(content, "Chunk");
  Chunk c;
  c.message_start_time = r.u64("message_start_time");
  c.message_end_time = r.u64("message_end_time");
  c.uncompressed_size = r.u64("uncompressed_size");
  c.uncompressed_crc = r.u32("uncompressed_crc");
  c.compression = r.string("compression");
  records = r.prefixed("records", 8);
  c.compressed_size = records.size();
  return c;
}

Attachment decode_attachment(std::span<const std::uint8_t> content,
                             std::span<const std::uint8_t>& crc_covered) {
  ByteReader r(content, "Attachment");
  Attachment a;
  a.log_time = r.u64("log_time");
  a.create_time = r.u64("create_time");
  a.name = r.string("name");
  a.media_type = r.string("media_type");
  a.data = r.bytes64("data");
  crc_covered = content.first(r.position());
  a.crc = r.u32("crc");
  return a;
}

Record decode_record(std::uint8_t opcode, std::span<const std::uint8_t> content) {
  std::span<const std::uint8_t> unused;
  switch (static_cast<Opcode>(opcode)) {
    case Opcode::kHeader: {
      ByteReader r(content, "Header");
      return decode_header(r);
    }
    case Opcode::kFooter: {
      ByteReader r(content, "Footer");
      return decode_footer(r);
    }
    case Opcode::kSchema: {
      ByteReader r(content, "Schema");
      return decode_schema(r);
    }
    case Opcode::kChannel: {
      ByteReader r(content, "Channel");
      return decode_channel(r);
    }
    case Opcode::kMessage: {
      ByteReader r(content, "Message");
      return decode_message(r);
    }
    case Opcode::kChunk:
      return decode_chunk(content, unused);
    case Opcode::kMessageIndex: {
      ByteReader r(content, "MessageIndex");
      return decode_message_index(r);
    }
    case Opcode::kChunkIndex: {
      ByteReader r(content, "ChunkIndex");
      return decode_chunk_index(r);
    }
    case Opcode::kAttachment:
      return decode_attachment(content, unused);
    case Opcode::kAttachmentIndex: {
      ByteReader r(content, "AttachmentIndex");
      return decode_attachment_index(r);
    }
    case Opcode::kStatistics: {
      ByteReader r(content, "Statistics");
      return decode_statistics(r);
    }
    case Opcode::kMetadata: {
      ByteReader r(content, "Metadata");
      return decode_metadata(r);
    }
    case Opcode::kMetadataIndex: {
      ByteReader r(content, "MetadataIndex");
      return decode_metadata_index(r);
    }
    case Opcode::kSummaryOffset: {
      ByteReader r(content, "SummaryOffset");
      return decode_summary_offset(r);
    }
    case Opcode::kDataEnd: {
      ByteReader r(content, "DataEnd");
      return DataEnd{r.u32("data_section_crc")};
    }
  }
  return UnknownRecord{opcode, content.size()};
}

void encode(Bytes& out, const Header& r) {
  const std::size_t start = begin_record(out, Opcode::kHeader);
  put_string(out, r.profile);
  put_string(out, r.library);
  end_record(out, start);
}

void encode(Bytes& out, const Footer& r) {
  const std::size_t start = begin_record(out, Opcode::kFooter);
  put_u64(out, r.summary_start);
  put_u64(out, r.summary_offset_start);
  put_u32(out, r.summary_crc);
  end_record(out, start);
}

void encode(Bytes& out, const Schema& r) {
  const std::size_t start = begin_record(out, Opcode::kSchema);
  put_u16(out, r.id);
  put_string(out, r.name);
  put_string(out, r.encoding);
  put_u32(out, static_cast<std::uint32_t>(r.data.size()));
  put_bytes(out, r.data);
  end_record(out, start);
}

void encode(Bytes& out, const Channel& r) {
  const std::size_t start = begin_record(out, Opcode::kChannel);
  put_u16(out, r.id);
  put_u16(out, r.schema_id);
  put_string(out, r.topic);
  put_string(out, r.message_encoding);
  put_string_map(out, r.metadata);
  end_record(out, start);
}

void encode(Bytes& out, const MessageIndex& r) {
  const std::size_t start = begin_record(out, Opcode::kMessageIndex);
  put_u16(out, r.channel_id);
  put_u32(out, static_cast<std::uint32_t>(r.records.size() * 16));
  for (const auto& [log_time, offset] : r.records) {
    put_u64(out, log_time);
    put_u64(out, offset);
  }
  end_record(out, start);
}

void encode(Bytes& out, const ChunkIndex& r) {
  const std::size_t start = begin_record(out, Opcode::kChunkIndex);
  put_u64(out, r.message_start_time);
  put_u64(out, r.message_end_time);
  put_u64(out, r.chunk_start_offset);
  put_u64(out, r.chunk_length);
  put_u32(out, static_cast<std::uint32_t>(r.message_index_offsets.size() * 10));
  for (const auto& [channel, offset] : r.message_index_offsets) {
    put_u16(out, channel);
    put_u64(out, offset);
  }
  put_u64(out, r.message_index_length);
  put_string(out, r.compression);
  put_u64(out, r.compressed_size);
  put_u64(out, r.uncompressed_size);
  end_record(out, start);
}

void encode(Bytes& out, const Statistics& r) {
  const std::size_t start = begin_record(out, Opcode::kStatistics);
  put_u64(out, r.message_count);
  put_u16(out, r.schema_count);
  put_u32(out, r.channel_count);
  put_u32(out, r.attachment_count);
  put_u32(out, r.metadata_count);
  put_u32(out, r.chunk_count);
  put_u64(out, r.message_start_time);
  put_u64(out, r.message_end_time);
  put_u32(out, static_cast<std::uint32_t>(r.channel_message_counts.size() * 10));
  for (const auto& [channel, count] : r.channel_message_counts) {
    put_u16(out, channel);
    put_u64(out, count);
  }
  end_record(out, start);
}

void encode(Bytes& out, const SummaryOffset& r) {
  const std::size_t start = begin_record(out, Opcode::kSummaryOffset);
  put_u8(out, r.group_opcode);
  put_u64(out, r.group_start);
  put_u64(out, r.group_length);
  end_record(out, start);
}

void encode(Bytes& out, const DataEnd& r) {
  const std::size_t start = begin_record(out, Opcode::kDataEnd);
  put_u32(out, r.data_section_crc);
  end_record(out, start);
}

void encode_message(Bytes& out, std::uint16_t channel_id, std::uint32_t sequence,
                    std::uint64_t log_time, std::uint64_t publish_time,
                    std::span<const std::uint8_t> data) {
  const std::size_t start = begin_record(out, Opcode::kMessage);
  put_u16(out, channel_id);
  put_u32(out, sequence);
  put_u64(out, log_time);
  put_u64(out, publish_time);
  put_bytes(out, data);
  end_record(out, start);
}

void encode_chunk(Bytes& out, const Chunk& chunk, std::span<const std::uint8_t> records) {
  const std::size_t start = begin_record(out, Opcode::kChunk);
  put_u64(out, chunk.message_start_time);
  put_u64(out, chunk.message_end_time);
  put_u64(out, chunk.uncompressed_size);
  put_u32(out, chunk.uncompressed_crc);
  put_string(out, chunk.compression);
  put_u64(out, records.size());
  put_bytes(out, records);
  end_record(out, start);
}

}  // namespace semap::drivers::mcap
