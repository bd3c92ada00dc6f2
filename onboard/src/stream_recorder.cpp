#include "semap/onboard/stream_recorder.hpp"

#include <spdlog/fmt/fmt.h>

#include <cstring>
#include <stdexcept>

#include "semap/firmware_bridge/candump_log.h"
#include "semap/firmware_bridge/candump_reader.hpp"

namespace semap::onboard {

StreamRecorder::Stream::Stream()
    : failures("recorder", "recording",
               "records are dropped and counted, writing is tried again every second; the "
               "robot goes on") {}

void StreamRecorder::Stream::note() {
  const auto& f = file();
  failures.update(f.failures(), f.failing(), f.error());
}

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
  can_ = std::make_unique<Stream>();
  can_->lines = std::make_unique<drivers::AppendFile>(dir_ / RecordingFiles::kImu,
                                                      std::vector<std::uint8_t>{});
  const auto stream_log = [&](const char* name, drivers::StreamLogKind kind) {
    auto stream = std::make_unique<Stream>();
    stream->log = std::make_unique<drivers::StreamLogWriter>(dir_ / name, kind);
    return stream;
  };
  gnss_ = stream_log(RecordingFiles::kGnss, drivers::StreamLogKind::kBytes);
  colour_ = stream_log(RecordingFiles::kColour, drivers::StreamLogKind::kFrames);
  depth_ = stream_log(RecordingFiles::kDepth, drivers::StreamLogKind::kFrames);
}

StreamRecorder::~StreamRecorder() { flush(); }

void StreamRecorder::can_frame(common::Stamp stamp, const SemapCanFrame& frame, bool error_frame) {
  SemapCandumpRecord record{};
  record.seconds = static_cast<std::uint64_t>(stamp.ns / 1'000'000'000);
  record.microseconds = static_cast<std::uint32_t>((stamp.ns % 1'000'000'000) / 1'000);
  std::memcpy(record.interface, interface_.c_str(), interface_.size() + 1);
  record.kind = error_frame ? SEMAP_CANDUMP_ERROR : SEMAP_CANDUMP_DATA;
  record.frame = frame;
  const std::string line = firmware_bridge::format_candump_line(record);
  if (line.empty()) return;
  std::lock_guard lock(can_->mutex);
  can_->lines->append({reinterpret_cast<const std::uint8_t*>(line.data()), line.size()});
  can_->note();
}

void StreamRecorder::gnss_bytes(common::Stamp stamp, std::span<const std::uint8_t> bytes) {
  std::lock_guard lock(gnss_->mutex);
  if (gnss_->log->write_bytes(stamp, bytes)) gnss_->payload += bytes.size();
  gnss_->note();
}

void StreamRecorder::write_frame(Stream& stream, const common::ImageFrame& frame) {
  std::lock_guard lock(stream.mutex);
  if (stream.log->write_frame(frame)) stream.payload += frame.data.size();
  stream.note();
}

void StreamRecorder::colour_frame(const common::ImageFrame& frame) { write_frame(*colour_, frame); }

void StreamRecorder::depth_frame(const common::ImageFrame& frame) { write_frame(*depth_, frame); }

void StreamRecorder::flush() {
  {
    std::lock_guard lock(can_->mutex);
    can_->lines->flush();
    can_->note();
  }
  for (Stream* s : {gnss_.get(), colour_.get(), depth_.get()}) {
    std::lock_guard lock(s->mutex);
    s->log->flush();
    s->note();
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
      "depth frames, {:.1f} MB, {} write failures{}",
      dir_.string(), r.can_frames, r.gnss_reads, r.gnss_bytes, r.colour_frames, r.depth_frames,
      static_cast<double>(r.bytes) / 1e6, r.write_failures,
      r.last_error.empty()
          ? ""
          : fmt::format(" ({}; last error: {})",
                        r.failing ? "still failing at exit" : "writing again", r.last_error)));
}

void StreamRecorder::writers(std::vector<dds_idl::WriterHealthData>& out) const {
  const auto r = counters();
  dds_idl::WriterHealthData h;
  h.name = "recorder";
  h.path = dir_.string();
  h.writes = r.can_frames + r.gnss_reads + r.colour_frames + r.depth_frames;
  h.failures = r.write_failures;
  h.failing = r.failing;
  h.last_error = r.last_error;
  out.push_back(std::move(h));
}

RecorderCounters StreamRecorder::counters() const {
  RecorderCounters c;
  const auto add = [&](const Stream& s, std::uint64_t& records) {
    std::lock_guard lock(s.mutex);
    const auto& f = s.file();
    records = f.records();
    c.bytes += f.bytes();
    c.write_failures += f.lost();
    // A failing stream's error says more than one that has recovered.
    if (!f.error().empty() && (f.failing() || !c.failing)) c.last_error = f.error();
    c.failing = c.failing || f.failing();
  };
  add(*can_, c.can_frames);
  add(*gnss_, c.gnss_reads);
  add(*colour_, c.colour_frames);
  add(*depth_, c.depth_frames);
  std::lock_guard lock(gnss_->mutex);
  c.gnss_bytes = gnss_->payload;
  return c;
}

}  // namespace semap::onboard
