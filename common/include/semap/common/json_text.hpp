#pragma once

#include <string>
#include <string_view>

namespace semap::common {

// `s` as a JSON string literal: quoted, with quotes, backslashes and control characters escaped.
std::string json_string(std::string_view s);

}  // namespace semap::common
