#pragma once

#include <spdlog/spdlog.h>

#include <memory>
#include <string>

namespace semap::common {

// Sets the default spdlog logger's level ("trace".."off") and pattern once per process.
void setup_logging(const std::string& level = "info");

// A named logger that shares the default sink; created on first use.
std::shared_ptr<spdlog::logger> logger(const std::string& name);

}  // namespace semap::common
