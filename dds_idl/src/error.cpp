#include "semap/dds_idl/error.hpp"

namespace semap::dds_idl {

DdsError::DdsError(std::string_view what, dds_return_t code)
    : std::runtime_error(std::string(what) + ": " + dds_strretcode(code) + " (" +
                         std::to_string(code) + ")"),
      code_(code) {}

dds_return_t check(dds_return_t rc, std::string_view what) {
  if (rc < 0) throw DdsError(what, rc);
  return rc;
}

}  // namespace semap::dds_idl
