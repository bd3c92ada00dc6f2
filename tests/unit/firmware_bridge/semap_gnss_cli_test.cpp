// Runs the real semap-gnss executable on the shared gpsd captures, from a file and through a
// pty as a serial device.
#include <gtest/gtest.h>
#include <pty.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "support/cli_run.hpp"

namespace {

const std::string kDir = std::string(SEMAP_SHARED_DATA_DIR) + "/gnss/";

using semap::test_support::CliResult;

CliResult run(const std::string& args) {
  return semap::test_support::run_cli(SEMAP_GNSS_EXE, args);
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) out.push_back(line);
  return out;
}

std::string field(const std::string& line, const std::string& key) {
  const std::string tag = "\"" + key + "\":";
  const std::size_t at = line.find(tag);
  if (at == std::string::npos) return "";
  std::size_t b = at + tag.size();
  if (line[b] == '"') return line.substr(b + 1, line.find('"', b + 1) - b - 1);
  std::size_t e = b;
  int depth = 0;
  while (e < line.size() && (depth > 0 || (line[e] != ',' && line[e] != '}'))) {
    depth += line[e] == '[' ? 1 : line[e] == ']' ? -1 : 0;
    ++e;
  }
  return line.substr(b, e - b);
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() / (name + "." + std::to_string(::getpid())))
      .string();
}

// gpsd's last TPV with a position per time, as lat/lon text.
std::map<std::string, std::pair<double, double>> gpsd_positions(const std::string& chk) {
  std::map<std::string, std::pair<double, double>> out;
  std::ifstream in(chk);
  std::string line;
  while (std::getline(in, line)) {
    if (field(line, "class") != "TPV" || field(line, "lat").empty()) continue;
    out[field(line, "time")] = {std::stod(field(line, "lat")), std::stod(field(line, "lon"))};
  }
  return out;
}

TEST(SemapGnssCli, JsonPerFixMatchesGpsdAndEndsWithEveryCounter) {
  const std::string capture = kDir + "ublox-neo-m8p.log";
  const CliResult r = run("--input " + capture + " --json");
  ASSERT_EQ(r.status, 0) << r.out;
  const std::vector<std::string> out = lines(r.out);
  ASSERT_EQ(out.size(), 59u + 1u) << r.out;
  const auto gpsd = gpsd_positions(capture + ".chk");
  std::size_t matched = 0;
  for (std::size_t i = 0; i + 1 < out.size(); ++i) {
    const std::string& fix = out[i];
    ASSERT_EQ(field(fix, "class"), "FIX") << fix;
    for (const char* key : {"time", "lat", "lon", "alt_hae", "mode", "sats", "h_acc", "v_acc",
                            "vel_enu", "heading"}) {
      EXPECT_FALSE(field(fix, key).empty()) << key << " missing: " << fix;
    }
    EXPECT_EQ(field(fix, "mode"), "3d");
    EXPECT_EQ(field(fix, "vel_enu").front(), '[');
    EXPECT_EQ(field(fix, "heading"), "null");  // one antenna
    const auto it = gpsd.find(field(fix, "time"));
    if (it == gpsd.end()) continue;  // the first epoch, which gpsd does not report
    ++matched;
    EXPECT_NEAR(std::stod(field(fix, "lat")), it->second.first, 1e-7) << fix;
    EXPECT_NEAR(std::stod(field(fix, "lon")), it->second.second, 1e-7) << fix;
  }
  EXPECT_EQ(matched, gpsd.size());
  EXPECT_EQ(field(out[0], "time"), "2021-06-10T18:18:55.500Z");
  EXPECT_EQ(field(out[0], "h_acc"), "2.517");
  const std::string& counters = out.back();
  EXPECT_EQ(field(counters, "class"), "COUNTERS");
  EXPECT_EQ(field(counters, "fixes"), "59");
  EXPECT_EQ(field(counters, "bytes"), std::to_string(std::filesystem::file_size(capture)));
  EXPECT_EQ(field(counters, "text_lines"), "12");
  for (const char* key : {"garbage_bytes", "nmea_sentences", "ubx_frames", "rtcm3_frames",
                          "bad_checksum", "too_long", "truncated", "unknown", "bad_field"}) {
    EXPECT_FALSE(field(counters, key).empty()) << key;
  }
}

TEST(SemapGnssCli, TextLinesAndARecordingThatIsTheInput) {
  const std::string capture = kDir + "st-teseo-liv4f.log";
  const std::string recording = temp_path("semap_gnss_record");
  const CliResult r = run("--input " + capture + " --record " + recording);
  ASSERT_EQ(r.status, 0) << r.out;
  const std::vector<std::string> out = lines(r.out);
  ASSERT_EQ(out.size(), 12u + 1u) << r.out;
  EXPECT_EQ(out[0].rfind("2025-03-21T13:58:06.000Z 3d", 0), 0u) << out[0];
  EXPECT_NE(out[0].find("lat 47.383414000 lon 0.764691667"), std::string::npos) << out[0];
  EXPECT_NE(out.back().find("bad_checksum=1"), std::string::npos) << out.back();
  EXPECT_EQ(read_file(recording), read_file(capture));
  // Replaying the recording gives the same output.
  EXPECT_EQ(run("--input " + recording).out, r.out);
  std::filesystem::remove(recording);
}

TEST(SemapGnssCli, ReadsASerialDeviceUntilCountAndRecordsIt) {
  int master = -1;
  int slave = -1;
  char name[128] = {};
  ASSERT_EQ(::openpty(&master, &slave, name, nullptr, nullptr), 0);
  const std::string capture = read_file(kDir + "ublox-neo-m9n-nmea.log");
  const std::string recording = temp_path("semap_gnss_device");
  std::atomic<bool> done{false};
  // The tool flushes the port when it opens it: keep writing the capture until it has enough.
  std::thread writer([&] {
    while (!done) {
      for (std::size_t pos = 0; pos < capture.size() && !done; pos += 512) {
        const std::size_t n = std::min<std::size_t>(512, capture.size() - pos);
        if (::write(master, capture.data() + pos, n) < 0) return;
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
      }
    }
  });
  const CliResult r = run(std::string("--device ") + name + " --baud 9600 --count 3 --seconds 30 " +
                          "--json --record " + recording);
  done = true;
  writer.join();
  ::close(slave);
  ::close(master);
  ASSERT_EQ(r.status, 0) << r.out;
  const std::vector<std::string> out = lines(r.out);
  ASSERT_EQ(out.size(), 3u + 1u) << r.out;
  // Joining mid-stream, a GGA before the first RMC has no date yet: its time is null. Once an
  // RMC was read (at the latest by the third fix, one epoch later) every time is dated.
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(field(out[i], "mode"), "dgps") << out[i];
    const std::string time = field(out[i], "time");
    if (i < 2 && time == "null") continue;
    EXPECT_EQ(time.rfind("2020-07-11T22:", 0), 0u) << out[i];
  }
  EXPECT_EQ(field(out.back(), "bytes"), std::to_string(std::filesystem::file_size(recording)));
  std::filesystem::remove(recording);
}

TEST(SemapGnssCli, RejectsMissingOrConflictingSources) {
  EXPECT_EQ(run("").status, 2);
  EXPECT_NE(run("--input " + kDir + "ublox-neo-m8p.log --device /dev/null").status, 0);
  EXPECT_NE(run("--device /nonexistent/tty").status, 0);
}

}  // namespace
