#pragma once

#include <span>
#include <string>

#include "semap/mapping/confusion_matrix.hpp"

namespace semap::map_io {

// One row of the table: a name (`input`, `S-CSM`, `S-BKI`) and its confusion over the 20
// SemanticKITTI learning classes, unlabelled points already left out.
struct IouTableRow {
  std::string name;
  const mapping::ConfusionMatrix* confusion = nullptr;
};

// Mean IoU over the classes 1..19 present in the ground truth (as the paper averages a
// sequence); NaN when none is present.
double kitti_mean_iou(const mapping::ConfusionMatrix& confusion);

// The rows in the layout of Table IV of Gan et al.: a header with the 19 class names and
// `average`, then per row its name, each class's IoU in percent with one decimal (`n/a` for a
// class absent from that row's ground truth) and kitti_mean_iou in percent. Throws
// std::invalid_argument for a row without 20 classes.
std::string format_kitti_iou_table(std::span<const IouTableRow> rows);

}  // namespace semap::map_io
