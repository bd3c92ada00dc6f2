#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "semap/common/messages.hpp"
#include "semap/dds_idl/message_tap.hpp"
#include "semap/drivers/mcap_writer.hpp"
#include "semap/firmware_bridge/can_frame.h"
#include "semap/onboard/pipeline.hpp"
#include "semap/onboard/write_failure_log.hpp"

namespace semap::onboard {

struct McapRecorderOptions {
  // Profile ros2, 1 MiB / 1 s chunks; semap-onboard sets the compression (--record-compression,
  // lz4 by default).
  drivers::mcap::McapWriterOptions writer;
  // Bytes waiting for the recorder thread at most (copies of frames, reads, messages); what
  // comes while the queue is full is dropped and counted, so no driver or stage ever waits.
  std::size_t queue_bytes = 64u << 20;
  std::string can_interface = "sim";  // the CAN frames' header.frame_id
};

struct RecorderCounters {
  std::uint64_t can_frames = 0;
  std::uint64_t gnss_reads = 0;
  std::uint64_t gnss_bytes = 0;
  std::uint64_t colour_frames = 0;
  std::uint64_t depth_frames = 0;
  std::uint64_t outputs = 0;         // messages of the DDS outputs (the tap)
  std::uint64_t bytes = 0;           // the file's size
  std::uint64_t dropped = 0;         // not queued: the queue was full (or a CAN FD frame)
  std::uint64_t write_failures = 0;  // messages lost with a chunk that could not be written
  bool failing = false;              // the last chunk could not be written
  std::string last_error;
};

// semap-onboard --record FILE.mcap: one MCAP file (docs/record-replay.md) with the raw inputs
// as the drivers received them (the IMU's CAN frames, the GNSS port's reads, the camera frames
// the perception stage took, in their delivered format), the configuration, and every message
// of the DDS outputs as the CDR DDS sends (as a dds_idl::MessageTap). The threads that produce
// them only copy into a bounded queue (full: dropped and counted); the recorder's own thread
// serialises, compresses and writes. A chunk that cannot be written (disk full) is counted,
// logged (rate-limited) and reported in health; the file keeps ending after its last whole
// chunk and the next chunk tries again.
class McapRecorder final : public PipelineObserver, public dds_idl::MessageTap {
 public:
  // Creates `path` (refused when it exists) and writes the configuration file into it.
  McapRecorder(const std::filesystem::path& path, const std::filesystem::path& config_file,
               McapRecorderOptions options = {});
  ~McapRecorder() override;
  McapRecorder(const McapRecorder&) = delete;
  McapRecorder& operator=(const McapRecorder&) = delete;

  // Records what the pipeline's rig reads, the frames its perception stage takes and its DDS
  // outputs (when DDS is on); before start().
  void attach(Pipeline& pipeline);

  void can_frame(common::Stamp stamp, const SemapCanFrame& frame, bool error_frame);
  void gnss_bytes(common::Stamp stamp, std::span<const std::uint8_t> bytes);
  void on_frame(const common::ImageFrame& frame, bool depth) override;
  std::uint32_t add_channel(const dds_idl::TapChannel& channel) override;
  void on_message(std::uint32_t channel, common::Stamp stamp,
                  std::span<const std::uint8_t> cdr) noexcept override;

  // Writes everything queued and closes the file (summary, footer); later records are dropped.
  void close();
  void on_stopped() override { close(); }
  void summary(std::vector<std::string>& lines) const override;
  void writers(std::vector<dds_idl::WriterHealthData>& out) const override;

  RecorderCounters counters() const;
  const std::filesystem::path& path() const { return path_; }

 private:
  enum class Kind : std::uint8_t { kCan, kGnss, kColour, kDepth, kTap };
  struct Item {
    Kind kind = Kind::kCan;
    common::Stamp stamp;
    std::uint32_t channel = 0;  // kTap
    SemapCanFrame can{};
    bool error_frame = false;
    std::vector<std::uint8_t> bytes;  // GNSS read, tap CDR
    common::ImageFrame frame;
  };
  bool enqueue(Item&& item, std::size_t size);
  void run(std::stop_token stop);
  void write_item(Item& item);
  void write_frame(const common::ImageFrame& frame, bool depth);
  std::uint16_t input_channel(const char* topic, const char* type,
                              drivers::mcap::StringMap metadata = {});
  // Calls the writer, turning a failed chunk into counters and the log line.
  template <typename F>
  void guarded(F&& f);

  std::filesystem::path path_;
  McapRecorderOptions options_;

  // The queue, filled by drivers and stages, emptied by the recorder thread.
  mutable std::mutex queue_mutex_;
  std::condition_variable_any queue_cv_;
  std::deque<Item> queue_;
  std::size_t queued_bytes_ = 0;
  bool closing_ = false;
  std::uint64_t dropped_ = 0;

  // The writer and its channels: the recorder thread (and add_channel before start()).
  std::mutex writer_mutex_;
  std::unique_ptr<drivers::mcap::McapWriter> writer_;
  std::uint16_t can_channel_ = 0, gnss_channel_ = 0;
  std::uint16_t colour_channel_ = 0, depth_channel_ = 0;
  std::uint16_t colour_jpeg_channel_ = 0, depth_jpeg_channel_ = 0;
  std::uint32_t can_sequence_ = 0, gnss_sequence_ = 0;
  std::vector<std::uint32_t> tap_sequences_;  // by channel id
  std::vector<std::uint8_t> cdr_;             // reused
  std::uint64_t last_file_size_ = 0;
  WriteFailureLog failure_log_;

  mutable std::mutex counters_mutex_;
  RecorderCounters counters_;
  std::jthread thread_;
};

}  // namespace semap::onboard
