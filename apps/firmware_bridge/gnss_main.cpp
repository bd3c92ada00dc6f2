// semap-gnss: decodes a GNSS receiver's byte stream (NMEA, UBX, RTCM3 and text lines, as
// GnssStreamDecoder frames them) from a raw capture or a serial device and prints one line or
// one JSON object per fix, then every counter. Like gpsd's gpspipe / gpsdecode for our decoder.
#include <CLI/CLI.hpp>
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "semap/common/logging.hpp"
#include "semap/common/messages.hpp"
#include "semap/drivers/serial_port.hpp"
#include "semap/firmware_bridge/gnss_stream_decoder.hpp"

namespace {

namespace fb = semap::firmware_bridge;
using semap::common::FixMode;
using semap::common::GnssFix;

std::atomic<bool> g_stop{false};

void on_signal(int) { g_stop = true; }

const char* mode_name(FixMode m) {
  switch (m) {
    case FixMode::kNoFix:
      return "no_fix";
    case FixMode::k2D:
      return "2d";
    case FixMode::k3D:
      return "3d";
    case FixMode::kDgps:
      return "dgps";
    case FixMode::kRtkFloat:
      return "rtk_float";
    case FixMode::kRtkFixed:
      return "rtk_fixed";
  }
  return "unknown";
}

// ISO 8601 UTC with milliseconds (truncated, as gpsd prints it), e.g. 2021-06-10T18:18:55.750Z.
std::string iso8601(std::int64_t utc_ns) {
  std::int64_t ms = utc_ns / 1'000'000;
  if (utc_ns % 1'000'000 < 0) --ms;
  std::int64_t s = ms / 1000;
  int milli = static_cast<int>(ms % 1000);
  if (milli < 0) {
    milli += 1000;
    --s;
  }
  const auto t = static_cast<std::time_t>(s);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900,
                tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, milli);
  return buf;
}

// 1-sigma horizontal (radial, sqrt of the east + north variances) and vertical accuracy, m.
double h_acc(const GnssFix& f) { return std::sqrt(f.covariance(0, 0) + f.covariance(1, 1)); }
double v_acc(const GnssFix& f) { return std::sqrt(f.covariance(2, 2)); }

void print_text(const GnssFix& f) {
  const std::string time = f.utc_ns ? iso8601(*f.utc_ns) : "no-time";
  std::printf("%s %-9s lat %.9f lon %.9f alt_hae %.3f m sats %u h_acc %.3f m v_acc %.3f m",
              time.c_str(), mode_name(f.mode), f.latitude_deg, f.longitude_deg, f.altitude_m,
              static_cast<unsigned>(f.satellites), h_acc(f), v_acc(f));
  if (f.velocity_enu) {
    std::printf(" vel_enu %.3f %.3f %.3f m/s", f.velocity_enu->x(), f.velocity_enu->y(),
                f.velocity_enu->z());
  }
  if (f.heading_deg) std::printf(" heading %.2f deg", *f.heading_deg);
  std::printf("\n");
}

