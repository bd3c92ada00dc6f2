// semap-can on a live vcan0: records the firmware emulator's frames and an error frame as a
// candump -L log, can-utils' canplayer replays that log onto vcan0, and semap-can decoding the
// replay live gives the very samples it decodes from the log file.
#include <linux/can.h>
#include <linux/can/error.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "hil_env.hpp"
#include "semap/drivers/can_socket.hpp"
#include "semap/firmware_bridge/candump_reader.hpp"
#include "semap/sim/emulator.hpp"

namespace semap::hil {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

// The samples of semap-can --json output without their time: what a replay must reproduce.
std::vector<std::string> samples_without_time(const std::string& out) {
  std::vector<std::string> samples;
  std::istringstream in(out);
  std::string line;
  while (std::getline(in, line)) {
    if (line.find("\"class\":\"IMU\"") == std::string::npos) continue;
    samples.push_back(line.substr(line.find("\"seq\"")));
  }
  return samples;
}

TEST(CanToolHil, RecordsALogThatCanplayerReplaysToTheSameSamples) {
  if (!fs::exists("/sys/class/net/vcan0")) SEMAP_HIL_UNAVAILABLE("no vcan0 interface");
  const std::string tool = find_program("semap-can", SEMAP_CAN_BIN);
  const std::string canplayer = find_program("canplayer", SEMAP_CANPLAYER_BIN);
  ASSERT_FALSE(tool.empty());
  ASSERT_FALSE(canplayer.empty());
  const fs::path dir = fs::temp_directory_path() / ("can_tool_hil." + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path log = dir / "drive.log";

  // 1. Record 300 samples (900 classic frames) and a bus-off error frame.
  std::thread recorder([&] {
    const std::string cmd = tool + " --interface vcan0 --record " + log.string() +
                            " --seconds 6 > " + (dir / "record.out").string() + " 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << read_file(dir / "record.out");
  });
  std::this_thread::sleep_for(1s);  // the recorder's socket is bound
  drivers::CanSocket tx("vcan0", false);
  sim::EmulatorConfig ec;
  ec.can_fd = tx.fd();
  sim::Emulator emulator(ec);
  for (int i = 0; i < 300; ++i) {
    common::ImuSample s;
    s.stamp = common::Stamp::now();
    s.gyro = Eigen::Vector3d(0.01 * i, -0.02, 0.3);
    s.accel = Eigen::Vector3d(0.5, -0.25 + 0.001 * i, 9.81);
    emulator.emit(s);
    std::this_thread::sleep_for(2500us);
  }
  can_frame bus_off{};
  bus_off.can_id = CAN_ERR_FLAG | CAN_ERR_BUSOFF;
  bus_off.len = CAN_ERR_DLC;
  ASSERT_EQ(::write(tx.fd(), &bus_off, sizeof bus_off), static_cast<ssize_t>(sizeof bus_off));
  recorder.join();

  std::ifstream file(log);
  firmware_bridge::CandumpReader reader(file, log.string());
  int data = 0;
  int errors = 0;
  while (const auto r = reader.next()) {
    EXPECT_STREQ(r->interface, "vcan0");
    (r->kind == SEMAP_CANDUMP_ERROR ? errors : data)++;
  }
  EXPECT_EQ(reader.error(), "");
  EXPECT_EQ(data, static_cast<int>(emulator.stats().can_frames));
  EXPECT_EQ(errors, 1);

  // 2. Decoded from the file.
  const std::string from_file_cmd =
      tool + " --input " + log.string() + " --json > " + (dir / "file.out").string() + " 2>&1";
  ASSERT_EQ(std::system(from_file_cmd.c_str()), 0) << read_file(dir / "file.out");
  const std::string from_file_out = read_file(dir / "file.out");
  const auto from_file = samples_without_time(from_file_out);
  ASSERT_EQ(from_file.size(), 300u) << from_file_out;
  EXPECT_NE(from_file_out.find("\"state\":\"bus-off\""), std::string::npos) << from_file_out;

  // 3. canplayer replays the log onto vcan0 while semap-can decodes the interface live.
  std::thread live([&] {
    const std::string cmd = tool + " --interface vcan0 --json --count 300 --seconds 20 > " +
                            (dir / "live.out").string() + " 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << read_file(dir / "live.out");
  });
  std::this_thread::sleep_for(1s);
  const std::string play =
      canplayer + " -I " + log.string() + " > " + (dir / "play.out").string() + " 2>&1";
  EXPECT_EQ(std::system(play.c_str()), 0) << read_file(dir / "play.out");
  live.join();
  const auto replayed = samples_without_time(read_file(dir / "live.out"));
  std::printf(
      "semap-can: recorded %d frames + %d error frame, %zu samples from the file, %zu "
      "from canplayer's replay\n",
      data, errors, from_file.size(), replayed.size());
  EXPECT_EQ(replayed, from_file);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace semap::hil
