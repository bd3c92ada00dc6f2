#include "dnn_network.hpp"

#include <filesystem>
#include <stdexcept>
#include <string_view>

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
  // (Plain string search: std::regex trips GCC 12's -Wmaybe-uninitialized at -O1 under ASan.)
  for (const std::string_view marker : {"of type ", "Torch class "}) {
    const std::size_t at = e.err.find(marker);
    if (at == std::string::npos) continue;
    const std::size_t open = at + marker.size();
    if (open >= e.err.size() || (e.err[open] != '"' && e.err[open] != '\'')) continue;
    const std::size_t close = e.err.find_first_of("\"'", open + 1);
    if (close == std::string::npos || close == open + 1) continue;
    return e.err + "; unsupported layer type '" + e.err.substr(open + 1, close - open - 1) + "'";
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
