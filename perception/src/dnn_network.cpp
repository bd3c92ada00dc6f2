#include "dnn_network.hpp"

#include <filesystem>
#include <regex>
#include <stdexcept>

namespace semap::perception::detail {

namespace {

cv::dnn::Net read_format(const ModelCard& card) {
  const std::string model = card.model_file.string();
  const std::string config = card.config_file.string();
  switch (card.format) {
    case ModelFormat::kOnnx:
      return cv::dnn::readNetFromONNX(model);
    case ModelFormat::kTorch:
      return cv::dnn::readNetFromTorch(model);
    case ModelFormat::kCaffe:
      return cv::dnn::readNetFromCaffe(config, model);
    case ModelFormat::kTensorflow:
      return cv::dnn::readNetFromTensorflow(model, config);
    case ModelFormat::kDarknet:
      return cv::dnn::readNetFromDarknet(config, model);
  }
  throw std::logic_error("read_network: unhandled model format");
}

}  // namespace

std::string explain_opencv_error(const cv::Exception& e) {
  // OpenCV 4.6 names the layer type in these forms: Caffe, TensorFlow, Darknet and the network
  // set-up `Can't create layer "name" of type "Type"`, ONNX `Node for layer 'name' of type
  // 'Type' wasn't initialized`, Torch7 `Unsupported Torch class "Type"`.
  static const std::regex layer_type(R"((?:of type|Torch class) ["']([^"']+)["'])");
  std::smatch match;
  if (std::regex_search(e.err, match, layer_type)) {
    return e.err + "; unsupported layer type '" + match[1].str() + "'";
  }
  return e.err;
}

cv::dnn::Net read_network(const ModelCard& card) {
  std::string where = "model card " + card.card_file.string() + ": model file '" +
                      card.model_file.string() + "' (" + std::string(format_name(card.format));
  if (!card.config_file.empty()) where += ", config '" + card.config_file.string() + "'";
  where += ")";
  for (const auto& file : {card.model_file, card.config_file}) {
    if (!file.empty() && !std::filesystem::is_regular_file(file)) {
      throw std::runtime_error(where + ": '" + file.string() + "' not found");
    }
  }
  cv::dnn::Net net;
  try {
    net = read_format(card);
  } catch (const cv::Exception& e) {
    throw std::runtime_error(where + " does not load: " + explain_opencv_error(e));
  } catch (const std::exception& e) {  // a damaged file can ask for absurd sizes (bad_alloc)
    throw std::runtime_error(where + " does not load: " + e.what());
  }
  if (net.empty()) throw std::runtime_error(where + " holds no network");
  net.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  net.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  return net;
}

}  // namespace semap::perception::detail
