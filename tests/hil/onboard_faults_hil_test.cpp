// Faults injected into a running semap-onboard (docs/reliability.md): the CAN controller goes
// bus-off mid-drive (natively where the host has vcan0, otherwise inside scripts/hil-qemu) and
// the wall clock steps an hour forward and back (only inside scripts/hil-qemu's throwaway VM:
// it would step the host's clock). The camera's unplug is in onboard_hil_test.cpp, with vivid.
#include <time.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "hil_env.hpp"
#include "onboard_process.hpp"

namespace semap::hil {
namespace {

namespace fs = std::filesystem;

constexpr double kDriveSeconds = 30.0;

// The simulated rig cut down for TCG: a small camera rendered straight into its ring, palette
// segmenter, coarse map, GNSS NMEA on the rig's pty; `extra` adds sections or keys.
std::string rig_config(const std::string& imu_interface, const std::string& rig_extra,
                       const std::string& extra) {
  std::ostringstream c;
  c << "log_level: info\n"
    << "rig:\n"
    << "  kind: sim\n"
    << "  scenario: figure8\n"
    << "  speed_m_s: 2\n"
    << "  gnss_rate_hz: 5\n"
    << "  gnss_sigma_m: 0.3\n"
    << "  camera_image: classes\n"
    << rig_extra << "imu:\n"
    << "  interface: \"" << imu_interface << "\"\n"
    << "gnss:\n"
    << "  device: pty\n"
    << "camera:\n"
    << "  width: 160\n"
    << "  height: 120\n"
    << "  fps: 2\n"
    << "  fov_deg: 90\n"
    << "  mount_xyz: [0.3, 0, 1.5]\n"
    << "  mount_rpy_deg: [0, 10, 0]\n"
    << "depth:\n"
    << "  source: aligned\n"
    << "  max_range: 10\n"
    << "  stride: 4\n"
    << "segmenter:\n"
    << "  kind: palette\n"
    << "map:\n"
    << "  resolution: 0.2\n"
    << "  num_classes: 8\n"
    << "  free_res: 2.0\n"
    << "  ds_res: 0.4\n"
    << "  max_range: 10\n"
    << "  threads: 1\n"
    << "  start_heading_sigma_deg: 180\n"
    << extra;
  return c.str();
}

// One figure from the run's output, or -1.
double figure(const std::string& out, const std::string& pattern) {
  std::smatch m;
  if (!std::regex_search(out, m, std::regex(pattern)) || m.size() < 2) return -1.0;
  return std::stod(m[1]);
}

class OnboardFaults : public ::testing::Test {
 protected:
  void SetUp() override {
    onboard_ = find_program("semap-onboard", SEMAP_ONBOARD_BIN);
    ASSERT_FALSE(onboard_.empty()) << "semap-onboard not found";
    dir_ = fs::temp_directory_path() / ("semap_faults_hil_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Runs semap-onboard on `config` for the drive; `during` runs meanwhile (the fault).
  std::string run(const std::string& config, const std::function<void(Child&)>& during, int& code) {
    write_file(dir_ / "onboard.yaml", config);
    Child onboard({onboard_, "--config", (dir_ / "onboard.yaml").string(), "--duration",
                   std::to_string(kDriveSeconds)},
                  dir_ / "onboard.log");
    if (during) during(onboard);
    const auto status =
        onboard.wait(std::chrono::milliseconds(static_cast<int>(1e3 * kDriveSeconds)) + 150s);
    code = status.value_or(-1);
    const std::string out = onboard.output();
    std::printf("---- semap-onboard ----\n%s\n", out.c_str());
    std::fflush(stdout);
    return out;
  }

  std::string onboard_;
  fs::path dir_;
};

// The controller goes bus-off 12 s into the drive for 3 s (the rig writes the error frames a
// controller's driver sends and no IMU frame meanwhile): the driver counts the bus-off and the
// restart, the summary shows the 3 s gap, IMU samples resume and the filter, restarted after
// the gap, stays on the truth.
TEST_F(OnboardFaults, CanBusOffMidDriveIsReportedAndTheFilterHolds) {
  if (!fs::exists("/sys/class/net/vcan0")) SEMAP_HIL_UNAVAILABLE("no vcan0 interface");
  int code = 0;
  const std::string out =
      run(rig_config("vcan0", "  faults: {can_bus_off_at_s: 12, can_bus_off_s: 3}\n",
                     "dds:\n  enabled: false\n"),
          nullptr, code);
  EXPECT_EQ(code, 0);
  const Summary s = parse_summary(out);
  EXPECT_TRUE(s.initialised);
  const double bus_off = figure(out, R"(imu driver +: .*, (\d+) bus-off)");
  const double restarts = figure(out, R"(imu driver +: .*bus-off \((\d+) restarts\))");
  const double gap = figure(out, R"(imu driver +: .*longest gap ([0-9.]+) s)");
  const double unsent = figure(out, R"(CAN bus-off from .* (\d+) IMU samples not sent)");
  const double received = figure(out, R"(imu driver +: (\d+) samples)");
  std::printf("bus-off %g, restarts %g, longest IMU gap %g s, %g samples not sent, %g received\n",
              bus_off, restarts, gap, unsent, received);
  EXPECT_EQ(bus_off, 1.0);
  EXPECT_EQ(restarts, 1.0);
  EXPECT_GE(gap, 2.8) << "the health report shows the gap";
  EXPECT_LT(gap, 5.0);
  EXPECT_GT(unsent, 0.0);
  // Samples resume: the drive after the gap is longer than the drive before it.
  EXPECT_GT(received, 1.5 * unsent);
  ASSERT_TRUE(s.pose_rmse) << "no pose vs truth line";
  EXPECT_LT(*s.pose_rmse, 1.0);
  EXPECT_LT(figure(out, R"(pose vs truth +: position RMSE [0-9.]+ m, max ([0-9.]+) m)"), 5.0)
      << "the filter diverged";
}

// Steps CLOCK_REALTIME by `seconds`; false when not allowed.
bool step_wall_clock(long seconds) {
  timespec t{};
  ::clock_gettime(CLOCK_REALTIME, &t);
  t.tv_sec += seconds;
  return ::clock_settime(CLOCK_REALTIME, &t) == 0;
}

// The wall clock steps an hour forward 10 s into the drive and back 10 s later (an NTP or GNSS
// time fix on a robot that booted without one). What goes out over DDS is stamped in ROS time
// and follows the wall clock; inside, everything runs on CLOCK_MONOTONIC, so the filter, the
// colour/depth pairing and the checkpoint interval do not notice.
TEST_F(OnboardFaults, WallClockStepsAnHourForwardAndBack) {
  if (!hil_required()) GTEST_SKIP() << "steps the wall clock: only inside scripts/hil-qemu's VM";
  const std::string listener = find_program("semap-map-listener", SEMAP_LISTENER_BIN);
  ASSERT_FALSE(listener.empty()) << "semap-map-listener not found";
  // Cyclone on loopback only, without multicast (the content of config/cyclonedds-loopback.xml
  // that matters here).
  ::setenv("CYCLONEDDS_URI",
           "<General><Interfaces><NetworkInterface address=\"127.0.0.1\"/></Interfaces>"
           "<AllowMulticast>false</AllowMulticast></General><Discovery><ParticipantIndex>auto"
           "</ParticipantIndex><Peers><Peer address=\"127.0.0.1\"/></Peers></Discovery>",
           1);
  Child listening({listener, "--domain", "7", "--ns", "clock", "--classes", "8", "--odometry",
                   (dir_ / "odometry.csv").string()},
                  dir_ / "listener.log");
  const double start =
      std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  bool stepped_forward = false, stepped_back = false;
  int code = 0;
  const std::string out = run(
      rig_config("", "",
                 "  save_path: " + (dir_ / "map.smap").string() +
                     "\n  checkpoint_s: 2\ndds:\n  domain: 7\n  namespace: clock\n"),
      [&](Child&) {
        std::this_thread::sleep_for(10s);
        stepped_forward = step_wall_clock(3600);
        std::this_thread::sleep_for(10s);
        stepped_back = step_wall_clock(-3600);
      },
      code);
  listening.stop(5s);
  ASSERT_TRUE(stepped_forward && stepped_back) << "clock_settime refused (needs CAP_SYS_TIME)";
  EXPECT_EQ(code, 0);
  const Summary s = parse_summary(out);
  EXPECT_TRUE(s.initialised);
  ASSERT_TRUE(s.pose_rmse) << "no pose vs truth line";
  EXPECT_LT(*s.pose_rmse, 1.0) << "the filter noticed the wall clock";
  EXPECT_EQ(figure(out, R"(perception +: .* (\d+) unpaired)"), 0.0) << "colour/depth pairing";
  // One checkpoint every 2 s of CLOCK_MONOTONIC: about 15 in the 30 s drive, neither none nor
  // an hour's worth.
  const double checkpoints = figure(out, R"(map checkpoint +: .*, (\d+) checkpoints)");
  EXPECT_GE(checkpoints, 10.0);
  EXPECT_LE(checkpoints, 20.0);

  // The odometry stamps: before the step within the run's first seconds, an hour ahead while
  // the clock was, and back after it.
  std::ifstream csv(dir_ / "odometry.csv");
  std::string line;
  std::getline(csv, line);
  int before = 0, ahead = 0, after = 0, outside = 0;
  bool seen_ahead = false;
  while (std::getline(csv, line)) {
    // The last column: the header's stamp as sent (ROS time).
    const double t = std::stod(line.substr(line.rfind(',') + 1)) - start;
    if (t > 3600.0 - 60.0 && t < 3600.0 + kDriveSeconds + 60.0) {
      ++ahead;
      seen_ahead = true;
    } else if (t > -5.0 && t < kDriveSeconds + 60.0) {
      ++(seen_ahead ? after : before);
    } else {
      ++outside;
    }
  }
  std::printf(
      "odometry stamps: %d before the step, %d an hour ahead, %d after the step back, "
      "%d elsewhere; %g checkpoints\n",
      before, ahead, after, outside, checkpoints);
  EXPECT_GT(before, 0);
  EXPECT_GT(ahead, 0);
  EXPECT_GT(after, 0);
  EXPECT_EQ(outside, 0);
}

}  // namespace
}  // namespace semap::hil
