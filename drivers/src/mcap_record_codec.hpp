#pragma once
// Record content <-> record structs. Decoders throw FormatError naming "<Record>.<field>" and
// the field's byte within the content; bytes after the known fields are ignored, as the
// specification asks (newer fields, padding).
#include <cstdint>
#include <span>

#include "semap/drivers/mcap_records.hpp"

namespace semap::drivers::mcap {

// Any record but Chunk and Attachment, which need more than the struct (below); an opcode the
// specification does not define gives an UnknownRecord.
Record decode_record(std::uint8_t opcode, std::span<const std::uint8_t> content);
// `records` is set to the (compressed) records field.
Chunk decode_chunk(std::span<const std::uint8_t> content, std::span<const std::uint8_t>& records);
// `crc_covered` is set to the bytes the crc field covers (log_time through data).
Attachment decode_attachment(std::span<const std::uint8_t> content,
                             std::span<const std::uint8_t>& crc_covered);

// Each appends one whole record (opcode, length, content) to `out`.
void encode(Bytes& out, const Header& r);
void encode(Bytes& out, const Footer& r);
void encode(Bytes& out, const Schema& r);
void encode(Bytes& out, const Channel& r);
void encode(Bytes& out, const MessageIndex& r);
void encode(Bytes& out, const ChunkIndex& r);
void encode(Bytes& out, const Statistics& r);
void encode(Bytes& out, const SummaryOffset& r);
void encode(Bytes& out, const DataEnd& r);
// A Message without copying its data into a struct first.
void encode_message(Bytes& out, std::uint16_t channel_id, std::uint32_t sequence,
                    std::uint64_t log_time, std::uint64_t publish_time,
                    std::span<const std::uint8_t> data);
// A Chunk whose records field is `records` (compressed as `chunk.compression` says).
void encode_chunk(Bytes& out, const Chunk& chunk, std::span<const std::uint8_t> records);

}  // namespace semap::drivers::mcap
