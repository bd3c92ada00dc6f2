#include "semap/common/config.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace semap::common {

namespace {

std::string type_name(const YAML::Node& n) {
  switch (n.Type()) {
    case YAML::NodeType::Null:
      return "null";
    case YAML::NodeType::Scalar:
      return "'" + n.Scalar() + "'";
    case YAML::NodeType::Sequence:
      return "a list";
    case YAML::NodeType::Map:
      return "a mapping";
    default:
      return "nothing";
  }
}

}  // namespace

ConfigSection::ConfigSection(YAML::Node node, std::string path, std::shared_ptr<State> state)
    : node_(std::move(node)), path_(std::move(path)), state_(std::move(state)) {}

ConfigSection ConfigSection::load_file(const std::filesystem::path& path) {
  auto state = std::make_shared<State>(State{path.string()});
  YAML::Node root;
  try {
    root = YAML::LoadFile(path.string());
  } catch (const YAML::BadFile&) {
    throw ConfigError(path.string() + ": cannot open configuration file");
  } catch (const YAML::ParserException& e) {
    throw ConfigError(path.string() + ":" + std::to_string(e.mark.line + 1) +
                      ": YAML syntax error: " + e.msg);
  }
  if (root.IsNull()) root = YAML::Node(YAML::NodeType::Map);
  if (!root.IsMap()) throw ConfigError(path.string() + ": top level must be a mapping");
  return ConfigSection(root, "", state);
}

ConfigSection ConfigSection::load_string(const std::string& yaml, const std::string& name) {
  auto state = std::make_shared<State>(State{name});
  YAML::Node root;
  try {
    root = YAML::Load(yaml);
  } catch (const YAML::ParserException& e) {
    throw ConfigError(name + ":" + std::to_string(e.mark.line + 1) +
                      ": YAML syntax error: " + e.msg);
  }
  if (root.IsNull()) root = YAML::Node(YAML::NodeType::Map);
  if (!root.IsMap()) throw ConfigError(name + ": top level must be a mapping");
  return ConfigSection(root, "", state);
}

std::string ConfigSection::qualified(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

void ConfigSection::fail(const YAML::Node& at, const std::string& key,
                         const std::string& what) const {
  std::ostringstream msg;
  msg << state_->file;
  const YAML::Mark mark = at.IsDefined() ? at.Mark() : node_.Mark();
  if (mark.line >= 0) msg << ":" << mark.line + 1;
  msg << ": key '" << qualified(key) << "': " << what;
  throw ConfigError(msg.str());
}

bool ConfigSection::has(const std::string& key) const {
  used_->insert(key);
  return node_.IsMap() && node_[key].IsDefined() && !node_[key].IsNull();
}

bool ConfigSection::is_list(const std::string& key) const {
  return has(key) && node_[key].IsSequence();
}

YAML::Node ConfigSection::child(const std::string& key) const {
  used_->insert(key);
  const YAML::Node n = node_[key];
  if (!n.IsDefined() || n.IsNull()) fail(node_, key, "required but missing");
  return n;
}

template <>
double ConfigSection::get<double>(const std::string& key) const {
  const YAML::Node n = child(key);
  double v = 0;
  if (!n.IsScalar() || !YAML::convert<double>::decode(n, v) || !std::isfinite(v)) {
    fail(n, key, "expected a number, got " + type_name(n));
  }
  return v;
}

template <>
int ConfigSection::get<int>(const std::string& key) const {
  const YAML::Node n = child(key);
  int v = 0;
  if (!n.IsScalar() || !YAML::convert<int>::decode(n, v)) {
    fail(n, key, "expected an integer, got " + type_name(n));
  }
  return v;
}

template <>
bool ConfigSection::get<bool>(const std::string& key) const {
  const YAML::Node n = child(key);
  bool v = false;
  if (!n.IsScalar() || !YAML::convert<bool>::decode(n, v)) {
    fail(n, key, "expected true or false, got " + type_name(n));
  }
  return v;
}

template <>
std::string ConfigSection::get<std::string>(const std::string& key) const {
  const YAML::Node n = child(key);
  if (!n.IsScalar()) fail(n, key, "expected a string, got " + type_name(n));
  return n.Scalar();
}

template <>
std::vector<double> ConfigSection::get<std::vector<double>>(const std::string& key) const {
  const YAML::Node n = child(key);
  if (!n.IsSequence()) fail(n, key, "expected a list of numbers, got " + type_name(n));
  std::vector<double> out;
  for (std::size_t i = 0; i < n.size(); ++i) {
    double v = 0;
    if (!n[i].IsScalar() || !YAML::convert<double>::decode(n[i], v)) {
      fail(n[i], key, "element " + std::to_string(i) + " is not a number: " + type_name(n[i]));
    }
    out.push_back(v);
  }
  return out;
}

template <>
std::vector<std::string> ConfigSection::get<std::vector<std::string>>(
    const std::string& key) const {
  const YAML::Node n = child(key);
  if (!n.IsSequence()) fail(n, key, "expected a list of strings, got " + type_name(n));
  std::vector<std::string> out;
  for (std::size_t i = 0; i < n.size(); ++i) {
    if (!n[i].IsScalar()) fail(n[i], key, "element " + std::to_string(i) + " is not a string");
    out.push_back(n[i].Scalar());
  }
  return out;
}

double ConfigSection::get_in_range(const std::string& key, double fallback, double lo,
                                   double hi) const {
  if (!has(key)) return fallback;
  const double v = get<double>(key);
  if (v < lo || v > hi) {
    std::ostringstream what;
    what << "value " << v << " out of range [" << lo << ", " << hi << "]";
    fail(node_[key], key, what.str());
  }
  return v;
}

std::string ConfigSection::get_choice(const std::string& key, const std::string& fallback,
                                      const std::vector<std::string>& choices) const {
  if (!has(key)) return fallback;
  const std::string v = get<std::string>(key);
  if (std::find(choices.begin(), choices.end(), v) == choices.end()) {
    std::string list;
    for (const auto& c : choices) list += (list.empty() ? "" : "|") + c;
    fail(node_[key], key, "'" + v + "' is not one of " + list);
  }
  return v;
}

ConfigSection ConfigSection::section(const std::string& key) const {
  const YAML::Node n = child(key);
  if (!n.IsMap()) fail(n, key, "expected a mapping, got " + type_name(n));
  return ConfigSection(n, qualified(key), state_);
}

ConfigSection ConfigSection::section_or_empty(const std::string& key) const {
  if (!has(key)) return ConfigSection(YAML::Node(YAML::NodeType::Map), qualified(key), state_);
  return section(key);
}

void ConfigSection::reject(const std::string& key, const std::string& what) const {
  fail(node_.IsMap() ? node_[key] : YAML::Node(), key, what);
}

void ConfigSection::reject(const std::string& key, std::size_t index,
                           const std::string& what) const {
  const YAML::Node n = node_.IsMap() ? node_[key] : YAML::Node();
  const bool in_list = n.IsSequence() && index < n.size();
  fail(in_list ? n[index] : n, key, "element " + std::to_string(index) + ": " + what);
}

void ConfigSection::finish() const {
  if (!node_.IsMap()) return;
  for (const auto& kv : node_) {
    const std::string key = kv.first.as<std::string>();
    if (!used_->count(key)) fail(kv.first, key, "unknown key");
  }
}

}  // namespace semap::common
