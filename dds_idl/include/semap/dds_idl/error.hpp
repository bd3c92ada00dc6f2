#pragma once

#include <dds/dds.h>

#include <stdexcept>
#include <string>
#include <string_view>

namespace semap::dds_idl {

// A failed Cyclone DDS call: the message names the call and carries dds_strretcode's text.
class DdsError : public std::runtime_error {
 public:
  DdsError(std::string_view what, dds_return_t code);
  dds_return_t code() const { return code_; }

 private:
  dds_return_t code_;
};

// Returns `rc` when it is not an error (entity handles and counts are positive), else throws.
dds_return_t check(dds_return_t rc, std::string_view what);

}  // namespace semap::dds_idl
