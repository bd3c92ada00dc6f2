#pragma once

#include <cstdint>
#include <optional>

#include "semap/common/messages.hpp"

namespace semap::estimation {

struct ImuLimits {
  double max_dt_s = 0.1;          // larger gaps are not integrated
  double max_gyro_rad_s = 35.0;   // ~2000 deg/s full scale
  double max_accel_m_s2 = 160.0;  // ~16 g full scale
};

struct ImuCounters {
  std::uint64_t accepted = 0;
  std::uint64_t non_increasing_stamp = 0;  // dt <= 0
  std::uint64_t gap = 0;                   // dt > max_dt (the sample restarts integration)
  std::uint64_t not_finite = 0;
  std::uint64_t out_of_range = 0;
  std::uint64_t rejected() const { return non_increasing_stamp + gap + not_finite + out_of_range; }
};

enum class ImuVerdict : std::uint8_t {
  kAccept,
  kFirst,
  kNonIncreasing,
  kGap,
  kNotFinite,
  kOutOfRange
};

// Checks each IMU sample against the previous accepted one. kAccept comes with the dt to
// integrate; kFirst and kGap mean "accepted as a new time reference, nothing to integrate".
class ImuValidator {
 public:
  explicit ImuValidator(const ImuLimits& limits) : limits_(limits) {}

  ImuVerdict check(const common::ImuSample& sample, double& dt_out);
  const ImuCounters& counters() const { return counters_; }

 private:
  ImuLimits limits_;
  ImuCounters counters_;
  std::optional<common::Stamp> last_;
};

const char* to_string(ImuVerdict verdict);

}  // namespace semap::estimation
