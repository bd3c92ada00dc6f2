// The MCAP recorder's messages decode back with Cyclone to what it was given (CAN frames with
// error and extended ones, GNSS reads, frames in every camera format, tapped outputs, the
// configuration), the replay's reader gives the inputs back in stamp order, and a file cut off
// reads up to its last whole chunk.
#include "semap/onboard/mcap_recorder.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "semap/dds_idl/message_tap.hpp"
#include "semap/dds_idl/recording_types.hpp"
#include "semap/drivers/mcap_message_reader.hpp"
#include "semap/onboard/mcap_recording.hpp"

namespace {

namespace fs = std::filesystem;
namespace dds = semap::dds_idl;
namespace mcap = semap::drivers::mcap;
using semap::common::ImageFrame;
using semap::common::PixelFormat;
using semap::common::Stamp;
using semap::onboard::McapRecorder;
using semap::onboard::McapRecordingReader;

class McapRecorderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("semap_mcap_recorder_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    std::ofstream(dir_ / "robot.yaml") << "rig:\n  kind: hardware\n";
  }
  void TearDown() override { fs::remove_all(dir_); }

  static ImageFrame frame(PixelFormat format, std::int64_t ns, std::uint32_t sequence) {
    ImageFrame f;
    f.stamp = Stamp(ns);
    f.sequence = sequence;
    f.format = format;
    f.width = 8;
    f.height = 4;
    const std::uint32_t bpp = format == PixelFormat::kBgr24  ? 3
                              : format == PixelFormat::kGrey ? 1
                                                             : 2;
    f.stride = f.width * bpp + 4;  // padded rows stay as they are
    f.data.resize(f.stride * f.height);
    if (format == PixelFormat::kMjpeg) {
      // SOI, then a SOF0 of 8x4: what the replay reads the size from.
      f.data = {0xff, 0xd8, 0xff, 0xc0, 0x00, 0x11, 0x08, 0x00, 0x04, 0x00, 0x08, 0x03, 0xff, 0xd9};
      f.stride = 0;
    }
    for (std::size_t i = 0; f.format != PixelFormat::kMjpeg && i < f.data.size(); ++i) {
      f.data[i] = static_cast<std::uint8_t>(i * 7 + sequence);
    }
    return f;
  }

  fs::path dir_;
};

