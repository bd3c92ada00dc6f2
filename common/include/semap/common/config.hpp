#pragma once

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace semap::common {

// Raised for any configuration problem; the message names the file, line and key.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A YAML mapping read with strict checks: wrong types and out-of-range values throw
// ConfigError naming `file:line: key`, and `finish()` rejects keys nobody asked for, so a
// typo in a config file is an error instead of a silently ignored setting.
class ConfigSection {
 public:
  static ConfigSection load_file(const std::filesystem::path& path);
  static ConfigSection load_string(const std::string& yaml, const std::string& name = "<string>");

  bool has(const std::string& key) const;
  // Whether the value is a list (for keys that take a scalar or a list).
  bool is_list(const std::string& key) const;

  // Required value.
  template <typename T>
  T get(const std::string& key) const;
  // Optional value with a default.
  template <typename T>
  T get(const std::string& key, const T& fallback) const {
    return has(key) ? get<T>(key) : fallback;
  }
  // Numeric value that must lie in [lo, hi].
  double get_in_range(const std::string& key, double fallback, double lo, double hi) const;
  // Value that must be one of `choices`.
  std::string get_choice(const std::string& key, const std::string& fallback,
                         const std::vector<std::string>& choices) const;

  // Nested mapping; `section_or_empty` returns an empty section when the key is absent.
  ConfigSection section(const std::string& key) const;
  ConfigSection section_or_empty(const std::string& key) const;

  // Throws if the mapping holds keys that were never read. Call after reading a section.
  void finish() const;

  // For rules only the caller can check (counts that must agree, a value that depends on
  // another): throws ConfigError naming `file:line: key` like the built-in checks. The second
  // form points at element `index` of a list value, so the line is that element's.
  [[noreturn]] void reject(const std::string& key, const std::string& what) const;
  [[noreturn]] void reject(const std::string& key, std::size_t index,
                           const std::string& what) const;

  const std::string& path() const { return path_; }
  const std::string& file() const { return state_->file; }

 private:
  struct State {
    std::string file;
  };
  ConfigSection(YAML::Node node, std::string path, std::shared_ptr<State> state);
  YAML::Node child(const std::string& key) const;
  [[noreturn]] void fail(const YAML::Node& at, const std::string& key,
                         const std::string& what) const;
  std::string qualified(const std::string& key) const;

  YAML::Node node_;
  std::string path_;  // dotted path of this section, "" for the root
  std::shared_ptr<State> state_;
  std::shared_ptr<std::set<std::string>> used_ = std::make_shared<std::set<std::string>>();
};

template <>
double ConfigSection::get<double>(const std::string& key) const;
template <>
int ConfigSection::get<int>(const std::string& key) const;
template <>
bool ConfigSection::get<bool>(const std::string& key) const;
template <>
std::string ConfigSection::get<std::string>(const std::string& key) const;
template <>
std::vector<double> ConfigSection::get<std::vector<double>>(const std::string& key) const;
template <>
std::vector<std::string> ConfigSection::get<std::vector<std::string>>(const std::string& key) const;

}  // namespace semap::common
