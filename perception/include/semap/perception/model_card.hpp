#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <opencv2/core/matx.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace semap::perception {

enum class ChannelOrder { kRgb, kBgr };
enum class ModelOutput { kLogits, kProbabilities };
// The network file formats OpenCV 4.6's DNN module reads.
enum class ModelFormat { kOnnx, kTorch, kCaffe, kTensorflow, kDarknet };

// "onnx", "torch", "caffe", "tensorflow", "darknet": the card's `format:` values.
std::string_view format_name(ModelFormat format);

// One output channel of a segmentation model.
struct ModelClass {
  std::string name;
  cv::Vec3b color;          // r, g, b, for overlays
  std::uint16_t map_class;  // the map class it feeds, 1..K-1, or kNoLabel when dropped
};

// Everything needed to run a segmentation network and turn its classes into map classes.
// The output layout is fixed: NCHW, [1, classes.size(), h, w].
struct ModelCard {
  std::filesystem::path card_file;   // for error messages
  std::filesystem::path model_file;  // resolved against the card's folder
  ModelFormat format = ModelFormat::kOnnx;
  // The second file the format reads (Caffe .prototxt, TensorFlow .pbtxt, Darknet .cfg),
  // resolved against the card's folder; empty when there is none.
  std::filesystem::path config_file;
  int input_width = 0;  // the network runs at this size
  int input_height = 0;
  ChannelOrder channel_order = ChannelOrder::kRgb;
  // Per channel, in the model's channel order, on the 0..1 pixel scale:
  // x = (pixel / 255 - mean) / std.
  std::array<float, 3> mean{};
  std::array<float, 3> std{};
  ModelOutput output = ModelOutput::kLogits;
  int threads = 1;
  std::vector<ModelClass> classes;  // one per output channel, in channel order
  int num_map_classes = 0;          // K; class 0 is free space and is never fed
};

// Reads a model card (shape documented in config/model-card-example.yaml). Every problem
// throws common::ConfigError naming the card file, line and key: a missing or unknown key,
// counts that do not agree, a map class outside 1..K-1, a model or config file that does not
// exist, a model file whose extension names no format when `format:` is absent, a format
// without the config file it needs (Caffe, Darknet) or with one it does not take.
ModelCard load_model_card(const std::filesystem::path& yaml);

}  // namespace semap::perception
