// The MCAP conformance suite (../shared/data/mcap-conformance, 416 files from foxglove/mcap,
// its README.md): each .mcap read with McapStreamReader must report exactly the records of its
// .json, in file order, without Chunk and MessageIndex records, with fields sorted by name and
// every integer and byte as a decimal string.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "semap/drivers/mcap_stream_reader.hpp"

namespace semap::drivers::mcap {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const fs::path kDir = fs::path(SEMAP_SHARED_DATA_DIR) / "mcap-conformance" / "data";

json num(std::uint64_t v) { return std::to_string(v); }

json bytes(const Bytes& data) {
  json out = json::array();
  for (const std::uint8_t b : data) out.push_back(std::to_string(b));
  return out;
}

json counts(const ChannelCounts& map) {
  json out = json::object();
  for (const auto& [key, value] : map) out[std::to_string(key)] = std::to_string(value);
  return out;
}

json strings(const StringMap& map) {
  json out = json::object();
  for (const auto& [key, value] : map) out[key] = value;
  return out;
}

// [[name, value], ...]: a JSON array of pairs (braces alone would make an object).
json pairs(std::initializer_list<std::pair<const char*, json>> fields) {
  json out = json::array();
  for (const auto& [name, value] : fields) out.push_back(json::array({name, value}));
  return out;
}

// The fields of the README's "Expected output 1", in its order; null for records left out.
json fields(const Record& record) {
  struct Visitor {
    json operator()(const Header& r) const {
      return pairs({{"library", r.library}, {"profile", r.profile}});
    }
    json operator()(const Footer& r) const {
      return pairs({{"summary_crc", num(r.summary_crc)},
                    {"summary_offset_start", num(r.summary_offset_start)},
                    {"summary_start", num(r.summary_start)}});
    }
    json operator()(const Schema& r) const {
      return pairs(
          {{"data", bytes(r.data)}, {"encoding", r.encoding}, {"id", num(r.id)}, {"name", r.name}});
    }
    json operator()(const Channel& r) const {
      return pairs({{"id", num(r.id)},
                    {"message_encoding", r.message_encoding},
                    {"metadata", strings(r.metadata)},
                    {"schema_id", num(r.schema_id)},
                    {"topic", r.topic}});
    }
    json operator()(const Message& r) const {
      return pairs({{"channel_id", num(r.channel_id)},
                    {"data", bytes(r.data)},
                    {"log_time", num(r.log_time)},
                    {"publish_time", num(r.publish_time)},
                    {"sequence", num(r.sequence)}});
    }
    json operator()(const Chunk&) const { return nullptr; }
    json operator()(const MessageIndex&) const { return nullptr; }
    json operator()(const ChunkIndex& r) const {
      return pairs({{"chunk_length", num(r.chunk_length)},
                    {"chunk_start_offset", num(r.chunk_start_offset)},
                    {"compressed_size", num(r.compressed_size)},
                    {"compression", r.compression},
                    {"message_end_time", num(r.message_end_time)},
                    {"message_index_length", num(r.message_index_length)},
                    {"message_index_offsets", counts(r.message_index_offsets)},
                    {"message_start_time", num(r.message_start_time)},
                    {"uncompressed_size", num(r.uncompressed_size)}});
    }
    json operator()(const Attachment& r) const {
      return pairs({{"create_time", num(r.create_time)},
                    {"data", bytes(r.data)},
                    {"log_time", num(r.log_time)},
                    {"media_type", r.media_type},
                    {"name", r.name}});
    }
    json operator()(const AttachmentIndex& r) const {
      return pairs({{"create_time", num(r.create_time)},
                    {"data_size", num(r.data_size)},
                    {"length", num(r.length)},
                    {"log_time", num(r.log_time)},
                    {"media_type", r.media_type},
                    {"name", r.name},
                    {"offset", num(r.offset)}});
    }
    json operator()(const Statistics& r) const {
      return pairs({{"attachment_count", num(r.attachment_count)},
                    {"channel_count", num(r.channel_count)},
                    {"channel_message_counts", counts(r.channel_message_counts)},
                    {"chunk_count", num(r.chunk_count)},
                    {"message_count", num(r.message_count)},
                    {"message_end_time", num(r.message_end_time)},
                    {"message_start_time", num(r.message_start_time)},
                    {"metadata_count", num(r.metadata_count)},
                    {"schema_count", num(r.schema_count)}});
    }
    json operator()(const Metadata& r) const {
      return pairs({{"metadata", strings(r.metadata)}, {"name", r.name}});
    }
    json operator()(const MetadataIndex& r) const {
      return pairs({{"length", num(r.length)}, {"name", r.name}, {"offset", num(r.offset)}});
    }
    json operator()(const SummaryOffset& r) const {
      return pairs({{"group_length", num(r.group_length)},
                    {"group_opcode", num(r.group_opcode)},
                    {"group_start", num(r.group_start)}});
    }
    json operator()(const DataEnd& r) const {
      return pairs({{"data_section_crc", num(r.data_section_crc)}});
    }
    json operator()(const UnknownRecord&) const { return nullptr; }
  };
  return std::visit(Visitor{}, record);
}

// What the streamed reader reports for one file: {"records": [...]}, or the error.
json read_records(const fs::path& path, std::string& error) {
  McapStreamReader reader(path);
  json records = json::array();
  while (const auto record = reader.next()) {
    json f = fields(*record);
    if (!f.is_null()) records.push_back({{"type", record_name(*record)}, {"fields", f}});
  }
  if (reader.status() != McapReadStatus::kEnd) error = reader.error();
  return records;
}

TEST(McapConformance, StreamedReaderReportsTheRecordsOfEveryFile) {
  if (!fs::is_directory(kDir)) {
    GTEST_SKIP() << kDir << " is absent (../shared/data/mcap-conformance, see its README.md)";
  }
  std::vector<fs::path> files;
  for (const auto& entry : fs::recursive_directory_iterator(kDir)) {
    if (entry.path().extension() == ".mcap") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  int passed = 0;
  for (const fs::path& file : files) {
    std::ifstream in(fs::path(file).replace_extension(".json"));
    const json expected = json::parse(in)["records"];
    std::string error;
    const json got = read_records(file, error);
    EXPECT_EQ(error, "") << file.filename();
    EXPECT_EQ(got, expected) << file.filename() << "\n got: " << got.dump()
                             << "\n want: " << expected.dump();
    passed += error.empty() && got == expected ? 1 : 0;
  }
  EXPECT_EQ(files.size(), 416u);
  EXPECT_EQ(passed, 416);
  std::printf("MCAP conformance: %d of %zu files read as expected\n", passed, files.size());
}

}  // namespace
}  // namespace semap::drivers::mcap
