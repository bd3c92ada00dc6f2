// CanImuDriver against the firmware emulator on a real vcan0: natively where the host kernel
// can create vcan0, otherwise inside scripts/hil-qemu (see docs/hil.md).
#include <linux/can.h>
#include <linux/can/error.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "hil_env.hpp"
#include "semap/drivers/can_imu_driver.hpp"
#include "semap/sim/constant_turn_source.hpp"
#include "semap/sim/emulator.hpp"

namespace semap::drivers {
namespace {

using common::ImuSample;
using common::SpscRing;
using namespace std::chrono_literals;

constexpr const char* kInterface = "vcan0";

// SIOCSIFFLAGS, as `ip link set vcan0 up/down` does.
bool set_link_up(const char* name, bool up) {
  const int s = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (s < 0) return false;
  ifreq ifr{};
  std::strncpy(ifr.ifr_name, name, IFNAMSIZ - 1);
  bool ok = ::ioctl(s, SIOCGIFFLAGS, &ifr) == 0;
  if (ok) {
    ifr.ifr_flags = static_cast<short>(up ? (ifr.ifr_flags | IFF_UP) : (ifr.ifr_flags & ~IFF_UP));
    ok = ::ioctl(s, SIOCSIFFLAGS, &ifr) == 0;
  }
  ::close(s);
  return ok;
}

// vcan0 exists and is up, creating it when the kernel allows (root with the vcan module).
bool ensure_vcan() {
  if (::if_nametoindex(kInterface) == 0) {
    const char* ip = std::getenv("SEMAP_HIL_IP");
    const std::string cmd =
        std::string(ip ? ip : "ip") + " link add dev " + kInterface + " type vcan 2>/dev/null";
    if (std::system(cmd.c_str()) != 0 || ::if_nametoindex(kInterface) == 0) return false;
  }
  return set_link_up(kInterface, true);
}

// Writes an error frame as a CAN controller driver does (vcan passes it to every socket whose
// CAN_RAW_ERR_FILTER asks for its class).
bool send_error_frame(int fd, canid_t error_class, std::uint8_t controller = 0) {
  can_frame f{};
  f.can_id = CAN_ERR_FLAG | error_class;
  f.len = CAN_ERR_DLC;
  f.data[1] = controller;
  return ::write(fd, &f, sizeof f) == static_cast<ssize_t>(sizeof f);
}

struct Received {
  std::vector<ImuSample> samples;
};

class VcanTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!ensure_vcan()) SEMAP_HIL_UNAVAILABLE("cannot create vcan0 on this kernel");
  }

  static CanImuConfig config() {
    CanImuConfig c;
    c.interface = kInterface;
    c.backoff.initial = 10ms;
    c.backoff.max = 50ms;
    return c;
  }

  static sim::ConstantTurnConfig truth(double seconds) {
    sim::ConstantTurnConfig t;
    t.duration_s = seconds;
    t.imu_rate_hz = 400.0;
    t.gnss_rate_hz = 1.0;  // not sent: no serial fd
    return t;
  }

  static sim::EmulatorConfig emulator_config(int fd, double speed) {
    sim::EmulatorConfig ec;
    ec.can_fd = fd;
    ec.speed = speed;
    return ec;
  }

  // Consumer thread standing in for the estimator: pops until told to stop.
  void start_consumer(SpscRing<ImuSample>& ring) {
    consumer_ = std::jthread([this, &ring](std::stop_token stop) {
      ImuSample s;
      while (!stop.stop_requested()) {
        while (ring.try_pop(s)) received_.samples.push_back(s);
        std::this_thread::sleep_for(1ms);
      }
      while (ring.try_pop(s)) received_.samples.push_back(s);
    });
  }
  void stop_consumer() {
    consumer_.request_stop();
    consumer_.join();
  }

  Received received_;
  std::jthread consumer_;
};

