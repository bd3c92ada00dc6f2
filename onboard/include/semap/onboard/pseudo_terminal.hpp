#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

namespace semap::onboard {

// A pseudo-terminal standing in for a receiver's serial port: the rig writes the receiver's
// bytes into the master side and the real GnssDriver opens the slave by its name, with termios.
// The slave stays open here too, so the master never sees a hang-up between driver reconnects.
class PseudoTerminal {
 public:
  PseudoTerminal();  // throws std::runtime_error when openpty fails
  ~PseudoTerminal();
  PseudoTerminal(const PseudoTerminal&) = delete;
  PseudoTerminal& operator=(const PseudoTerminal&) = delete;

  int master() const { return master_; }  // non-blocking
  const std::string& slave_name() const { return slave_name_; }
  // Writes all of `bytes`, waiting up to 100 ms for room; returns the bytes not taken (as a
  // UART overruns when nobody reads).
  std::size_t write(std::span<const std::uint8_t> bytes);

 private:
  int master_ = -1;
  int slave_ = -1;
  std::string slave_name_;
};

}  // namespace semap::onboard
