// End-to-end driver latency: bytes/frames written into the kernel interface -> value popped
// from the driver's ring, one message in flight at a time. Figures: p50/p99/max in µs.
//   pty:  NMEA GGA written to a pty master -> GnssDriver -> ring (runs anywhere)
//   vcan: one IMU sample (3 CAN frames) written to vcan0 -> CanImuDriver -> ring (needs vcan0;
//         scripts/hil-qemu build/bin/driver_bench runs it inside the HIL VM)
#include <benchmark/benchmark.h>
#include <fcntl.h>
#include <net/if.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "semap/drivers/can_imu_driver.hpp"
#include "semap/drivers/can_socket.hpp"
#include "semap/drivers/gnss_driver.hpp"
#include "semap/firmware_bridge/can_imu.h"
#include "semap/firmware_bridge/linux_can.hpp"
#include "semap/firmware_bridge/nmea.h"

namespace {

using semap::common::Stamp;
using namespace std::chrono_literals;
namespace drivers = semap::drivers;
namespace fb = semap::firmware_bridge;

constexpr int kMessages = 1000;

void report(benchmark::State& state, const char* name, std::vector<double>& latencies_us) {
  std::sort(latencies_us.begin(), latencies_us.end());
  const auto at = [&](double q) {
    return latencies_us[static_cast<std::size_t>(q * static_cast<double>(latencies_us.size() - 1))];
  };
  state.counters["p50_us"] = at(0.50);
  state.counters["p99_us"] = at(0.99);
  state.counters["max_us"] = latencies_us.back();
  std::printf("%s latency over %zu messages: p50 %.1f us, p99 %.1f us, max %.1f us\n", name,
              latencies_us.size(), at(0.50), at(0.99), latencies_us.back());
}

template <typename T>
bool wait_pop(semap::common::SpscRing<T>& ring, T& out) {
  const auto end = std::chrono::steady_clock::now() + 1s;
  // Yielding spin: lowest latency on real cores, and it lets the driver thread run when both
  // share one (as in the TCG-emulated HIL VM).
  while (!ring.try_pop(out)) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::yield();
  }
  return true;
}

bool wait_running(const drivers::DriverRunner& d) {
  const auto end = std::chrono::steady_clock::now() + 5s;
  while (d.state() != drivers::DriverState::kRunning) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(1ms);
  }
  return true;
}

void BM_PtyWriteToRingPop(benchmark::State& state) {
  const int master = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (master < 0 || ::grantpt(master) != 0 || ::unlockpt(master) != 0) {
    state.SkipWithError("no pty");
    return;
  }
  drivers::GnssConfig config;
  config.serial.device = ::ptsname(master);
  semap::common::SpscRing<semap::common::GnssFix> ring(64,
                                                       semap::common::OverflowPolicy::kDropOldest);
  drivers::GnssDriver driver(config, ring);
  driver.start();
  if (!wait_running(driver)) {
    state.SkipWithError("GNSS driver did not start");
    ::close(master);
    return;
  }
  SemapNmeaGga gga{};
  gga.has_time = gga.has_position = gga.has_hdop = gga.has_altitude = 1;
  gga.latitude_deg = 48.1;
  gga.longitude_deg = 11.5;
  gga.quality = 1;
  gga.satellites = 10;
  gga.hdop = 0.8;
  char sentence[SEMAP_NMEA_MAX_LENGTH + 1];
  std::vector<double> latencies;
  for (auto _ : state) {
    latencies.clear();
    for (int i = 0; i < kMessages; ++i) {
      gga.time_ms = i * 100;
      const std::size_t n =
          semap_nmea_encode_gga(&gga, SEMAP_NMEA_TALKER_GN, sentence, sizeof(sentence));
      const Stamp written = Stamp::now();
      if (::write(master, sentence, n) != static_cast<ssize_t>(n)) break;
      semap::common::GnssFix fix;
      if (!wait_pop(ring, fix)) break;
      latencies.push_back(static_cast<double>(Stamp::now().ns - written.ns) * 1e-3);
    }
  }
  driver.stop();
  ::close(master);
  if (latencies.size() != static_cast<std::size_t>(kMessages)) {
    state.SkipWithError("lost GNSS messages");
    return;
  }
  report(state, "pty NMEA", latencies);
}

void BM_VcanWriteToRingPop(benchmark::State& state) {
  if (::if_nametoindex("vcan0") == 0 || !drivers::interface_is_up("vcan0")) {
    state.SkipWithError("no vcan0 (run inside scripts/hil-qemu)");
    return;
  }
  drivers::CanImuConfig config;
  config.interface = "vcan0";
  semap::common::SpscRing<semap::common::ImuSample> ring(
      64, semap::common::OverflowPolicy::kDropOldest);
  drivers::CanImuDriver driver(config, ring);
  driver.start();
  if (!wait_running(driver)) {
    state.SkipWithError("CAN driver did not start");
    return;
  }
  drivers::CanSocket tx("vcan0", false);
  std::vector<double> latencies;
  std::vector<double> kernel_to_pop;
  for (auto _ : state) {
    latencies.clear();
    kernel_to_pop.clear();
    for (int i = 0; i < kMessages; ++i) {
      const double gyro[3] = {0.1, 0.2, 0.3};
      const double accel[3] = {0.0, 0.0, 9.81};
      SemapImuRaw raw;
      semap_can_imu_quantize(gyro, accel, static_cast<std::uint32_t>(i) * 2500,
                             static_cast<std::uint8_t>(i), 0, &raw);
      SemapCanFrame frames[SEMAP_CAN_IMU_FRAMES_PER_SAMPLE];
      semap_can_imu_encode(&raw, SEMAP_CAN_IMU_DEFAULT_BASE_ID, frames);
      for (int f = 0; f < 2; ++f) fb::write_can_frame(tx.fd(), frames[f]);
      // The last frame completes the sample: its write starts the clock.
      const Stamp written = Stamp::now();
      fb::write_can_frame(tx.fd(), frames[2]);
      semap::common::ImuSample sample;
      if (!wait_pop(ring, sample)) break;
      const Stamp popped = Stamp::now();
      latencies.push_back(static_cast<double>(popped.ns - written.ns) * 1e-3);
      kernel_to_pop.push_back(static_cast<double>(popped.ns - sample.stamp.ns) * 1e-3);
    }
  }
  driver.stop();
  if (latencies.size() != static_cast<std::size_t>(kMessages)) {
    state.SkipWithError("lost IMU samples");
    return;
  }
  report(state, "vcan IMU sample", latencies);
  std::sort(kernel_to_pop.begin(), kernel_to_pop.end());
  state.counters["kernel_stamp_to_pop_p50_us"] = kernel_to_pop[kernel_to_pop.size() / 2];
}

BENCHMARK(BM_PtyWriteToRingPop)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_VcanWriteToRingPop)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