TEST_F(VcanTest, Receives400HzFor10sWithoutLossCrcErrorsOrGaps) {
  SpscRing<ImuSample> ring(4096, common::OverflowPolicy::kDropOldest);
  CanImuDriver driver(config(), ring);
  driver.start();
  ASSERT_TRUE(hil::wait_until([&] { return driver.state() == DriverState::kRunning; }, 5s))
      << driver.last_error();
  start_consumer(ring);

  CanSocket tx(kInterface, false);
  sim::Emulator emulator(emulator_config(tx.fd(), 1.0));
  sim::ConstantTurnSource source(truth(10.0));
  const common::Stamp run_start = common::Stamp::now();
  emulator.run(source);
  const common::Stamp run_end = common::Stamp::now();
  const auto sent = emulator.stats();
  EXPECT_TRUE(hil::wait_until([&] { return driver.stats().frames >= sent.imu_samples; }, 5s));
  driver.stop();
  stop_consumer();
  // Every frame carries the kernel's receive stamp: the thread's lateness behind it is measured.
  const auto wakeup = driver.stats().wakeup;
  std::printf("vcan wake-up lateness: p50 %.3f ms, p99 %.3f ms, max %.3f ms over %zu frames\n",
              wakeup.p50_ms, wakeup.p99_ms, wakeup.max_ms, wakeup.count);
  EXPECT_EQ(wakeup.count, 1024u);
  EXPECT_LE(wakeup.p50_ms, wakeup.max_ms);

  const auto c = driver.imu_counters();
  const auto& got = received_.samples;
  std::printf(
      "vcan clean: sent %llu samples (%llu frames, %llu write failures), received %zu, "
      "CRC errors %llu, gaps %llu (missed %llu), ring drops %llu, kernel drops %llu\n",
      (unsigned long long)sent.imu_samples, (unsigned long long)sent.can_frames,
      (unsigned long long)sent.can_write_failures, got.size(), (unsigned long long)c.crc_errors,
      (unsigned long long)c.sequence_gaps, (unsigned long long)c.missed_samples,
      (unsigned long long)driver.stats().ring_drops,
      (unsigned long long)driver.stats().input_drops);
  EXPECT_EQ(sent.imu_samples, 4000u);
  EXPECT_EQ(sent.can_write_failures, 0u);
  ASSERT_EQ(got.size(), sent.imu_samples);
  EXPECT_EQ(c.crc_errors, 0u);
  EXPECT_EQ(c.sequence_gaps, 0u);
  EXPECT_EQ(c.incomplete, 0u);
  EXPECT_EQ(driver.stats().ring_drops, 0u);
  EXPECT_EQ(driver.stats().input_drops, 0u);
  EXPECT_EQ(driver.stats().bytes, sent.can_frames * 8);
  for (std::size_t i = 1; i < got.size(); ++i) {
    ASSERT_EQ(got[i].sequence, got[i - 1].sequence + 1) << i;
    ASSERT_GT(got[i].stamp, got[i - 1].stamp) << i;
  }
  // Kernel receive stamps, mapped onto CLOCK_MONOTONIC, fall inside the window in which the
  // emulator wrote (vcan stamps a frame within the sender's write call). The slack covers the
  // realtime/monotonic offset's uncertainty. The window is the emulator's real duration: in a
  // starved VM it can exceed the 10 s of sensor time.
  const double slack_s = 0.002;
  EXPECT_GE(common::seconds_between(got.front().stamp, run_start), -slack_s);
  EXPECT_LE(common::seconds_between(got.back().stamp, run_end), slack_s);
  const double span = common::seconds_between(got.back().stamp, got.front().stamp);
  EXPECT_GT(span, 9.9);
  std::printf("vcan clean: stamps span %.3f s, emulator wrote for %.3f s\n", span,
              common::seconds_between(run_end, run_start));
}

