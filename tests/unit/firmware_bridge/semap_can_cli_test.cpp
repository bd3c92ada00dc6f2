// Runs the real semap-can executable on candump -L logs made with the firmware codecs: both
// IMU profiles, the profile taken from an onboard config, error frames, and damaged logs.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "semap/firmware_bridge/can_imu.h"
#include "semap/firmware_bridge/candump_reader.hpp"
#include "semap/firmware_bridge/j1939.h"
#include "support/cli_run.hpp"

namespace semap::firmware_bridge {
namespace {

using test_support::CliResult;

CliResult run(const std::string& args) { return test_support::run_cli(SEMAP_CAN_EXE, args); }

std::vector<std::string> lines_with(const std::string& text, const std::string& tag) {
  std::vector<std::string> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.find(tag) != std::string::npos) out.push_back(line);
  }
  return out;
}

std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() / (name + "." + std::to_string(::getpid())))
      .string();
}

std::string line_of(const SemapCanFrame& frame, std::uint64_t us, std::uint8_t kind) {
  SemapCandumpRecord r{};
  r.seconds = 1700000000u + us / 1'000'000u;
  r.microseconds = static_cast<std::uint32_t>(us % 1'000'000u);
  std::strcpy(r.interface, "can0");
  r.kind = kind;
  r.frame = frame;
  return format_candump_line(r);
}

// `n` samples at 400 Hz: yaw rate 0.1 rad/s, gravity on z, as either profile's frames.
std::string imu_log(bool j1939, int n, std::uint8_t priority = 3) {
  std::string log;
  for (int i = 0; i < n; ++i) {
    const std::uint64_t us = static_cast<std::uint64_t>(i) * 2500u;
    if (j1939) {
      SemapJ1939AngularRate rate{};
      rate.yaw_dps = 0.1 * 180.0 / 3.14159265358979;
      rate.latency_ms = -1.0;
      SemapJ1939Acceleration acc{};
      acc.vertical_mps2 = 9.81;
      SemapCanFrame f;
      semap_j1939_encode_angular_rate(&rate, priority, 0x80, &f);
      log += line_of(f, us, SEMAP_CANDUMP_DATA);
      semap_j1939_encode_acceleration(&acc, priority, 0x80, &f);
      log += line_of(f, us + 100, SEMAP_CANDUMP_DATA);
    } else {
      const double gyro[3] = {0.0, 0.0, 0.1};
      const double accel[3] = {0.0, 0.0, 9.81};
      SemapImuRaw raw;
      semap_can_imu_quantize(gyro, accel, static_cast<std::uint32_t>(us),
                             static_cast<std::uint8_t>(i), 0, &raw);
      SemapCanFrame frames[SEMAP_CAN_IMU_FRAMES_PER_SAMPLE];
      semap_can_imu_encode(&raw, SEMAP_CAN_IMU_DEFAULT_BASE_ID, frames);
      for (unsigned k = 0; k < SEMAP_CAN_IMU_FRAMES_PER_SAMPLE; ++k) {
        log += line_of(frames[k], us + 100u * k, SEMAP_CANDUMP_DATA);
      }
    }
  }
  return log;
}

