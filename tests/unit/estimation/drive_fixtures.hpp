#pragma once

// Simulated drives and figures shared by the filter tests (estimator_test, eskf_test).
#include <algorithm>
#include <cstdint>

#include "semap/estimation/estimator_config.hpp"
#include "semap/estimation/evaluation.hpp"
#include "semap/estimation/so3.hpp"
#include "semap/sim/drive_simulator.hpp"

namespace semap::estimation::test {

inline sim::SimulatorConfig drive(double seconds, std::uint64_t seed = 11) {
  sim::SimulatorConfig c;
  c.duration_s = seconds;
  c.seed = seed;
  return c;
}

// A filter told the true initial heading (5 cm rad sigma), so a test is about what follows.
inline EstimatorConfig heading_known(const DriveData& data,
                                     FilterKind filter = FilterKind::kLeftInekf) {
  EstimatorConfig c;
  c.filter = filter;
  c.init.yaw_rad = yaw_of(data.truth.front().state.rotation);
  c.init.yaw_sigma_rad = 0.05;
  return c;
}

inline double max_position_error_after(const EvaluationRun& run, double t0) {
  double worst = 0.0;
  for (const auto& s : run.samples) {
    if (s.t >= t0) worst = std::max(worst, (s.estimate.position - s.truth.position).norm());
  }
  return worst;
}

}  // namespace semap::estimation::test
