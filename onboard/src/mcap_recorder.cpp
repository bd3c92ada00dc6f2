#include "semap/onboard/mcap_recorder.hpp"

#include <pthread.h>
#include <spdlog/fmt/fmt.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "semap/common/logging.hpp"
#include "semap/dds_idl/recording_types.hpp"
#include "semap/dds_idl/ros2msg.hpp"
#include "semap/onboard/mcap_recording.hpp"

namespace semap::onboard {

namespace mcap = drivers::mcap;

namespace {

// The recording's stamps are the pipeline's CLOCK_MONOTONIC, kept exactly (not dds.stamp_clock).
dds_idl::msg::Time raw_time(common::Stamp stamp) {
  dds_idl::msg::Time t{};
  t.sec_ = static_cast<std::int32_t>(stamp.ns / 1'000'000'000);
  t.nanosec_ = static_cast<std::uint32_t>(stamp.ns % 1'000'000'000);
  return t;
}

std::uint64_t log_time(common::Stamp stamp) {
  return stamp.ns < 0 ? 0 : static_cast<std::uint64_t>(stamp.ns);
}

// Bytes an item holds beyond its own size.
constexpr std::size_t kItemOverhead = 128;

}  // namespace

McapRecorder::McapRecorder(const std::filesystem::path& path,
                           const std::filesystem::path& config_file, McapRecorderOptions options)
    : path_(path),
      options_(std::move(options)),
      failure_log_("recorder", "recording",
                   "the chunk's messages are lost and counted, the next chunk tries again; the "
                   "robot goes on") {
  if (std::filesystem::exists(path_)) {
    throw std::runtime_error("--record " + path_.string() + ": exists already");
  }
  if (path_.has_parent_path()) std::filesystem::create_directories(path_.parent_path());
  std::ifstream in(config_file, std::ios::binary);
  if (!in) throw std::runtime_error("--record: cannot read " + config_file.string());
  std::ostringstream text;
  text << in.rdbuf();
  const std::string config = text.str();
  if (options_.can_interface.empty()) options_.can_interface = "sim";

  writer_ = std::make_unique<mcap::McapWriter>(path_, options_.writer);
  // The configuration first: a replay needs nothing else, even from a cut-off file.
  const auto schema = writer_->add_schema("std_msgs/msg/String", "ros2msg",
                                          dds_idl::ros2msg_schema("std_msgs/msg/String"));
  const auto channel = writer_->add_channel(schema, dds_idl::RecordingTopics::kConfig, "cdr",
                                            {{"file", config_file.filename().string()}});
  dds_idl::msg::String m{};
  m.data_ = const_cast<char*>(config.c_str());
  dds_idl::serialize_cdr(m, cdr_);
  const auto now = log_time(common::Stamp::now());
  writer_->write(channel, 0, now, now, cdr_);
  thread_ = std::jthread([this](std::stop_token stop) { run(stop); });
}

McapRecorder::~McapRecorder() { close(); }

void McapRecorder::attach(Pipeline& pipeline) {
  pipeline.rig().set_taps(
      {.can_frame = [this](common::Stamp stamp, const SemapCanFrame& frame,
                           bool error_frame) { can_frame(stamp, frame, error_frame); },
       .gnss_bytes = [this](common::Stamp stamp,
                            std::span<const std::uint8_t> bytes) { gnss_bytes(stamp, bytes); }});
  pipeline.attach(*this);
  pipeline.attach_tap(*this);  // the DDS outputs, when there are some
}

bool McapRecorder::enqueue(Item&& item, std::size_t size) {
  {
    std::lock_guard lock(queue_mutex_);
    if (closing_) return false;  // after the run: the file is closed
    if (queued_bytes_ + size > options_.queue_bytes) {
      ++dropped_;
      return false;
    }
    queued_bytes_ += size;
    queue_.push_back(std::move(item));
  }
  queue_cv_.notify_one();
  return true;
}

void McapRecorder::can_frame(common::Stamp stamp, const SemapCanFrame& frame, bool error_frame) {
  if (frame.len > SEMAP_CAN_MAX_DLEN) {  // CAN FD: can_msgs/msg/Frame holds 8 bytes
    std::lock_guard lock(queue_mutex_);
    ++dropped_;
    return;
  }
  Item item;
  item.kind = Kind::kCan;
  item.stamp = stamp;
  item.can = frame;
  item.error_frame = error_frame;
  enqueue(std::move(item), kItemOverhead);
}

void McapRecorder::gnss_bytes(common::Stamp stamp, std::span<const std::uint8_t> bytes) {
  Item item;
  item.kind = Kind::kGnss;
  item.stamp = stamp;
  item.bytes.assign(bytes.begin(), bytes.end());
  enqueue(std::move(item), kItemOverhead + bytes.size());
}

void McapRecorder::on_frame(const common::ImageFrame& frame, bool depth) {
  {
    // Not even the copy when it would not fit.
    std::lock_guard lock(queue_mutex_);
    if (closing_) return;
    if (queued_bytes_ + frame.data.size() + kItemOverhead > options_.queue_bytes) {
      ++dropped_;
      return;
    }
  }
  Item item;
  item.kind = depth ? Kind::kDepth : Kind::kColour;
  item.stamp = frame.stamp;
  item.frame = frame;
  enqueue(std::move(item), kItemOverhead + frame.data.size());
}

std::uint32_t McapRecorder::add_channel(const dds_idl::TapChannel& channel) {
  std::lock_guard lock(writer_mutex_);
  const auto schema =
      writer_->add_schema(channel.type, "ros2msg", dds_idl::ros2msg_schema(channel.type));
  mcap::StringMap metadata;
  if (channel.latched) metadata["durability"] = "transient_local";
  const auto id = writer_->add_channel(schema, channel.topic, "cdr", std::move(metadata));
  if (tap_sequences_.size() <= id) tap_sequences_.resize(id + 1u, 0);
  return id;
}

void McapRecorder::on_message(std::uint32_t channel, common::Stamp stamp,
                              std::span<const std::uint8_t> cdr) noexcept {
  try {
    Item item;
    item.kind = Kind::kTap;
    item.stamp = stamp;
    item.channel = channel;
    item.bytes.assign(cdr.begin(), cdr.end());
    enqueue(std::move(item), kItemOverhead + cdr.size());
  } catch (...) {  // out of memory: one message less
    std::lock_guard lock(queue_mutex_);
    ++dropped_;
  }
}

std::uint16_t McapRecorder::input_channel(const char* topic, const char* type,
                                          mcap::StringMap metadata) {
  const auto schema = writer_->add_schema(type, "ros2msg", dds_idl::ros2msg_schema(type));
  return writer_->add_channel(schema, topic, "cdr", std::move(metadata));
}

template <typename F>
void McapRecorder::guarded(F&& f) {
  try {
    f();
    // A chunk reached the file: writing works (again).
    if (writer_->file_size() != last_file_size_) {
      last_file_size_ = writer_->file_size();
      std::lock_guard lock(counters_mutex_);
      counters_.failing = false;
    }
  } catch (const mcap::McapWriteError& e) {
    std::lock_guard lock(counters_mutex_);
    counters_.failing = true;
    counters_.last_error = e.what();
  }
  std::lock_guard lock(counters_mutex_);
  counters_.write_failures = writer_->messages_lost();
  counters_.bytes = writer_->file_size();
  failure_log_.update(counters_.write_failures, counters_.failing, counters_.last_error);
}

void McapRecorder::write_frame(const common::ImageFrame& frame, bool depth) {
  const auto stamp = raw_time(frame.stamp);
  const auto t = log_time(frame.stamp);
  char frame_id[] = "camera";
  char depth_id[] = "depth";
  if (frame.format == common::PixelFormat::kMjpeg) {
    auto& channel = depth ? depth_jpeg_channel_ : colour_jpeg_channel_;
    if (channel == 0) {
      channel = input_channel(depth ? dds_idl::RecordingTopics::kDepthCompressed
                                    : dds_idl::RecordingTopics::kColourCompressed,
                              "sensor_msgs/msg/CompressedImage");
    }
    dds_idl::msg::CompressedImage m{};
    m.header_.stamp_ = stamp;
    m.header_.frame_id_ = depth ? depth_id : frame_id;
    char format[] = "jpeg";
    m.format_ = format;
    m.data_ = dds_idl::borrow_sequence<dds_sequence_uint8>(
        const_cast<std::uint8_t*>(frame.data.data()), frame.data.size());
    dds_idl::serialize_cdr(m, cdr_);
    guarded([&] { writer_->write(channel, frame.sequence, t, t, cdr_); });
    return;
  }
  auto& channel = depth ? depth_channel_ : colour_channel_;
  if (channel == 0) {
    channel =
        input_channel(depth ? dds_idl::RecordingTopics::kDepth : dds_idl::RecordingTopics::kColour,
                      "sensor_msgs/msg/Image");
  }
  dds_idl::msg::Image m{};
  m.header_.stamp_ = stamp;
  m.header_.frame_id_ = depth ? depth_id : frame_id;
  m.height_ = frame.height;
  m.width_ = frame.width;
  std::string encoding(image_encoding(frame.format));
  m.encoding_ = encoding.data();
  m.is_bigendian_ = 0;
  m.step_ = frame.stride;
  m.data_ = dds_idl::borrow_sequence<dds_sequence_uint8>(
      const_cast<std::uint8_t*>(frame.data.data()), frame.data.size());
  dds_idl::serialize_cdr(m, cdr_);
  // The MCAP sequence carries the driver's frame sequence (a ROS 2 Header has none).
  guarded([&] { writer_->write(channel, frame.sequence, t, t, cdr_); });
}

void McapRecorder::write_item(Item& item) {
  const auto t = log_time(item.stamp);
  switch (item.kind) {
    case Kind::kCan: {
      if (can_channel_ == 0) {
        can_channel_ = input_channel(dds_idl::RecordingTopics::kCan, "can_msgs/msg/Frame",
                                     {{"interface", options_.can_interface}});
      }
      dds_idl::msg::CanFrame m{};
      m.header_.stamp_ = raw_time(item.stamp);
      m.header_.frame_id_ = options_.can_interface.data();
      m.id_ = item.can.id;
      m.is_rtr_ = false;
      m.is_extended_ = item.can.extended != 0;
      m.is_error_ = item.error_frame;
      m.dlc_ = item.can.len;
      std::memcpy(m.data_, item.can.data, std::min<std::size_t>(item.can.len, 8));
      dds_idl::serialize_cdr(m, cdr_);
      guarded([&] { writer_->write(can_channel_, can_sequence_++, t, t, cdr_); });
      std::lock_guard lock(counters_mutex_);
      ++counters_.can_frames;
      break;
    }
    case Kind::kGnss: {
      if (gnss_channel_ == 0) {
        gnss_channel_ = input_channel(dds_idl::RecordingTopics::kGnss, "semap_msgs/msg/GnssBytes");
      }
      dds_idl::msg::GnssBytes m{};
      m.header_.stamp_ = raw_time(item.stamp);
      char frame_id[] = "gnss";
      m.header_.frame_id_ = frame_id;
      m.data_ = dds_idl::borrow_sequence<dds_sequence_uint8>(item.bytes.data(), item.bytes.size());
      dds_idl::serialize_cdr(m, cdr_);
      guarded([&] { writer_->write(gnss_channel_, gnss_sequence_++, t, t, cdr_); });
      std::lock_guard lock(counters_mutex_);
      ++counters_.gnss_reads;
      counters_.gnss_bytes += item.bytes.size();
      break;
    }
    case Kind::kColour:
    case Kind::kDepth: {
      const bool depth = item.kind == Kind::kDepth;
      write_frame(item.frame, depth);
      std::lock_guard lock(counters_mutex_);
      ++(depth ? counters_.depth_frames : counters_.colour_frames);
      break;
    }
    case Kind::kTap: {
      const auto id = static_cast<std::uint16_t>(item.channel);
      guarded([&] { writer_->write(id, tap_sequences_[id]++, t, t, item.bytes); });
      std::lock_guard lock(counters_mutex_);
      ++counters_.outputs;
      break;
    }
  }
}

void McapRecorder::run(std::stop_token stop) {
  pthread_setname_np(pthread_self(), "recorder");  // its CPU in top -H, bench/recording
  std::deque<Item> batch;
  auto last_message = std::chrono::steady_clock::now();
  bool unflushed = false;
  const auto idle = std::chrono::nanoseconds(
      options_.writer.chunk_duration_ns > 0 ? options_.writer.chunk_duration_ns : 1'000'000'000);
  for (;;) {
    bool closing = false;
    {
      std::unique_lock lock(queue_mutex_);
      queue_cv_.wait_for(lock, stop, std::chrono::milliseconds(200),
                         [&] { return !queue_.empty() || closing_; });
      batch.swap(queue_);
      queued_bytes_ = 0;
      closing = closing_;
    }
    if (!batch.empty()) {
      std::lock_guard lock(writer_mutex_);
      for (Item& item : batch) write_item(item);
      batch.clear();
      last_message = std::chrono::steady_clock::now();
      unflushed = true;
    } else if (unflushed && std::chrono::steady_clock::now() - last_message >= idle) {
      // The streams went quiet: the open chunk goes to the disk now, not with the next message.
      std::lock_guard lock(writer_mutex_);
      guarded([&] { writer_->flush(); });
      unflushed = false;
    }
    if (closing || stop.stop_requested()) break;
  }
}

void McapRecorder::close() {
  {
    std::lock_guard lock(queue_mutex_);
    if (closing_) return;
    closing_ = true;
  }
  queue_cv_.notify_one();
  if (thread_.joinable()) thread_.join();
  std::lock_guard lock(writer_mutex_);
  // Whatever the thread did not take (it stops after its last batch).
  for (Item& item : queue_) write_item(item);
  queue_.clear();
  guarded([&] { writer_->close(); });
  std::lock_guard counters_lock(counters_mutex_);
  counters_.bytes = std::filesystem::exists(path_) ? std::filesystem::file_size(path_) : 0;
}

RecorderCounters McapRecorder::counters() const {
  RecorderCounters c;
  {
    std::lock_guard lock(counters_mutex_);
    c = counters_;
  }
  std::lock_guard lock(queue_mutex_);
  c.dropped = dropped_;
  return c;
}

void McapRecorder::summary(std::vector<std::string>& lines) const {
  const auto r = counters();
  lines.push_back(fmt::format(
      "recording        : {}: {} CAN frames, {} GNSS reads ({} bytes), {} colour and {} "
      "depth frames, {} output messages, {:.1f} MB ({}), {} dropped (queue full), {} write "
      "failures{}",
      path_.string(), r.can_frames, r.gnss_reads, r.gnss_bytes, r.colour_frames, r.depth_frames,
      r.outputs, static_cast<double>(r.bytes) / 1e6,
      mcap::compression_name(options_.writer.compression).empty()
          ? "uncompressed"
          : std::string(mcap::compression_name(options_.writer.compression)),
      r.dropped, r.write_failures,
      r.last_error.empty()
          ? ""
          : fmt::format(" ({}; last error: {})",
                        r.failing ? "still failing at exit" : "writing again", r.last_error)));
}

void McapRecorder::writers(std::vector<dds_idl::WriterHealthData>& out) const {
  const auto r = counters();
  dds_idl::WriterHealthData h;
  h.name = "recorder";
  h.path = path_.string();
  h.writes = r.can_frames + r.gnss_reads + r.colour_frames + r.depth_frames + r.outputs;
  h.failures = r.write_failures + r.dropped;
  h.failing = r.failing;
  h.last_error = r.last_error;
  out.push_back(std::move(h));
}

}  // namespace semap::onboard
