#pragma once

#include <memory>
#include <string>

#include "semap/perception/model_card.hpp"
#include "semap/perception/segmentation.hpp"

namespace semap::perception {

// Runs an ONNX segmentation network with OpenCV's DNN module (OpenCV backend, CPU) and turns
// its per-pixel class distribution into map classes as the model card says. Soft labels.
//
// Construction reads the network and runs it once on a black image to check the output is
// [1, C, h, w] with C the card's class count; a missing or malformed .onnx file or another
// shape throws std::runtime_error naming the files (and both shapes).
//
// Not thread-safe: segment() reuses buffers; use one instance per thread.
class OnnxSegmenter : public Segmenter {
 public:
  explicit OnnxSegmenter(ModelCard card);
  ~OnnxSegmenter() override;
  OnnxSegmenter(const OnnxSegmenter&) = delete;
  OnnxSegmenter& operator=(const OnnxSegmenter&) = delete;

  Segmentation segment(const cv::Mat& bgr) override;
  int num_classes() const override;
  std::string describe() const override;

  const ModelCard& card() const;

 private:
  struct Impl;  // keeps OpenCV's DNN headers out of users' builds
  std::unique_ptr<Impl> impl_;
};

}  // namespace semap::perception
