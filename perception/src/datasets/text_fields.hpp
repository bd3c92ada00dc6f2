#pragma once

// Line-oriented text as the dataset files hold it (TUM lists, Redwood .log, KITTI poses and
// times): lines with their numbers, fields, strict numbers and short quotes for messages.
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace semap::perception::datasets {

// The whole file; throws DatasetError naming it when it cannot be opened.
std::string read_text_file(const std::filesystem::path& path);

struct TextLine {
  int number = 0;         // 1-based
  std::string_view text;  // without the line end and surrounding blanks
};

// Every line of `text`, blank ones included, so that numbers match an editor's.
std::vector<TextLine> text_lines(std::string_view text);

// A line that carries no data: blank or a '#' comment (TUM's headers).
bool is_blank_or_comment(std::string_view line);

// Fields separated by spaces, tabs or commas (TUM's associate.py accepts all three).
std::vector<std::string_view> fields(std::string_view line);

// A whole field as a finite number; false for anything else ("1.5x", "nan", "").
bool parse_number(std::string_view field, double& value);

// `s` in quotes, cut short, for messages about input that may be long or binary.
std::string quoted(std::string_view s);

// "name:line", the `where` of a problem on a line.
std::string at_line(const std::string& name, int line);

}  // namespace semap::perception::datasets
