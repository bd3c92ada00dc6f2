#include "kitti_raw_drive.hpp"

#include <algorithm>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "semap/estimation/oxts_reader.hpp"
#include "semap/perception/dnn_segmenter.hpp"
#include "semap/perception/model_card.hpp"

namespace semap::apps {

namespace fs = std::filesystem;

namespace {

fs::path image_of(const fs::path& dir, const fs::path& scan) {
  return dir / (scan.stem().string() + ".png");
}

cv::Mat read_image(const fs::path& path, int flags) {
  if (!fs::is_regular_file(path)) throw DriveError(path.string() + ": missing image for the scan");
  cv::Mat image = cv::imread(path.string(), flags);
  if (image.empty()) throw DriveError(path.string() + ": cannot decode the image");
  return image;
}

class ModelLabelSource : public ScanLabelSource {
 public:
  ModelLabelSource(perception::ModelCard card, fs::path image_dir)
      : segmenter_(std::move(card)), image_dir_(std::move(image_dir)) {}
  perception::Segmentation labels_for(const fs::path& scan) override {
    return segmenter_.segment(read_image(image_of(image_dir_, scan), cv::IMREAD_COLOR));
  }
  int num_classes() const override { return segmenter_.num_classes(); }
  std::string describe() const override { return segmenter_.describe(); }

 private:
  perception::DnnSegmenter segmenter_;
  fs::path image_dir_;
};

class LabelImageSource : public ScanLabelSource {
 public:
  LabelImageSource(fs::path dir, int num_classes) : dir_(std::move(dir)), classes_(num_classes) {}
  perception::Segmentation labels_for(const fs::path& scan) override {
    const fs::path path = image_of(dir_, scan);
    const cv::Mat ids = read_image(path, cv::IMREAD_UNCHANGED);
    if (ids.type() != CV_8UC1) {
      throw DriveError(path.string() + ": not an 8-bit single-channel label image");
    }
    perception::Segmentation seg;
    seg.num_classes = classes_;
    seg.labels.create(ids.size(), CV_16UC1);
    seg.confidence.create(ids.size(), CV_32FC1);
    for (int v = 0; v < ids.rows; ++v) {
      const auto* in = ids.ptr<std::uint8_t>(v);
      auto* label = seg.labels.ptr<std::uint16_t>(v);
      auto* confidence = seg.confidence.ptr<float>(v);
      for (int u = 0; u < ids.cols; ++u) {
        // Class 0 is the map's free space: a label image uses it for "no class".
        const bool known = in[u] != 0 && in[u] < classes_;
        label[u] = known ? in[u] : perception::kNoLabel;
        confidence[u] = known ? 1.0f : 0.0f;
      }
    }
    return seg;
  }
  int num_classes() const override { return classes_; }
  std::string describe() const override {
    return "label images " + dir_.string() + " (" + std::to_string(classes_) + " classes, hard)";
  }

 private:
  fs::path dir_;
  int classes_;
};

}  // namespace

KittiRawDrive open_kitti_raw_drive(const fs::path& folder) {
  KittiRawDrive drive;
  drive.folder = folder;
  const fs::path data = folder / "velodyne_points" / "data";
  const fs::path stamps_path = folder / "velodyne_points" / "timestamps.txt";
  if (!fs::is_directory(data)) throw DriveError(data.string() + ": not a directory");
  for (const auto& entry : fs::directory_iterator(data)) {
    if (entry.is_regular_file() && entry.path().extension() == ".bin") {
      drive.scans.push_back(entry.path());
    }
  }
  std::sort(drive.scans.begin(), drive.scans.end());
  std::ifstream in(stamps_path);
  if (!in) throw DriveError(stamps_path.string() + ": cannot open");
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    const auto stamp = estimation::parse_kitti_timestamp(line);
    if (!stamp) {
      throw DriveError(stamps_path.string() + ":" + std::to_string(drive.scan_stamps.size() + 1) +
                       ": bad timestamp '" + line.substr(0, 40) + "'");
    }
    drive.scan_stamps.push_back(*stamp);
  }
  if (drive.scan_stamps.size() != drive.scans.size()) {
    throw DriveError(stamps_path.string() + ": " + std::to_string(drive.scan_stamps.size()) +
                     " stamps for " + std::to_string(drive.scans.size()) + " scans in " +
                     data.string());
  }
  return drive;
}

std::unique_ptr<ScanLabelSource> make_model_label_source(const fs::path& model_card,
                                                         const fs::path& image_dir) {
  return std::make_unique<ModelLabelSource>(perception::load_model_card(model_card), image_dir);
}

std::unique_ptr<ScanLabelSource> make_label_image_source(const fs::path& dir, int num_classes) {
  return std::make_unique<LabelImageSource>(dir, num_classes);
}

}  // namespace semap::apps
