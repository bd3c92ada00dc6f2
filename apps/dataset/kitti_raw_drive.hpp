#pragma once

// The files of one KITTI raw drive (a *_sync or *_extract folder) that `semap-dataset kitti-raw`
// reads, and the labels of a scan's camera image.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "semap/common/stamp.hpp"
#include "semap/perception/segmentation.hpp"

namespace semap::apps {

// Input that cannot be used; the message names the file (exit status 2).
class DriveError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct KittiRawDrive {
  std::filesystem::path folder;
  std::vector<std::filesystem::path> scans;  // velodyne_points/data/*.bin, sorted
  std::vector<common::Stamp> scan_stamps;    // velodyne_points/timestamps.txt, one per scan
};

// Lists the scans and their stamps. Throws DriveError naming the file when a folder or the
// timestamps file is missing, a stamp does not parse or the counts differ.
KittiRawDrive open_kitti_raw_drive(const std::filesystem::path& folder);

// Labels the camera image of one scan, found by the scan's file name (NNNNNNNNNN.png).
class ScanLabelSource {
 public:
  virtual ~ScanLabelSource() = default;
  // Throws DriveError naming the image when it is missing or unreadable.
  virtual perception::Segmentation labels_for(const std::filesystem::path& scan) = 0;
  virtual int num_classes() const = 0;
  virtual std::string describe() const = 0;
};

// The segmenter of an ONNX model card on image_02/data/<scan>.png.
std::unique_ptr<ScanLabelSource> make_model_label_source(const std::filesystem::path& model_card,
                                                         const std::filesystem::path& image_dir);

// 8-bit single-channel PNGs of map class ids (<dir>/<scan>.png), hard labels; 0 and ids of
// num_classes or more are unlabelled (the points are dropped and counted as no_label).
std::unique_ptr<ScanLabelSource> make_label_image_source(const std::filesystem::path& dir,
                                                         int num_classes);

}  // namespace semap::apps
