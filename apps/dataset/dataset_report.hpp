#pragma once

#include <filesystem>
#include <vector>

#include "semap/onboard/dataset_rig.hpp"
#include "semap/onboard/pipeline.hpp"

namespace semap::apps {

// What a dataset run wrote and measured, after the pipeline stopped: map.smap, map.ply (as
// semap-export writes it), top.png and summary.json in `out`; returns how many selected frames
// did not reach the map (each with its reason in summary.json).
std::size_t write_dataset_outputs(const std::filesystem::path& out, onboard::Pipeline& pipeline,
                                  const onboard::DatasetRig& rig, double wall_s);

}  // namespace semap::apps
