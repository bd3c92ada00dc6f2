#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "semap/common/stamp.hpp"
#include "semap/estimation/drive_data.hpp"

namespace semap::estimation {

// One line of a KITTI raw OXTS file (oxts/data/NNNNNNNNNN.txt, 30 values, see the KITTI
// devkit dataformat.txt). Body frame: x forward, y left, z up.
struct OxtsRecord {
  common::Stamp stamp;
  double latitude_deg = 0.0;
  double longitude_deg = 0.0;
  double altitude_m = 0.0;
  double roll = 0.0;                                       // rad
  double pitch = 0.0;                                      // rad
  double yaw = 0.0;                                        // rad, 0 = east, counter-clockwise
  Eigen::Vector3d velocity_enu = Eigen::Vector3d::Zero();  // (ve, vn, vu)
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();         // (ax, ay, az), includes gravity
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();          // (wx, wy, wz)
  double position_accuracy_m = 0.0;
  int satellites = 0;
};

inline constexpr int kOxtsFields = 30;

// Parses the 30 values of one OXTS line (stamp left unset). On failure returns nothing and
// sets `error` to the field at fault.
std::optional<OxtsRecord> parse_oxts_line(std::string_view line, std::string& error);

// "2011-09-26 13:02:25.964389445" (UTC) to nanoseconds since the epoch. Years outside
// kMinKittiYear..kMaxKittiYear are refused (nanoseconds since 1970 end in 2262 in an int64).
// On failure returns nothing and sets `error` to the field at fault ("year 7182 outside ...").
inline constexpr int kMinKittiYear = 1970;
inline constexpr int kMaxKittiYear = 2262;
std::optional<common::Stamp> parse_kitti_timestamp(std::string_view text, std::string& error);
std::optional<common::Stamp> parse_kitti_timestamp(std::string_view text);

struct OxtsData {
  std::vector<OxtsRecord> records;
  std::vector<std::string> errors;  // "file:line: what" for each skipped record
};

// Reads <dir>/timestamps.txt and <dir>/data/*.txt (one record per file, sorted by name).
// Bad records are skipped and reported in `errors`; a missing folder throws.
OxtsData read_oxts_folder(const std::filesystem::path& dir);

// Which sigma the simulated GNSS fixes get: one configured value for every fix, or each
// packet's own pos_accuracy (the OXTS unit's 1-sigma estimate, floored at kMinPacketSigmaM so a
// packet reporting 0 still gives an invertible covariance).
enum class OxtsGnssNoise : std::uint8_t { kFixedSigma, kPacketAccuracy };
inline constexpr double kMinPacketSigmaM = 0.01;

// Turns OXTS records into estimator inputs: IMU samples from the rates and accelerations,
// GNSS fixes from the positions plus seeded white noise (gnss_sigma_m per axis, or the packet's
// pos_accuracy with kPacketAccuracy) and that sigma as covariance, and the OXTS solution as
// truth (biases unknown, left zero), anchored at the first record.
DriveData oxts_to_inputs(const OxtsData& data, double gnss_sigma_m, std::uint64_t seed,
                         OxtsGnssNoise noise = OxtsGnssNoise::kFixedSigma);

}  // namespace semap::estimation
