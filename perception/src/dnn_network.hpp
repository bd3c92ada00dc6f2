#pragma once

// Reading a segmentation network in any format OpenCV 4.6's DNN module knows (ONNX, Torch7,
// Caffe, TensorFlow, Darknet), with errors a user can act on.

#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>
#include <string>

#include "semap/perception/model_card.hpp"

namespace semap::perception::detail {

// The card's network, set to run on the CPU with OpenCV's own backend. A missing file, a file
// OpenCV cannot parse or an empty network throws std::runtime_error naming the card, the
// model file (and config file), the format and OpenCV's message.
cv::dnn::Net read_network(const ModelCard& card);

// OpenCV's message, and when it is about a layer OpenCV cannot create or run, that layer's
// type spelled out ("...; unsupported layer type 'X'"): the thing a user looks up.
std::string explain_opencv_error(const cv::Exception& e);

}  // namespace semap::perception::detail
