#include "semap/dds_idl/ros2msg.hpp"

#include <algorithm>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace semap::dds_idl {

// cmake/SemapEmbed.cmake: the files of dds_idl/msg, "pkg/Type.msg" -> text.
std::vector<std::pair<std::string_view, std::string_view>> embedded_msg_files();

namespace {

// "pkg/Type" -> text.
const std::map<std::string, std::string_view, std::less<>>& definitions() {
  static const auto defs = [] {
    std::map<std::string, std::string_view, std::less<>> m;
    for (const auto& [path, text] : embedded_msg_files()) {
      std::string name(path);
      if (name.size() > 4 && name.ends_with(".msg")) name.resize(name.size() - 4);
      m.emplace(std::move(name), text);
    }
    return m;
  }();
  return defs;
}

bool is_primitive(std::string_view t) {
  static const std::set<std::string_view> kPrimitives = {
      "bool",  "byte",   "char",  "float32", "float64", "int8",    "uint8", "int16",   "uint16",
      "int32", "uint32", "int64", "uint64",  "string",  "wstring", "time",  "duration"};
  return kPrimitives.count(t) != 0;
}

// "nav_msgs/msg/Odometry" or "nav_msgs/Odometry" -> "nav_msgs/Odometry".
std::string short_name(std::string_view type) {
  std::string s(type);
  const auto p = s.find("/msg/");
  if (p != std::string::npos) s.erase(p, 4);
  return s;
}

// The complex types one definition's fields use, as "pkg/Type", in order.
std::vector<std::string> field_types(std::string_view package, std::string_view text) {
  std::vector<std::string> out;
  std::istringstream in{std::string(text)};
  std::string line;
  while (std::getline(in, line)) {
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    std::istringstream words(line);
    std::string type;
    if (!(words >> type)) continue;
    type = type.substr(0, type.find('['));  // arrays
    type = type.substr(0, type.find('<'));  // bounded strings
    if (is_primitive(type)) continue;
    if (type == "Header") type = "std_msgs/Header";
    if (type.find('/') == std::string::npos) {
      std::string qualified(package);
      qualified.push_back('/');
      qualified.append(type);
      type = std::move(qualified);
    }
    out.push_back(short_name(type));
  }
  return out;
}

std::string_view definition(const std::string& name, std::string_view wanted_by) {
  const auto it = definitions().find(name);
  if (it == definitions().end()) {
    throw std::invalid_argument(
        "ros2msg_schema: no .msg definition of " + name +
        (wanted_by.empty() ? "" : " (used by " + std::string(wanted_by) + ")"));
  }
  return it->second;
}

}  // namespace

std::vector<std::string> ros2msg_types() {
  std::vector<std::string> out;
  for (const auto& [name, text] : definitions()) {
    const auto slash = name.find('/');
    std::string full = name.substr(0, slash);
    full.append("/msg");
    full.append(name, slash);
    out.push_back(std::move(full));
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::string ros2msg_schema(std::string_view type) {
  const std::string root = short_name(type);
  std::string out(definition(root, {}));
  // Dependencies in the order they are first used, depth first, each once.
  std::set<std::string> seen{root};
  std::vector<std::pair<std::string, std::string>> stack;  // (type, wanted by)
  const auto push_fields = [&](const std::string& name, std::string_view text) {
    const auto types = field_types(name.substr(0, name.find('/')), text);
    for (auto it = types.rbegin(); it != types.rend(); ++it) stack.emplace_back(*it, name);
  };
  push_fields(root, out);
  while (!stack.empty()) {
    auto [name, wanted_by] = std::move(stack.back());
    stack.pop_back();
    if (!seen.insert(name).second) continue;
    const std::string_view text = definition(name, wanted_by);
    if (!out.empty() && out.back() != '\n') out += '\n';
    out.append(80, '=');
    out.append("\nMSG: ");
    out.append(name);
    out.push_back('\n');
    out.append(text);
    push_fields(name, text);
  }
  return out;
}

std::string ros2_type_name(std::string_view dds_type_name) {
  // Scopes separated by "::", the "dds_" scope left out, the trailing '_' of the name too.
  std::string out;
  out.reserve(dds_type_name.size());
  std::string_view rest = dds_type_name;
  while (!rest.empty()) {
    const auto sep = rest.find("::");
    std::string_view scope = rest.substr(0, sep);
    rest = sep == std::string_view::npos ? std::string_view{} : rest.substr(sep + 2);
    if (scope == "dds_") continue;
    if (rest.empty() && scope.ends_with('_')) scope.remove_suffix(1);
    if (!out.empty()) out.push_back('/');
    out.append(scope);
  }
  return out;
}

std::string ros2_topic_name(std::string_view dds_topic) {
  if (dds_topic.starts_with("rt/")) dds_topic.remove_prefix(2);
  std::string out;
  out.reserve(dds_topic.size() + 1);
  if (!dds_topic.starts_with('/')) out.push_back('/');
  out.append(dds_topic);
  return out;
}

}  // namespace semap::dds_idl
