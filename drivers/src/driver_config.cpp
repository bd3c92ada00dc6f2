#include "semap/drivers/driver_config.hpp"

#include <cmath>

#include "semap/drivers/realtime.hpp"

namespace semap::drivers {
namespace {

int get_int(const common::ConfigSection& s, const std::string& key, int fallback, int lo, int hi) {
  const double v = s.get_in_range(key, fallback, lo, hi);
  if (v != std::floor(v)) s.reject(key, "must be an integer");
  return static_cast<int>(v);
}

BackoffConfig backoff(const common::ConfigSection& s) {
  BackoffConfig b;
  b.initial = std::chrono::milliseconds(
      get_int(s, "reconnect_min_ms", static_cast<int>(b.initial.count()), 1, 60'000));
  b.max = std::chrono::milliseconds(get_int(s, "reconnect_max_ms", static_cast<int>(b.max.count()),
                                            static_cast<int>(b.initial.count()), 600'000));
  return b;
}

int realtime_priority(const common::ConfigSection& s) {
  return get_int(s, "realtime_priority", 0, 0, kMaxRealtimePriority);
}

}  // namespace

CanImuConfig can_imu_config(const common::ConfigSection& imu) {
  CanImuConfig c;
  c.interface = imu.get<std::string>("interface", c.interface);
  const std::string profile = imu.get_choice("profile", "semap", {"semap", "j1939"});
  c.decoder.profile = profile == "semap" ? firmware_bridge::ImuProfile::kSemap
                                         : firmware_bridge::ImuProfile::kJ1939;
  c.decoder.base_id = static_cast<std::uint32_t>(
      get_int(imu, "base_id", static_cast<int>(c.decoder.base_id), 0, 0x7FC));
  // A J1939 node claims 0..253 (254 is the null address, 255 the global destination).
  if (imu.has("j1939_source") && imu.get<std::string>("j1939_source") != "any") {
    c.decoder.j1939_source = static_cast<std::uint16_t>(get_int(imu, "j1939_source", 0, 0, 253));
  }
  c.fd_frames = imu.get<bool>("fd_frames", c.fd_frames);
  c.restart_bus_off = imu.get<bool>("restart_bus_off", c.restart_bus_off);
  c.backoff = backoff(imu);
  c.realtime_priority = realtime_priority(imu);
  c.cpus = cpu_list(imu, "cpus");
  return c;
}

GnssConfig gnss_config(const common::ConfigSection& gnss) {
  GnssConfig c;
  c.serial.device = gnss.get<std::string>("device", c.serial.device);
  if (c.serial.device.empty()) gnss.reject("device", "must name the receiver's serial device");
  c.serial.baud = get_int(gnss, "baud", c.serial.baud, 1, 4'000'000);
  try {
    baud_constant(c.serial.baud);
  } catch (const std::invalid_argument&) {
    gnss.reject("baud", std::to_string(c.serial.baud) +
                            " is not a supported rate (4800, 9600, 19200, 38400, 57600, 115200, "
                            "230400, 460800, 921600)");
  }
  c.serial.vmin = get_int(gnss, "vmin", c.serial.vmin, 0, 255);
  c.serial.vtime = get_int(gnss, "vtime", c.serial.vtime, 0, 255);
  c.fix.uere_m = gnss.get_in_range("uere_m", c.fix.uere_m, 0.01, 100.0);
  c.backoff = backoff(gnss);
  c.realtime_priority = realtime_priority(gnss);
  c.cpus = cpu_list(gnss, "cpus");
  return c;
}

CameraConfig camera_config(const common::ConfigSection& camera) {
  CameraConfig c;
  c.device = camera.get<std::string>("device", c.device);
  const std::string format = camera.get_choice("format", "YUYV", {"YUYV", "MJPEG", "GREY", "Z16"});
  c.format = format == "YUYV"    ? common::PixelFormat::kYuyv
             : format == "MJPEG" ? common::PixelFormat::kMjpeg
             : format == "GREY"  ? common::PixelFormat::kGrey
                                 : common::PixelFormat::kZ16;
  c.width = static_cast<std::uint32_t>(get_int(camera, "width", 640, 16, 8192));
  c.height = static_cast<std::uint32_t>(get_int(camera, "height", 480, 16, 8192));
  c.fps = camera.get_in_range("fps", c.fps, 0.1, 1000.0);
  c.buffers = static_cast<std::uint32_t>(get_int(camera, "buffers", 4, 2, 32));
  c.backoff = backoff(camera);
  c.realtime_priority = realtime_priority(camera);
  c.cpus = cpu_list(camera, "cpus");
  return c;
}

std::vector<int> cpu_list(const common::ConfigSection& s, const std::string& key) {
  if (!s.has(key)) return {};
  std::vector<int> list;
  for (const double v : s.get<std::vector<double>>(key)) {
    if (v != std::floor(v) || v < 0 || v >= 1024) s.reject(key, "CPU numbers are integers 0..1023");
    list.push_back(static_cast<int>(v));
  }
  if (list.empty()) s.reject(key, "name at least one CPU, or leave the key out");
  return list;
}

}  // namespace semap::drivers
