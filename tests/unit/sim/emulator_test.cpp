#include "semap/sim/emulator.hpp"

#include <gtest/gtest.h>
#include <poll.h>
#include <pty.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <numbers>
#include <thread>
#include <vector>

#include "semap/firmware_bridge/gnss_stream_decoder.hpp"
#include "semap/firmware_bridge/linux_can.hpp"
#include "semap/sim/constant_turn_source.hpp"

namespace semap::sim {
namespace {

// The emulator speaks the firmware's codecs; the tests decode with them.
using namespace semap::firmware_bridge;

// A pty pair in raw mode, as a GNSS driver would configure its end.
struct Pty {
  int master = -1;
  int slave = -1;
  Pty() {
    termios raw{};
    cfmakeraw(&raw);
    cfsetspeed(&raw, B115200);
    if (openpty(&master, &slave, nullptr, &raw, nullptr) != 0) ADD_FAILURE() << "openpty failed";
  }
  ~Pty() {
    ::close(master);
    ::close(slave);
  }
};

// Reads `fd` until `done` is set and nothing arrived for 200 ms, decoding as it goes.
void read_gnss(int fd, const std::atomic<bool>& done, GnssStreamDecoder& decoder,
               std::vector<common::GnssFix>& fixes) {
  std::vector<std::uint8_t> buf(4096);
  for (;;) {
    pollfd pfd{fd, POLLIN, 0};
    const int ready = ::poll(&pfd, 1, 200);
    if (ready == 0 && done.load()) return;
    if (ready <= 0) continue;
    const ssize_t n = ::read(fd, buf.data(), buf.size());
    if (n <= 0) return;
    decoder.feed({buf.data(), static_cast<std::size_t>(n)}, common::Stamp::now(), fixes);
  }
}

void read_can(int fd, const std::atomic<bool>& done, CanImuDecoder& decoder,
              std::vector<common::ImuSample>& samples) {
  std::uint8_t buf[128];
  for (;;) {
    pollfd pfd{fd, POLLIN, 0};
    const int ready = ::poll(&pfd, 1, 200);
    if (ready == 0 && done.load()) return;
    if (ready <= 0) continue;
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    if (n <= 0) return;
    SemapCanFrame frame;
    ASSERT_TRUE(from_kernel_frame(buf, static_cast<std::size_t>(n), frame)) << n;
    if (auto s = decoder.push(frame, common::Stamp::now())) samples.push_back(*s);
  }
}

// Exact counting must not depend on a lucky seed.
class EmulatorSeed : public ::testing::TestWithParam<std::uint32_t> {};

ConstantTurnConfig turn(double duration_s) {
  ConstantTurnConfig c;
  c.duration_s = duration_s;
  return c;
}

TEST(ConstantTurnSource, ProducesTimeOrderedImuAndGnssOnACircle) {
  ConstantTurnConfig c = turn(2.0);
  ConstantTurnSource source(c);
  int imu = 0;
  int gnss = 0;
  common::Stamp last;
  const double radius = c.speed_mps / c.yaw_rate_rad_s;
  const double m_per_deg_lat = 111'200.0;
  const double m_per_deg_lon = m_per_deg_lat * std::cos(c.origin_lat_deg * std::numbers::pi / 180);
  while (auto e = source.next()) {
    const common::Stamp s = std::visit([](const auto& x) { return x.stamp; }, *e);
    EXPECT_LE(last, s);
    last = s;
    if (const auto* fix = std::get_if<common::GnssFix>(&*e)) {
      ++gnss;
      const double east = (fix->longitude_deg - c.origin_lon_deg) * m_per_deg_lon;
      const double north = (fix->latitude_deg - c.origin_lat_deg) * m_per_deg_lat;
      EXPECT_NEAR(std::hypot(east, north - radius), radius, 0.5);
    } else {
      ++imu;
      EXPECT_NEAR(std::get<common::ImuSample>(*e).accel.y(), c.speed_mps * c.yaw_rate_rad_s, 1e-12);
    }
  }
  EXPECT_EQ(imu, 800);
  EXPECT_EQ(gnss, 20);
}

TEST_P(EmulatorSeed, NmeaIntoARealPtyWithEveryFaultCountedExactly) {
  Pty pty;
  EmulatorConfig config;
  config.serial_fd = pty.master;
  config.speed = 0.0;
  config.faults.garbage = 0.2;
  config.faults.truncate = 0.2;
  config.faults.gnss_jump = 0.1;
  config.faults.gnss_jump_m = 150.0;  // more than the circle's diameter: always off the track
  config.faults.silence_every_s = 5.0;
  config.faults.silence_duration_s = 0.5;
  config.faults.seed = GetParam();
  Emulator emulator(config);
  GnssStreamDecoder decoder;
  std::vector<common::GnssFix> fixes;
  std::atomic<bool> done{false};
  std::thread reader([&] { read_gnss(pty.slave, done, decoder, fixes); });

  const ConstantTurnConfig c = turn(20.0);
  ConstantTurnSource source(c);
  emulator.run(source);
  // A clean last epoch, so that a sentence cut at the very end is closed and counted.
  emulator.set_faults(FaultConfig{});
  // Built in place: copying a GnssFix with an empty optional trips gcc 12's
  // -Wmaybe-uninitialized under the sanitizer presets.
  SensorEvent event{std::in_place_type<common::GnssFix>};
  auto& last = std::get<common::GnssFix>(event);
  last.stamp = common::Stamp(c.start.ns + 20'000'000'000);
  last.latitude_deg = c.origin_lat_deg;
  last.longitude_deg = c.origin_lon_deg;
  last.quality = common::FixQuality::kGps;
  emulator.emit(event);
  done = true;
  reader.join();

  const EmulatorStats& st = emulator.stats();
  const InjectedFaults& inj = st.injected;
  const GnssStreamCounters& rx = decoder.counters();
  EXPECT_GT(inj.truncated, 10u);
  EXPECT_GT(inj.garbage_bursts, 10u);
  EXPECT_GT(inj.gnss_jumps, 5u);
  EXPECT_EQ(inj.silenced_gnss_epochs, 20u);  // 4 silences of 0.5 s at 10 Hz
  EXPECT_EQ(st.gnss_epochs + inj.silenced_gnss_epochs, 201u);
  EXPECT_EQ(rx.bytes, st.serial_bytes);
  EXPECT_EQ(rx.nmea_sentences, st.nmea_sentences) << "every good sentence arrives";
  EXPECT_EQ(rx.truncated, inj.truncated) << "every cut sentence is counted once";
  EXPECT_EQ(rx.garbage_bytes, inj.garbage_bytes);
  EXPECT_EQ(rx.bad_checksum + rx.bad_field + rx.too_long + rx.unknown, 0u);
  EXPECT_LE(fixes.size(), st.gnss_epochs);
  EXPECT_GE(fixes.size(), st.gnss_epochs - inj.truncated);

  // Jumps show up as fixes far off the circle (radius 50 m around (0, 50 m) ENU).
  const double radius = c.speed_mps / c.yaw_rate_rad_s;
  const double m_per_deg_lat = 111'200.0;
  const double m_per_deg_lon = m_per_deg_lat * std::cos(c.origin_lat_deg * std::numbers::pi / 180);
  std::uint64_t off_track = 0;
  for (std::size_t i = 0; i + 1 < fixes.size(); ++i) {
    const double east = (fixes[i].longitude_deg - c.origin_lon_deg) * m_per_deg_lon;
    const double north = (fixes[i].latitude_deg - c.origin_lat_deg) * m_per_deg_lat;
    if (std::abs(std::hypot(east, north - radius) - radius) > 20.0) ++off_track;
  }
  EXPECT_LE(off_track, inj.gnss_jumps);
  EXPECT_GE(off_track + inj.truncated, inj.gnss_jumps);
}

// Scheduled windows in sensor time: a 3 s GNSS silence while the IMU keeps sending, then 2 s of
// fixes offset 50 m north. Each epoch is counted, and the fixes that arrive say which is which.
TEST(Emulator, ScheduledGnssSilenceAndJumpWindows) {
  Pty pty;
  EmulatorConfig config;
  config.serial_fd = pty.master;
  config.can_sink = [](const SemapCanFrame&) {};  // a CAN link without a bus
  config.speed = 0.0;
  config.faults.gnss_silent_at_s = 5.0;
  config.faults.gnss_silent_s = 3.0;
  config.faults.gnss_jump_at_s = 12.0;
  config.faults.gnss_jump_s = 2.0;
  config.faults.gnss_jump_m = 50.0;
  Emulator emulator(config);
  GnssStreamDecoder decoder;
  std::vector<common::GnssFix> fixes;
  std::atomic<bool> done{false};
  std::thread reader([&] { read_gnss(pty.slave, done, decoder, fixes); });
  const ConstantTurnConfig c = turn(20.0);
  ConstantTurnSource source(c);
  emulator.run(source);
  done = true;
  reader.join();

  const EmulatorStats& st = emulator.stats();
  EXPECT_EQ(st.injected.gnss_silent_epochs, 30u);  // [5, 8) s at 10 Hz
  EXPECT_EQ(st.injected.gnss_jumps, 20u);          // [12, 14) s
  EXPECT_EQ(st.gnss_epochs, 200u - 30u);
  EXPECT_EQ(st.imu_samples, 8000u) << "the IMU keeps sending through the silence";
  ASSERT_EQ(fixes.size(), st.gnss_epochs);
  // The first event is the IMU sample at t = 0; fixes carry their sensor time as UTC.
  const double m_per_deg_lat = 111'200.0;
  const double radius = c.speed_mps / c.yaw_rate_rad_s;
  const double m_per_deg_lon = m_per_deg_lat * std::cos(c.origin_lat_deg * std::numbers::pi / 180);
  int jumped = 0;
  for (const auto& fix : fixes) {
    ASSERT_TRUE(fix.utc_ns.has_value());
    const double t = static_cast<double>(*fix.utc_ns / 1'000'000 - config.utc_start_unix_ms) / 1e3;
    EXPECT_FALSE(t >= 5.0 - 1e-6 && t < 8.0 - 1e-6) << "a fix inside the silence at " << t;
    const double east = (fix.longitude_deg - c.origin_lon_deg) * m_per_deg_lon;
    const double north = (fix.latitude_deg - c.origin_lat_deg) * m_per_deg_lat;
    const double off = std::hypot(east, north - radius) - radius;
    const bool in_jump = t >= 12.0 - 1e-6 && t < 14.0 - 1e-6;
    if (in_jump) {
      ++jumped;
      // 50 m north of a point on the circle: off the circle by up to 50 m.
      const double north_back = north - 50.0 * m_per_deg_lat / 111'320.0;
      EXPECT_NEAR(std::hypot(east, north_back - radius), radius, 0.5) << t;
    } else {
      EXPECT_NEAR(off, 0.0, 0.5) << t;
    }
  }
  EXPECT_EQ(jumped, 20);
}

TEST_P(EmulatorSeed, UbxIntoARealPtyCountsCutFramesOnce) {
  Pty pty;
  EmulatorConfig config;
  config.serial_fd = pty.master;
  config.gnss_protocol = GnssProtocol::kUbx;
  config.speed = 0.0;
  config.faults.garbage = 0.3;
  config.faults.truncate = 0.1;
  config.faults.seed = GetParam();
  Emulator emulator(config);
  GnssStreamDecoder decoder;
  std::vector<common::GnssFix> fixes;
  std::atomic<bool> done{false};
  std::thread reader([&] { read_gnss(pty.slave, done, decoder, fixes); });
  ConstantTurnSource source(turn(10.0));
  emulator.run(source);
  emulator.set_faults(FaultConfig{});
  SensorEvent event{std::in_place_type<common::GnssFix>};
  std::get<common::GnssFix>(event).stamp = common::Stamp(1'000'000'000 + 10'000'000'000);
  emulator.emit(event);
  done = true;
  reader.join();

  const EmulatorStats& st = emulator.stats();
  const GnssStreamCounters& rx = decoder.counters();
  EXPECT_GT(st.injected.truncated, 3u);
  EXPECT_EQ(rx.ubx_frames, st.ubx_frames);
  EXPECT_EQ(fixes.size(), st.ubx_frames);
  EXPECT_EQ(rx.bad_checksum, st.injected.truncated);
  EXPECT_EQ(rx.truncated + rx.too_long, 0u);
}

struct CanRun {
  EmulatorStats stats;
  CanImuCounters rx;
  std::vector<common::ImuSample> samples;
};

// The emulator writes kernel CAN frames into one end of a SOCK_SEQPACKET socketpair (one
// datagram per frame, exactly as a CAN_RAW socket delivers them) and a reader decodes the other.
CanRun run_can(EmulatorConfig config, double duration_s) {
  int sv[2];
  EXPECT_EQ(::socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv), 0);
  config.can_fd = sv[0];
  config.speed = 0.0;
  CanImuDecoderConfig dc;
  dc.profile = config.imu_profile;
  CanImuDecoder decoder(dc);
  CanRun out;
  std::atomic<bool> done{false};
  std::thread reader([&] { read_can(sv[1], done, decoder, out.samples); });
  Emulator emulator(config);
  ConstantTurnConfig c = turn(duration_s);
  ConstantTurnSource source(c);
  emulator.run(source);
  emulator.set_faults(FaultConfig{});
  common::ImuSample last;
  last.stamp = common::Stamp(c.start.ns + static_cast<std::int64_t>(duration_s * 1e9));
  emulator.emit(last);
  done = true;
  reader.join();
  ::close(sv[0]);
  ::close(sv[1]);
  out.stats = emulator.stats();
  out.rx = decoder.counters();
  return out;
}

TEST_P(EmulatorSeed, ClassicCanFaultsAreCountedExactlyByTheAssembler) {
  EmulatorConfig config;
  config.faults.seed = GetParam();
  config.faults.crc_error = 0.01;
  config.faults.drop_frame = 0.01;
  config.faults.sequence_gap = 0.01;
  config.faults.silence_every_s = 5.0;
  config.faults.silence_duration_s = 0.25;
  const CanRun r = run_can(config, 10.0);
  const InjectedFaults& inj = r.stats.injected;
  EXPECT_GT(inj.crc_errors, 10u);
  EXPECT_GT(inj.dropped_frames, 10u);
  EXPECT_GT(inj.sequence_gaps, 10u);
  EXPECT_EQ(inj.silenced_imu_samples, 200u);
  EXPECT_EQ(r.stats.can_write_failures, 0u);
  EXPECT_EQ(r.rx.crc_errors, inj.crc_errors);
  EXPECT_EQ(r.rx.incomplete, inj.crc_errors + inj.dropped_frames);
  EXPECT_EQ(r.rx.missed_samples,
            inj.crc_errors + inj.dropped_frames + inj.sequence_gaps + inj.silenced_imu_samples);
  EXPECT_EQ(r.rx.samples, r.stats.imu_samples - inj.crc_errors - inj.dropped_frames);
  EXPECT_EQ(r.rx.samples, r.samples.size());
  EXPECT_EQ(r.rx.frames, r.stats.can_frames);
  // The sequence numbers the driver sees are the emulator's unwrapped counter.
  EXPECT_EQ(r.samples.back().sequence, 4000u + inj.sequence_gaps);
  EXPECT_NEAR(r.samples[1].gyro.z(), 0.1, 0.001);
}

TEST(Emulator, CanFdAndJ1939Profiles) {
  EmulatorConfig fd;
  fd.can_fd_frames = true;
  fd.faults.crc_error = 0.02;
  fd.faults.drop_frame = 0.02;
  const CanRun a = run_can(fd, 2.0);
  EXPECT_EQ(a.rx.crc_errors, a.stats.injected.crc_errors);
  EXPECT_EQ(a.rx.incomplete, 0u) << "an FD frame is a whole sample";
  EXPECT_EQ(a.rx.missed_samples, a.stats.injected.crc_errors + a.stats.injected.dropped_frames);
  EXPECT_EQ(a.rx.samples + a.stats.injected.crc_errors + a.stats.injected.dropped_frames, 801u);

  EmulatorConfig j;
  j.imu_profile = ImuProfile::kJ1939;
  const CanRun b = run_can(j, 1.0);
  EXPECT_EQ(b.rx.samples, 401u);
  EXPECT_EQ(b.rx.unpaired + b.rx.bad_frames, 0u);
  EXPECT_NEAR(b.samples[5].accel.z(), 9.80665, 0.01);
  EXPECT_NEAR(b.samples[5].gyro.z(), 0.1, 0.001);
}

TEST(Emulator, PacesInScaledRealTime) {
  int sv[2];
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv), 0);
  EmulatorConfig config;
  config.can_fd = sv[0];
  config.can_fd_frames = true;
  config.speed = 2.0;
  Emulator emulator(config);
  ConstantTurnSource source(turn(0.4));
  const auto start = std::chrono::steady_clock::now();
  std::atomic<bool> done{false};
  std::thread drain([&] {
    std::uint8_t buf[128];
    while (!done.load()) {
      pollfd pfd{sv[1], POLLIN, 0};
      if (::poll(&pfd, 1, 50) > 0) (void)::recv(sv[1], buf, sizeof buf, 0);
    }
  });
  emulator.run(source);
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  done = true;
  drain.join();
  ::close(sv[0]);
  ::close(sv[1]);
  // 0.4 s of sensor time at 2x: the last sample is due 0.1975 s after the first.
  EXPECT_GE(elapsed, 0.19);
  EXPECT_EQ(emulator.stats().imu_samples, 160u);
}

INSTANTIATE_TEST_SUITE_P(Seeds, EmulatorSeed, ::testing::Values(1u, 2u, 3u));

}  // namespace
}  // namespace semap::sim
