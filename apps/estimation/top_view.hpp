#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "semap/estimation/evaluation.hpp"

namespace semap::apps {

// Top view (east right, north up) of the truth (named `truth_label` in the legend), each
// estimate and the GNSS fixes, as PNG.
void write_top_view(const std::filesystem::path& path, const estimation::DriveData& data,
                    const std::vector<estimation::NamedEvaluationRun>& runs,
                    const std::string& truth_label = "truth");

// One row per sample and filter: t, truth and estimated position and yaw, heading error, NEES.
void write_csv(const std::filesystem::path& path,
               const std::vector<estimation::NamedEvaluationRun>& runs);

}  // namespace semap::apps
