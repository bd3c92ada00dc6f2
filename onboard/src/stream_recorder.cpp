#include "semap/onboard/stream_recorder.hpp"

#include <spdlog/fmt/fmt.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "semap/common/logging.hpp"
#include "semap/firmware_bridge/candump_log.h"
#include "semap/firmware_bridge/candump_reader.hpp"

namespace semap::onboard {

StreamRecorder::StreamRecorder(const std::filesystem::path& dir,
                               const std::filesystem::path& config_file, std::string can_interface)
    : dir_(dir), interface_(std::move(can_interface)) {
  std::filesystem::create_directories(dir_);
  if (std::filesystem::exists(dir_ / RecordingFiles::kImu)) {
    throw std::runtime_error("--record " + dir_.string() + ": holds a recording already");
  }
  if (interface_.empty() || interface_.size() > SEMAP_CANDUMP_MAX_INTERFACE) interface_ = "sim";
  std::filesystem::copy_file(config_file, dir_ / RecordingFiles::kConfig,
                             std::filesystem::copy_options::overwrite_existing);
  const auto imu = dir_ / RecordingFiles::kImu;
  can_log_ = std::fopen(imu.c_str(), "w");
  if (can_log_ == nullptr) {
    throw std::runtime_error(imu.string() + ": cannot create: " + std::strerror(errno));
  }
  gnss_.log = std::make_unique<drivers::StreamLogWriter>(dir_ / RecordingFiles::kGnss,
                                                         drivers::StreamLogKind::kBytes);
  colour_.log = std::make_unique<drivers::StreamLogWriter>(dir_ / RecordingFiles::kColour,
                                                           drivers::StreamLogKind::kFrames);
  depth_.log = std::make_unique<drivers::StreamLogWriter>(dir_ / RecordingFiles::kDepth,
                                                          drivers::StreamLogKind::kFrames);
}

StreamRecorder::~StreamRecorder() {
  flush();
  if (can_log_ != nullptr) std::fclose(can_log_);
}

void StreamRecorder::failed(const std::string& what, std::uint64_t& failures) {
  if (failures++ == 0) common::logger("recorder")->error("{}: write failed; recording stops", what);
}

void StreamRecorder::can_frame(common::Stamp stamp, const SemapCanFrame& frame, bool error_frame) {
  SemapCandumpRecord record{};
  record.seconds = static_cast<std::uint64_t>(stamp.ns / 1'000'000'000);
  record.microseconds = static_cast<std::uint32_t>((stamp.ns % 1'000'000'000) / 1'000);
  std::memcpy(record.interface, interface_.c_str(), interface_.size() + 1);
  record.kind = error_frame ? SEMAP_CANDUMP_ERROR : SEMAP_CANDUMP_DATA;
  record.frame = frame;
  const std::string line = firmware_bridge::format_candump_line(record);
  std::lock_guard lock(can_mutex_);
  if (!can_ok_ || line.empty() ||
      std::fwrite(line.data(), 1, line.size(), can_log_) != line.size()) {
    can_ok_ = false;
    failed((dir_ / RecordingFiles::kImu).string(), can_failures_);
    return;
  }
  ++can_frames_;
  can_bytes_ += line.size();
}

void StreamRecorder::gnss_bytes(common::Stamp stamp, std::span<const std::uint8_t> bytes) {
  std::lock_guard lock(gnss_.mutex);
  if (gnss_.log->write_bytes(stamp, bytes)) {
    gnss_.payload += bytes.size();
  } else {
    failed(gnss_.log->path().string(), gnss_.failures);
  }
}

void StreamRecorder::write_frame(Stream& stream, const common::ImageFrame& frame) {
  std::lock_guard lock(stream.mutex);
  if (stream.log->write_frame(frame)) {
    stream.payload += frame.data.size();
  } else {
    failed(stream.log->path().string(), stream.failures);
  }
}

void StreamRecorder::colour_frame(const common::ImageFrame& frame) { write_frame(colour_, frame); }

void StreamRecorder::depth_frame(const common::ImageFrame& frame) { write_frame(depth_, frame); }

void StreamRecorder::flush() {
  {
    std::lock_guard lock(can_mutex_);
    if (can_log_ != nullptr && can_ok_ && std::fflush(can_log_) != 0) {
      can_ok_ = false;
      failed((dir_ / RecordingFiles::kImu).string(), can_failures_);
    }
  }
  for (Stream* s : {&gnss_, &colour_, &depth_}) {
    std::lock_guard lock(s->mutex);
    if (!s->log->flush()) failed(s->log->path().string(), s->failures);
  }
}

void StreamRecorder::attach(Pipeline& pipeline) {
  pipeline.rig().set_taps(
      {.can_frame = [this](common::Stamp stamp, const SemapCanFrame& frame,
                           bool error_frame) { can_frame(stamp, frame, error_frame); },
       .gnss_bytes = [this](common::Stamp stamp,
                            std::span<const std::uint8_t> bytes) { gnss_bytes(stamp, bytes); }});
  pipeline.attach(*this);
}

void StreamRecorder::on_frame(const common::ImageFrame& frame, bool depth) {
  depth ? depth_frame(frame) : colour_frame(frame);
}

void StreamRecorder::summary(std::vector<std::string>& lines) const {
  const auto r = counters();
  lines.push_back(fmt::format(
      "recording        : {}: {} CAN frames, {} GNSS reads ({} bytes), {} colour and {} "
      "depth frames, {:.1f} MB, {} write failures",
      dir_.string(), r.can_frames, r.gnss_reads, r.gnss_bytes, r.colour_frames, r.depth_frames,
      static_cast<double>(r.bytes) / 1e6, r.write_failures));
}

RecorderCounters StreamRecorder::counters() const {
  RecorderCounters c;
  {
    std::lock_guard lock(can_mutex_);
    c.can_frames = can_frames_;
    c.bytes += can_bytes_;
    c.write_failures += can_failures_;
  }
  const auto add = [&](const Stream& s, std::uint64_t& records) {
    std::lock_guard lock(s.mutex);
    records = s.log->records();
    c.bytes += s.log->size();
    c.write_failures += s.failures;
  };
  add(gnss_, c.gnss_reads);
  add(colour_, c.colour_frames);
  add(depth_, c.depth_frames);
  std::lock_guard lock(gnss_.mutex);
  c.gnss_bytes = gnss_.payload;
  return c;
}

}  // namespace semap::onboard
