#include "semap/estimation/oxts_reader.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <ctime>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>

#include "semap/estimation/so3.hpp"

namespace semap::estimation {

namespace {

constexpr std::array<const char*, kOxtsFields> kFieldNames = {
    "lat",          "lon",     "alt",     "roll",    "pitch",   "yaw",    "vn", "ve",
    "vf",           "vl",      "vu",      "ax",      "ay",      "az",     "af", "al",
    "au",           "wx",      "wy",      "wz",      "wf",      "wl",     "wu", "pos_accuracy",
    "vel_accuracy", "navstat", "numsats", "posmode", "velmode", "orimode"};

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

}  // namespace

std::optional<OxtsRecord> parse_oxts_line(std::string_view line, std::string& error) {
  std::array<double, kOxtsFields> v{};
  std::size_t pos = 0;
  int field = 0;
  while (true) {
    while (pos < line.size() && is_space(line[pos])) ++pos;
    if (pos >= line.size()) break;
    if (field >= kOxtsFields) {
      error = "more than 30 values";
      return std::nullopt;
    }
    std::size_t end = pos;
    while (end < line.size() && !is_space(line[end])) ++end;
    double value = 0.0;
    const auto [ptr, ec] = std::from_chars(line.data() + pos, line.data() + end, value);
    if (ec != std::errc() || ptr != line.data() + end || !std::isfinite(value)) {
      error = "field " + std::to_string(field + 1) + " (" + kFieldNames[field] +
              "): not a finite number: '" +
              std::string(line.substr(pos, std::min<std::size_t>(end - pos, 32))) + "'";
      return std::nullopt;
    }
    v[field++] = value;
    pos = end;
  }
  if (field != kOxtsFields) {
    error = "expected 30 values, got " + std::to_string(field);
    return std::nullopt;
  }
  if (std::abs(v[0]) > 90.0 || std::abs(v[1]) > 180.0) {
    error = "field 1/2 (lat/lon): out of range";
    return std::nullopt;
  }
  // A satellite count becomes an int: a count no receiver reports (beyond int, found by
  // oxts_fuzz as undefined behaviour) is refused.
  if (v[26] < 0.0 || v[26] > 1000.0) {
    error = "field 27 (" + std::string(kFieldNames[26]) + "): out of range";
    return std::nullopt;
  }
  OxtsRecord r;
  r.latitude_deg = v[0];
  r.longitude_deg = v[1];
  r.altitude_m = v[2];
  r.roll = v[3];
  r.pitch = v[4];
  r.yaw = v[5];
  r.velocity_enu = {v[7], v[6], v[10]};
  r.accel = {v[11], v[12], v[13]};
  r.gyro = {v[17], v[18], v[19]};
  r.position_accuracy_m = v[23];
  r.satellites = static_cast<int>(v[26]);
  return r;
}

std::optional<common::Stamp> parse_kitti_timestamp(std::string_view text, std::string& error) {
  error.clear();
  while (!text.empty() && is_space(text.back())) text.remove_suffix(1);
  // YYYY-MM-DD HH:MM:SS[.fraction]
  if (text.size() < 19 || text[4] != '-' || text[7] != '-' || text[10] != ' ' || text[13] != ':' ||
      text[16] != ':') {
    error = "not 'YYYY-MM-DD HH:MM:SS[.fraction]'";
    return std::nullopt;
  }
  struct Field {
    const char* name;
    std::size_t at, len;
    int min, max;
    int value = 0;
  };
  // The year range keeps nanoseconds since 1970 within int64 (which ends in April 2262).
  std::array<Field, 6> fields = {{{"year", 0, 4, kMinKittiYear, kMaxKittiYear},
                                  {"month", 5, 2, 1, 12},
                                  {"day", 8, 2, 1, 31},
                                  {"hour", 11, 2, 0, 23},
                                  {"minute", 14, 2, 0, 59},
                                  {"second", 17, 2, 0, 60}}};
  for (Field& f : fields) {
    const char* begin = text.data() + f.at;
    const char* end = begin + f.len;
    const auto [ptr, ec] = std::from_chars(begin, end, f.value);
    if (ec != std::errc() || ptr != end ||
        !std::all_of(begin, end, [](char c) { return c >= '0' && c <= '9'; })) {
      error = std::string(f.name) + " '" + std::string(begin, end) + "' is not a number";
      return std::nullopt;
    }
    if (f.value < f.min || f.value > f.max) {
      error = std::string(f.name) + " " + std::to_string(f.value) + " outside " +
              std::to_string(f.min) + ".." + std::to_string(f.max);
      return std::nullopt;
    }
  }
  const int year = fields[0].value, month = fields[1].value, day = fields[2].value;
  const bool leap = (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
  constexpr std::array<int, 12> kDays = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  const int month_days = kDays[static_cast<std::size_t>(month - 1)] + (month == 2 && leap ? 1 : 0);
  if (day > month_days) {
    error = "day " + std::to_string(day) + " outside 1.." + std::to_string(month_days) +
            " for month " + std::to_string(month);
    return std::nullopt;
  }
  std::int64_t nanos = 0;
  if (text.size() > 19) {
    if (text[19] != '.' || text.size() > 29 || text.size() == 20) {
      error = "fraction must be '.' and 1 to 9 digits";
      return std::nullopt;
    }
    std::int64_t scale = 100000000;
    for (std::size_t i = 20; i < text.size(); ++i) {
      if (text[i] < '0' || text[i] > '9') {
        error = "fraction has a non-digit";
        return std::nullopt;
      }
      nanos += (text[i] - '0') * scale;
      scale /= 10;
    }
  }
  std::tm tm{};
  tm.tm_year = year - 1900;
  tm.tm_mon = month - 1;
  tm.tm_mday = day;
  tm.tm_hour = fields[3].value;
  tm.tm_min = fields[4].value;
  tm.tm_sec = fields[5].value;
  const std::int64_t seconds = static_cast<std::int64_t>(timegm(&tm));
  constexpr std::int64_t kNs = 1'000'000'000;
  // Within the year range this only trips in the last months of 2262.
  if (seconds > (std::numeric_limits<std::int64_t>::max() - nanos) / kNs) {
    error = "time beyond 2262-04-11 (nanoseconds since 1970 overflow int64)";
    return std::nullopt;
  }
  return common::Stamp(seconds * kNs + nanos);
}

std::optional<common::Stamp> parse_kitti_timestamp(std::string_view text) {
  std::string error;
  return parse_kitti_timestamp(text, error);
}

OxtsData read_oxts_folder(const std::filesystem::path& dir) {
  const auto stamps_path = dir / "timestamps.txt";
  const auto data_dir = dir / "data";
  std::ifstream stamps_in(stamps_path);
  if (!stamps_in) throw std::runtime_error(stamps_path.string() + ": cannot open");
  if (!std::filesystem::is_directory(data_dir)) {
    throw std::runtime_error(data_dir.string() + ": not a directory");
  }
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(data_dir)) {
    if (entry.is_regular_file() && entry.path().extension() == ".txt")
      files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());

  OxtsData out;
  std::string line;
  std::size_t line_no = 0;
  for (const auto& file : files) {
    ++line_no;
    if (!std::getline(stamps_in, line)) {
      out.errors.push_back(stamps_path.string() + ":" + std::to_string(line_no) +
                           ": missing timestamp for " + file.filename().string());
      break;
    }
    std::string stamp_error;
    const auto stamp = parse_kitti_timestamp(line, stamp_error);
    if (!stamp) {
      out.errors.push_back(stamps_path.string() + ":" + std::to_string(line_no) +
                           ": bad timestamp '" + line.substr(0, 40) + "': " + stamp_error);
      continue;
    }
    std::ifstream in(file);
    std::string text;
    std::getline(in, text);
    std::string error;
    auto record = parse_oxts_line(text, error);
    if (!record) {
      out.errors.push_back(file.string() + ":1: " + error);
      continue;
    }
    if (!out.records.empty() && *stamp <= out.records.back().stamp) {
      out.errors.push_back(stamps_path.string() + ":" + std::to_string(line_no) +
                           ": timestamp not increasing");
      continue;
    }
    record->stamp = *stamp;
    out.records.push_back(*record);
  }
  return out;
}

DriveData oxts_to_inputs(const OxtsData& data, double gnss_sigma_m, std::uint64_t seed,
                         OxtsGnssNoise noise) {
  DriveData out;
  if (data.records.empty()) return out;
  const auto& first = data.records.front();
  out.origin = Geodetic{first.latitude_deg, first.longitude_deg, first.altitude_m};
  const LocalEnu enu(out.origin);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uint32_t sequence = 0;
  for (const auto& r : data.records) {
    TruthSample truth;
    truth.stamp = r.stamp;
    truth.state.rotation = rotation_from_rpy(r.roll, r.pitch, r.yaw);
    truth.state.velocity = r.velocity_enu;
    truth.state.position = enu.to_enu({r.latitude_deg, r.longitude_deg, r.altitude_m});
    out.truth.push_back(truth);

    common::ImuSample imu;
    imu.stamp = r.stamp;
    imu.sequence = sequence++;
    imu.gyro = r.gyro;
    imu.accel = r.accel;
    out.imu.push_back(imu);

    const double sigma = noise == OxtsGnssNoise::kPacketAccuracy
                             ? std::max(r.position_accuracy_m, kMinPacketSigmaM)
                             : gnss_sigma_m;
    const Eigen::Vector3d noisy =
        truth.state.position + sigma * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    const Geodetic g = enu.to_geodetic(noisy);
    common::GnssFix fix;
    fix.stamp = r.stamp;
    fix.latitude_deg = g.latitude_deg;
    fix.longitude_deg = g.longitude_deg;
    fix.altitude_m = g.altitude_m;
    fix.covariance = Eigen::Matrix3d::Identity() * sigma * sigma;
    fix.quality = common::FixQuality::kGps;
    fix.mode = common::FixMode::k3D;
    fix.satellites = static_cast<std::uint8_t>(std::clamp(r.satellites, 0, 255));
    out.gnss.push_back(fix);
  }
  return out;
}

}  // namespace semap::estimation
