// McapWriter's files read back record by record: the messages as written, a MessageIndex per
// channel after each chunk pointing at its messages, and a summary (schemas, channels,
// statistics, chunk indexes, summary offsets, footer) that agrees with the data section.
#include "semap/drivers/mcap_writer.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "mcap_test_recording.hpp"
#include "semap/drivers/mcap_message_reader.hpp"
#include "semap/drivers/mcap_stream_reader.hpp"

namespace semap::drivers::mcap {
namespace {

namespace fs = std::filesystem;
using test_recording::SentMessage;

class McapWriterTest : public ::testing::TestWithParam<Compression> {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("mcap_writer_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

// Everything the stream reader reports about one file, with where each record was.
struct ReadBack {
  Header header;
  std::vector<Message> messages;
  std::vector<std::uint64_t> chunk_offsets;
  std::vector<Chunk> chunks;
  // Per chunk: message offset in its records -> message.
  std::vector<std::map<std::uint64_t, Message>> chunk_messages;
  // Per chunk: its MessageIndex records and their file offsets.
  std::vector<std::map<std::uint16_t, std::pair<std::uint64_t, MessageIndex>>> indexes;
  std::vector<std::pair<std::uint64_t, Record>> summary;  // after DataEnd, with offsets
  std::uint64_t data_end_offset = 0;
  McapReadStatus status = McapReadStatus::kReading;
  std::string error;
};

ReadBack read_back(const fs::path& path) {
  ReadBack out;
  McapStreamReader reader(path);
  bool after_data_end = false;
  while (auto record = reader.next()) {
    if (after_data_end) {
      out.summary.emplace_back(reader.record_offset(), std::move(*record));
      continue;
    }
    if (auto* h = std::get_if<Header>(&*record)) out.header = *h;
    if (auto* c = std::get_if<Chunk>(&*record)) {
      out.chunk_offsets.push_back(reader.record_offset());
      out.chunks.push_back(*c);
      out.chunk_messages.emplace_back();
      out.indexes.emplace_back();
    }
    if (auto* m = std::get_if<Message>(&*record)) {
      EXPECT_TRUE(reader.in_chunk());
      out.chunk_messages.back()[reader.offset_in_chunk()] = *m;
      out.messages.push_back(*m);
    }
    if (auto* i = std::get_if<MessageIndex>(&*record)) {
      out.indexes.back()[i->channel_id] = {reader.record_offset(), *i};
    }
    if (std::holds_alternative<DataEnd>(*record)) {
      out.data_end_offset = reader.record_offset();
      after_data_end = true;
    }
  }
  out.status = reader.status();
  out.error = reader.error();
  return out;
}

TEST_P(McapWriterTest, RoundTripsMessagesIndexesAndSummary) {
  const fs::path path = dir_ / "run.mcap";
  std::vector<SentMessage> sent;
  {
    McapWriterOptions options;
    options.compression = GetParam();
    options.chunk_size = 32 * 1024;  // many chunks
    options.chunk_duration_ns = 0;
    McapWriter writer(path, options);
    sent = test_recording::write_recording(writer, 24, 3000, 1500);
    writer.close();
    EXPECT_EQ(writer.messages_written(), sent.size());
    EXPECT_EQ(writer.file_size(), fs::file_size(path));
  }
  const ReadBack back = read_back(path);
  ASSERT_EQ(back.status, McapReadStatus::kEnd) << back.error;
  EXPECT_EQ(back.header.profile, "ros2");
  EXPECT_EQ(back.header.library.rfind("semap ", 0), 0u) << back.header.library;

  ASSERT_EQ(back.messages.size(), sent.size());
  for (std::size_t i = 0; i < sent.size(); ++i) {
    const Message& m = back.messages[i];
    ASSERT_EQ(m.channel_id, sent[i].channel_id) << i;
    EXPECT_EQ(m.sequence, sent[i].sequence) << i;
    EXPECT_EQ(m.log_time, sent[i].log_time) << i;
    EXPECT_EQ(m.publish_time, sent[i].publish_time) << i;
    ASSERT_EQ(m.data, sent[i].data) << i;
  }

  // Each chunk: its compression and times, and one MessageIndex per channel in it whose
  // entries point at exactly its messages on that channel.
  ASSERT_GT(back.chunks.size(), 10u);
  for (std::size_t c = 0; c < back.chunks.size(); ++c) {
    EXPECT_EQ(back.chunks[c].compression, compression_name(GetParam()));
    std::size_t indexed = 0;
    for (const auto& [channel, where] : back.indexes[c]) {
      for (const auto& [log_time, offset] : where.second.records) {
        const auto m = back.chunk_messages[c].find(offset);
        ASSERT_NE(m, back.chunk_messages[c].end()) << "chunk " << c << " offset " << offset;
        EXPECT_EQ(m->second.channel_id, channel);
        EXPECT_EQ(m->second.log_time, log_time);
        EXPECT_GE(log_time, back.chunks[c].message_start_time);
        EXPECT_LE(log_time, back.chunks[c].message_end_time);
        ++indexed;
      }
    }
    EXPECT_EQ(indexed, back.chunk_messages[c].size()) << "chunk " << c;
  }

  // The summary: groups in order, each named by a SummaryOffset, then the Footer.
  std::map<std::uint8_t, std::pair<std::uint64_t, std::uint64_t>> groups;  // opcode -> start, end
  std::set<std::uint16_t> schema_ids, channel_ids;
  const Statistics* stats = nullptr;
  std::vector<const ChunkIndex*> chunk_index;
  std::map<std::uint8_t, SummaryOffset> offsets;
  const Footer* footer = nullptr;
  std::uint64_t first_offset_record = 0;
  for (std::size_t i = 0; i < back.summary.size(); ++i) {
    const auto& [at, record] = back.summary[i];
    const auto op = static_cast<std::uint8_t>(record.index() + 1);
    const std::uint64_t end = i + 1 < back.summary.size() ? back.summary[i + 1].first : at;
    if (auto* s = std::get_if<Schema>(&record)) schema_ids.insert(s->id);
    if (auto* c = std::get_if<Channel>(&record)) channel_ids.insert(c->id);
    if (auto* s = std::get_if<Statistics>(&record)) stats = s;
    if (auto* c = std::get_if<ChunkIndex>(&record)) chunk_index.push_back(c);
    if (auto* o = std::get_if<SummaryOffset>(&record)) {
      if (offsets.empty()) first_offset_record = at;
      offsets[o->group_opcode] = *o;
    } else if (auto* f = std::get_if<Footer>(&record)) {
      footer = f;
    } else {
      auto [g, fresh] = groups.try_emplace(op, at, end);
      if (!fresh) {
        EXPECT_EQ(g->second.second, at) << "group " << int(op) << " is not contiguous";
        g->second.second = end;
      }
    }
  }
  EXPECT_EQ(schema_ids, (std::set<std::uint16_t>{1, 2, 3}));
  EXPECT_EQ(channel_ids.size(), 25u);  // the one without messages too
  ASSERT_NE(stats, nullptr);
  EXPECT_EQ(stats->message_count, sent.size());
  EXPECT_EQ(stats->chunk_count, back.chunks.size());
  EXPECT_EQ(stats->channel_count, 25u);
  EXPECT_EQ(stats->schema_count, 3u);
  std::map<std::uint16_t, std::uint64_t> counts;
  std::uint64_t first = UINT64_MAX, last = 0;
  for (const SentMessage& m : sent) {
    ++counts[m.channel_id];
    first = std::min(first, m.log_time);
    last = std::max(last, m.log_time);
  }
  EXPECT_EQ(stats->channel_message_counts, (ChannelCounts(counts.begin(), counts.end())));
  EXPECT_EQ(stats->message_start_time, first);
  EXPECT_EQ(stats->message_end_time, last);

  ASSERT_EQ(chunk_index.size(), back.chunks.size());
  for (std::size_t c = 0; c < chunk_index.size(); ++c) {
    const ChunkIndex& ci = *chunk_index[c];
    EXPECT_EQ(ci.chunk_start_offset, back.chunk_offsets[c]);
    EXPECT_EQ(ci.compression, back.chunks[c].compression);
    EXPECT_EQ(ci.compressed_size, back.chunks[c].compressed_size);
    EXPECT_EQ(ci.uncompressed_size, back.chunks[c].uncompressed_size);
    EXPECT_EQ(ci.message_start_time, back.chunks[c].message_start_time);
    EXPECT_EQ(ci.message_end_time, back.chunks[c].message_end_time);
    ASSERT_EQ(ci.message_index_offsets.size(), back.indexes[c].size());
    for (const auto& [channel, where] : back.indexes[c]) {
      EXPECT_EQ(ci.message_index_offsets.at(channel), where.first);
    }
    const std::uint64_t next =
        c + 1 < chunk_index.size() ? back.chunk_offsets[c + 1] : back.data_end_offset;
    EXPECT_EQ(ci.chunk_start_offset + ci.chunk_length + ci.message_index_length, next);
  }

  ASSERT_EQ(offsets.size(), groups.size());
  for (const auto& [op, range] : groups) {
    EXPECT_EQ(offsets[op].group_start, range.first) << int(op);
    EXPECT_EQ(offsets[op].group_length, range.second - range.first) << int(op);
  }
  ASSERT_NE(footer, nullptr);
  EXPECT_EQ(footer->summary_start, back.summary.front().first);
  EXPECT_EQ(footer->summary_offset_start, first_offset_record);
  EXPECT_NE(footer->summary_crc, 0u);  // checked by the reader

  // The message iterator gives the same messages with their channel and schema.
  McapMessageReader messages(path);
  std::size_t n = 0;
  while (const auto view = messages.next()) {
    ASSERT_LT(n, sent.size());
    EXPECT_EQ(view->message.sequence, sent[n].sequence);
    EXPECT_EQ(view->channel.id, sent[n].channel_id);
    EXPECT_EQ(view->channel.message_encoding, "cdr");
    EXPECT_EQ(view->schema == nullptr, view->channel.id == 24) << view->channel.topic;
    if (view->schema) {
      EXPECT_EQ(view->schema->encoding, "ros2msg");
    }
    ++n;
  }
  EXPECT_EQ(n, sent.size());
  EXPECT_EQ(messages.status(), McapReadStatus::kEnd) << messages.error();
}

INSTANTIATE_TEST_SUITE_P(Compressions, McapWriterTest,
                         ::testing::Values(Compression::kZstd, Compression::kLz4,
                                           Compression::kNone),
                         [](const auto& info) {
                           const auto name = compression_name(info.param);
                           return name.empty() ? std::string("none") : std::string(name);
                         });

TEST_F(McapWriterTest, ChunkDurationBoundsTheLogTimeOfAChunk) {
  const fs::path path = dir_ / "slow.mcap";
  McapWriterOptions options;
  options.chunk_duration_ns = 100'000'000;  // 100 ms
  McapWriter writer(path, options);
  const std::uint16_t channel = writer.add_channel(0, "/gnss", "cdr");
  const Bytes fix(40, 7);
  for (std::uint32_t i = 0; i < 50; ++i) writer.write(channel, i, i * 10'000'000ull, 0, fix);
  // 50 messages 10 ms apart: a chunk closes at every 100 ms of log time (11 messages each), so
  // a crash now would lose only the open chunk's 6: the file reads as truncated with 44.
  {
    McapMessageReader crashed(path);
    std::size_t n = 0;
    while (crashed.next()) ++n;
    EXPECT_EQ(n, 44u);
    EXPECT_EQ(crashed.status(), McapReadStatus::kTruncated) << crashed.error();
  }
  writer.close();
  McapStreamReader reader(path);
  std::vector<Chunk> chunks;
  while (auto record = reader.next()) {
    if (auto* c = std::get_if<Chunk>(&*record)) chunks.push_back(*c);
  }
  ASSERT_EQ(reader.status(), McapReadStatus::kEnd) << reader.error();
  ASSERT_EQ(chunks.size(), 5u);
  for (const Chunk& c : chunks) EXPECT_LE(c.message_end_time - c.message_start_time, 100'000'000u);
}

// A channel that never carried a message still reaches the file, in a chunk of its own that
// claims no time span (indexed readers such as @mcap/core reject one that claims the previous
// chunk's).
TEST_F(McapWriterTest, AChunkWithoutMessagesHasNoTimeSpan) {
  const fs::path path = dir_ / "quiet.mcap";
  {
    McapWriter writer(path);
    const std::uint16_t odometry = writer.add_channel(0, "/odometry", "cdr");
    writer.write(odometry, 0, 5'000'000'000ull, 0, Bytes(16, 1));
    writer.flush();
    writer.add_channel(0, "/costmap_updates", "cdr");
    writer.close();
  }
  McapStreamReader reader(path);
  std::vector<Chunk> chunks;
  while (auto record = reader.next()) {
    if (auto* c = std::get_if<Chunk>(&*record)) chunks.push_back(*c);
  }
  ASSERT_EQ(reader.status(), McapReadStatus::kEnd) << reader.error();
  ASSERT_EQ(chunks.size(), 2u);
  EXPECT_EQ(chunks[0].message_start_time, 5'000'000'000u);
  EXPECT_EQ(chunks[1].message_start_time, 0u);
  EXPECT_EQ(chunks[1].message_end_time, 0u);
}

TEST_F(McapWriterTest, RejectsUnknownIdsAndWritesAfterClose) {
  McapWriter writer(dir_ / "ids.mcap");
  EXPECT_THROW(writer.add_channel(5, "/x", "cdr"), std::invalid_argument);
  const std::uint16_t channel = writer.add_channel(0, "/x", "cdr");
  EXPECT_THROW(writer.write(channel + 1, 0, 0, 0, {}), std::invalid_argument);
  writer.close();
  EXPECT_THROW(writer.write(channel, 0, 0, 0, {}), std::logic_error);
}

}  // namespace
}  // namespace semap::drivers::mcap
