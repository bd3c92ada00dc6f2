// Real receiver captures from gpsd's regression suite (../shared/data/gnss) replayed through
// GnssStreamDecoder and compared with gpsd's own decode of the same bytes (*.chk).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "semap/firmware_bridge/gnss_stream_decoder.hpp"

namespace semap::firmware_bridge {
namespace {

const std::string kDir = std::string(SEMAP_SHARED_DATA_DIR) + "/gnss/";

std::vector<std::uint8_t> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The value after "key": in one flat JSON object, as text without quotes ("" when absent).
std::string json_field(const std::string& line, const std::string& key) {
  const std::string tag = "\"" + key + "\":";
  const std::size_t at = line.find(tag);
  if (at == std::string::npos) return "";
  std::size_t b = at + tag.size();
  if (line[b] == '"') {
    const std::size_t e = line.find('"', b + 1);
    return line.substr(b + 1, e - b - 1);
  }
  std::size_t e = b;
  while (e < line.size() && line[e] != ',' && line[e] != '}') ++e;
  return line.substr(b, e - b);
}

struct GpsdFix {
  std::string time;  // ISO 8601 with milliseconds, as gpsd prints it
  double lat = 0, lon = 0;
  bool has_alt = false;
  double alt_hae = 0;
  int mode = 0;
  double eph = 0, epv = 0;  // 0 when absent
};

double number(const std::string& line, const std::string& key) {
  const std::string v = json_field(line, key);
  return v.empty() ? 0.0 : std::stod(v);
}

// gpsd reports an epoch in several TPV objects as its sentences arrive; the last one with a
// position holds everything it learned. Keyed by time.
std::map<std::string, GpsdFix> gpsd_fixes(const std::string& chk) {
  std::map<std::string, GpsdFix> out;
  std::ifstream in(chk);
  std::string line;
  while (std::getline(in, line)) {
    if (json_field(line, "class") != "TPV" || json_field(line, "lat").empty()) continue;
    GpsdFix f;
    f.time = json_field(line, "time");
    f.lat = std::stod(json_field(line, "lat"));
    f.lon = std::stod(json_field(line, "lon"));
    const std::string alt = json_field(line, "altHAE");
    f.has_alt = !alt.empty();
    if (f.has_alt) f.alt_hae = std::stod(alt);
    f.mode = std::stoi(json_field(line, "mode"));
    f.eph = number(line, "eph");
    f.epv = number(line, "epv");
    out[f.time] = f;
  }
  return out;
}

struct GpsdGst {
  double lat = 0, lon = 0, alt = 0;  // 1-sigma errors, m
};

std::map<std::string, GpsdGst> gpsd_gst(const std::string& chk) {
  std::map<std::string, GpsdGst> out;
  std::ifstream in(chk);
  std::string line;
  while (std::getline(in, line)) {
    if (json_field(line, "class") != "GST") continue;
    out[json_field(line, "time")] = {number(line, "lat"), number(line, "lon"), number(line, "alt")};
  }
  return out;
}

// gpsd's ISO 8601 form of a UTC time in ns: milliseconds, truncated.
std::string iso8601_ms(std::int64_t utc_ns) {
  const std::int64_t ms = utc_ns >= 0 ? utc_ns / 1'000'000 : (utc_ns - 999'999) / 1'000'000;
  const std::time_t s = static_cast<std::time_t>(ms >= 0 ? ms / 1000 : (ms - 999) / 1000);
  std::tm tm{};
  gmtime_r(&s, &tm);
  char buf[96];
  std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900,
                tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec,
                static_cast<int>(ms - static_cast<std::int64_t>(s) * 1000));
  return buf;
}

int gpsd_mode(common::FixMode m) {
  switch (m) {
    case common::FixMode::kNoFix:
      return 1;
    case common::FixMode::k2D:
      return 2;
    default:
      return 3;
  }
}

struct Replay {
  std::vector<common::GnssFix> fixes;
  GnssStreamCounters counters;
};

// Feeds the whole file (gpsd's '#' header included: the framer skips it as text lines) in
// chunks of `chunk` bytes.
Replay replay(const std::string& name, std::size_t chunk, const GnssFixBuilderConfig& config = {}) {
  const std::vector<std::uint8_t> bytes = read_bytes(kDir + name);
  EXPECT_FALSE(bytes.empty()) << kDir + name;
  GnssStreamDecoder decoder(config);
  Replay r;
  for (std::size_t pos = 0; pos < bytes.size(); pos += chunk) {
    const std::size_t n = std::min(chunk, bytes.size() - pos);
    decoder.feed({bytes.data() + pos, n}, common::Stamp(static_cast<std::int64_t>(pos)), r.fixes);
  }
  r.counters = decoder.counters();
  return r;
}

std::string describe(const GnssStreamCounters& c) {
  std::ostringstream s;
  s << "bytes " << c.bytes << " garbage " << c.garbage_bytes << " nmea " << c.nmea_sentences
    << " ubx " << c.ubx_frames << " rtcm3 " << c.rtcm3_frames << " text " << c.text_lines
    << " bad_checksum " << c.bad_checksum << " too_long " << c.too_long << " truncated "
    << c.truncated << " unknown " << c.unknown << " bad_field " << c.bad_field << " fixes "
    << c.fixes;
  return s.str();
}

// Every gpsd fix has one of ours at the same UTC time with the same position, altitude and
// mode, and we have no fix gpsd does not, except at the times in `extra`.
// kGst: the covariance is the GST of the epoch before (GST follows GGA in both captures and
// the robot does not wait for it); kGstSameEpoch: of the same epoch (wait_for_gst).
enum class Accuracy { kGst, kGstSameEpoch, kNavPvt };

void expect_same_fixes_as_gpsd(const std::string& name, const Replay& r, Accuracy accuracy,
                               const std::set<std::string>& extra = {}) {
  const std::map<std::string, GpsdFix> gpsd = gpsd_fixes(kDir + name + ".chk");
  ASSERT_FALSE(gpsd.empty());
  const std::map<std::string, GpsdGst> gsts = gpsd_gst(kDir + name + ".chk");
  std::map<std::string, const common::GnssFix*> ours;
  for (const common::GnssFix& f : r.fixes) {
    ASSERT_TRUE(f.utc_ns.has_value()) << name << ": a fix without receiver time";
    if (f.valid()) ours[iso8601_ms(*f.utc_ns)] = &f;
  }
  std::printf("%s: %zu fixes (%zu valid, distinct times), gpsd %zu; %s\n", name.c_str(),
              r.fixes.size(), ours.size(), gpsd.size(), describe(r.counters).c_str());
  EXPECT_EQ(ours.size(), gpsd.size() + extra.size()) << name;
  for (const auto& [time, f] : ours) {
    EXPECT_TRUE(gpsd.count(time) || extra.count(time)) << name << ": gpsd has no fix at " << time;
  }
  for (const auto& [time, g] : gpsd) {
    const auto it = ours.find(time);
    if (it == ours.end()) {
      ADD_FAILURE() << name << ": no fix at gpsd's " << time;
      continue;
    }
    const common::GnssFix& f = *it->second;
    EXPECT_NEAR(f.latitude_deg, g.lat, 1e-7) << name << " " << time;
    EXPECT_NEAR(f.longitude_deg, g.lon, 1e-7) << name << " " << time;
    if (g.has_alt) {
      EXPECT_NEAR(f.altitude_m, g.alt_hae, 1e-3) << name << " " << time;
    }
    EXPECT_EQ(gpsd_mode(f.mode), g.mode) << name << " " << time;
    const Eigen::Matrix3d& c = f.covariance;
    if (accuracy == Accuracy::kNavPvt) {
      // gpsd's eph / epv are NAV-PVT's hAcc / vAcc.
      EXPECT_NEAR(std::sqrt(c(0, 0) + c(1, 1)), g.eph, 1e-3) << name << " " << time;
      EXPECT_NEAR(std::sqrt(c(2, 2)), g.epv, 1e-3) << name << " " << time;
    } else if (time != gpsd.begin()->first) {
      // 1-sigma latitude, longitude and altitude errors of GST. The first epoch's fix goes out
      // before any GST, with the HDOP-based covariance.
      auto gst = gsts.find(time);
      ASSERT_NE(gst, gsts.end()) << name << " " << time;
      if (accuracy == Accuracy::kGst) --gst;
      EXPECT_NEAR(std::sqrt(c(0, 0)), gst->second.lon, 1e-9) << name << " " << time;
      EXPECT_NEAR(std::sqrt(c(1, 1)), gst->second.lat, 1e-9) << name << " " << time;
      EXPECT_NEAR(std::sqrt(c(2, 2)), gst->second.alt, 1e-9) << name << " " << time;
    }
  }
}

// The same fixes whatever the read size, down to one byte at a time.
void expect_chunking_does_not_matter(const std::string& name, const Replay& reference) {
  for (const std::size_t chunk : {std::size_t{1}, std::size_t{7}, std::size_t{1} << 20}) {
    const Replay r = replay(name, chunk);
    ASSERT_EQ(r.fixes.size(), reference.fixes.size()) << name << " chunk " << chunk;
    for (std::size_t i = 0; i < r.fixes.size(); ++i) {
      EXPECT_EQ(r.fixes[i].utc_ns, reference.fixes[i].utc_ns);
      EXPECT_EQ(r.fixes[i].latitude_deg, reference.fixes[i].latitude_deg);
    }
    EXPECT_EQ(describe(r.counters), describe(reference.counters)) << name << " chunk " << chunk;
  }
}

// Errors of any kind: bad checksums, overlong, truncated, bad fields.
std::uint64_t errors(const GnssStreamCounters& c) {
  return c.bad_checksum + c.too_long + c.truncated + c.bad_field;
}

// Every sentence starts with "$$", BeiDou satellites come on the old BD talker, and one GSV has
// a bad checksum (the capture's own note).
TEST(GnssCaptures, StTeseoDoubledDollarAndBdTalker) {
  const std::string name = "st-teseo-liv4f.log";
  const Replay r = replay(name, 61);
  expect_same_fixes_as_gpsd(name, r, Accuracy::kGst);
  GnssFixBuilderConfig wait;
  wait.wait_for_gst = true;
  expect_same_fixes_as_gpsd(name, replay(name, 61, wait), Accuracy::kGstSameEpoch);
  EXPECT_EQ(r.fixes.size(), 12u);
  EXPECT_EQ(r.counters.garbage_bytes, 0u) << "the doubled $ is not garbage";
  EXPECT_EQ(r.counters.text_lines, 8u);       // the '#' header
  EXPECT_EQ(r.counters.nmea_sentences, 48u);  // GGA, RMC, GST, VTG x 12
  EXPECT_EQ(r.counters.bad_checksum, 1u);
  EXPECT_EQ(errors(r.counters), 1u);
  EXPECT_EQ(r.counters.rtcm3_frames + r.counters.ubx_frames, 0u);
  expect_chunking_does_not_matter(name, r);
}

// GN/GP/GL/GA/GB talkers, GGA with RMC, GST and VTG and many sentences we do not decode; lines
// end in LF only.
TEST(GnssCaptures, UbloxM9nMultiConstellationNmea) {
  const std::string name = "ublox-neo-m9n-nmea.log";
  const Replay r = replay(name, 512);
  expect_same_fixes_as_gpsd(name, r, Accuracy::kGst);
  GnssFixBuilderConfig wait;
  wait.wait_for_gst = true;
  expect_same_fixes_as_gpsd(name, replay(name, 512, wait), Accuracy::kGstSameEpoch);
  EXPECT_EQ(r.fixes.size(), 61u);
  EXPECT_EQ(r.counters.garbage_bytes, 0u);
  EXPECT_EQ(r.counters.text_lines, 11u);
  EXPECT_EQ(r.counters.nmea_sentences, 4u * 61u);
  EXPECT_EQ(errors(r.counters), 0u);
  for (const common::GnssFix& f : r.fixes) EXPECT_EQ(f.mode, common::FixMode::kDgps);  // GGA 2
  expect_chunking_does_not_matter(name, r);
}

// UBX only: NAV-PVT among eight other NAV and MON messages (NAV-SAT of 284 bytes). The capture
// ends with a cut NAV-EOE and a LF: the only garbage byte.
TEST(GnssCaptures, NavisysUbxNavPvt) {
  const std::string name = "navisys-gr8013.log";
  const Replay r = replay(name, 100);
  expect_same_fixes_as_gpsd(name, r, Accuracy::kNavPvt);
  EXPECT_EQ(r.fixes.size(), 35u);
  EXPECT_EQ(r.counters.ubx_frames, 35u);
  EXPECT_EQ(r.counters.text_lines, 13u);
  EXPECT_EQ(r.counters.garbage_bytes, 1u);
  EXPECT_EQ(errors(r.counters), 0u);
  for (const common::GnssFix& f : r.fixes) {
    EXPECT_EQ(f.mode, common::FixMode::kDgps);  // diffSoln set; gpsd's status 2 (DGPS) too
    ASSERT_TRUE(f.velocity_enu.has_value());
  }
  expect_chunking_does_not_matter(name, r);
}

// UBX after three gpsd JSON lines. gpsd reports nothing for the first epoch (18:18:55.500): it
// learns where a u-blox cycle ends from that first cycle. We decode its NAV-PVT as well.
TEST(GnssCaptures, UbloxM8pUbxAfterJsonLines) {
  const std::string name = "ublox-neo-m8p.log";
  const Replay r = replay(name, 512);
  expect_same_fixes_as_gpsd(name, r, Accuracy::kNavPvt, {"2021-06-10T18:18:55.500Z"});
  EXPECT_EQ(r.fixes.size(), 59u);
  EXPECT_EQ(r.counters.text_lines, 9u + 3u);  // '#' header and the JSON lines
  EXPECT_EQ(r.counters.garbage_bytes, 0u);
  EXPECT_EQ(errors(r.counters), 0u);
  expect_chunking_does_not_matter(name, r);
}

}  // namespace
}  // namespace semap::firmware_bridge
