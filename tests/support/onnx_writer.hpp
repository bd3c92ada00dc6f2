#pragma once

// Writes small ONNX networks so tests and benchmarks need no downloaded model and no Python.
//
// ONNX files are protobuf messages (onnx/onnx.proto). Only the fields these networks need are
// written, with the field numbers of the spec:
//   ModelProto       ir_version = 1, graph = 7, opset_import = 8
//   OperatorSetId    domain = 1, version = 2
//   GraphProto       node = 1, name = 2, initializer = 5, input = 11, output = 12
//   NodeProto        input = 1, output = 2, name = 3, op_type = 4, attribute = 5
//   AttributeProto   name = 1, i = 3, ints = 8, type = 20 (INT = 2, INTS = 7)
//   TensorProto      dims = 1, data_type = 2 (FLOAT = 1), name = 8, raw_data = 9
//   ValueInfoProto   name = 1, type = 2
//   TypeProto        tensor_type = 1;  TypeProto.Tensor elem_type = 1, shape = 2
//   TensorShapeProto dim = 1;          Dimension dim_value = 1

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace semap::test {

// Protobuf wire format: every field is a key varint (field << 3 | wire type) and a value;
// wire type 0 is a varint, 2 is length-delimited (a varint length, then the bytes).
class ProtoMessage {
 public:
  ProtoMessage& varint(int field, std::uint64_t value) {
    key(field, 0);
    put_varint(value);
    return *this;
  }
  ProtoMessage& bytes(int field, std::string_view value) {
    key(field, 2);
    put_varint(value.size());
    out_.append(value);
    return *this;
  }
  ProtoMessage& message(int field, const ProtoMessage& m) { return bytes(field, m.out_); }
  const std::string& data() const { return out_; }

 private:
  void key(int field, int wire_type) {
    put_varint(static_cast<std::uint64_t>(field) << 3 | static_cast<std::uint64_t>(wire_type));
  }
  // 7 bits per byte, least significant group first; the top bit says "more bytes follow".
  void put_varint(std::uint64_t v) {
    while (v >= 0x80) {
      out_.push_back(static_cast<char>((v & 0x7F) | 0x80));
      v >>= 7;
    }
    out_.push_back(static_cast<char>(v));
  }

  std::string out_;
};

// A chain of Conv and Relu layers on one float input "input" of shape [1, C, H, W]; the last
// layer's tensor is the output, NCHW. ir_version 7, opset 11 (both read by OpenCV 4.6).
class OnnxChain {
 public:
  OnnxChain(int channels, int height, int width)
      : channels_(channels), height_(height), width_(width) {
    graph_.bytes(11, value_info("input", {1, channels, height, width}));
  }

  // Conv with a kernel x kernel window, the given stride and padding kernel / 2:
  // out = floor((in + 2 * (kernel / 2) - kernel) / stride) + 1. `weights` is
  // [out_channels][in_channels][kernel][kernel], row-major; `bias` has out_channels values.
  OnnxChain& conv(int out_channels, int kernel, int stride, const std::vector<float>& weights,
                  const std::vector<float>& bias) {
    const std::size_t expected = static_cast<std::size_t>(out_channels) *
                                 static_cast<std::size_t>(channels_ * kernel * kernel);
    if (weights.size() != expected || bias.size() != static_cast<std::size_t>(out_channels)) {
      throw std::invalid_argument("OnnxChain::conv: weights or bias have the wrong size");
    }
    const std::string name = "conv" + std::to_string(layers_);
    graph_.bytes(5, tensor(name + ".w", {out_channels, channels_, kernel, kernel}, weights));
    graph_.bytes(5, tensor(name + ".b", {out_channels}, bias));
    const int pad = kernel / 2;
    ProtoMessage node = start_node("Conv", name);
    node.bytes(1, name + ".w").bytes(1, name + ".b");
    node.message(5, ints_attribute("kernel_shape", {kernel, kernel}));
    node.message(5, ints_attribute("strides", {stride, stride}));
    node.message(5, ints_attribute("pads", {pad, pad, pad, pad}));
    node.message(5, ints_attribute("dilations", {1, 1}));
    node.message(5, int_attribute("group", 1));
    finish_node(node);
    channels_ = out_channels;
    height_ = (height_ + 2 * pad - kernel) / stride + 1;
    width_ = (width_ + 2 * pad - kernel) / stride + 1;
    return *this;
  }

  OnnxChain& relu() {
    ProtoMessage node = start_node("Relu", "relu" + std::to_string(layers_));
    finish_node(node);
    return *this;
  }

  // The serialised ModelProto.
  std::string model() const {
    ProtoMessage graph = graph_;
    graph.bytes(2, "semap_test_net");
    graph.bytes(12, value_info(last_, {1, channels_, height_, width_}));
    ProtoMessage opset;
    opset.bytes(1, "").varint(2, 11);
    ProtoMessage model;
    model.varint(1, 7).message(7, graph).message(8, opset);
    return model.data();
  }

 private:
  ProtoMessage start_node(std::string_view op_type, const std::string& name) const {
    ProtoMessage node;
    node.bytes(1, last_).bytes(3, name).bytes(4, op_type);
    return node;
  }
  // Protobuf fields may come in any order, so the output name can follow the attributes.
  void finish_node(ProtoMessage& node) {
    last_ = "t" + std::to_string(layers_++);
    node.bytes(2, last_);
    graph_.message(1, node);
  }

  static std::string value_info(const std::string& name, const std::vector<int>& shape) {
    ProtoMessage dims;
    for (const int d : shape)
      dims.message(1, ProtoMessage().varint(1, static_cast<std::uint64_t>(d)));
    ProtoMessage tensor_type;
    tensor_type.varint(1, 1).message(2, dims);
    ProtoMessage info;
    info.bytes(1, name).message(2, ProtoMessage().message(1, tensor_type));
    return info.data();
  }

  // raw_data holds the floats little-endian, as ONNX requires.
  static std::string tensor(const std::string& name, const std::vector<int>& dims,
                            const std::vector<float>& values) {
    static_assert(std::endian::native == std::endian::little);
    ProtoMessage t;
    for (const int d : dims) t.varint(1, static_cast<std::uint64_t>(d));
    t.varint(2, 1).bytes(8, name);
    t.bytes(9, std::string_view(reinterpret_cast<const char*>(values.data()),
                                values.size() * sizeof(float)));
    return t.data();
  }

  static ProtoMessage int_attribute(std::string_view name, int value) {
    ProtoMessage a;
    a.bytes(1, name).varint(3, static_cast<std::uint64_t>(value)).varint(20, 2);
    return a;
  }
  static ProtoMessage ints_attribute(std::string_view name, const std::vector<int>& values) {
    ProtoMessage a;
    a.bytes(1, name);
    for (const int v : values) a.varint(8, static_cast<std::uint64_t>(v));
    a.varint(20, 7);
    return a;
  }

  ProtoMessage graph_;
  std::string last_ = "input";
  int layers_ = 0;
  int channels_, height_, width_;
};

// One 1x1 convolution: the output for class k at a pixel is the affine function
//   z_k = sum_c weights[3 k + c] * x_c + bias[k]
// of that pixel's three input values x_c (after the segmenter's normalisation), so a test can
// compute the expected softmax by hand. Output [1, bias.size(), height, width].
inline std::string affine_pixel_model(int height, int width, const std::vector<float>& weights,
                                      const std::vector<float>& bias) {
  OnnxChain net(3, height, width);
  net.conv(static_cast<int>(bias.size()), 1, 1, weights, bias);
  return net.model();
}

// A segmentation-shaped network for benchmarks, deterministic pseudo-random weights:
//   conv3x3/2 (3 -> w) -> relu -> conv3x3/2 (w -> w) -> relu
//   -> middle_layers x (conv3x3 (w -> w) -> relu) -> conv1x1 (w -> classes)
// Output at a quarter of the input size. Multiply-adds, with P = H W / 16 output pixels:
//   4 P (27 w) + P (9 w^2) (1 + middle_layers) + P w classes; FLOPs are twice that.
// E.g. 320x240, w = 48, 3 middle layers: 0.85 GFLOP; 640x480, w = 32, 1 middle layer: 0.86
// (19 classes).
inline std::string segmentation_benchmark_model(int height, int width, int channels, int classes,
                                                int middle_layers, std::uint64_t seed = 1) {
  // splitmix64: the same weights on every platform, unlike std:: distributions.
  auto next = [state = seed]() mutable {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  };
  // Uniform in +-sqrt(6 / fan_in) (He initialisation) keeps activations from vanishing.
  auto weights = [&](int out, int in, int kernel) {
    const float limit = std::sqrt(6.0f / static_cast<float>(in * kernel * kernel));
    std::vector<float> w(static_cast<std::size_t>(out * in * kernel * kernel));
    for (float& v : w) v = limit * (2.0f * static_cast<float>(next() >> 40) / 16777216.0f - 1.0f);
    return w;
  };
  const std::vector<float> bias(static_cast<std::size_t>(channels), 0.01f);
  OnnxChain net(3, height, width);
  net.conv(channels, 3, 2, weights(channels, 3, 3), bias).relu();
  net.conv(channels, 3, 2, weights(channels, channels, 3), bias).relu();
  for (int i = 0; i < middle_layers; ++i) {
    net.conv(channels, 3, 1, weights(channels, channels, 3), bias).relu();
  }
  net.conv(classes, 1, 1, weights(classes, channels, 1),
           std::vector<float>(static_cast<std::size_t>(classes), 0.0f));
  return net.model();
}

// Writes a model (or deliberately malformed bytes) to a file.
inline void write_bytes(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

}  // namespace semap::test
