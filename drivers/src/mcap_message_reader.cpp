#include "semap/drivers/mcap_message_reader.hpp"

namespace semap::drivers::mcap {

McapMessageReader::McapMessageReader(std::span<const std::uint8_t> bytes, std::string name,
                                     McapReaderOptions options)
    : records_(bytes, std::move(name), options) {}

McapMessageReader::McapMessageReader(const std::filesystem::path& path, McapReaderOptions options)
    : records_(path, options) {}

std::optional<McapMessageView> McapMessageReader::next() {
  while (status_ == McapReadStatus::kReading) {
    std::optional<Record> record = records_.next();
    if (!record) {
      status_ = records_.status();
      error_ = records_.error();
      break;
    }
    if (auto* schema = std::get_if<Schema>(&*record)) {
      // Schema id 0 is invalid and ignored, as the specification asks.
      if (schema->id != 0) schemas_[schema->id] = std::move(*schema);
    } else if (auto* channel = std::get_if<Channel>(&*record)) {
      if (channel->schema_id != 0 && !schemas_.contains(channel->schema_id)) {
        fail("Channel " + std::to_string(channel->id) + " ('" + channel->topic + "'): schema " +
             std::to_string(channel->schema_id) + " has no Schema record before it");
        break;
      }
      channels_[channel->id] = std::move(*channel);
    } else if (auto* message = std::get_if<Message>(&*record)) {
      const auto channel = channels_.find(message->channel_id);
      if (channel == channels_.end()) {
        fail("Message: channel " + std::to_string(message->channel_id) +
             " has no Channel record before it");
        break;
      }
      message_ = std::move(*message);
      ++messages_;
      const auto schema = schemas_.find(channel->second.schema_id);
      return McapMessageView{channel->second, schema == schemas_.end() ? nullptr : &schema->second,
                             message_};
    }
  }
  return std::nullopt;
}

void McapMessageReader::fail(const std::string& what) {
  status_ = McapReadStatus::kError;
  const std::string where = records_.in_chunk()
                                ? "byte " + std::to_string(records_.record_offset()) +
                                      ": in the Chunk, record at byte " +
                                      std::to_string(records_.offset_in_chunk())
                                : "byte " + std::to_string(records_.record_offset());
  error_ = records_.name() + ": " + where + ": " + what;
}

}  // namespace semap::drivers::mcap
