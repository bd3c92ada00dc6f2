#pragma once

#include <atomic>
#include <filesystem>
#include <vector>

#include "semap/onboard/pipeline.hpp"

namespace semap::onboard {

// Runs a built pipeline as the robot's main job, under systemd (Type=notify) or from a shell:
// starts it and says READY=1, calls tick() every 100 ms and pings the watchdog once a second
// until `stop_requested` is set (a signal) or the rig has played all it had; then says
// STOPPING=1, stops the pipeline and saves the map to each of `save_paths` (a save that fails,
// e.g. on a full disk, is logged and kept in Pipeline::save_failures(); the others are still
// tried and nothing is thrown). While the stages
// drain and the map is written, another thread keeps pinging: on a slow computer that takes
// longer than WatchdogSec and is not a hang (TimeoutStopSec bounds a real one).
void run_service(Pipeline& pipeline, const std::atomic<bool>& stop_requested,
                 const std::vector<std::filesystem::path>& save_paths);

}  // namespace semap::onboard
