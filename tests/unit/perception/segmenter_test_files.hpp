#pragma once

// Files the segmenter tests write: a private temporary folder, model cards, text files.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

namespace semap::perception::testing {

// A fresh folder per test, removed afterwards.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::temp_directory_path() /
            ("semap_seg_" + std::string(info->test_suite_name()) + "_" + info->name() + "_" +
             std::to_string(::getpid()));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

inline std::filesystem::path write_text(const std::filesystem::path& path,
                                        const std::string& text) {
  std::ofstream(path) << text;
  return path;
}

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

// The message of the exception `f` throws, or "" when it throws none.
template <typename Exception>
std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Exception& e) {
    return e.what();
  }
  return "";
}

}  // namespace semap::perception::testing
