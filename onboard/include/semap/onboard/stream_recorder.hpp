#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <vector>

#include "semap/common/messages.hpp"
#include "semap/drivers/stream_log.hpp"
#include "semap/firmware_bridge/can_frame.h"
#include "semap/onboard/pipeline.hpp"

namespace semap::onboard {

// Files of a recording (semap-onboard --record DIR), as ReplayRig reads them.
struct RecordingFiles {
  static constexpr const char* kImu = "imu.log";        // candump -L
  static constexpr const char* kGnss = "gnss.log";      // drivers::StreamLogKind::kBytes
  static constexpr const char* kColour = "colour.log";  // drivers::StreamLogKind::kFrames
  static constexpr const char* kDepth = "depth.log";    // drivers::StreamLogKind::kFrames
  static constexpr const char* kConfig = "config.yaml";
};

struct RecorderCounters {
  std::uint64_t can_frames = 0;
  std::uint64_t gnss_reads = 0;
  std::uint64_t gnss_bytes = 0;
  std::uint64_t colour_frames = 0;
  std::uint64_t depth_frames = 0;
  std::uint64_t bytes = 0;           // written to disk, all files
  std::uint64_t write_failures = 0;  // records lost to a failed write (disk full, I/O error)
};

// Writes the raw sensor streams as they arrive: the IMU's CAN traffic as a `candump -L` log
// (stamps are CLOCK_MONOTONIC, as the pipeline's; canplayer replays by their differences), the
// GNSS port's bytes with their read stamps, colour and depth frames with their driver stamps,
// and a copy of the configuration. Each stream is written by the thread that produces it; a
// failed write is counted and logged once, and never stops the robot.
class StreamRecorder final : public PipelineObserver {
 public:
  // Creates `dir` (and fails, naming it, if it holds a recording already). `can_interface`
  // names the IMU's frames in the log ("sim" when the rig has no bus).
  StreamRecorder(const std::filesystem::path& dir, const std::filesystem::path& config_file,
                 std::string can_interface);
  ~StreamRecorder();
  StreamRecorder(const StreamRecorder&) = delete;
  StreamRecorder& operator=(const StreamRecorder&) = delete;

  // Records what the pipeline's rig reads and what its perception stage takes; before start().
  void attach(Pipeline& pipeline);
  void on_frame(const common::ImageFrame& frame, bool depth) override;
  void on_stopped() override { flush(); }
  void summary(std::vector<std::string>& lines) const override;

  void can_frame(common::Stamp stamp, const SemapCanFrame& frame, bool error_frame);
  void gnss_bytes(common::Stamp stamp, std::span<const std::uint8_t> bytes);
  void colour_frame(const common::ImageFrame& frame);
  void depth_frame(const common::ImageFrame& frame);

  // Flushes every file; what is on disk is then a complete recording.
  void flush();
  RecorderCounters counters() const;
  const std::filesystem::path& dir() const { return dir_; }

 private:
  // One log file and the lock of the thread that writes it.
  struct Stream {
    mutable std::mutex mutex;
    std::unique_ptr<drivers::StreamLogWriter> log;
    std::uint64_t payload = 0;  // bytes of the records' contents
    std::uint64_t failures = 0;
  };
  void write_frame(Stream& stream, const common::ImageFrame& frame);
  void failed(const std::string& what, std::uint64_t& failures);

  std::filesystem::path dir_;
  std::string interface_;
  mutable std::mutex can_mutex_;
  std::FILE* can_log_ = nullptr;
  std::uint64_t can_frames_ = 0;
  std::uint64_t can_bytes_ = 0;
  std::uint64_t can_failures_ = 0;
  bool can_ok_ = true;
  Stream gnss_;
  Stream colour_;
  Stream depth_;
};

}  // namespace semap::onboard
