#include "semap/drivers/stream_log.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace semap::drivers {
namespace {

std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

common::ImageFrame test_frame(std::uint32_t sequence) {
  common::ImageFrame f;
  f.stamp = common::Stamp(1'000'000'007 + sequence);
  f.sequence = sequence;
  f.format = common::PixelFormat::kYuyv;
  f.width = 4;
  f.height = 3;
  f.stride = 10;  // rows padded past 4 pixels x 2 bytes
  f.data.resize(30);
  for (std::size_t i = 0; i < f.data.size(); ++i)
    f.data[i] = static_cast<std::uint8_t>(i * 7 + sequence);
  return f;
}

class StreamLog : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        std::filesystem::temp_directory_path() / ("stream_log_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
};

TEST_F(StreamLog, BytesComeBackWithTheirStamps) {
  const auto path = dir_ / "gnss.log";
  {
    StreamLogWriter w(path, StreamLogKind::kBytes);
    const std::vector<std::uint8_t> a{'$', 'G', 'N'}, b{0xB5, 0x62, 0x01};
    ASSERT_TRUE(w.write_bytes(common::Stamp(5), a));
    ASSERT_TRUE(w.write_bytes(common::Stamp(-3), {}));  // an empty read keeps its stamp
    ASSERT_TRUE(w.write_bytes(common::Stamp(std::int64_t{1} << 40), b));
    EXPECT_EQ(w.records(), 3u);
    EXPECT_EQ(w.size(), 16u + 3 * 12 + 6);
  }
  std::istringstream in(slurp(path));
  StreamLogReader r(in, "gnss.log", StreamLogKind::kBytes);
  ASSERT_EQ(r.error(), "");
  auto c = r.next_bytes();
  ASSERT_TRUE(c);
  EXPECT_EQ(c->stamp.ns, 5);
  EXPECT_EQ(c->bytes, (std::vector<std::uint8_t>{'$', 'G', 'N'}));
  c = r.next_bytes();
  ASSERT_TRUE(c);
  EXPECT_EQ(c->stamp.ns, -3);
  EXPECT_TRUE(c->bytes.empty());
  c = r.next_bytes();
  ASSERT_TRUE(c);
  EXPECT_EQ(c->stamp.ns, std::int64_t{1} << 40);
  EXPECT_EQ(c->bytes, (std::vector<std::uint8_t>{0xB5, 0x62, 0x01}));
  EXPECT_FALSE(r.next_bytes());
  EXPECT_EQ(r.error(), "");
  EXPECT_EQ(r.records(), 3u);
}

TEST_F(StreamLog, FramesComeBackWhole) {
  const auto path = dir_ / "colour.log";
  {
    StreamLogWriter w(path, StreamLogKind::kFrames);
    for (std::uint32_t s = 0; s < 3; ++s) ASSERT_TRUE(w.write_frame(test_frame(s)));
    EXPECT_FALSE(w.write_bytes(common::Stamp(1), {}));  // not a log of bytes
  }
  std::istringstream in(slurp(path));
  StreamLogReader r(in, "colour.log", StreamLogKind::kFrames);
  for (std::uint32_t s = 0; s < 3; ++s) {
    const auto f = r.next_frame();
    ASSERT_TRUE(f) << r.error();
    const auto want = test_frame(s);
    EXPECT_EQ(f->stamp, want.stamp);
    EXPECT_EQ(f->sequence, s);
    EXPECT_EQ(f->format, want.format);
    EXPECT_EQ(f->width, want.width);
    EXPECT_EQ(f->height, want.height);
    EXPECT_EQ(f->stride, want.stride);
    EXPECT_EQ(f->data, want.data);
  }
  EXPECT_FALSE(r.next_frame());
  EXPECT_EQ(r.error(), "");
}

// A log cut anywhere (a crash mid-write) gives every record before the cut, and an error
// naming the record and field unless the cut falls between records.
TEST_F(StreamLog, ACutLogGivesTheRecordsBeforeTheCut) {
  const auto path = dir_ / "colour.log";
  std::vector<std::size_t> ends;  // where each record ends
  {
    StreamLogWriter w(path, StreamLogKind::kFrames);
    for (std::uint32_t s = 0; s < 4; ++s) {
      ASSERT_TRUE(w.write_frame(test_frame(s)));
      ASSERT_TRUE(w.flush());
      ends.push_back(w.size());
    }
  }
  const std::string whole = slurp(path);
  ASSERT_EQ(whole.size(), ends.back());
  for (std::size_t cut = 16; cut < whole.size(); ++cut) {
    std::istringstream in(whole.substr(0, cut));
    StreamLogReader r(in, "colour.log", StreamLogKind::kFrames);
    std::size_t frames = 0;
    while (r.next_frame()) ++frames;
    std::size_t complete = 0;
    while (complete < ends.size() && ends[complete] <= cut) ++complete;
    EXPECT_EQ(frames, complete) << "cut at " << cut;
    const bool between = cut == 16 || std::find(ends.begin(), ends.end(), cut) != ends.end();
    if (between) {
      EXPECT_EQ(r.error(), "") << "cut at " << cut;
    } else {
      const std::string where = "colour.log: record " + std::to_string(complete + 1) + " at byte " +
                                std::to_string(complete == 0 ? 16 : ends[complete - 1]) + ": ";
      EXPECT_EQ(r.error().rfind(where, 0), 0u) << r.error();
      EXPECT_NE(r.error().find("truncated"), std::string::npos) << r.error();
    }
  }
}

TEST_F(StreamLog, AWrongHeaderIsNamed) {
  const auto path = dir_ / "gnss.log";
  { StreamLogWriter w(path, StreamLogKind::kBytes); }
  const std::string header = slurp(path);
  const auto error_of = [](const std::string& bytes, StreamLogKind kind) {
    std::istringstream in(bytes);
    StreamLogReader r(in, "x.log", kind);
    return r.error();
  };
  EXPECT_EQ(error_of(header, StreamLogKind::kBytes), "");
  EXPECT_EQ(error_of(header, StreamLogKind::kFrames), "x.log: kind: expected a log of frames");
  EXPECT_EQ(error_of("", StreamLogKind::kBytes), "x.log: header: empty log");
  std::string bad = header;
  bad[0] = 'X';
  EXPECT_EQ(error_of(bad, StreamLogKind::kBytes),
            "x.log: header: not a semap stream log (no SEMAPLOG magic)");
  bad = header;
  bad[12] = 2;
  EXPECT_EQ(error_of(bad, StreamLogKind::kBytes), "x.log: version: 2 is not 1");
  EXPECT_NE(error_of(header.substr(0, 10), StreamLogKind::kBytes).find("header: truncated"),
            std::string::npos);
}

// Fields a reader downstream would trust: each damage is refused and named.
TEST_F(StreamLog, FrameFieldsOutsideTheLimitsAreNamed) {
  const auto path = dir_ / "colour.log";
  {
    StreamLogWriter w(path, StreamLogKind::kFrames);
    ASSERT_TRUE(w.write_frame(test_frame(0)));
  }
  const std::string good = slurp(path);
  const auto with = [&](std::size_t at, std::uint32_t value) {
    std::string bytes = good;
    for (int i = 0; i < 4; ++i) bytes[16 + at + i] = static_cast<char>(value >> (8 * i));
    std::istringstream in(bytes);
    StreamLogReader r(in, "c.log", StreamLogKind::kFrames);
    EXPECT_FALSE(r.next_frame());
    return r.error();
  };
  // Offsets in the record: stamp 0, sequence 8, fourcc 12, width 16, height 20, stride 24,
  // length 28.
  EXPECT_EQ(with(12, 0x34333231),
            "c.log: record 1 at byte 16: fourcc: 0x34333231 is not a pixel "
            "format semap reads");
  EXPECT_EQ(with(16, 0), "c.log: record 1 at byte 16: width: 0 outside 1..16384");
  EXPECT_EQ(with(20, 20000), "c.log: record 1 at byte 16: height: 20000 outside 1..16384");
  EXPECT_EQ(with(24, 7), "c.log: record 1 at byte 16: stride: 7 below the row's 8 bytes");
  EXPECT_EQ(with(28, kStreamLogMaxFrame + 1),
            "c.log: record 1 at byte 16: length: 268435457 beyond 268435456");
  // Shorter than its rows: the record reads whole, the frame is refused.
  std::string bytes = good.substr(0, good.size() - 1);
  for (int i = 0; i < 4; ++i) bytes[16 + 28 + i] = static_cast<char>(29u >> (8 * i));
  std::istringstream in(bytes);
  StreamLogReader r(in, "c.log", StreamLogKind::kFrames);
  EXPECT_FALSE(r.next_frame());
  EXPECT_EQ(r.error(), "c.log: record 1 at byte 16: length: 29 below stride x height 30");
}

TEST_F(StreamLog, AFailedWriteIsReportedAndSticks) {
  if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  StreamLogWriter w("/dev/full", StreamLogKind::kBytes);
  const std::vector<std::uint8_t> big(1 << 16, 'x');  // past stdio's buffer: the write fails
  EXPECT_FALSE(w.write_bytes(common::Stamp(1), big) && w.flush());
  EXPECT_FALSE(w.ok());
  EXPECT_FALSE(w.write_bytes(common::Stamp(2), big));
  EXPECT_THROW(StreamLogWriter(dir_ / "missing" / "x.log", StreamLogKind::kBytes),
               std::runtime_error);
}

}  // namespace
}  // namespace semap::drivers
