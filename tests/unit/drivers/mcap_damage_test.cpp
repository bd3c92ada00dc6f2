// MCAP files as a crash or bad storage leaves them: cut at many offsets, every message of every
// whole chunk comes back and the reader says where the file was cut; a flipped byte anywhere
// gives the messages before the damage and an error naming it, never a crash.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "mcap_test_recording.hpp"
#include "semap/drivers/mcap_message_reader.hpp"
#include "semap/drivers/mcap_stream_reader.hpp"

namespace semap::drivers::mcap {
namespace {

namespace fs = std::filesystem;
using test_recording::SentMessage;

struct Recording {
  Bytes file;
  std::vector<SentMessage> sent;
  struct ChunkSpan {
    std::uint64_t start;
    std::uint64_t end;               // of the Chunk record
    std::size_t messages_up_to_end;  // in the file up to its end
  };
  std::vector<ChunkSpan> chunks;
};

Recording make_recording(Compression compression) {
  const fs::path path = fs::temp_directory_path() / ("mcap_damage_" + std::to_string(::getpid()));
  Recording r;
  {
    McapWriterOptions options;
    options.compression = compression;
    options.chunk_size = 2048;
    McapWriter writer(path, options);
    r.sent = test_recording::write_recording(writer, 5, 200, 120);
  }
  r.file = test_recording::read_file(path);
  fs::remove(path);
  McapStreamReader reader(r.file, "full.mcap");
  std::size_t messages = 0;
  std::uint64_t chunk_at = 0;
  bool chunk_open = false;
  const auto close_chunk = [&](std::uint64_t end) {
    if (chunk_open) r.chunks.push_back({chunk_at, end, messages});
    chunk_open = false;
  };
  while (const auto record = reader.next()) {
    if (!reader.in_chunk()) close_chunk(reader.record_offset());
    if (std::holds_alternative<Chunk>(*record)) {
      chunk_at = reader.record_offset();
      chunk_open = true;
    }
    if (std::holds_alternative<Message>(*record)) ++messages;
  }
  EXPECT_EQ(reader.status(), McapReadStatus::kEnd) << reader.error();
  EXPECT_EQ(messages, r.sent.size());
  EXPECT_GT(chunk_at, 0u);
  return r;
}

// Messages the reader gives for `bytes`; each must be the next one written.
std::size_t read_prefix(McapMessageReader& reader, const std::vector<SentMessage>& sent) {
  std::size_t n = 0;
  while (const auto view = reader.next()) {
    EXPECT_LT(n, sent.size());
    if (n >= sent.size()) break;
    EXPECT_EQ(view->message.channel_id, sent[n].channel_id) << "message " << n;
    EXPECT_EQ(view->message.sequence, sent[n].sequence) << "message " << n;
    EXPECT_EQ(view->message.data, sent[n].data) << "message " << n;
    ++n;
  }
  return n;
}

TEST(McapTruncatedFile, GivesEveryMessageOfEveryWholeChunkAndWhereItWasCut) {
  const Recording r = make_recording(Compression::kZstd);
  ASSERT_GT(r.chunks.size(), 5u);
  for (std::size_t cut = 0; cut < r.file.size(); ++cut) {
    const auto bytes = std::span<const std::uint8_t>(r.file).first(cut);
    McapMessageReader reader(bytes, "cut.mcap");
    const std::size_t n = read_prefix(reader, r.sent);
    std::size_t expected = 0;
    for (const auto& chunk : r.chunks) {
      if (chunk.end <= cut) expected = chunk.messages_up_to_end;
    }
    ASSERT_EQ(n, expected) << "cut at " << cut;
    ASSERT_EQ(reader.status(), McapReadStatus::kTruncated) << "cut at " << cut;
    EXPECT_LE(reader.truncated_at(), cut);
    EXPECT_EQ(reader.error().rfind(
                  "cut.mcap: truncated at byte " + std::to_string(reader.truncated_at()) + ": ", 0),
              0u)
        << reader.error();
  }
}

// Every byte of an uncompressed and of an lz4 file flipped in turn. A flip in a chunk (after
// its opcode and length) never gives a wrong message: the chunk CRC or its decoding catches it
// before any of its messages comes out. Elsewhere a flip can reframe the top-level records
// (an uncompressed chunk's Message records then read as top-level ones) until DataEnd's CRC
// catches it, as in any streaming MCAP reader; there the reader must only not crash and name
// the file.
TEST(McapDamagedFile, FlippedBytesInAChunkNeverGiveWrongMessages) {
  for (const Compression compression : {Compression::kNone, Compression::kLz4}) {
    const Recording r = make_recording(compression);
    std::size_t errors = 0;
    for (std::size_t at = 0; at < r.file.size(); ++at) {
      Bytes damaged = r.file;
      damaged[at] ^= 0x5a;
      McapMessageReader reader(damaged, "bad.mcap");
      const bool in_chunk = std::any_of(r.chunks.begin(), r.chunks.end(), [&](const auto& c) {
        return at >= c.start + kRecordHeadSize && at < c.end;
      });
      if (in_chunk) {
        read_prefix(reader, r.sent);
      } else {
        while (reader.next()) {
        }
      }
      if (reader.status() != McapReadStatus::kEnd) {
        ++errors;
        EXPECT_EQ(reader.error().rfind("bad.mcap: ", 0), 0u) << reader.error();
      }
    }
    // Nearly every flip is noticed (the data section and summary CRCs cover the rest).
    EXPECT_GT(errors, r.file.size() * 9 / 10);
  }
}

TEST(McapDamagedFile, ErrorNamesTheRecordTheFieldAndTheByte) {
  const Recording r = make_recording(Compression::kNone);
  std::uint64_t chunk = 0;
  McapStreamReader intact(r.file, "intact.mcap");
  while (const auto record = intact.next()) {
    if (std::holds_alternative<Chunk>(*record)) {
      chunk = intact.record_offset();
      break;
    }
  }
  Bytes damaged = r.file;
  damaged[chunk + kRecordHeadSize + 24] ^= 1;  // uncompressed_crc
  McapStreamReader reader(damaged, "run.mcap");
  while (reader.next()) {
  }
  EXPECT_EQ(reader.status(), McapReadStatus::kError);
  EXPECT_EQ(reader.error().rfind("run.mcap: byte " + std::to_string(chunk + kRecordHeadSize + 24) +
                                     ": Chunk.uncompressed_crc: 0x",
                                 0),
            0u)
      << reader.error();

  // A length past the end of a record's content names the field.
  Bytes short_header(kMagic.begin(), kMagic.end());
  const std::uint8_t header[] = {1, 4, 0, 0, 0, 0, 0, 0, 0, 200, 0, 0, 0};
  short_header.insert(short_header.end(), std::begin(header), std::end(header));
  McapStreamReader bad(short_header, "h.mcap");
  EXPECT_FALSE(bad.next());
  EXPECT_EQ(bad.error(), "h.mcap: byte 17: Header.profile: needs 200 bytes, 0 left in the record");

  McapStreamReader not_mcap(std::span<const std::uint8_t>(r.file).subspan(1), "n.mcap");
  EXPECT_FALSE(not_mcap.next());
  EXPECT_EQ(not_mcap.status(), McapReadStatus::kError);
}

TEST(McapDamagedFile, AChunkClaimingMoreThanTheLimitIsRejectedBeforeAllocating) {
  const Recording r = make_recording(Compression::kZstd);
  McapReaderOptions options;
  options.max_chunk_size = 1000;  // the chunks hold about 2 KiB
  McapMessageReader reader(r.file, "big.mcap", options);
  EXPECT_FALSE(reader.next());
  EXPECT_EQ(reader.status(), McapReadStatus::kError);
  EXPECT_NE(reader.error().find("Chunk.uncompressed_size: "), std::string::npos) << reader.error();
}

}  // namespace
}  // namespace semap::drivers::mcap
