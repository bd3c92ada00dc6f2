#pragma once

#include <cstdint>
#include <string>

#include "semap/onboard/onboard_config.hpp"
#include "semap/sim/camera_feed.hpp"
#include "semap/sim/drive_simulator.hpp"
#include "semap/sim/emulator.hpp"

namespace semap::sim {

// The simulated rig's own keys in the `rig:` section: the drive, the street world and what the
// camera shows.
struct SimRigConfig {
  SimulatorConfig trajectory;    // scenario, speed_m_s, imu_rate_hz, gnss_rate_hz, ... seed
  std::uint32_t scene_seed = 7;  // the street world and the camera's noise
  double world_density = 1.0;    // scales the number of buildings, trees, cars and poles
  SimCameraImage camera_image = SimCameraImage::kRgb;
  // Nice value of the camera's renderer thread (0..19). The renderer stands for a camera's
  // hardware; > 0 puts the pipeline's threads first on the CPUs they share (the latency
  // benchmark uses 10). 0 by default: on a machine shared with other work a niced renderer
  // falls behind the camera rate, and the tests count frames rendered.
  int render_nice = 0;
  // A V4L2 video output device (vivid's, looped to its capture side): the rig writes its colour
  // frames there as BGR24 and a CameraDriver on camera.device captures them back. Empty: the
  // frames go straight into the colour ring.
  std::string camera_output;
  // rig.faults: scheduled GNSS faults in the firmware emulator (seconds from the drive's first
  // sample): gnss_silent_at_s / gnss_silent_s, gnss_jump_at_s / gnss_jump_s / gnss_jump_m.
  FaultConfig faults;
};

// Reads the simulated rig's keys into `out` when load_onboard_config calls it, and checks the
// rest of the configuration against the rig (aligned depth only; with camera_output, BGR24 and
// a sync tolerance below half the frame period).
onboard::RigKeys sim_rig_keys(SimRigConfig& out);

}  // namespace semap::sim