std::string write_file(const std::string& name, const std::string& text) {
  const std::string path = temp_path(name);
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

std::string counter(const std::string& out, const std::string& name) {
  const std::string tag = " " + name + "=";
  const std::size_t at = out.find(tag);
  if (at == std::string::npos) return "";
  const std::size_t b = at + tag.size();
  return out.substr(b, out.find_first_of(" \n", b) - b);
}

TEST(SemapCanCli, DecodesBothProfilesFromACandumpLog) {
  const std::string semap = write_file("semap.log", imu_log(false, 40));
  const CliResult a = run("--input " + semap);
  EXPECT_EQ(a.status, 0) << a.out;
  const auto samples = lines_with(a.out, " seq ");
  ASSERT_EQ(samples.size(), 40u) << a.out;
  EXPECT_EQ(samples.front().rfind("1700000000.000200 seq 0 gyro", 0), 0u) << samples.front();
  EXPECT_NE(samples.back().find("rad/s accel 0.0000 0.0000 9.8100 m/s^2"), std::string::npos)
      << samples.back();
  EXPECT_EQ(counter(a.out, "samples"), "40");
  EXPECT_EQ(counter(a.out, "crc_errors"), "0");

  // The same J1939 log at priority 6, through the profile of an onboard config.
  const std::string j1939 = write_file("j1939.log", imu_log(true, 25, 6));
  const std::string config =
      write_file("robot.yaml", "imu: { interface: can0, profile: j1939, j1939_source: 128 }\n");
  const CliResult b = run("--input " + j1939 + " --config " + config + " --json");
  EXPECT_EQ(b.status, 0) << b.out;
  const auto json = lines_with(b.out, "\"class\":\"IMU\"");
  ASSERT_EQ(json.size(), 25u) << b.out;
  EXPECT_NE(json[3].find("\"seq\":3,"), std::string::npos) << json[3];
  EXPECT_NE(json[3].find(",9.8100]}"), std::string::npos) << json[3];
  EXPECT_NE(b.out.find("\"samples\":25"), std::string::npos) << b.out;
  // The flag overrides the config: another source address takes none of these frames.
  const CliResult c = run("--input " + j1939 + " --config " + config + " --j1939-source 7");
  EXPECT_EQ(c.status, 0) << c.out;
  EXPECT_EQ(counter(c.out, "samples"), "0");
  EXPECT_EQ(counter(c.out, "unknown"), "50");
  // The wrong profile decodes nothing and says so in its counters.
  const CliResult d = run("--input " + j1939 + " --profile semap");
  EXPECT_EQ(counter(d.out, "samples"), "0");
  EXPECT_EQ(counter(d.out, "unknown"), "50");
  const CliResult bad = run("--input " + j1939 + " --j1939-source 254");
  EXPECT_NE(bad.status, 0);
  EXPECT_NE(bad.out.find("j1939_source"), std::string::npos) << bad.out;
  for (const auto& p : {semap, j1939, config}) std::filesystem::remove(p);
}

TEST(SemapCanCli, ReportsBusEventsFromErrorFrames) {
  SemapCanFrame busoff{};
  busoff.id = 0x40;  // CAN_ERR_BUSOFF
  busoff.len = 8;
  SemapCanFrame restarted{};
  restarted.id = 0x100;  // CAN_ERR_RESTARTED
  restarted.len = 8;
  SemapCanFrame passive{};
  passive.id = 0x04;  // CAN_ERR_CRTL
  passive.len = 8;
  passive.data[1] = 0x20;  // CAN_ERR_CRTL_TX_PASSIVE
  SemapCanFrame no_ack{};
  no_ack.id = 0x20;  // CAN_ERR_ACK: a bus error, no state change
  no_ack.len = 8;
  const std::string log = imu_log(false, 4) + line_of(passive, 20000, SEMAP_CANDUMP_ERROR) +
                          line_of(no_ack, 25000, SEMAP_CANDUMP_ERROR) +
                          line_of(busoff, 30000, SEMAP_CANDUMP_ERROR) +
                          line_of(restarted, 40000, SEMAP_CANDUMP_ERROR);
  const std::string path = write_file("errors.log", log);
  const CliResult r = run("--input " + path);
  EXPECT_EQ(r.status, 0) << r.out;
  const auto events = lines_with(r.out, " bus ");
  ASSERT_EQ(events.size(), 3u) << r.out;
  EXPECT_EQ(events[0], "1700000000.020000 bus error-passive");
  EXPECT_EQ(events[1], "1700000000.030000 bus bus-off");
  EXPECT_EQ(events[2], "1700000000.040000 bus error-active (restarted)");
  EXPECT_EQ(counter(r.out, "error_frames"), "4");
  EXPECT_EQ(counter(r.out, "bus_errors"), "1");
  EXPECT_EQ(counter(r.out, "bus_off"), "1");
  EXPECT_EQ(counter(r.out, "samples"), "4");
  std::filesystem::remove(path);
}

TEST(SemapCanCli, DamagedLogsDecodeUpToTheDamageNamingTheLine) {
  const std::string log = imu_log(false, 10);  // 30 lines
  // Cut inside line 17: samples 0..4 (lines 1..15) are whole.
  std::size_t cut = 0;
  for (int i = 0; i < 16; ++i) cut = log.find('\n', cut) + 1;
  const std::string truncated = write_file("truncated.log", log.substr(0, cut + 20));
  const CliResult t = run("--input " + truncated);
  EXPECT_EQ(t.status, 1) << t.out;
  EXPECT_EQ(lines_with(t.out, " seq ").size(), 5u) << t.out;
  EXPECT_NE(t.out.find(truncated + ":17: line: truncated"), std::string::npos) << t.out;
  EXPECT_EQ(counter(t.out, "samples"), "5");

  // A corrupt byte in line 8's data: samples 0 and 1 come out, the error names line 8.
  std::string corrupt = log;
  std::size_t at = 0;
  for (int i = 0; i < 7; ++i) at = corrupt.find('\n', at) + 1;
  corrupt[corrupt.find('#', at) + 3] = 'Z';
  const std::string damaged = write_file("corrupt.log", corrupt);
  const CliResult c = run("--input " + damaged);
  EXPECT_EQ(c.status, 1);
  EXPECT_EQ(lines_with(c.out, " seq ").size(), 2u) << c.out;
  EXPECT_NE(c.out.find(damaged + ":8: data: bad_field"), std::string::npos) << c.out;

  // Not a log at all.
  const std::string binary = write_file("binary.log", std::string("\x00\x01\x02\n", 4));
  const CliResult b = run("--input " + binary);
  EXPECT_EQ(b.status, 1);
  EXPECT_NE(b.out.find(binary + ":1: timestamp: bad_field"), std::string::npos) << b.out;
  for (const auto& p : {truncated, damaged, binary}) std::filesystem::remove(p);
}

}  // namespace
}  // namespace semap::firmware_bridge