TEST_F(VcanTest, CountsInjectedCrcErrorsDropsAndGapsExactly) {
  SpscRing<ImuSample> ring(4096, common::OverflowPolicy::kDropOldest);
  CanImuDriver driver(config(), ring);
  driver.start();
  ASSERT_TRUE(hil::wait_until([&] { return driver.state() == DriverState::kRunning; }, 5s));
  start_consumer(ring);

  CanSocket tx(kInterface, false);
  auto ec = emulator_config(tx.fd(), 2.0);
  ec.faults.crc_error = 0.02;
  ec.faults.drop_frame = 0.01;
  ec.faults.sequence_gap = 0.01;
  ec.faults.seed = 3;
  sim::Emulator emulator(ec);
  sim::ConstantTurnSource source(truth(4.0));
  emulator.run(source);
  // Clean samples after the run, so a fault in the last sample is detected too.
  emulator.set_faults({});
  for (int i = 1; i <= 3; ++i) {
    ImuSample tail;
    tail.stamp = truth(4.0).start + (4.0 + i / 400.0);
    emulator.emit(tail);
  }
  const auto sent = emulator.stats();
  const auto& inj = sent.injected;
  const std::uint64_t lost = inj.crc_errors + inj.dropped_frames;
  ASSERT_TRUE(hil::wait_until(
      [&] { return driver.imu_counters().samples >= sent.imu_samples - lost; }, 5s));
  std::this_thread::sleep_for(50ms);
  driver.stop();
  stop_consumer();

  const auto c = driver.imu_counters();
  const auto stats = driver.stats();
  std::printf(
      "vcan faults: sent %llu samples; injected CRC %llu, dropped frames %llu, gaps %llu; "
      "counted CRC %llu, incomplete %llu, sequence gaps %llu, missed samples %llu; "
      "received %zu\n",
      (unsigned long long)sent.imu_samples, (unsigned long long)inj.crc_errors,
      (unsigned long long)inj.dropped_frames, (unsigned long long)inj.sequence_gaps,
      (unsigned long long)c.crc_errors, (unsigned long long)c.incomplete,
      (unsigned long long)c.sequence_gaps, (unsigned long long)c.missed_samples,
      received_.samples.size());
  ASSERT_GT(inj.crc_errors, 0u);
  ASSERT_GT(inj.dropped_frames, 0u);
  ASSERT_GT(inj.sequence_gaps, 0u);
  EXPECT_EQ(c.crc_errors, inj.crc_errors);
  EXPECT_EQ(c.incomplete, inj.crc_errors + inj.dropped_frames);
  EXPECT_EQ(c.missed_samples, inj.crc_errors + inj.dropped_frames + inj.sequence_gaps);
  EXPECT_EQ(received_.samples.size(), sent.imu_samples - lost);
  EXPECT_EQ(c.samples, received_.samples.size());
  EXPECT_EQ(stats.checksum_failures, c.crc_errors);
  EXPECT_EQ(stats.sequence_gaps, c.missed_samples);
  // Every sample the sensor made is either delivered or counted as missed.
  EXPECT_EQ(received_.samples.back().sequence - received_.samples.front().sequence + 1,
            received_.samples.size() + c.missed_samples);
}

// The CAN FD variant (one 64-byte frame per sample) and the J1939 profile (29-bit ids): 2 s of
// 400 Hz sent at double speed, every sample through the kernel filter and the assembler.
TEST_F(VcanTest, CanFdAndJ1939ProfilesArriveComplete) {
  struct Case {
    const char* name;
    firmware_bridge::ImuProfile profile;
    bool fd;
  };
  for (const Case& k : {Case{"semap CAN FD", firmware_bridge::ImuProfile::kSemap, true},
                        Case{"J1939", firmware_bridge::ImuProfile::kJ1939, false}}) {
    SCOPED_TRACE(k.name);
    SpscRing<ImuSample> ring(4096, common::OverflowPolicy::kDropOldest);
    auto c = config();
    c.decoder.profile = k.profile;
    c.fd_frames = k.fd;
    CanImuDriver driver(c, ring);
    driver.start();
    ASSERT_TRUE(hil::wait_until([&] { return driver.state() == DriverState::kRunning; }, 5s));

    CanSocket tx(kInterface, k.fd);
    auto ec = emulator_config(tx.fd(), 2.0);
    ec.imu_profile = k.profile;
    ec.can_fd_frames = k.fd;
    sim::Emulator emulator(ec);
    sim::ConstantTurnSource source(truth(2.0));
    emulator.run(source);
    const auto sent = emulator.stats();
    EXPECT_TRUE(hil::wait_until([&] { return driver.stats().frames >= sent.imu_samples; }, 5s));
    driver.stop();
    const auto counters = driver.imu_counters();
    std::printf("vcan %s: sent %llu samples in %llu frames, received %llu, errors %llu\n", k.name,
                (unsigned long long)sent.imu_samples, (unsigned long long)sent.can_frames,
                (unsigned long long)driver.stats().frames,
                (unsigned long long)(counters.crc_errors + counters.bad_frames +
                                     counters.incomplete + counters.unpaired));
    EXPECT_EQ(sent.imu_samples, 800u);
    EXPECT_EQ(sent.can_write_failures, 0u);
    EXPECT_EQ(driver.stats().frames, sent.imu_samples);
    EXPECT_EQ(counters.unknown, 0u);  // the kernel filter let only the profile's frames through
    EXPECT_EQ(counters.crc_errors + counters.bad_frames + counters.incomplete + counters.unpaired,
              0u);
    ImuSample first;
    ASSERT_TRUE(ring.try_pop(first));
    EXPECT_NEAR(first.accel.norm(), 9.81, 0.1);  // gravity plus the small centripetal term
  }
}