TEST_F(McapRecorderTest, EveryMessageDecodesBackToItsInput) {
  const fs::path file = dir_ / "run.mcap";
  std::vector<SemapCanFrame> can;
  std::vector<ImageFrame> frames;
  {
    semap::onboard::McapRecorderOptions options;
    options.can_interface = "can1";
    McapRecorder recorder(file, dir_ / "robot.yaml", options);
    for (int i = 0; i < 50; ++i) {
      SemapCanFrame f{};
      f.id = i % 5 == 0 ? 0x1abcdef0u + static_cast<std::uint32_t>(i) : 0x100u + i;
      f.extended = i % 5 == 0;
      f.len = static_cast<std::uint8_t>(i % 9);
      for (int b = 0; b < f.len; ++b) f.data[b] = static_cast<std::uint8_t>(i + b);
      recorder.can_frame(Stamp(1'000'000'000 + i * 1'000'000), f, i == 7);
      can.push_back(f);
    }
    const std::vector<std::uint8_t> nmea = {'$', 'G', 'P', 'G', 'G', 'A', ',', 0, 0xff};
    recorder.gnss_bytes(Stamp(1'000'500'000), nmea);
    std::uint32_t seq = 10;
    for (const auto format :
         {PixelFormat::kYuyv, PixelFormat::kGrey, PixelFormat::kBgr24, PixelFormat::kMjpeg}) {
      frames.push_back(frame(format, 1'001'000'000 + seq, seq));
      recorder.on_frame(frames.back(), false);
      ++seq;
    }
    frames.push_back(frame(PixelFormat::kZ16, 1'001'000'000 + seq, seq));
    recorder.on_frame(frames.back(), true);
    // An output as the DDS writers tap it.
    const auto channel = recorder.add_channel({"/semap/odometry", "nav_msgs/msg/Odometry", false});
    dds::msg::Odometry odom{};
    char map[] = "map", base[] = "base_link";
    odom.header_.frame_id_ = map;
    odom.child_frame_id_ = base;
    odom.pose_.pose_.position_.x_ = 1.5;
    std::vector<std::uint8_t> cdr;
    dds::serialize_cdr(odom, cdr);
    recorder.on_message(channel, Stamp(1'002'000'000), cdr);
    recorder.close();
    const auto c = recorder.counters();
    EXPECT_EQ(c.can_frames, 50u);
    EXPECT_EQ(c.gnss_reads, 1u);
    EXPECT_EQ(c.colour_frames, 4u);
    EXPECT_EQ(c.depth_frames, 1u);
    EXPECT_EQ(c.outputs, 1u);
    EXPECT_EQ(c.dropped, 0u);
    EXPECT_EQ(c.write_failures, 0u);
  }

  mcap::McapMessageReader reader(file);
  std::map<std::string, int> counts;
  std::size_t can_at = 0;
  while (const auto m = reader.next()) {
    const std::string topic = m->channel.topic;
    ASSERT_NE(m->schema, nullptr);
    EXPECT_EQ(m->schema->encoding, "ros2msg");
    EXPECT_EQ(m->channel.message_encoding, "cdr");
    ++counts[topic];
    if (topic == dds::RecordingTopics::kCan) {
      EXPECT_EQ(m->schema->name, "can_msgs/msg/Frame");
      dds::msg::CanFrame f{};
      ASSERT_TRUE(dds::deserialize_cdr(m->message.data, f));
      const SemapCanFrame& in = can[can_at];
      EXPECT_EQ(f.id_, in.id);
      EXPECT_EQ(f.is_extended_, in.extended != 0);
      EXPECT_EQ(f.is_error_, can_at == 7);
      EXPECT_FALSE(f.is_rtr_);
      EXPECT_EQ(f.dlc_, in.len);
      EXPECT_EQ(std::memcmp(f.data_, in.data, in.len), 0);
      EXPECT_STREQ(f.header_.frame_id_, "can1");
      EXPECT_EQ(f.header_.stamp_.sec_, 1);
      EXPECT_EQ(f.header_.stamp_.nanosec_, can_at * 1'000'000u);
      EXPECT_EQ(m->message.log_time, 1'000'000'000u + can_at * 1'000'000u);
      dds_sample_free(&f, dds::TypeDescriptor<dds::msg::CanFrame>::get(), DDS_FREE_CONTENTS);
      ++can_at;
    } else if (topic == dds::RecordingTopics::kGnss) {
      dds::msg::GnssBytes g{};
      ASSERT_TRUE(dds::deserialize_cdr(m->message.data, g));
      ASSERT_EQ(g.data_._length, 9u);
      EXPECT_EQ(g.data_._buffer[8], 0xff);
      EXPECT_EQ(g.header_.stamp_.nanosec_, 500'000u);
      dds_sample_free(&g, dds::TypeDescriptor<dds::msg::GnssBytes>::get(), DDS_FREE_CONTENTS);
    } else if (topic == dds::RecordingTopics::kColour || topic == dds::RecordingTopics::kDepth) {
      dds::msg::Image image{};
      ASSERT_TRUE(dds::deserialize_cdr(m->message.data, image));
      const ImageFrame* in = nullptr;
      for (const auto& f : frames) in = f.sequence == m->message.sequence ? &f : in;
      ASSERT_NE(in, nullptr);
      EXPECT_EQ(std::string(image.encoding_), semap::onboard::image_encoding(in->format));
      EXPECT_EQ(image.width_, in->width);
      EXPECT_EQ(image.height_, in->height);
      EXPECT_EQ(image.step_, in->stride);
      ASSERT_EQ(image.data_._length, in->data.size());
      EXPECT_EQ(std::memcmp(image.data_._buffer, in->data.data(), in->data.size()), 0);
      dds_sample_free(&image, dds::TypeDescriptor<dds::msg::Image>::get(), DDS_FREE_CONTENTS);
    } else if (topic == dds::RecordingTopics::kColourCompressed) {
      dds::msg::CompressedImage image{};
      ASSERT_TRUE(dds::deserialize_cdr(m->message.data, image));
      EXPECT_STREQ(image.format_, "jpeg");
      EXPECT_EQ(image.data_._length, 14u);
      dds_sample_free(&image, dds::TypeDescriptor<dds::msg::CompressedImage>::get(),
                      DDS_FREE_CONTENTS);
    } else if (topic == "/semap/odometry") {
      dds::msg::Odometry o{};
      ASSERT_TRUE(dds::deserialize_cdr(m->message.data, o));
      EXPECT_EQ(o.pose_.pose_.position_.x_, 1.5);
      EXPECT_STREQ(o.child_frame_id_, "base_link");
      dds_sample_free(&o, dds::TypeDescriptor<dds::msg::Odometry>::get(), DDS_FREE_CONTENTS);
    }
  }
  EXPECT_EQ(reader.status(), mcap::McapReadStatus::kEnd) << reader.error();
  EXPECT_EQ(counts[dds::RecordingTopics::kCan], 50);
  EXPECT_EQ(counts[dds::RecordingTopics::kColour], 3);
  EXPECT_EQ(counts[dds::RecordingTopics::kColourCompressed], 1);
  EXPECT_EQ(counts[dds::RecordingTopics::kDepth], 1);
  EXPECT_EQ(counts["/semap/odometry"], 1);
  EXPECT_EQ(semap::onboard::recorded_config(file), "rig:\n  kind: hardware\n");

  // The replay's reader: every input back, the frames as delivered.
  McapRecordingReader inputs(file);
  std::vector<std::int64_t> can_stamps;
  std::vector<ImageFrame> colour;
  while (!inputs.ended() || !inputs.can.empty() || !inputs.colour.empty()) {
    inputs.fill();
    for (const auto& c : inputs.can) can_stamps.push_back(c.stamp.ns);
    for (auto& f : inputs.colour) colour.push_back(std::move(f));
    inputs.can.clear();
    inputs.colour.clear();
    inputs.gnss.clear();
    inputs.depth.clear();
  }
  EXPECT_EQ(inputs.error(), "");
  ASSERT_EQ(can_stamps.size(), 50u);
  EXPECT_EQ(can_stamps[49], 1'049'000'000);
  ASSERT_EQ(colour.size(), 4u);
  for (std::size_t i = 0; i < colour.size(); ++i) {
    EXPECT_EQ(colour[i].format, frames[i].format);
    EXPECT_EQ(colour[i].sequence, frames[i].sequence);
    EXPECT_EQ(colour[i].stamp.ns, frames[i].stamp.ns);
    EXPECT_EQ(colour[i].width, frames[i].width);
    EXPECT_EQ(colour[i].height, frames[i].height);
    EXPECT_EQ(colour[i].stride, frames[i].stride);
    EXPECT_EQ(colour[i].data, frames[i].data);
  }
}

// Cut off anywhere, a recording gives the inputs of its whole chunks, then says where it ends.
TEST_F(McapRecorderTest, ACutOffRecordingReadsUpToItsLastWholeChunk) {
  const fs::path file = dir_ / "run.mcap";
  {
    semap::onboard::McapRecorderOptions options;
    options.writer.chunk_size = 4096;  // many chunks
    McapRecorder recorder(file, dir_ / "robot.yaml", options);
    for (int i = 0; i < 3000; ++i) {
      SemapCanFrame f{};
      f.id = 0x100;
      f.len = 8;
      std::memcpy(f.data, &i, sizeof(i));
      recorder.can_frame(Stamp(1'000'000'000 + i * 5'000'000LL), f, false);
    }
    recorder.close();
  }
  const auto size = fs::file_size(file);
  std::size_t previous = 0;
  for (const double fraction : {0.2, 0.5, 0.9, 0.999}) {
    const fs::path cut = dir_ / "cut.mcap";
    fs::copy_file(file, cut, fs::copy_options::overwrite_existing);
    fs::resize_file(cut, static_cast<std::uintmax_t>(static_cast<double>(size) * fraction));
    McapRecordingReader reader(cut);
    std::size_t n = 0;
    while (!reader.ended() || !reader.can.empty()) {
      reader.fill();
      for (const auto& c : reader.can) {
        int value = 0;
        std::memcpy(&value, c.frame.data, sizeof(value));
        ASSERT_EQ(value, static_cast<int>(n));  // in order, none missing
        ++n;
      }
      reader.can.clear();
    }
    EXPECT_NE(reader.error().find(cut.string() + ": truncated at byte "), std::string::npos)
        << reader.error();
    // Cut in the summary (0.999) every message is there; before it, fewer each time.
    EXPECT_LE(n, 3000u);
    if (fraction < 0.95) {
      EXPECT_GT(n, previous);
      EXPECT_LT(n, 3000u);
    }
    previous = n;
  }
}

// The queue is bounded: what does not fit is dropped and counted, never waited for.
TEST_F(McapRecorderTest, AFullQueueDropsAndCounts) {
  semap::onboard::McapRecorderOptions options;
  options.queue_bytes = 1u << 20;
  McapRecorder recorder(dir_ / "run.mcap", dir_ / "robot.yaml", options);
  ImageFrame big;
  big.format = PixelFormat::kBgr24;
  big.width = 1024;
  big.height = 1024;
  big.stride = 3072;
  big.data.resize(3u << 20);  // larger than the whole queue
  recorder.on_frame(big, false);
  recorder.close();
  EXPECT_EQ(recorder.counters().dropped, 1u);
  std::vector<semap::dds_idl::WriterHealthData> health;
  recorder.writers(health);
  ASSERT_EQ(health.size(), 1u);
  EXPECT_EQ(health[0].name, "recorder");
  EXPECT_EQ(health[0].failures, 1u);
}

}  // namespace
