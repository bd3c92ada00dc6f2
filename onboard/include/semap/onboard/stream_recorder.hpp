#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <vector>

#include "semap/common/messages.hpp"
#include "semap/drivers/append_file.hpp"
#include "semap/drivers/stream_log.hpp"
#include "semap/firmware_bridge/can_frame.h"
#include "semap/onboard/pipeline.hpp"
#include "semap/onboard/write_failure_log.hpp"

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
  bool failing = false;              // a stream's last write failed
  std::string last_error;            // a failing stream's error, else the last one
};

// Writes the raw sensor streams as they arrive: the IMU's CAN traffic as a `candump -L` log
// (stamps are CLOCK_MONOTONIC, as the pipeline's; canplayer replays by their differences), the
// GNSS port's bytes with their read stamps, colour and depth frames with their driver stamps,
// and a copy of the configuration. Each stream is written by the thread that produces it
// (drivers::AppendFile). A write that fails (disk full) never stops the robot: the file keeps
// its whole records, the lost ones are counted, logged (rate-limited) and reported in health,
// and the stream records again once the disk has room.
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
  void writers(std::vector<dds_idl::WriterHealthData>& out) const override;

  void can_frame(common::Stamp stamp, const SemapCanFrame& frame, bool error_frame);
  void gnss_bytes(common::Stamp stamp, std::span<const std::uint8_t> bytes);
  void colour_frame(const common::ImageFrame& frame);
  void depth_frame(const common::ImageFrame& frame);

  // Flushes every file; what is on disk is then a complete recording.
  void flush();
  RecorderCounters counters() const;
  const std::filesystem::path& dir() const { return dir_; }

 private:
  // One file, the lock of the thread that writes it, and the log line of its failures.
  struct Stream {
    Stream();
    const drivers::AppendFile& file() const { return log ? log->file() : *lines; }
    // After a write, under the lock: its failures into the log.
    void note();

    mutable std::mutex mutex;
    std::unique_ptr<drivers::StreamLogWriter> log;  // GNSS, colour, depth
    std::unique_ptr<drivers::AppendFile> lines;     // the CAN log
    std::uint64_t payload = 0;                      // bytes of the records' contents (logs)
    WriteFailureLog failures;
  };
  void write_frame(Stream& stream, const common::ImageFrame& frame);

  std::filesystem::path dir_;
  std::string interface_;
  std::unique_ptr<Stream> can_;
  std::unique_ptr<Stream> gnss_;
  std::unique_ptr<Stream> colour_;
  std::unique_ptr<Stream> depth_;
};

}  // namespace semap::onboard