TEST_F(VcanTest, ResumesAfterInterfaceDownAndUp) {
  SpscRing<ImuSample> ring(4096, common::OverflowPolicy::kDropOldest);
  CanImuDriver driver(config(), ring);
  driver.start();
  ASSERT_TRUE(hil::wait_until([&] { return driver.state() == DriverState::kRunning; }, 5s));
  start_consumer(ring);

  CanSocket tx(kInterface, false);
  sim::Emulator emulator(emulator_config(tx.fd(), 1.0));
  sim::ConstantTurnSource source(truth(3.0));
  std::jthread sender([&] { emulator.run(source); });

  ASSERT_TRUE(hil::wait_until([&] { return driver.stats().frames >= 400; }, 5s));
  ASSERT_TRUE(set_link_up(kInterface, false));
  const bool reported = hil::wait_until([&] { return driver.failures() > 0; }, 2s);
  std::this_thread::sleep_for(150ms);  // the driver's reopen attempts find it down
  const DriverState while_down = driver.state();
  const std::uint64_t frames_while_down = driver.stats().frames;
  ASSERT_TRUE(set_link_up(kInterface, true));
  sender.join();
  ASSERT_TRUE(hil::wait_until([&] { return driver.stats().reconnects == 1; }, 2s))
      << driver.last_error();
  std::this_thread::sleep_for(50ms);
  driver.stop();
  stop_consumer();

  const auto c = driver.imu_counters();
  const auto sent = emulator.stats();
  const auto& got = received_.samples;
  std::printf(
      "vcan down/up: sent %llu samples (%llu frame writes failed while down), received "
      "%zu, missed %llu, failures %llu, reconnects %llu, lost: '%s'\n",
      (unsigned long long)sent.imu_samples, (unsigned long long)sent.can_write_failures, got.size(),
      (unsigned long long)c.missed_samples, (unsigned long long)driver.failures(),
      (unsigned long long)driver.stats().reconnects, driver.last_loss().c_str());
  EXPECT_TRUE(reported);
  EXPECT_NE(while_down, DriverState::kRunning);
  EXPECT_NE(driver.last_loss().find("Network is down"), std::string::npos) << driver.last_loss();
  EXPECT_NE(driver.last_error().find("down"), std::string::npos) << driver.last_error();
  EXPECT_GT(sent.can_write_failures, 0u);
  // It resumed: samples after the outage arrived, up to the emulator's last one.
  ASSERT_FALSE(got.empty());
  EXPECT_GT(got.size(), frames_while_down + 400);
  EXPECT_EQ(got.back().sequence, 1199u);
  EXPECT_EQ(got.back().sequence - got.front().sequence + 1, got.size() + c.missed_samples);
  EXPECT_EQ(c.crc_errors, 0u);
}

