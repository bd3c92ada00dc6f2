#include "semap/onboard/replay_rig.hpp"

#include <spdlog/fmt/fmt.h>

#include <chrono>
#include <stdexcept>

#include "semap/common/logging.hpp"
#include "semap/onboard/rig_clock.hpp"

namespace semap::onboard {

namespace {

// A recording's stamps are CLOCK_MONOTONIC; the replay starts this long after it is set up, so
// the stages and the drivers are running when the first record is due.
constexpr double kStartDelay_s = 1.5;

common::Stamp stamp_of(const SemapCandumpRecord& r) {
  return common::Stamp(static_cast<std::int64_t>(r.seconds) * 1'000'000'000 +
                       static_cast<std::int64_t>(r.microseconds) * 1'000);
}

void open(std::ifstream& file, const std::filesystem::path& path) {
  file.open(path, std::ios::binary);
  if (!file) throw std::runtime_error("rig.replay: cannot read " + path.string());
}

}  // namespace

ReplayRig::ReplayRig(const OnboardConfig& config, const SensorRings& rings)
    : dir_(config.rig.replay),
      pace_(config.rig.pace),
      imu_ring_(rings.imu),
      gnss_ring_(rings.gnss),
      colour_ring_(rings.colour),
      depth_ring_(rings.depth),
      imu_decoder_(config.imu.driver.decoder),
      gnss_decoder_(config.gnss.driver.fix) {
  const std::filesystem::path& path = config.rig.replay;
  std::optional<common::Stamp> first;
  const auto earliest = [&](common::Stamp s) { first = first ? std::min(*first, s) : s; };
  if (std::filesystem::is_directory(path)) {
    open_directory(config);
    if (imu_next_) earliest(stamp_of(*imu_next_));
    if (gnss_next_) earliest(gnss_next_->stamp);
    if (colour_) earliest(colour_->next->stamp);
    if (depth_) earliest(depth_->next->stamp);
  } else {
    if (!is_mcap_file(path)) {
      throw std::runtime_error("rig.replay: " + path.string() +
                               " is neither an MCAP recording nor a recording's directory");
    }
    mcap_ = std::make_unique<McapRecordingReader>(path);
    mcap_->fill();
    const auto front = [&](const auto& queue) {
      if (!queue.empty()) earliest(queue.front().stamp);
    };
    front(mcap_->can);
    front(mcap_->gnss);
    front(mcap_->colour);
    front(mcap_->depth);
    if (!first) {
      throw std::runtime_error("rig.replay: " + path.string() + " holds no inputs" +
                               (mcap_->error().empty() ? "" : ": " + mcap_->error()));
    }
    // Whether a camera was recorded: its first frame within the recording's first 30 s.
    McapRecordingReader probe(path, 30'000'000'000);
    probe.fill();
    mcap_camera_ = !probe.colour.empty();
  }
  if (pace_ == ReplayPace::kRecorded) {
    pty_ = std::make_unique<PseudoTerminal>();
    auto gnss = config.gnss.driver;
    gnss.serial.device = pty_->slave_name();
    drivers_.add_gnss(gnss, rings.gnss);
    offset_ns_ = (common::Stamp::now() + kStartDelay_s).ns - first->ns;
  }
}

void ReplayRig::open_directory(const OnboardConfig& config) {
  const std::filesystem::path& dir = config.rig.replay;
  open(imu_file_, dir / RecordingFiles::kImu);
  imu_reader_ = std::make_unique<firmware_bridge::CandumpReader>(
      imu_file_, (dir / RecordingFiles::kImu).string());
  open(gnss_file_, dir / RecordingFiles::kGnss);
  gnss_reader_ = std::make_unique<drivers::StreamLogReader>(
      gnss_file_, (dir / RecordingFiles::kGnss).string(), drivers::StreamLogKind::kBytes);
  if (!gnss_reader_->error().empty()) throw std::runtime_error(gnss_reader_->error());
  const auto frames = [&](const char* name) -> std::unique_ptr<FrameStream> {
    const auto path = dir / name;
    if (!std::filesystem::exists(path)) return nullptr;
    auto stream = std::make_unique<FrameStream>();
    open(stream->file, path);
    stream->reader = std::make_unique<drivers::StreamLogReader>(stream->file, path.string(),
                                                                drivers::StreamLogKind::kFrames);
    if (!stream->reader->error().empty()) throw std::runtime_error(stream->reader->error());
    advance(*stream);
    // A recording without a camera has empty frame logs.
    return stream->next ? std::move(stream) : nullptr;
  };
  colour_ = frames(RecordingFiles::kColour);
  depth_ = frames(RecordingFiles::kDepth);
  advance_imu();
  advance_gnss();
  if (!imu_next_ && !gnss_next_ && !colour_) {
    throw std::runtime_error("rig.replay: " + dir.string() + " holds no records");
  }
}

ReplayRig::~ReplayRig() { stop(); }

void ReplayRig::set_taps(RawTaps) { throw std::runtime_error("a replay cannot be recorded again"); }

void ReplayRig::start() {
  drivers_.start();
  thread_ = std::jthread([this](std::stop_token stop) { run(stop); });
}

void ReplayRig::stop() {
  if (thread_.joinable()) {
    thread_.request_stop();
    thread_.join();
  }
  drivers_.stop();
}

void ReplayRig::summary(std::vector<std::string>& lines) const {
  const auto r = counters();
  const std::string damage = error();
  lines.push_back(fmt::format(
      "replay           : {} CAN frames ({} error frames), {} IMU samples, {} GNSS reads, "
      "{} colour and {} depth frames{}{}",
      r.can_frames, r.can_error_frames, r.imu_samples, r.gnss_reads, r.colour_frames,
      r.depth_frames, damage.empty() ? "" : "; damaged: ", damage));
}

ReplayCounters ReplayRig::counters() const {
  std::lock_guard lock(mutex_);
  return counters_;
}

std::string ReplayRig::error() const {
  std::lock_guard lock(mutex_);
  return error_;
}

void ReplayRig::note_error(const std::string& error) {
  if (error.empty()) return;
  common::logger("replay")->error("{}: the stream ends here", error);
  std::lock_guard lock(mutex_);
  if (error_.empty()) error_ = error;
}

void ReplayRig::advance_imu() {
  imu_next_ = imu_reader_->next();
  if (!imu_next_) note_error(imu_reader_->error());
}

void ReplayRig::advance_gnss() {
  gnss_next_ = gnss_reader_->next_bytes();
  if (!gnss_next_) note_error(gnss_reader_->error());
}

void ReplayRig::advance(FrameStream& stream) { stream.next = stream.reader->next_frame(); }

template <typename T>
void ReplayRig::push(common::SpscRing<T>& ring, T value, std::stop_token stop) {
  // As fast as possible nothing may be dropped: wait for room instead.
  if (pace_ == ReplayPace::kFast) {
    while (ring.size() + 1 >= ring.capacity() && !stop.stop_requested()) {
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
  }
  ring.try_push(std::move(value));
}

void ReplayRig::wait_settled(std::stop_token stop) {
  if (pace_ != ReplayPace::kFast || !taken_) return;
  const auto c = counters();
  const HandedOver handed{c.imu_samples, c.gnss_fixes, c.colour_frames};
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!taken_(handed) && !stop.stop_requested()) {
    if (std::chrono::steady_clock::now() > give_up) {
      common::logger("replay")->warn("the stages did not settle within 10 s: going on");
      return;
    }
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
}

void ReplayRig::play_can(const SemapCanFrame& frame, bool error_frame, common::Stamp stamp,
                         std::stop_token stop) {
  if (error_frame) {
    std::lock_guard lock(mutex_);
    ++counters_.can_error_frames;
    return;
  }
  const auto sample = imu_decoder_.push(frame, stamp);
  {
    std::lock_guard lock(mutex_);
    ++counters_.can_frames;
  }
  if (!sample) return;
  push(imu_ring_, *sample, stop);
  std::lock_guard lock(mutex_);
  ++counters_.imu_samples;
}

void ReplayRig::play_gnss(const std::vector<std::uint8_t>& bytes, common::Stamp stamp,
                          std::stop_token stop) {
  if (pty_) {
    if (const std::size_t lost = pty_->write(bytes); lost > 0) {
      common::logger("replay")->warn("{} GNSS bytes not taken by the driver", lost);
    }
    std::lock_guard lock(mutex_);
    ++counters_.gnss_reads;
    return;
  }
  fixes_.clear();
  gnss_decoder_.feed(bytes, stamp, fixes_);
  for (auto& fix : fixes_) push(gnss_ring_, std::move(fix), stop);
  std::lock_guard lock(mutex_);
  ++counters_.gnss_reads;
  counters_.gnss_fixes += fixes_.size();
}

void ReplayRig::play_frame(common::ImageFrame frame, common::SpscRing<common::ImageFrame>& ring,
                           bool colour, std::stop_token stop) {
  frame.stamp = common::Stamp(frame.stamp.ns + offset_ns_);
  if (colour) wait_settled(stop);
  push(ring, std::move(frame), stop);
  std::lock_guard lock(mutex_);
  ++(colour ? counters_.colour_frames : counters_.depth_frames);
}

void ReplayRig::run(std::stop_token stop) {
  auto log = common::logger("replay");
  // The earliest record next; on equal stamps depth before colour (a colour frame then finds
  // its partner), sensors before frames.
  enum class Next { kNone, kImu, kGnss, kDepth, kColour };
  while (!stop.stop_requested()) {
    Next next = Next::kNone;
    common::Stamp at;
    const auto consider = [&](Next which, common::Stamp stamp) {
      if (next == Next::kNone || stamp < at) {
        next = which;
        at = stamp;
      }
    };
    if (mcap_) {
      mcap_->fill();
      if (!mcap_->can.empty()) consider(Next::kImu, mcap_->can.front().stamp);
      if (!mcap_->gnss.empty()) consider(Next::kGnss, mcap_->gnss.front().stamp);
      if (!mcap_->depth.empty()) consider(Next::kDepth, mcap_->depth.front().stamp);
      if (!mcap_->colour.empty()) consider(Next::kColour, mcap_->colour.front().stamp);
    } else {
      if (imu_next_) consider(Next::kImu, stamp_of(*imu_next_));
      if (gnss_next_) consider(Next::kGnss, gnss_next_->stamp);
      if (depth_ && depth_->next) consider(Next::kDepth, depth_->next->stamp);
      if (colour_ && colour_->next) consider(Next::kColour, colour_->next->stamp);
    }
    if (next == Next::kNone) {
      if (mcap_) note_error(mcap_->error());
      break;
    }
    const common::Stamp stamp(at.ns + offset_ns_);
    if (pace_ == ReplayPace::kRecorded) sleep_until(stamp, stop);
    if (mcap_) {
      switch (next) {
        case Next::kImu:
          play_can(mcap_->can.front().frame, mcap_->can.front().error_frame, stamp, stop);
          mcap_->can.pop_front();
          break;
        case Next::kGnss:
          play_gnss(mcap_->gnss.front().bytes, stamp, stop);
          mcap_->gnss.pop_front();
          break;
        case Next::kDepth:
          play_frame(std::move(mcap_->depth.front()), depth_ring_, false, stop);
          mcap_->depth.pop_front();
          break;
        case Next::kColour:
          play_frame(std::move(mcap_->colour.front()), colour_ring_, true, stop);
          mcap_->colour.pop_front();
          break;
        case Next::kNone:
          break;
      }
      continue;
    }
    switch (next) {
      case Next::kImu:
        if (imu_next_->kind != SEMAP_CANDUMP_DATA) {
          play_can(imu_next_->frame, true, stamp, stop);
        } else {
          play_can(imu_next_->frame, false, stamp, stop);
        }
        advance_imu();
        break;
      case Next::kGnss:
        play_gnss(gnss_next_->bytes, stamp, stop);
        advance_gnss();
        break;
      case Next::kDepth:
        play_frame(std::move(*depth_->next), depth_ring_, false, stop);
        advance(*depth_);
        if (!depth_->next) note_error(depth_->reader->error());
        break;
      case Next::kColour:
        play_frame(std::move(*colour_->next), colour_ring_, true, stop);
        advance(*colour_);
        if (!colour_->next) note_error(colour_->reader->error());
        break;
      case Next::kNone:
        break;
    }
  }
  // The last frame's clouds are mapped before the run is called finished.
  wait_settled(stop);
  const auto c = counters();
  log->info(
      "replay finished: {} CAN frames -> {} IMU samples, {} GNSS reads{}, {} colour and {} depth "
      "frames",
      c.can_frames, c.imu_samples, c.gnss_reads,
      pty_ ? "" : " -> " + std::to_string(c.gnss_fixes) + " fixes", c.colour_frames,
      c.depth_frames);
  finished_.store(true, std::memory_order_release);
}

}  // namespace semap::onboard
