#include "semap/estimation/imu_validator.hpp"

namespace semap::estimation {

ImuVerdict ImuValidator::check(const common::ImuSample& sample, double& dt_out) {
  dt_out = 0.0;
  if (!sample.gyro.allFinite() || !sample.accel.allFinite()) {
    ++counters_.not_finite;
    return ImuVerdict::kNotFinite;
  }
  if (sample.gyro.cwiseAbs().maxCoeff() > limits_.max_gyro_rad_s ||
      sample.accel.cwiseAbs().maxCoeff() > limits_.max_accel_m_s2) {
    ++counters_.out_of_range;
    return ImuVerdict::kOutOfRange;
  }
  if (!last_) {
    last_ = sample.stamp;
    ++counters_.accepted;
    return ImuVerdict::kFirst;
  }
  const double dt = common::seconds_between(sample.stamp, *last_);
  if (dt <= 0.0) {
    ++counters_.non_increasing_stamp;
    return ImuVerdict::kNonIncreasing;
  }
  last_ = sample.stamp;
  if (dt > limits_.max_dt_s) {
    ++counters_.gap;
    return ImuVerdict::kGap;
  }
  ++counters_.accepted;
  dt_out = dt;
  return ImuVerdict::kAccept;
}

const char* to_string(ImuVerdict verdict) {
  switch (verdict) {
    case ImuVerdict::kAccept:
      return "accepted";
    case ImuVerdict::kFirst:
      return "first sample";
    case ImuVerdict::kNonIncreasing:
      return "dt <= 0";
    case ImuVerdict::kGap:
      return "dt above limit";
    case ImuVerdict::kNotFinite:
      return "not finite";
    case ImuVerdict::kOutOfRange:
      return "out of range";
  }
  return "unknown";
}

}  // namespace semap::estimation
