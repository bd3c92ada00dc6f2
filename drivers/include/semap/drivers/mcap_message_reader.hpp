#pragma once
// The messages of an MCAP file in file order, each with its channel and schema: what a replay
// or `semap-can` needs. Built on McapStreamReader, so it reads files that end early (a crash,
// a power loss while recording): every message of every whole chunk comes out, then status()
// is kTruncated and error() says "<file>: truncated at byte N: ...". Damage is kError; nothing
// throws.
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <span>
#include <string>

#include "semap/drivers/mcap_records.hpp"
#include "semap/drivers/mcap_stream_reader.hpp"

namespace semap::drivers::mcap {

// Valid until the next call of next().
struct McapMessageView {
  const Channel& channel;
  const Schema* schema;  // null for a channel without schema (schema_id 0)
  const Message& message;
};

class McapMessageReader {
 public:
  McapMessageReader(std::span<const std::uint8_t> bytes, std::string name,
                    McapReaderOptions options = {});
  explicit McapMessageReader(const std::filesystem::path& path, McapReaderOptions options = {});

  // The next message; nothing at the end of the file, at its truncation or on damage (a
  // message whose channel, or a channel whose schema, has no record before it is damage).
  std::optional<McapMessageView> next();

  McapReadStatus status() const { return status_; }
  const std::string& error() const { return error_; }
  std::uint64_t truncated_at() const { return records_.truncated_at(); }
  std::uint64_t messages() const { return messages_; }  // given so far
  // Every schema and channel met so far (all of them at the end of a complete file).
  const std::map<std::uint16_t, Schema>& schemas() const { return schemas_; }
  const std::map<std::uint16_t, Channel>& channels() const { return channels_; }

 private:
  void fail(const std::string& what);

  McapStreamReader records_;
  McapReadStatus status_ = McapReadStatus::kReading;
  std::string error_;
  std::map<std::uint16_t, Schema> schemas_;
  std::map<std::uint16_t, Channel> channels_;
  Message message_;
  std::uint64_t messages_ = 0;
};

}  // namespace semap::drivers::mcap
