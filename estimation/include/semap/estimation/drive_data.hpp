#pragma once

#include <Eigen/Core>
#include <vector>

#include "semap/common/messages.hpp"
#include "semap/estimation/geodesy.hpp"
#include "semap/estimation/nav_state.hpp"

namespace semap::estimation {

struct TruthSample {
  common::Stamp stamp;
  NavState state;  // includes the true biases
};

// One drive's filter inputs with their truth, simulated (sim::simulate) or read from a recorded
// drive (oxts_to_inputs). Time-ordered sequences; truth[i] is the state at imu[i].stamp. Each IMU
// sample is the motion at the middle of the interval that ends at its stamp (what an averaging
// MEMS part reports), plus bias and white noise.
struct DriveData {
  std::vector<TruthSample> truth;
  std::vector<common::ImuSample> imu;
  std::vector<common::GnssFix> gnss;
  Geodetic origin;
  Eigen::Vector3d lever_arm = Eigen::Vector3d::Zero();
};

}  // namespace semap::estimation
