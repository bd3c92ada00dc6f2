#pragma once

#include <stdexcept>
#include <string>

namespace semap::drivers {

// A failure of a kernel interface call; the message names the device and the call, and `error`
// keeps errno so that a driver can tell a vanished device (ENODEV, EIO, ENETDOWN) from a bug.
class DriverError : public std::runtime_error {
 public:
  DriverError(const std::string& what, int error);
  int error() const { return error_; }

 private:
  int error_;
};

// Throws DriverError("<context>: <strerror(errno)>", errno).
[[noreturn]] void throw_errno(const std::string& context);

}  // namespace semap::drivers
