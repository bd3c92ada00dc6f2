// semap-sensor-sim: replays a trajectory as IMU CAN frames and GNSS NMEA/UBX bytes, like the
// sensor firmware would, with injectable faults. Thin: flags and config in, library objects run.
#include <fcntl.h>
#include <pty.h>
#include <termios.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <memory>
#include <optional>
#include <string>

#include "semap/common/config.hpp"
#include "semap/common/logging.hpp"
#include "semap/drivers/can_socket.hpp"
#include "semap/drivers/serial_port.hpp"
#include "semap/sim/constant_turn_source.hpp"
#include "semap/sim/emulator.hpp"

namespace {

namespace fb = semap::firmware_bridge;

std::atomic<bool> g_stop{false};

void on_signal(int) { g_stop = true; }

// The serial side: a pty we create (slave kept open so the master never sees EIO) or a device.
struct SerialOutput {
  int fd = -1;
  int pty_slave = -1;
  ~SerialOutput() {
    if (fd >= 0) ::close(fd);
    if (pty_slave >= 0) ::close(pty_slave);
  }
};

void open_serial(SerialOutput& out, bool use_pty, const std::string& device, int baud) {
  termios raw{};
  cfmakeraw(&raw);
  cfsetspeed(&raw, semap::drivers::baud_constant(baud));
  if (use_pty) {
    char name[128] = {};
    if (::openpty(&out.fd, &out.pty_slave, name, &raw, nullptr) != 0) {
      throw std::runtime_error(std::string("openpty: ") + std::strerror(errno));
    }
    std::printf("pty %s\n", name);
    std::fflush(stdout);
  } else {
    out.fd = ::open(device.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC);
    if (out.fd < 0) {
      throw std::runtime_error("serial device '" + device + "': " + std::strerror(errno));
    }
    if (::isatty(out.fd) && ::tcsetattr(out.fd, TCSANOW, &raw) != 0) {
      throw std::runtime_error("serial device '" + device +
                               "': tcsetattr: " + std::strerror(errno));
    }
  }
  // A UART never stalls the firmware: a reader that stops reading loses bytes (counted).
  ::fcntl(out.fd, F_SETFL, ::fcntl(out.fd, F_GETFL) | O_NONBLOCK);
}

semap::sim::ConstantTurnConfig trajectory_from(const semap::common::ConfigSection& t) {
  semap::sim::ConstantTurnConfig c;
  const std::vector<double> origin =
      t.get<std::vector<double>>("origin", {c.origin_lat_deg, c.origin_lon_deg, c.origin_alt_m});
  if (origin.size() != 3) {
    throw semap::common::ConfigError(t.file() + ": trajectory.origin needs [lat, lon, alt]");
  }
  c.origin_lat_deg = origin[0];
  c.origin_lon_deg = origin[1];
  c.origin_alt_m = origin[2];
  c.speed_mps = t.get_in_range("speed_mps", c.speed_mps, 0.0, 100.0);
  c.yaw_rate_rad_s = t.get_in_range("yaw_rate_rad_s", c.yaw_rate_rad_s, -10.0, 10.0);
  c.imu_rate_hz = t.get_in_range("imu_rate_hz", c.imu_rate_hz, 1.0, 4000.0);
  c.gnss_rate_hz = t.get_in_range("gnss_rate_hz", c.gnss_rate_hz, 0.1, 100.0);
  c.gnss_sigma_m = t.get_in_range("gnss_sigma_m", c.gnss_sigma_m, 0.001, 100.0);
  t.finish();
  return c;
}

void print_stats(const semap::sim::EmulatorStats& s) {
  const semap::sim::InjectedFaults& i = s.injected;
  std::printf(
      "sent: imu_samples=%llu can_frames=%llu can_write_failures=%llu gnss_epochs=%llu "
      "nmea_sentences=%llu ubx_frames=%llu serial_bytes=%llu serial_dropped_bytes=%llu\n",
      static_cast<unsigned long long>(s.imu_samples), static_cast<unsigned long long>(s.can_frames),
      static_cast<unsigned long long>(s.can_write_failures),
      static_cast<unsigned long long>(s.gnss_epochs),
      static_cast<unsigned long long>(s.nmea_sentences),
      static_cast<unsigned long long>(s.ubx_frames),
      static_cast<unsigned long long>(s.serial_bytes),
      static_cast<unsigned long long>(s.serial_dropped_bytes));
  std::printf(
      "injected: crc_errors=%llu dropped_frames=%llu sequence_gaps=%llu garbage_bursts=%llu "
      "garbage_bytes=%llu truncated=%llu gnss_jumps=%llu silenced_imu_samples=%llu "
      "silenced_gnss_epochs=%llu\n",
      static_cast<unsigned long long>(i.crc_errors),
      static_cast<unsigned long long>(i.dropped_frames),
      static_cast<unsigned long long>(i.sequence_gaps),
      static_cast<unsigned long long>(i.garbage_bursts),
      static_cast<unsigned long long>(i.garbage_bytes),
      static_cast<unsigned long long>(i.truncated), static_cast<unsigned long long>(i.gnss_jumps),
      static_cast<unsigned long long>(i.silenced_imu_samples),
      static_cast<unsigned long long>(i.silenced_gnss_epochs));
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Sensor firmware emulator: IMU over SocketCAN, GNSS NMEA/UBX over a serial line"};
  std::string can_if;
  bool can_fd = false;
  std::string imu_profile = "semap";
  std::uint32_t base_id = SEMAP_CAN_IMU_DEFAULT_BASE_ID;
  unsigned j1939_source = 0x80;
  std::string serial;
  bool use_pty = false;
  int baud = 115200;
  std::string protocol = "nmea";
  double duration = 60.0;
  double speed = 1.0;
  std::string config_path;
  std::string log_level = "info";
  semap::sim::FaultConfig faults;
  app.add_option("--can-if", can_if, "CAN interface for the IMU (e.g. vcan0); none: no IMU");
  app.add_flag("--can-fd", can_fd, "semap profile: one 64-byte CAN FD frame per sample");
  app.add_option("--imu-profile", imu_profile, "IMU protocol")
      ->check(CLI::IsMember({"semap", "j1939"}));
  app.add_option("--base-id", base_id, "semap profile: first CAN id (4-aligned)")
      ->check(CLI::Range(0u, 0x7FCu));
  app.add_option("--j1939-source", j1939_source, "j1939 profile: source address")
      ->check(CLI::Range(0u, 253u));
  auto* serial_opt = app.add_option(
      "--serial", serial, "serial device for GNSS (a real UART, or one end of a socat pty pair)");
  app.add_flag("--pty", use_pty, "create a pty for GNSS and print its slave path")
      ->excludes(serial_opt);
  app.add_option("--baud", baud, "serial baud rate");
  app.add_option("--protocol", protocol, "GNSS protocol")->check(CLI::IsMember({"nmea", "ubx"}));
  app.add_option("--duration", duration, "seconds of sensor time")->check(CLI::PositiveNumber);
  app.add_option("--speed", speed, "wall-clock speed factor; 0 = as fast as possible")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--config", config_path, "YAML with a 'trajectory' section")
      ->check(CLI::ExistingFile);
  app.add_option("--crc-error", faults.crc_error, "probability per IMU sample")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--drop-frame", faults.drop_frame, "probability per IMU sample")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--sequence-gap", faults.sequence_gap, "probability per IMU sample")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--garbage", faults.garbage, "probability per GNSS epoch")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--truncate", faults.truncate, "probability per GNSS epoch")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--gnss-jump", faults.gnss_jump, "probability per GNSS epoch")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--gnss-jump-m", faults.gnss_jump_m, "size of a GNSS jump, m");
  app.add_option("--silence-every", faults.silence_every_s, "seconds between silences");
  app.add_option("--silence-duration", faults.silence_duration_s, "length of a silence, s");
  app.add_option("--seed", faults.seed, "fault random seed");
  app.add_option("--log-level", log_level, "trace..off");
  CLI11_PARSE(app, argc, argv);
  semap::common::setup_logging(log_level);
  const auto log = semap::common::logger("sensor-sim");

  try {
    if (base_id % 4 != 0) {
      throw std::runtime_error("--base-id must be a multiple of 4 (one filter per IMU node)");
    }
    if (faults.crc_error + faults.drop_frame + faults.sequence_gap > 1.0) {
      throw std::runtime_error("--crc-error + --drop-frame + --sequence-gap must not exceed 1");
    }
    semap::sim::ConstantTurnConfig trajectory;
    if (!config_path.empty()) {
      const auto root = semap::common::ConfigSection::load_file(config_path);
      trajectory = trajectory_from(root.section("trajectory"));
      root.finish();
    }
    trajectory.duration_s = duration;

    semap::sim::EmulatorConfig config;
    config.imu_profile = imu_profile == "j1939" ? fb::ImuProfile::kJ1939 : fb::ImuProfile::kSemap;
    config.can_fd_frames = can_fd;
    config.base_id = base_id;
    config.j1939_source = static_cast<std::uint8_t>(j1939_source);
    config.gnss_protocol = protocol == "ubx" ? fb::GnssProtocol::kUbx : fb::GnssProtocol::kNmea;
    config.speed = speed;
    config.faults = faults;
    std::unique_ptr<semap::drivers::CanSocket> can;
    if (!can_if.empty()) {
      can = std::make_unique<semap::drivers::CanSocket>(can_if, can_fd);
      config.can_fd = can->fd();
    }
    SerialOutput serial_out;
    if (use_pty || !serial.empty()) {
      open_serial(serial_out, use_pty, serial, baud);
      config.serial_fd = serial_out.fd;
    }
    if (config.can_fd < 0 && config.serial_fd < 0) {
      throw std::runtime_error("nothing to do: give --can-if and/or --serial/--pty");
    }
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    // The trajectory source is an interface: the estimation simulator or an OXTS reader can
    // replace the built-in constant-turn drive here.
    std::unique_ptr<semap::sim::SensorSource> source =
        std::make_unique<semap::sim::ConstantTurnSource>(trajectory);
    log->info("running {:.1f} s of sensor time at speed {}", duration, speed);
    semap::sim::Emulator emulator(config);
    emulator.run(*source, &g_stop);
    print_stats(emulator.stats());
  } catch (const std::exception& e) {
    log->error("{}", e.what());
    return 1;
  }
  return 0;
}
