// semap-can: decodes an IMU's CAN frames like the robot does (semap protocol or J1939, as the
// onboard config's imu: section or the flags say), from a live interface or a `candump -L`
// log or an MCAP recording of semap-onboard (its can_msgs/msg/Frame channel), into one line or
// JSON object per sample, then every counter. Records a live interface as a candump -L log that
// can-utils' canplayer replays, and extracts an MCAP recording's CAN frames as one.
#include <linux/can.h>

#include <CLI/CLI.hpp>
#include <array>
#include <atomic>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "semap/common/config.hpp"
#include "semap/common/logging.hpp"
#include "semap/dds_idl/message_tap.hpp"
#include "semap/dds_idl/recording_types.hpp"
#include "semap/drivers/can_bus_state.hpp"
#include "semap/drivers/can_socket.hpp"
#include "semap/drivers/driver_config.hpp"
#include "semap/drivers/mcap_message_reader.hpp"
#include "semap/firmware_bridge/can_imu_decoder.hpp"
#include "semap/firmware_bridge/candump_reader.hpp"

namespace {

namespace fb = semap::firmware_bridge;
namespace dr = semap::drivers;
using semap::common::ImuSample;
using semap::common::Stamp;

std::atomic<bool> g_stop{false};

void on_signal(int) { g_stop = true; }

// Frames and bus events beside the decoder's own counters.
struct InputCounters {
  std::uint64_t records = 0;        // log lines or frames read
  std::uint64_t other_channel = 0;  // log records of another interface (--channel)
  std::uint64_t remote = 0;
  std::uint64_t error_frames = 0;
  std::uint64_t bus_off = 0;
  std::uint64_t error_passive = 0;
  std::uint64_t restarted = 0;
  std::uint64_t bus_errors = 0;  // protocol, ACK, arbitration, transceiver, overflow
};

// Sample and event times are CLOCK_REALTIME, as candump logs them.
Stamp realtime_stamp(const SemapCandumpRecord& r) {
  return Stamp(static_cast<std::int64_t>(r.seconds) * 1'000'000'000 +
               static_cast<std::int64_t>(r.microseconds) * 1'000);
}

void print_sample(const ImuSample& s, bool json) {
  const double t = static_cast<double>(s.stamp.ns) * 1e-9;
  if (json) {
    std::printf(
        "{\"class\":\"IMU\",\"time\":%.6f,\"seq\":%u,\"gyro\":[%.6f,%.6f,%.6f],"
        "\"accel\":[%.4f,%.4f,%.4f]}\n",
        t, s.sequence, s.gyro.x(), s.gyro.y(), s.gyro.z(), s.accel.x(), s.accel.y(), s.accel.z());
  } else {
    std::printf("%.6f seq %u gyro %.6f %.6f %.6f rad/s accel %.4f %.4f %.4f m/s^2\n", t, s.sequence,
                s.gyro.x(), s.gyro.y(), s.gyro.z(), s.accel.x(), s.accel.y(), s.accel.z());
  }
}

// An error frame (class bits in frame.id): prints the controller state it reports, if any.
void handle_error_frame(const SemapCanFrame& frame, Stamp stamp, bool json, InputCounters& c) {
  ++c.error_frames;
  can_frame kernel{};
  kernel.can_id = CAN_ERR_FLAG | frame.id;
  kernel.len = frame.len;
  std::memcpy(kernel.data, frame.data, frame.len < CAN_MAX_DLEN ? frame.len : CAN_MAX_DLEN);
  const dr::CanErrorReport report = dr::classify_error_frame(kernel);
  if (report.bus_error) ++c.bus_errors;
  if (!report.state) return;
  if (*report.state == dr::CanBusState::kBusOff) ++c.bus_off;
  if (*report.state == dr::CanBusState::kErrorPassive) ++c.error_passive;
  if (report.restarted) ++c.restarted;
  const double t = static_cast<double>(stamp.ns) * 1e-9;
  const char* state = dr::to_string(*report.state);
  if (json) {
    std::printf("{\"class\":\"BUS\",\"time\":%.6f,\"state\":\"%s\",\"restarted\":%s}\n", t, state,
                report.restarted ? "true" : "false");
  } else {
    std::printf("%.6f bus %s%s\n", t, state, report.restarted ? " (restarted)" : "");
  }
}

void print_counters(const fb::CanImuCounters& d, const InputCounters& in, bool json) {
  const std::vector<std::pair<const char*, std::uint64_t>> all = {
      {"records", in.records},
      {"other_channel", in.other_channel},
      {"remote", in.remote},
      {"error_frames", in.error_frames},
      {"bus_off", in.bus_off},
      {"error_passive", in.error_passive},
      {"restarted", in.restarted},
      {"bus_errors", in.bus_errors},
      {"frames", d.frames},
      {"unknown", d.unknown},
      {"samples", d.samples},
      {"crc_errors", d.crc_errors},
      {"bad_frames", d.bad_frames},
      {"incomplete", d.incomplete},
      {"sequence_gaps", d.sequence_gaps},
      {"missed_samples", d.missed_samples},
      {"unpaired", d.unpaired}};
  std::printf(json ? "{\"class\":\"COUNTERS\"" : "counters:");
  for (const auto& [name, value] : all) {
    std::printf(json ? ",\"%s\":%llu" : " %s=%llu", name, static_cast<unsigned long long>(value));
  }
  std::printf(json ? "}\n" : "\n");
}

// The live interface's frames as candump -L lines, flushed per frame so a crash loses none.
class LogRecorder {
 public:
  LogRecorder(const std::string& path, std::string interface) : interface_(std::move(interface)) {
    if (path.empty()) return;
    file_ = std::fopen(path.c_str(), "w");
    if (file_ == nullptr) throw std::runtime_error("--record " + path + ": cannot create");
    path_ = path;
  }
  ~LogRecorder() {
    if (file_ != nullptr) std::fclose(file_);
  }
  LogRecorder(const LogRecorder&) = delete;
  LogRecorder& operator=(const LogRecorder&) = delete;

  void write(const dr::CanRxFrame& rx, bool error) {
    if (file_ == nullptr) return;
    SemapCandumpRecord r{};
    r.seconds = static_cast<std::uint64_t>(rx.realtime_ns / 1'000'000'000);
    r.microseconds = static_cast<std::uint32_t>((rx.realtime_ns % 1'000'000'000) / 1'000);
    std::snprintf(r.interface, sizeof r.interface, "%s", interface_.c_str());
    r.kind = error ? SEMAP_CANDUMP_ERROR : SEMAP_CANDUMP_DATA;
    r.frame = rx.frame;
    const std::string line = fb::format_candump_line(r);
    if (std::fputs(line.c_str(), file_) < 0 || std::fflush(file_) != 0) {
      throw std::runtime_error("--record " + path_ + ": write failed");
    }
  }

 private:
  std::string interface_;
  std::FILE* file_ = nullptr;
  std::string path_;
};

struct Options {
  std::string interface;
  std::string input;
  std::string from_mcap;
  std::string candump;
  std::string channel;
  std::string config;
  std::string profile;
  int base_id = -1;
  std::string j1939_source;
  bool fd = false;
  bool json = false;
  std::string record;
  std::uint64_t count = 0;
  double seconds = 0.0;
};

// The onboard config's imu: section when given, then the flags on top.
fb::CanImuDecoderConfig decoder_config(const Options& o, bool& fd_frames) {
  fb::CanImuDecoderConfig d;
  if (!o.config.empty()) {
    const auto root = semap::common::ConfigSection::load_file(o.config);
    const dr::CanImuConfig imu = dr::can_imu_config(root.section_or_empty("imu"));
    d = imu.decoder;
    fd_frames = imu.fd_frames;
  }
  // The flags go through the config reader too, so they obey the same ranges and spellings.
  std::string flags;
  if (!o.profile.empty()) flags += "profile: " + o.profile + "\n";
  if (o.base_id >= 0) flags += "base_id: " + std::to_string(o.base_id) + "\n";
  if (!o.j1939_source.empty()) flags += "j1939_source: " + o.j1939_source + "\n";
  if (!flags.empty()) {
    const auto section = semap::common::ConfigSection::load_string(flags, "command line");
    const dr::CanImuConfig parsed = dr::can_imu_config(section);
    if (!o.profile.empty()) d.profile = parsed.decoder.profile;
    if (o.base_id >= 0) d.base_id = parsed.decoder.base_id;
    if (!o.j1939_source.empty()) d.j1939_source = parsed.decoder.j1939_source;
  }
  fd_frames = fd_frames || o.fd;
  return d;
}

int run(int argc, char** argv) {
  CLI::App app{
      "Decode an IMU's CAN frames (semap protocol or J1939) from a live interface or a candump -L "
      "log: one line (or JSON object) per sample, then the counters; record a live interface as "
      "a candump -L log"};
  Options o;
  std::string log_level = "warn";
  auto* input_opt =
      app.add_option("--input", o.input, "candump -L log (candump -L can0 > drive.log)")
          ->check(CLI::ExistingFile);
  auto* interface_opt =
      app.add_option("--interface", o.interface, "live CAN interface (can0, vcan0)")
          ->excludes(input_opt);
  auto* mcap_opt = app.add_option("--from-mcap", o.from_mcap,
                                  "an MCAP recording of semap-onboard --record: its CAN frames "
                                  "(/semap/raw/can, can_msgs/msg/Frame)")
                       ->check(CLI::ExistingFile)
                       ->excludes(input_opt)
                       ->excludes(interface_opt);
  input_opt->excludes(interface_opt);
  app.add_option("--candump", o.candump,
                 "with --from-mcap: write its CAN frames as a candump -L log for can-utils")
      ->needs(mcap_opt);
  app.add_option("--channel", o.channel, "with --input: only records of this interface")
      ->needs(input_opt);
  app.add_option("--config", o.config, "onboard YAML: the IMU profile from its imu: section")
      ->check(CLI::ExistingFile);
  app.add_option("--profile", o.profile, "semap | j1939 (overrides the config)");
  app.add_option("--base-id", o.base_id, "semap profile: base identifier, 4-aligned");
  app.add_option("--j1939-source", o.j1939_source, "j1939 profile: source address 0..253 or any");
  app.add_flag("--fd", o.fd, "with --interface: also receive CAN FD frames");
  app.add_flag("--json", o.json, "one JSON object per sample and bus event, then the counters");
  app.add_option("--record", o.record, "with --interface: save every frame as a candump -L log")
      ->needs(interface_opt);
  app.add_option("--count", o.count, "stop after this many samples (0: no limit)");
  app.add_option("--seconds", o.seconds, "with --interface: stop after this long (0: Ctrl-C)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--log-level", log_level, "trace..off");
  CLI11_PARSE(app, argc, argv);
  semap::common::setup_logging(log_level);
  if (o.input.empty() && o.interface.empty() && o.from_mcap.empty()) {
    std::fprintf(stderr, "semap-can: give --input LOG, --from-mcap FILE.mcap or --interface IF\n");
    return 2;
  }

  bool fd_frames = false;
  fb::CanImuDecoder decoder(decoder_config(o, fd_frames));
  InputCounters in;
  std::uint64_t printed = 0;
  // Returns true once --count samples are out.
  const auto push = [&](const SemapCanFrame& frame, Stamp stamp) {
    if (auto sample = decoder.push(frame, stamp)) {
      print_sample(*sample, o.json);
      ++printed;
    }
    return o.count > 0 && printed >= o.count;
  };
  try {
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    if (!o.from_mcap.empty()) {
      // Stamps are the recording's (CLOCK_MONOTONIC, as the robot's), kept in the candump log.
      namespace dds = semap::dds_idl;
      semap::drivers::mcap::McapMessageReader reader{std::filesystem::path(o.from_mcap)};
      std::unique_ptr<std::FILE, int (*)(std::FILE*)> log(nullptr, &std::fclose);
      if (!o.candump.empty()) {
        log.reset(std::fopen(o.candump.c_str(), "w"));
        if (!log) throw std::runtime_error("--candump " + o.candump + ": cannot create");
      }
      while (!g_stop) {
        const auto m = reader.next();
        if (!m) break;
        if (m->channel.topic != dds::RecordingTopics::kCan) continue;
        dds::msg::CanFrame f{};
        if (!dds::deserialize_cdr(m->message.data, f) || f.dlc_ > SEMAP_CAN_MAX_DLEN) {
          throw std::runtime_error(o.from_mcap + ": a " + dds::RecordingTopics::kCan +
                                   " message does not decode as can_msgs/msg/Frame");
        }
        SemapCandumpRecord r{};
        r.seconds =
            f.header_.stamp_.sec_ < 0 ? 0 : static_cast<std::uint64_t>(f.header_.stamp_.sec_);
        r.microseconds = f.header_.stamp_.nanosec_ / 1000;
        const std::string interface = f.header_.frame_id_ != nullptr ? f.header_.frame_id_ : "";
        std::snprintf(r.interface, sizeof(r.interface), "%s",
                      interface.empty() ? "can0" : interface.c_str());
        r.kind = f.is_error_ ? SEMAP_CANDUMP_ERROR
                 : f.is_rtr_ ? SEMAP_CANDUMP_REMOTE
                             : SEMAP_CANDUMP_DATA;
        r.frame.id = f.id_;
        r.frame.extended = f.is_extended_ ? 1 : 0;
        r.frame.len = f.dlc_;
        std::memcpy(r.frame.data, f.data_, 8);
        dds_sample_free(&f, dds::TypeDescriptor<dds::msg::CanFrame>::get(), DDS_FREE_CONTENTS);
        if (log) {
          const std::string line = fb::format_candump_line(r);
          if (std::fputs(line.c_str(), log.get()) < 0) {
            throw std::runtime_error("--candump " + o.candump + ": write failed");
          }
        }
        ++in.records;
        if (!o.channel.empty() && o.channel != r.interface) {
          ++in.other_channel;
        } else if (r.kind == SEMAP_CANDUMP_REMOTE) {
          ++in.remote;
        } else if (r.kind == SEMAP_CANDUMP_ERROR) {
          handle_error_frame(r.frame, realtime_stamp(r), o.json, in);
        } else if (push(r.frame, realtime_stamp(r))) {
          break;
        }
      }
      if (log && std::fclose(log.release()) != 0) {
        throw std::runtime_error("--candump " + o.candump + ": write failed");
      }
      if (reader.status() != semap::drivers::mcap::McapReadStatus::kEnd && !g_stop &&
          !(o.count > 0 && printed >= o.count)) {
        // A recording cut off (a crash): its frames up to the last whole chunk are out.
        std::fprintf(stderr, "semap-can: %s\n", reader.error().c_str());
      }
    } else if (!o.input.empty()) {
      std::ifstream file(o.input, std::ios::binary);
      if (!file) throw std::runtime_error("--input " + o.input + ": cannot open");
      fb::CandumpReader reader(file, o.input);
      while (!g_stop) {
        const auto r = reader.next();
        if (!r) break;
        ++in.records;
        if (!o.channel.empty() && o.channel != r->interface) {
          ++in.other_channel;
        } else if (r->kind == SEMAP_CANDUMP_REMOTE) {
          ++in.remote;
        } else if (r->kind == SEMAP_CANDUMP_ERROR) {
          handle_error_frame(r->frame, realtime_stamp(*r), o.json, in);
        } else if (push(r->frame, realtime_stamp(*r))) {
          break;
        }
      }
      if (!reader.error().empty()) throw std::runtime_error(reader.error());
    } else {
      // Every data frame (standard and extended) passes, so the log holds the whole bus.
      const std::array<fb::CanIdFilter, 2> all{fb::CanIdFilter{0, 0, false},
                                               fb::CanIdFilter{0, 0, true}};
      dr::CanSocket socket(o.interface, all, fd_frames);
      LogRecorder recorder(o.record, o.interface);
      const Stamp start = Stamp::now();
      dr::CanRxFrame rx;
      while (!g_stop) {
        if (o.seconds > 0 && seconds_between(Stamp::now(), start) >= o.seconds) break;
        const dr::CanRead read = socket.receive(200, rx);
        if (read == dr::CanRead::kTimeout) continue;
        ++in.records;
        recorder.write(rx, read == dr::CanRead::kError);
        if (read == dr::CanRead::kError) {
          handle_error_frame(rx.frame, Stamp(rx.realtime_ns), o.json, in);
        } else if (push(rx.frame, Stamp(rx.realtime_ns))) {
          break;
        }
        std::fflush(stdout);
      }
    }
  } catch (const std::exception& e) {
    std::fflush(stdout);
    std::fprintf(stderr, "semap-can: %s\n", e.what());
    print_counters(decoder.counters(), in, o.json);
    return 1;
  }
  print_counters(decoder.counters(), in, o.json);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "semap-can: %s\n", e.what());
  } catch (...) {
    std::fprintf(stderr, "semap-can: unknown error\n");
  }
  return 1;
}
