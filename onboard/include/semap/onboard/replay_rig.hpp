#pragma once

#include <atomic>
#include <cstdint>
#include <fstream>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "semap/common/messages.hpp"
#include "semap/common/spsc_ring.hpp"
#include "semap/drivers/stream_log.hpp"
#include "semap/firmware_bridge/can_imu_decoder.hpp"
#include "semap/firmware_bridge/candump_reader.hpp"
#include "semap/firmware_bridge/gnss_stream_decoder.hpp"
#include "semap/onboard/mcap_recording.hpp"
#include "semap/onboard/onboard_config.hpp"
#include "semap/onboard/pseudo_terminal.hpp"
#include "semap/onboard/sensor_rig.hpp"

namespace semap::onboard {

// The files of a recording in the directory format of semap before MCAP (replayed for one
// more release; semap-onboard --record writes MCAP files only).
struct RecordingFiles {
  static constexpr const char* kImu = "imu.log";        // candump -L
  static constexpr const char* kGnss = "gnss.log";      // drivers::StreamLogKind::kBytes
  static constexpr const char* kColour = "colour.log";  // drivers::StreamLogKind::kFrames
  static constexpr const char* kDepth = "depth.log";    // drivers::StreamLogKind::kFrames
  static constexpr const char* kConfig = "config.yaml";
};

// What a replay has handed to the pipeline so far.
struct ReplayCounters {
  std::uint64_t can_frames = 0;
  std::uint64_t can_error_frames = 0;  // recorded bus errors: counted, not decoded
  std::uint64_t imu_samples = 0;
  std::uint64_t gnss_reads = 0;
  std::uint64_t gnss_fixes = 0;  // fast pace: decoded here; recorded pace: the driver decodes
  std::uint64_t colour_frames = 0;
  std::uint64_t depth_frames = 0;
};

// rig.kind: replay. Plays a recording made with `semap-onboard --record` (an MCAP file, or a
// directory of the format before it) back through the
// pipeline's own decoders, all streams merged in stamp order: the IMU's CAN frames through the
// CAN IMU decoder of the configured profile into the IMU ring, the GNSS bytes into a pty read by
// the real GnssDriver (recorded pace) or, as fast as possible, through the GNSS stream decoder
// with their recorded read stamps, and the camera's frames into the colour and depth rings.
// At recorded pace every stamp is shifted by offset() so the run happens now; as fast as
// possible the recorded stamps are kept and each colour frame waits until the stages have
// taken everything before it (pace_by), so a replay maps what the recorded run mapped.
// A damaged log ends its stream where the damage starts, with the error logged.
class ReplayRig final : public SensorRig {
 public:
  ReplayRig(const OnboardConfig& config, const SensorRings& rings);
  ~ReplayRig() override;
  ReplayRig(const ReplayRig&) = delete;
  ReplayRig& operator=(const ReplayRig&) = delete;

  std::string describe() const override { return "on a replay of " + dir_.string(); }
  bool has_camera() const override { return colour_ != nullptr || mcap_camera_; }
  // Pipeline stamp minus recorded stamp.
  std::int64_t stamp_offset_ns() const override { return offset_ns_; }
  // A replay is not recorded again: throws.
  void set_taps(RawTaps taps) override;
  void pace_by(Taken taken) override { taken_ = std::move(taken); }
  void start() override;
  void stop() override;
  bool finished() const override { return finished_.load(std::memory_order_acquire); }
  const RigDrivers& drivers() const override { return drivers_; }
  void summary(std::vector<std::string>& lines) const override;

  ReplayCounters counters() const;
  // The first damage found in any log, empty when every log was read to its end.
  std::string error() const;

 private:
  // One recorded stream: its file, its reader and the record up next.
  struct FrameStream {
    std::ifstream file;
    std::unique_ptr<drivers::StreamLogReader> reader;
    std::optional<common::ImageFrame> next;
  };
  void run(std::stop_token stop);
  void advance_imu();
  void advance_gnss();
  static void advance(FrameStream& stream);
  void play_can(const SemapCanFrame& frame, bool error_frame, common::Stamp stamp,
                std::stop_token stop);
  void play_gnss(const std::vector<std::uint8_t>& bytes, common::Stamp stamp, std::stop_token stop);
  void play_frame(common::ImageFrame frame, common::SpscRing<common::ImageFrame>& ring, bool colour,
                  std::stop_token stop);
  void open_directory(const OnboardConfig& config);
  template <typename T>
  void push(common::SpscRing<T>& ring, T value, std::stop_token stop);
  void wait_settled(std::stop_token stop);
  void note_error(const std::string& error);

  std::filesystem::path dir_;
  ReplayPace pace_;
  common::SpscRing<common::ImuSample>& imu_ring_;
  common::SpscRing<common::GnssFix>& gnss_ring_;
  common::SpscRing<common::ImageFrame>& colour_ring_;
  common::SpscRing<common::ImageFrame>& depth_ring_;

  std::ifstream imu_file_;
  std::unique_ptr<firmware_bridge::CandumpReader> imu_reader_;
  std::optional<SemapCandumpRecord> imu_next_;
  firmware_bridge::CanImuDecoder imu_decoder_;

  std::ifstream gnss_file_;
  std::unique_ptr<drivers::StreamLogReader> gnss_reader_;
  std::optional<drivers::ByteChunk> gnss_next_;
  firmware_bridge::GnssStreamDecoder gnss_decoder_;
  std::vector<common::GnssFix> fixes_;
  std::unique_ptr<PseudoTerminal> pty_;
  RigDrivers drivers_;  // recorded pace: the GNSS driver reading the pty

  std::unique_ptr<FrameStream> colour_;
  std::unique_ptr<FrameStream> depth_;
  // An MCAP recording (instead of the directory's readers above).
  std::unique_ptr<McapRecordingReader> mcap_;
  bool mcap_camera_ = false;

  std::int64_t offset_ns_ = 0;
  Taken taken_;
  mutable std::mutex mutex_;  // counters_ and error_, read by the main thread
  ReplayCounters counters_;
  std::string error_;
  std::atomic<bool> finished_{false};
  std::jthread thread_;
};

}  // namespace semap::onboard
