#pragma once

// The `== semap-onboard summary ==` lines, one per part of the pipeline (the tests read them).
#include <filesystem>
#include <string>
#include <vector>

#include "semap/onboard/dds_outputs.hpp"
#include "semap/onboard/estimation_stage.hpp"
#include "semap/onboard/mapping_stage.hpp"
#include "semap/onboard/perception_stage.hpp"
#include "semap/onboard/run_figures.hpp"

namespace semap::onboard {

void estimation_summary(const EstimationStageStats& est, std::vector<std::string>& lines);
void perception_summary(const PerceptionStage& perception, std::vector<std::string>& lines);
void mapping_summary(const MappingStageStats& map, const std::filesystem::path& checkpoint_path,
                     double memory_radius_m, std::vector<std::string>& lines);
// "latency p50/p99  : frame_taken 40/80, segment 17/25, ... ms" (latency_phases()).
void latency_summary(const std::vector<LatencyPhase>& phases, std::vector<std::string>& lines);
void dds_summary(const DdsOutputs& dds, std::vector<std::string>& lines);
void ring_summary(const Rings& rings, std::vector<std::string>& lines);

}  // namespace semap::onboard
