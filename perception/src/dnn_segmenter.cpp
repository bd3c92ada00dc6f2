#include "semap/perception/dnn_segmenter.hpp"

#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <vector>

#include "dnn_network.hpp"
#include "input_image.hpp"

namespace semap::perception {

namespace {

// No model class may feed free space (class 0), so map plane 0 is free to collect the
// probability of the dropped model classes.
constexpr std::size_t kDroppedPlane = 0;

std::string shape_of(const cv::Mat& m) {
  std::string s = "[";
  for (int d = 0; d < m.dims; ++d) s += (d ? ", " : "") + std::to_string(m.size[d]);
  return s + "]";
}

void check_card(const ModelCard& card) {
  const std::string who = "DnnSegmenter(" + card.card_file.string() + ")";
  detail::require_storable_class_count(card.num_map_classes, who);
  if (card.classes.empty() || card.input_width < 1 || card.input_height < 1 || card.threads < 1) {
    throw std::invalid_argument(who + ": card without classes, input size or threads");
  }
  for (const ModelClass& c : card.classes) {
    if (c.map_class != kNoLabel && (c.map_class < 1 || c.map_class >= card.num_map_classes)) {
      throw std::invalid_argument(who + ": model class '" + c.name + "' feeds map class " +
                                  std::to_string(c.map_class) + ", outside 1..K-1");
    }
  }
  for (const float s : card.std) {
    if (!(s > 0.0f)) throw std::invalid_argument(who + ": std must be > 0");
  }
}

}  // namespace

struct DnnSegmenter::Impl {
  ModelCard card;
  cv::dnn::Net net;
  // Buffers reused from frame to frame.
  cv::Mat resized;                   // the image at the model's input size, BGR
  std::vector<cv::Mat> bgr_planes;   // its three 8-bit planes
  cv::Mat blob;                      // network input, [1, 3, H, W] float
  std::vector<cv::Mat> blob_planes;  // views of blob's channels
  cv::Mat max_logit, exp_logit, exp_sum;
  std::vector<cv::Mat> map_planes;    // at the model's output size; plane 0: dropped mass
  std::vector<cv::Mat> image_planes;  // the same, resized to the camera image

  explicit Impl(ModelCard c) : card(std::move(c)), net(detail::read_network(card)) {
    const int shape[] = {1, 3, card.input_height, card.input_width};
    blob.create(4, shape, CV_32F);
    for (int k = 0; k < 3; ++k) {
      blob_planes.emplace_back(card.input_height, card.input_width, CV_32F, blob.ptr<float>(0, k));
    }
    map_planes.resize(static_cast<std::size_t>(card.num_map_classes));
    image_planes.resize(map_planes.size());
  }

  // Pre-processing, per model channel k (taken from the image's R, G or B plane as the card's
  // channel order says): x_k = (pixel / 255 - mean_k) / std_k, as one scale and offset.
  void make_blob(const cv::Mat& bgr) {
    cv::resize(bgr, resized, blob_planes[0].size(), 0, 0, cv::INTER_LINEAR);
    cv::split(resized, bgr_planes);
    for (std::size_t k = 0; k < 3; ++k) {
      const std::size_t source = card.channel_order == ChannelOrder::kRgb ? 2 - k : k;
      const double scale = 1.0 / (255.0 * card.std[k]);
      const double offset = -card.mean[k] / card.std[k];
      bgr_planes[source].convertTo(blob_planes[k], CV_32F, scale, offset);
    }
  }

  cv::Mat run(const cv::Mat& bgr) {
    make_blob(bgr);
    net.setInput(blob);
    return net.forward();
  }

  // Map-class mass at the model's output size: q_c = sum of p_m over model classes m feeding
  // c, and q_0 = the dropped classes' sum. For logits, p is the softmax, computed stably:
  //   e_m = exp(z_m - max_j z_j),  p_m = e_m / sum_j e_j,  so  q_c = (sum_{m->c} e_m) / sum_j e_j
  // and only the K sums are divided.
  void map_class_mass(cv::Mat& output) {
    const cv::Size size(output.size[3], output.size[2]);
    std::vector<cv::Mat> model_planes;
    for (int m = 0; m < output.size[1]; ++m) {
      model_planes.emplace_back(size, CV_32F, output.ptr<float>(0, m));
    }
    for (cv::Mat& q : map_planes) {
      q.create(size, CV_32F);
      q.setTo(0.0f);
    }
    const bool logits = card.output == ModelOutput::kLogits;
    if (logits) {
      model_planes[0].copyTo(max_logit);
      for (std::size_t m = 1; m < model_planes.size(); ++m) {
        cv::max(max_logit, model_planes[m], max_logit);
      }
      exp_sum.create(size, CV_32F);
      exp_sum.setTo(0.0f);
    }
    for (std::size_t m = 0; m < model_planes.size(); ++m) {
      const std::uint16_t feeds = card.classes[m].map_class;
      cv::Mat& q = map_planes[feeds == kNoLabel ? kDroppedPlane : feeds];
      if (!logits) {
        q += model_planes[m];
        continue;
      }
      cv::subtract(model_planes[m], max_logit, exp_logit);
      cv::exp(exp_logit, exp_logit);
      q += exp_logit;
      exp_sum += exp_logit;
    }
    if (logits) {
      for (cv::Mat& q : map_planes) cv::divide(q, exp_sum, q);
    }
  }

