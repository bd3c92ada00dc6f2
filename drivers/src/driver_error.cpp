#include "semap/drivers/driver_error.hpp"

#include <cerrno>
#include <cstring>

namespace semap::drivers {

DriverError::DriverError(const std::string& what, int error)
    : std::runtime_error(what), error_(error) {}

void throw_errno(const std::string& context) {
  const int error = errno;
  throw DriverError(context + ": " + std::strerror(error), error);
}

}  // namespace semap::drivers
