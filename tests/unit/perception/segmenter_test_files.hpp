#pragma once

// The model cards the segmenter tests write (folders and text files: test_files.hpp).

#include <string>

#include "test_files.hpp"

namespace semap::perception::testing {

// A model card for a three-class network "net.onnx"; its lines are numbered in the comments
// so tests can check the line an error names. `extra` lines (format:, config:) come last.
struct CardFields {
  std::string model = "net.onnx";
  int width = 4;
  int height = 2;
  std::string channel_order = "rgb";
  std::string mean = "[0, 0, 0]";
  std::string std = "[1, 1, 1]";
  std::string output = "logits";
  std::string names = "[a, b, c]";
  std::string colors = "[255, 0, 0, 0, 255, 0, 0, 0, 255]";
  int num_classes = 4;
  std::string unmapped = "drop";
  std::string from_model = "{a: 1, b: 2, c: 3}";
  std::string extra;
};

inline std::string card_yaml(const CardFields& f) {
  // clang-format off
  return "model: " + f.model + "\n" +                                   // 1
         "input:\n"                                                     // 2
         "  width: " + std::to_string(f.width) + "\n" +                 // 3
         "  height: " + std::to_string(f.height) + "\n" +               // 4
         "  channel_order: " + f.channel_order + "\n" +                 // 5
         "  mean: " + f.mean + "\n" +                                   // 6
         "  std: " + f.std + "\n" +                                     // 7
         "output: " + f.output + "\n" +                                 // 8
         "threads: 1\n"                                                 // 9
         "model_classes:\n"                                             // 10
         "  names: " + f.names + "\n" +                                 // 11
         "  colors: " + f.colors + "\n" +                               // 12
         "map:\n"                                                       // 13
         "  num_classes: " + std::to_string(f.num_classes) + "\n" +    // 14
         "  unmapped: " + f.unmapped + "\n" +                           // 15
         "  from_model: " + f.from_model + "\n" +                       // 16
         f.extra;                                                       // 17...
  // clang-format on
}

}  // namespace semap::perception::testing
