// GnssDriver against the firmware emulator through a real pty: the emulator writes NMEA or UBX
// into the master, the driver reads the slave with 115200-baud raw termios settings.
#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "hil_env.hpp"
#include "semap/drivers/gnss_driver.hpp"
#include "semap/firmware_bridge/nmea.h"
#include "semap/firmware_bridge/ubx.h"
#include "semap/sim/constant_turn_source.hpp"
#include "semap/sim/emulator.hpp"

namespace semap::drivers {
namespace {

using common::GnssFix;
using common::SpscRing;
using firmware_bridge::GnssProtocol;
using namespace std::chrono_literals;

// A pty pair; the slave is reached through a symlink so that a test can swap the pty under the
// driver the way udev re-creates /dev/serial/by-id links when an adapter is re-plugged.
class Pty {
 public:
  Pty() {
    master_ = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
    if (master_ < 0 || ::grantpt(master_) != 0 || ::unlockpt(master_) != 0) {
      throw std::runtime_error("cannot allocate a pty");
    }
    slave_ = ::ptsname(master_);
  }
  ~Pty() { close(); }
  void close() {
    if (master_ >= 0) ::close(master_);
    master_ = -1;
  }
  int master() const { return master_; }
  const std::string& slave() const { return slave_; }

 private:
  int master_ = -1;
  std::string slave_;
};

class GnssPtyTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        std::filesystem::temp_directory_path() / ("semap-gnss-pty-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
    link_ = dir_ / "gnss";
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  void point_link_to(const Pty& pty) {
    std::filesystem::remove(link_);
    std::filesystem::create_symlink(pty.slave(), link_);
  }

  GnssConfig config() const {
    GnssConfig c;
    c.serial.device = link_.string();
    c.serial.baud = 115200;
    c.backoff.initial = 20ms;
    c.backoff.max = 200ms;
    return c;
  }

  // 10 s of a 10 Hz receiver, sent 20x faster than real time.
  static sim::EmulatorStats emulate(int fd, GnssProtocol protocol, const sim::FaultConfig& faults) {
    sim::ConstantTurnConfig truth;
    truth.duration_s = 10.0;
    truth.imu_rate_hz = 10.0;  // IMU events are not sent (no CAN fd); keep them few
    truth.gnss_rate_hz = 10.0;
    sim::ConstantTurnSource source(truth);
    sim::EmulatorConfig ec;
    ec.serial_fd = fd;
    ec.gnss_protocol = protocol;
    ec.speed = 20.0;
    ec.faults = faults;
    sim::Emulator emulator(ec);
    emulator.run(source);
    return emulator.stats();
  }

  static void write_all(int fd, const void* data, std::size_t len) {
    ASSERT_EQ(::write(fd, data, len), static_cast<ssize_t>(len));
  }

  // A valid GGA; with `corrupt` its checksum is wrong.
  static std::string gga(bool corrupt) {
    SemapNmeaGga g{};
    g.has_time = g.has_position = g.has_hdop = g.has_altitude = g.has_geoid = 1;
    g.time_ms = 43'200'000;
    g.latitude_deg = 48.1;
    g.longitude_deg = 11.5;
    g.quality = 1;
    g.satellites = 9;
    g.hdop = 0.9;
    g.altitude_msl_m = 500.0;
    g.geoid_separation_m = 47.0;
    char buf[SEMAP_NMEA_MAX_LENGTH + 1];
    const std::size_t n = semap_nmea_encode_gga(&g, SEMAP_NMEA_TALKER_GP, buf, sizeof(buf));
    std::string s(buf, n);
    if (corrupt) {
      char& digit = s[s.find('*') + 2];
      digit = digit == '0' ? '1' : '0';
    }
    return s;
  }

  static std::vector<std::uint8_t> nav_pvt() {
    SemapUbxNavPvt p{};
    p.year = 2026;
    p.month = 1;
    p.day = 1;
    p.fix_type = 3;
    p.flags = SEMAP_UBX_PVT_FLAG_GNSS_FIX_OK;
    p.num_sv = 12;
    p.lat_1e7_deg = 481'000'000;
    p.lon_1e7_deg = 115'000'000;
    p.height_mm = 520'000;
    p.h_acc_mm = 500;
    p.v_acc_mm = 800;
    std::vector<std::uint8_t> frame(SEMAP_UBX_NAV_PVT_FRAME_LEN);
    frame.resize(semap_ubx_encode_nav_pvt(&p, frame.data(), frame.size()));
    return frame;
  }

  static std::vector<GnssFix> drain(SpscRing<GnssFix>& ring) {
    std::vector<GnssFix> out;
    GnssFix f;
    while (ring.try_pop(f)) out.push_back(f);
    return out;
  }

  std::filesystem::path dir_;
  std::filesystem::path link_;
};

TEST_F(GnssPtyTest, AppliesRawTermiosAt115200) {
  Pty pty;
  point_link_to(pty);
  SerialConfig sc;
  sc.device = link_.string();
  SerialPort port(sc);
  termios tio{};
  ASSERT_EQ(::tcgetattr(port.fd(), &tio), 0);
  EXPECT_EQ(::cfgetispeed(&tio), static_cast<speed_t>(B115200));
  EXPECT_EQ(::cfgetospeed(&tio), static_cast<speed_t>(B115200));
  EXPECT_EQ(tio.c_cflag & CSIZE, static_cast<tcflag_t>(CS8));
  EXPECT_EQ(tio.c_cflag & (PARENB | CSTOPB | CRTSCTS), 0u);
  EXPECT_EQ(tio.c_lflag & (ICANON | ECHO | ISIG), 0u);
  EXPECT_EQ(tio.c_iflag & (IXON | IXOFF | ICRNL), 0u);
  EXPECT_EQ(tio.c_cc[VMIN], 1);
  EXPECT_EQ(tio.c_cc[VTIME], 0);
}

TEST_F(GnssPtyTest, NmeaWithFaultsDeliversEveryGoodSentenceAndCountsEveryBadOne) {
  Pty pty;
  point_link_to(pty);
  SpscRing<GnssFix> ring(1024, common::OverflowPolicy::kDropOldest);
  GnssDriver driver(config(), ring);
  driver.start();
  ASSERT_TRUE(hil::wait_until([&] { return driver.state() == DriverState::kRunning; }, 5s));

  constexpr int kBadChecksums = 5;
  for (int i = 0; i < kBadChecksums; ++i)
    write_all(pty.master(), gga(true).data(), gga(true).size());
  sim::FaultConfig faults;
  faults.garbage = 0.2;
  faults.truncate = 0.1;
  faults.seed = 7;
  const auto sent = emulate(pty.master(), GnssProtocol::kNmea, faults);
  // A clean sentence closes a truncated one the emulator may have ended with.
  const std::string tail = gga(false);
  write_all(pty.master(), tail.data(), tail.size());

  const std::uint64_t good = sent.nmea_sentences + 1;
  ASSERT_TRUE(hil::wait_until([&] { return driver.stream_counters().nmea_sentences >= good; }, 10s))
      << driver.stream_counters().nmea_sentences << " of " << good;
  std::this_thread::sleep_for(50ms);
  driver.stop();

  const auto c = driver.stream_counters();
  const auto fixes = drain(ring);
  std::printf(
      "pty NMEA: %llu epochs, %llu good sentences sent, %llu received, %zu fixes; "
      "injected %llu truncated, %llu garbage bursts (%llu bytes), %d bad checksums; "
      "counted truncated %llu, too long %llu, bad checksum %llu, garbage %llu bytes\n",
      (unsigned long long)sent.gnss_epochs, (unsigned long long)good,
      (unsigned long long)c.nmea_sentences, fixes.size(),
      (unsigned long long)sent.injected.truncated, (unsigned long long)sent.injected.garbage_bursts,
      (unsigned long long)sent.injected.garbage_bytes, kBadChecksums,
      (unsigned long long)c.truncated, (unsigned long long)c.too_long,
      (unsigned long long)c.bad_checksum, (unsigned long long)c.garbage_bytes);
  EXPECT_GT(sent.injected.truncated, 0u);
  EXPECT_GT(sent.injected.garbage_bursts, 0u);
  EXPECT_EQ(sent.serial_dropped_bytes, 0u);
  EXPECT_EQ(c.nmea_sentences, good);
  EXPECT_EQ(c.truncated + c.too_long, sent.injected.truncated);
  EXPECT_EQ(c.bad_checksum, static_cast<std::uint64_t>(kBadChecksums));
  EXPECT_EQ(c.garbage_bytes, sent.injected.garbage_bytes);
  EXPECT_EQ(fixes.size(), c.fixes);
  EXPECT_GE(fixes.size(), sent.gnss_epochs - sent.injected.truncated);
  const auto stats = driver.stats();
  EXPECT_EQ(stats.frames, fixes.size());
  EXPECT_EQ(stats.checksum_failures, static_cast<std::uint64_t>(kBadChecksums));
  EXPECT_EQ(stats.errors, c.truncated + c.too_long + c.bad_field);
  EXPECT_EQ(stats.ring_drops, 0u);
  EXPECT_EQ(stats.reconnects, 0u);
  for (std::size_t i = 1; i < fixes.size(); ++i) {
    ASSERT_GE(fixes[i].stamp, fixes[i - 1].stamp);
    ASSERT_TRUE(fixes[i].valid());
  }
}

TEST_F(GnssPtyTest, UbxWithFaultsDeliversEveryGoodFrameAndCountsEveryBadOne) {
  Pty pty;
  point_link_to(pty);
  SpscRing<GnssFix> ring(1024, common::OverflowPolicy::kDropOldest);
  GnssDriver driver(config(), ring);
  driver.start();
  ASSERT_TRUE(hil::wait_until([&] { return driver.state() == DriverState::kRunning; }, 5s));

  sim::FaultConfig faults;
  faults.garbage = 0.2;
  faults.truncate = 0.1;
  faults.seed = 11;
  const auto sent = emulate(pty.master(), GnssProtocol::kUbx, faults);
  // Two clean frames; the framer must find both even right after a truncated frame.
  for (int i = 0; i < 2; ++i) {
    const auto frame = nav_pvt();
    write_all(pty.master(), frame.data(), frame.size());
  }
  ASSERT_TRUE(hil::wait_until(
      [&] { return driver.stream_counters().ubx_frames >= sent.ubx_frames + 2; }, 10s));
  std::this_thread::sleep_for(50ms);
  driver.stop();

  const auto c = driver.stream_counters();
  const auto fixes = drain(ring);
  std::printf(
      "pty UBX: %llu epochs, %llu good frames sent (+2 clean), %llu received, %zu fixes; "
      "injected %llu truncated, %llu garbage bursts; counted bad checksum %llu, "
      "truncated %llu, too long %llu\n",
      (unsigned long long)sent.gnss_epochs, (unsigned long long)sent.ubx_frames,
      (unsigned long long)c.ubx_frames, fixes.size(), (unsigned long long)sent.injected.truncated,
      (unsigned long long)sent.injected.garbage_bursts, (unsigned long long)c.bad_checksum,
      (unsigned long long)c.truncated, (unsigned long long)c.too_long);
  EXPECT_GT(sent.injected.truncated, 0u);
  EXPECT_EQ(c.ubx_frames, sent.ubx_frames + 2);
  EXPECT_EQ(c.bad_checksum + c.truncated + c.too_long, sent.injected.truncated);
  EXPECT_EQ(fixes.size(), c.fixes);
  EXPECT_EQ(driver.stats().ring_drops, 0u);
}

TEST_F(GnssPtyTest, HangUpIsReportedAndTheDriverReopens) {
  SpscRing<GnssFix> ring(1024, common::OverflowPolicy::kDropOldest);
  auto first = std::make_unique<Pty>();
  point_link_to(*first);
  GnssDriver driver(config(), ring);
  driver.start();
  ASSERT_TRUE(hil::wait_until([&] { return driver.state() == DriverState::kRunning; }, 5s));
  const std::string s = gga(false);
  write_all(first->master(), s.data(), s.size());
  ASSERT_TRUE(hil::wait_until([&] { return driver.stats().frames == 1; }, 5s));

  first->close();  // the adapter vanishes: the slave sees a hang-up
  ASSERT_TRUE(hil::wait_until([&] { return driver.failures() > 0; }, 5s));
  EXPECT_NE(driver.last_loss().find("hang-up"), std::string::npos) << driver.last_loss();
  std::filesystem::remove(link_);
  std::this_thread::sleep_for(100ms);  // reopen attempts fail while the device is missing
  EXPECT_NE(driver.state(), DriverState::kRunning);

  Pty second;
  point_link_to(second);
  ASSERT_TRUE(hil::wait_until([&] { return driver.stats().reconnects == 1; }, 5s))
      << driver.last_error();
  ASSERT_TRUE(hil::wait_until([&] { return driver.state() == DriverState::kRunning; }, 5s));
  const auto sent = emulate(second.master(), GnssProtocol::kNmea, {});
  ASSERT_TRUE(hil::wait_until(
      [&] { return driver.stream_counters().nmea_sentences == sent.nmea_sentences + 1; }, 10s))
      << driver.stream_counters().nmea_sentences;
  driver.stop();
  EXPECT_EQ(drain(ring).size(), sent.gnss_epochs + 1);
  std::printf("pty hang-up: failures %llu, reconnects %llu, fixes after reopen %llu\n",
              (unsigned long long)driver.failures(), (unsigned long long)driver.stats().reconnects,
              (unsigned long long)sent.gnss_epochs);
}

}  // namespace
}  // namespace semap::drivers