// Controller trouble as error frames: error-passive and back, bus-off ended by the kernel's
// "restarted" frame (what restart-ms or can_do_restart produce), and bus-off ended by traffic
// alone. Each is counted, the socket stays open throughout (no reconnect), and every sample
// sent around the episodes arrives.
TEST_F(VcanTest, ErrorFramesAreCountedAndBusOffRecoversWithoutReconnecting) {
  SpscRing<ImuSample> ring(4096, common::OverflowPolicy::kDropOldest);
  CanImuDriver driver(config(), ring);
  driver.start();
  ASSERT_TRUE(hil::wait_until([&] { return driver.state() == DriverState::kRunning; }, 5s));
  start_consumer(ring);

  CanSocket tx(kInterface, false);
  CanSocket errors(kInterface, false);
  sim::Emulator emulator(emulator_config(tx.fd(), 1.0));
  std::uint64_t sent = 0;
  const auto send_samples = [&](int n) {
    for (int i = 0; i < n; ++i) {
      ImuSample s;
      s.stamp = common::Stamp::now();
      s.accel = Eigen::Vector3d(0.0, 0.0, 9.81);
      emulator.emit(s);
      ++sent;
      std::this_thread::sleep_for(2500us);
    }
  };
  const auto stats = [&] { return driver.stats(); };

  send_samples(200);
  ASSERT_TRUE(send_error_frame(errors.fd(), CAN_ERR_CRTL | CAN_ERR_CNT, CAN_ERR_CRTL_RX_PASSIVE));
  EXPECT_TRUE(hil::wait_until([&] { return stats().error_passive == 1; }, 2s));
  EXPECT_EQ(driver.bus_state(), CanBusState::kErrorPassive);
  send_samples(50);  // an error-passive node still receives
  ASSERT_TRUE(send_error_frame(errors.fd(), CAN_ERR_CRTL, CAN_ERR_CRTL_ACTIVE));
  EXPECT_TRUE(hil::wait_until([&] { return driver.bus_state() == CanBusState::kErrorActive; }, 2s));

  // Bus-off, then the kernel's restart frame.
  ASSERT_TRUE(send_error_frame(errors.fd(), CAN_ERR_BUSOFF));
  EXPECT_TRUE(hil::wait_until([&] { return stats().bus_off == 1; }, 2s));
  EXPECT_EQ(driver.bus_state(), CanBusState::kBusOff);
  ASSERT_TRUE(send_error_frame(errors.fd(), CAN_ERR_RESTARTED));
  EXPECT_TRUE(hil::wait_until([&] { return stats().bus_restarts == 1; }, 2s));
  EXPECT_EQ(driver.bus_state(), CanBusState::kErrorActive);
  send_samples(100);

  // Bus-off again, ended by frames arriving: a bus-off controller receives none.
  ASSERT_TRUE(send_error_frame(errors.fd(), CAN_ERR_BUSOFF));
  EXPECT_TRUE(hil::wait_until([&] { return stats().bus_off == 2; }, 2s));
  EXPECT_EQ(driver.bus_state(), CanBusState::kBusOff);
  send_samples(150);
  EXPECT_TRUE(hil::wait_until([&] { return stats().frames >= sent; }, 5s));
  driver.stop();
  stop_consumer();

  const DriverStats st = driver.stats();
  const auto c = driver.imu_counters();
  std::printf(
      "vcan error frames: sent %llu samples, received %zu; error-passive %llu, bus-off %llu, "
      "restarts %llu, reconnects %llu, missed %llu, last error '%s'\n",
      (unsigned long long)sent, received_.samples.size(), (unsigned long long)st.error_passive,
      (unsigned long long)st.bus_off, (unsigned long long)st.bus_restarts,
      (unsigned long long)st.reconnects, (unsigned long long)c.missed_samples,
      driver.last_error().c_str());
  EXPECT_EQ(st.error_passive, 1u);
  EXPECT_EQ(st.bus_off, 2u);
  EXPECT_EQ(st.bus_restarts, 2u);
  EXPECT_EQ(driver.bus_state(), CanBusState::kErrorActive);
  EXPECT_EQ(st.reconnects, 0u);
  EXPECT_EQ(driver.failures(), 0u);
  EXPECT_NE(driver.last_error().find("vcan0: controller is bus-off"), std::string::npos)
      << driver.last_error();
  EXPECT_EQ(received_.samples.size(), sent);
  EXPECT_EQ(c.missed_samples, 0u);
  EXPECT_EQ(c.crc_errors + c.bad_frames + c.incomplete + c.unknown, 0u);
}

}  // namespace
}  // namespace semap::drivers
