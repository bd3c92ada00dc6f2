// MCAP files (recordings replayed by semap-onboard, CAN frames extracted by semap-can): any bytes
// through the record stream reader and the message reader. Nothing crashes, a chunk never
// inflates past the reader's limit, the reader always ends with a status, and a damaged or
// truncated file leaves an error naming it.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "semap/drivers/mcap_message_reader.hpp"
#include "semap/drivers/mcap_stream_reader.hpp"

namespace {

using namespace semap::drivers::mcap;

void check_end(McapReadStatus status, const std::string& error, std::size_t size,
               std::uint64_t truncated_at) {
  if (status == McapReadStatus::kReading) std::abort();
  if (status == McapReadStatus::kEnd && !error.empty()) std::abort();
  if (status != McapReadStatus::kEnd && error.rfind("fuzz.mcap: ", 0) != 0) std::abort();
  if (status == McapReadStatus::kTruncated && truncated_at > size) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> bytes(data, size);
  McapReaderOptions options;
  options.max_chunk_size = 4u << 20;  // keeps each input's memory small
  {
    McapStreamReader reader(bytes, "fuzz.mcap", options);
    while (const auto record = reader.next()) {
      if (const auto* m = std::get_if<Message>(&*record)) {
        if (m->data.size() > options.max_chunk_size) std::abort();
      }
    }
    check_end(reader.status(), reader.error(), size, reader.truncated_at());
  }
  {
    McapMessageReader reader(bytes, "fuzz.mcap", options);
    std::uint64_t messages = 0;
    while (const auto view = reader.next()) {
      if (view->channel.id != view->message.channel_id) std::abort();
      if (view->schema && view->schema->id != view->channel.schema_id) std::abort();
      ++messages;
    }
    if (messages != reader.messages()) std::abort();
    check_end(reader.status(), reader.error(), size, reader.truncated_at());
  }
  return 0;
}
