#pragma once

#include <memory>
#include <string>

#include "semap/perception/model_card.hpp"
#include "semap/perception/segmentation.hpp"

namespace semap::perception {

// Runs a segmentation network with OpenCV's DNN module (OpenCV backend, CPU), in any format
// it reads (the card's `format:`: ONNX, Torch7, Caffe, TensorFlow, Darknet), and turns its
// per-pixel class distribution into map classes as the model card says. Soft labels.
//
// Construction reads the network and runs it once on a black image to check the output is
// [1, C, h, w] with C the card's class count; a missing or malformed file, a layer OpenCV
// cannot run or another shape throws std::runtime_error naming the card, the files and
// OpenCV's message (with the layer's type, or both shapes).
//
// Not thread-safe: segment() reuses buffers; use one instance per thread.
class DnnSegmenter : public Segmenter {
 public:
  explicit DnnSegmenter(ModelCard card);
  ~DnnSegmenter() override;
  DnnSegmenter(const DnnSegmenter&) = delete;
  DnnSegmenter& operator=(const DnnSegmenter&) = delete;

  Segmentation segment(const cv::Mat& bgr) override;
  int num_classes() const override;
  std::string describe() const override;

  const ModelCard& card() const;

  // The network's raw output for an image, pre-processed as the card says: [1, C, h, w]
  // floats, valid until the next call. For inspection and timing; the robot uses segment().
  cv::Mat forward(const cv::Mat& bgr);

 private:
  struct Impl;  // keeps OpenCV's DNN headers out of users' builds
  std::unique_ptr<Impl> impl_;
};

}  // namespace semap::perception