// A JSON number, or null for NaN / infinity (JSON has neither).
std::string num(double v, int decimals) {
  if (!std::isfinite(v)) return "null";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

void print_json(const GnssFix& f) {
  const std::string time = f.utc_ns ? "\"" + iso8601(*f.utc_ns) + "\"" : "null";
  std::string vel = "null";
  if (f.velocity_enu) {
    vel = "[" + num(f.velocity_enu->x(), 3) + "," + num(f.velocity_enu->y(), 3) + "," +
          num(f.velocity_enu->z(), 3) + "]";
  }
  std::printf(
      "{\"class\":\"FIX\",\"time\":%s,\"lat\":%s,\"lon\":%s,\"alt_hae\":%s,\"mode\":\"%s\","
      "\"sats\":%u,\"h_acc\":%s,\"v_acc\":%s,\"vel_enu\":%s,\"heading\":%s}\n",
      time.c_str(), num(f.latitude_deg, 9).c_str(), num(f.longitude_deg, 9).c_str(),
      num(f.altitude_m, 4).c_str(), mode_name(f.mode), static_cast<unsigned>(f.satellites),
      num(h_acc(f), 3).c_str(), num(v_acc(f), 3).c_str(), vel.c_str(),
      f.heading_deg ? num(*f.heading_deg, 2).c_str() : "null");
}

struct Counter {
  const char* name;
  std::uint64_t value;
};

std::vector<Counter> counters_of(const fb::GnssStreamCounters& c) {
  return {{"bytes", c.bytes},
          {"garbage_bytes", c.garbage_bytes},
          {"nmea_sentences", c.nmea_sentences},
          {"ubx_frames", c.ubx_frames},
          {"rtcm3_frames", c.rtcm3_frames},
          {"text_lines", c.text_lines},
          {"bad_checksum", c.bad_checksum},
          {"too_long", c.too_long},
          {"truncated", c.truncated},
          {"unknown", c.unknown},
          {"bad_field", c.bad_field},
          {"fixes", c.fixes}};
}

void print_counters(const fb::GnssStreamCounters& c, bool json) {
  const std::vector<Counter> all = counters_of(c);
  std::printf(json ? "{\"class\":\"COUNTERS\"" : "counters:");
  for (const Counter& k : all) {
    std::printf(json ? ",\"%s\":%llu" : " %s=%llu", k.name,
                static_cast<unsigned long long>(k.value));
  }
  std::printf(json ? "}\n" : "\n");
}

// Raw bytes as read, for --record (replayable with --input).
class Recorder {
 public:
  explicit Recorder(const std::string& path) {
    if (path.empty()) return;
    file_ = std::fopen(path.c_str(), "wb");
    if (file_ == nullptr) throw std::runtime_error("--record " + path + ": cannot create");
    path_ = path;
  }
  ~Recorder() {
    if (file_ != nullptr) std::fclose(file_);
  }
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  void write(const std::uint8_t* data, std::size_t n) {
    if (file_ == nullptr) return;
    if (std::fwrite(data, 1, n, file_) != n || std::fflush(file_) != 0) {
      throw std::runtime_error("--record " + path_ + ": write failed");
    }
  }

 private:
  std::FILE* file_ = nullptr;
  std::string path_;
};

int run(int argc, char** argv) {
  CLI::App app{
      "Decode a GNSS receiver's stream (NMEA, UBX; RTCM3 and text lines skipped) from a raw "
      "capture or a serial device: one line (or JSON object) per fix, then the counters"};
  std::string input;
  std::string device;
  int baud = 115200;
  bool json = false;
  std::string record;
  std::uint64_t count = 0;
  double seconds = 0.0;
  std::string log_level = "warn";
  auto* input_opt = app.add_option("--input", input, "raw capture: bytes as read from the port")
                        ->check(CLI::ExistingFile);
  auto* device_opt = app.add_option("--device", device, "serial device (tty, USB adapter or pty)")
                         ->excludes(input_opt);
  input_opt->excludes(device_opt);
  app.add_option("--baud", baud, "serial baud rate (with --device)")->needs(device_opt);
  app.add_flag("--json", json, "one JSON object per fix, then one with every counter");
  app.add_option("--record", record, "also save the raw bytes to this file");
  app.add_option("--count", count, "stop after this many fixes (0: no limit)");
  app.add_option("--seconds", seconds, "with --device: stop after this long (0: until Ctrl-C)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--log-level", log_level, "trace..off");
  CLI11_PARSE(app, argc, argv);
  semap::common::setup_logging(log_level);
  const auto log = semap::common::logger("gnss");
  if (input.empty() && device.empty()) {
    std::fprintf(stderr, "semap-gnss: give --input FILE or --device DEV\n");
    return 2;
  }

  fb::GnssStreamDecoder decoder;
  std::vector<GnssFix> fixes;
  std::uint64_t printed = 0;
  const auto emit = [&] {
    for (const GnssFix& f : fixes) {
      if (count > 0 && printed == count) break;
      json ? print_json(f) : print_text(f);
      ++printed;
    }
    fixes.clear();
    std::fflush(stdout);
    return count > 0 && printed >= count;
  };
  try {
    Recorder recorder(record);
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    std::vector<std::uint8_t> buffer(4096);
    if (!input.empty()) {
      std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(input.c_str(), "rb"),
                                                           &std::fclose);
      if (!file) throw std::runtime_error("--input " + input + ": cannot open");
      std::size_t n = 0;
      while (!g_stop && (n = std::fread(buffer.data(), 1, buffer.size(), file.get())) > 0) {
        recorder.write(buffer.data(), n);
        decoder.feed({buffer.data(), n}, semap::common::Stamp::now(), fixes);
        if (emit()) break;
      }
    } else {
      semap::drivers::SerialConfig config;
      config.device = device;
      config.baud = baud;
      semap::drivers::SerialPort port(config);
      const semap::common::Stamp start = semap::common::Stamp::now();
      while (!g_stop) {
        if (seconds > 0 && seconds_between(semap::common::Stamp::now(), start) >= seconds) break;
        std::size_t n = 0;
        if (port.read_some(buffer, 200, n) != semap::drivers::SerialRead::kData) continue;
        // The read time stamps the fixes these bytes complete, as in GnssDriver.
        const semap::common::Stamp stamp = semap::common::Stamp::now();
        recorder.write(buffer.data(), n);
        decoder.feed({buffer.data(), n}, stamp, fixes);
        if (emit()) break;
      }
    }
  } catch (const std::exception& e) {
    std::fflush(stdout);
    log->error("{}", e.what());
    print_counters(decoder.counters(), json);
    return 1;
  }
  print_counters(decoder.counters(), json);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "semap-gnss: %s\n", e.what());
  } catch (...) {
    std::fprintf(stderr, "semap-gnss: unknown error\n");
  }
  return 1;
}
