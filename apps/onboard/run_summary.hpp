#pragma once

#include <filesystem>

#include "dds_outputs.hpp"
#include "estimation_stage.hpp"
#include "mapping_stage.hpp"
#include "perception_stage.hpp"
#include "replay_rig.hpp"
#include "run_figures.hpp"
#include "semap/drivers/camera_driver.hpp"
#include "semap/drivers/can_imu_driver.hpp"
#include "semap/drivers/gnss_driver.hpp"
#include "stream_recorder.hpp"

namespace semap::onboard {

// What a run did, for the summary semap-onboard prints at exit; absent parts are null.
struct RunSummary {
  const drivers::GnssDriver* gnss_driver = nullptr;
  const drivers::CanImuDriver* imu_driver = nullptr;
  const drivers::CameraDriver* camera_driver = nullptr;
  EstimationStageStats estimation;
  const LiveAccuracy* accuracy = nullptr;  // the simulated rig's pose error
  const PerceptionStage* perception = nullptr;
  MappingStageStats map;
  std::filesystem::path checkpoint_path;
  double memory_radius_m = 0.0;
  const DdsOutputs* dds = nullptr;
  const StreamRecorder* recorder = nullptr;
  const ReplayRig* replay = nullptr;
  const Rings& rings;
};

// The `== semap-onboard summary ==` lines on stdout, one per part (the tests read them).
void print_summary(const RunSummary& s);

}  // namespace semap::onboard
