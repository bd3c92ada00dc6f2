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

#include "onboard_config.hpp"
#include "pseudo_terminal.hpp"
#include "semap/common/messages.hpp"
#include "semap/common/spsc_ring.hpp"
#include "semap/drivers/stream_log.hpp"
#include "semap/firmware_bridge/can_imu_decoder.hpp"
#include "semap/firmware_bridge/candump_reader.hpp"
#include "semap/firmware_bridge/gnss_stream_decoder.hpp"

namespace semap::onboard {

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

// rig.kind: replay. Plays a recording made with `semap-onboard --record` back through the
// pipeline's own decoders, all streams merged in stamp order: the IMU's CAN frames through the
// CAN IMU decoder of the configured profile into the IMU ring, the GNSS bytes into a pty read by
// the real GnssDriver (recorded pace) or, as fast as possible, through the GNSS stream decoder
// with their recorded read stamps, and the camera's frames into the colour and depth rings.
// At recorded pace every stamp is shifted by offset() so the run happens now; as fast as
// possible the recorded stamps are kept and each colour frame waits until the stages have
// taken everything before it (set_settled), so a replay maps what the recorded run mapped.
// A damaged log ends its stream where the damage starts, with the error logged.
class ReplayRig {
 public:
  ReplayRig(const OnboardConfig& config, common::SpscRing<common::ImuSample>& imu_ring,
            common::SpscRing<common::GnssFix>& gnss_ring,
            common::SpscRing<common::ImageFrame>& colour_ring,
            common::SpscRing<common::ImageFrame>& depth_ring);
  ~ReplayRig();
  ReplayRig(const ReplayRig&) = delete;
  ReplayRig& operator=(const ReplayRig&) = delete;

  // Fast pace: true once the stages have taken all that counters() says was handed over.
  using Settled = std::function<bool(const ReplayCounters&)>;
  void set_settled(Settled settled) { settled_ = std::move(settled); }

  // The pty the GNSS driver should open (recorded pace), empty otherwise.
  const std::string& gnss_device() const { return pty_name_; }
  // Pipeline stamp minus recorded stamp.
  std::int64_t offset_ns() const { return offset_ns_; }
  bool has_camera() const { return colour_ != nullptr; }

  void start();
  void stop();
  bool finished() const { return finished_.load(std::memory_order_acquire); }
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
  void play_imu(common::Stamp stamp, std::stop_token stop);
  void play_gnss(common::Stamp stamp, std::stop_token stop);
  void play_frame(FrameStream& stream, common::SpscRing<common::ImageFrame>& ring, bool colour,
                  std::stop_token stop);
  template <typename T>
  void push(common::SpscRing<T>& ring, T value, std::stop_token stop);
  void wait_settled(std::stop_token stop);
  void note_error(const std::string& error);

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
  std::string pty_name_;

  std::unique_ptr<FrameStream> colour_;
  std::unique_ptr<FrameStream> depth_;

  std::int64_t offset_ns_ = 0;
  Settled settled_;
  mutable std::mutex mutex_;  // counters_ and error_, read by the main thread
  ReplayCounters counters_;
  std::string error_;
  std::atomic<bool> finished_{false};
  std::jthread thread_;
};

}  // namespace semap::onboard