  // Bilinear resampling is linear, so resizing the K sums equals summing the resized model
  // probabilities, at K instead of C planes.
  const std::vector<cv::Mat>& at_image_size(const cv::Size& size) {
    if (map_planes[0].size() == size) return map_planes;
    for (std::size_t c = 0; c < map_planes.size(); ++c) {
      cv::resize(map_planes[c], image_planes[c], size, 0, 0, cv::INTER_LINEAR);
    }
    return image_planes;
  }

  // Per pixel, with d = q_0 the dropped mass and kept = sum_{c>=1} q_c:
  //   d > max_c q_c (or nothing kept)  ->  kNoLabel, confidence 0, p all 0
  //   otherwise  label = argmax_c q_c,  p_c = q_c / kept (p_0 = 0),  confidence = p_label.
  Segmentation label(const std::vector<cv::Mat>& q, const cv::Size& size) const {
    const int k = card.num_map_classes;
    Segmentation out;
    out.num_classes = k;
    out.labels.create(size, CV_16UC1);
    out.confidence.create(size, CV_32FC1);
    out.probabilities = cv::Mat::zeros(size, CV_32FC(k));
    std::vector<const float*> rows(static_cast<std::size_t>(k));
    for (int y = 0; y < size.height; ++y) {
      for (int c = 0; c < k; ++c) rows[static_cast<std::size_t>(c)] = q[c].ptr<float>(y);
      auto* labels = out.labels.ptr<std::uint16_t>(y);
      auto* confidence = out.confidence.ptr<float>(y);
      auto* p = out.probabilities.ptr<float>(y);
      for (int x = 0; x < size.width; ++x, p += k) {
        std::size_t best = 1;
        float kept = 0.0f;
        for (std::size_t c = 1; c < rows.size(); ++c) {
          kept += rows[c][x];
          if (rows[c][x] > rows[best][x]) best = c;
        }
        if (!(kept > 0.0f) || rows[kDroppedPlane][x] > rows[best][x]) {
          labels[x] = kNoLabel;
          confidence[x] = 0.0f;
          continue;
        }
        for (std::size_t c = 1; c < rows.size(); ++c) p[c] = rows[c][x] / kept;
        labels[x] = static_cast<std::uint16_t>(best);
        confidence[x] = p[best];
      }
    }
    return out;
  }
};

DnnSegmenter::DnnSegmenter(ModelCard card) {
  check_card(card);
  // OpenCV's thread count is process-wide: the last segmenter built sets it for everyone.
  cv::setNumThreads(card.threads);
  impl_ = std::make_unique<Impl>(std::move(card));

  // One pass on a black image proves the network runs and has the card's output shape.
  const ModelCard& c = impl_->card;
  cv::Mat output;
  try {
    output = impl_->run(cv::Mat::zeros(c.input_height, c.input_width, CV_8UC3));
  } catch (const cv::Exception& e) {
    throw std::runtime_error("model card " + c.card_file.string() + ": model file '" +
                             c.model_file.string() + "' fails on a [1, 3, " +
                             std::to_string(c.input_height) + ", " + std::to_string(c.input_width) +
                             "] input: " + detail::explain_opencv_error(e));
  }
  const int classes = static_cast<int>(c.classes.size());
  if (output.dims != 4 || output.size[0] != 1 || output.size[1] != classes) {
    throw std::runtime_error("model card " + c.card_file.string() + " lists " +
                             std::to_string(classes) + " classes, so the output must be [1, " +
                             std::to_string(classes) + ", h, w]; model file '" +
                             c.model_file.string() + "' gives " + shape_of(output));
  }
}

DnnSegmenter::~DnnSegmenter() = default;

Segmentation DnnSegmenter::segment(const cv::Mat& bgr) {
  detail::require_bgr_image(bgr, "DnnSegmenter::segment");
  cv::Mat output = impl_->run(bgr);
  impl_->map_class_mass(output);
  return impl_->label(impl_->at_image_size(bgr.size()), bgr.size());
}

int DnnSegmenter::num_classes() const { return impl_->card.num_map_classes; }

std::string DnnSegmenter::describe() const {
  const ModelCard& c = impl_->card;
  return "dnn segmenter: " + c.model_file.string() + " (" + std::string(format_name(c.format)) +
         ") at " + std::to_string(c.input_width) + "x" + std::to_string(c.input_height) +
         (c.channel_order == ChannelOrder::kRgb ? " rgb, " : " bgr, ") +
         (c.output == ModelOutput::kLogits ? "logits, " : "probabilities, ") +
         std::to_string(c.classes.size()) + " model classes -> " +
         std::to_string(c.num_map_classes) + " map classes, " + std::to_string(c.threads) +
         " threads";
}

const ModelCard& DnnSegmenter::card() const { return impl_->card; }

cv::Mat DnnSegmenter::forward(const cv::Mat& bgr) {
  detail::require_bgr_image(bgr, "DnnSegmenter::forward");
  return impl_->run(bgr);
}

}  // namespace semap::perception
