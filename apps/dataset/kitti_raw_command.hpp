#pragma once

// `semap-dataset kitti-raw`: the experiment of Chung et al. on a KITTI raw drive: the
// Left-InEKF (and the ESKF baseline) on OXTS-derived IMU and GNSS, and an S-BKI map of the
// Velodyne scans labelled through the left colour camera.
#include <CLI/CLI.hpp>

namespace semap::apps {

// Adds the subcommand (`kitti-raw`) to `app`; it runs as the parse's callback and a failure leaves
// as CLI::RuntimeError with the exit status (2: bad input, named on stderr).
void add_kitti_raw_command(CLI::App& app);

}  // namespace semap::apps
