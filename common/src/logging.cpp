#include "semap/common/logging.hpp"

#include <spdlog/sinks/stdout_color_sinks.h>

namespace semap::common {

void setup_logging(const std::string& level) {
  spdlog::set_pattern("[%H:%M:%S.%e] [%n] [%^%l%$] %v");
  spdlog::set_level(spdlog::level::from_str(level));
}

std::shared_ptr<spdlog::logger> logger(const std::string& name) {
  if (auto existing = spdlog::get(name)) return existing;
  try {
    auto created = spdlog::stderr_color_mt(name);
    created->set_level(spdlog::get_level());
    return created;
  } catch (const spdlog::spdlog_ex&) {
    return spdlog::get(name);  // another thread registered it first
  }
}

}  // namespace semap::common
