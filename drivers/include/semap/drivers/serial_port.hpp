#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

namespace semap::drivers {

struct SerialConfig {
  std::string device = "/dev/ttyUSB0";
  int baud = 115200;
  // termios VMIN/VTIME for the read after poll() reported data: VMIN=1, VTIME=0 returns what
  // is buffered at once.
  int vmin = 1;
  int vtime = 0;
};

// Outcome of one bounded wait for serial data.
enum class SerialRead : std::uint8_t { kData, kTimeout };

// A serial device in raw mode, 8N1, no flow control, at a fixed baud rate. read_some() throws
// DriverError on EIO/ENODEV or hang-up (POLLHUP), which is how a vanished USB adapter or a
// closed pty master shows up.
class SerialPort {
 public:
  explicit SerialPort(const SerialConfig& config);
  ~SerialPort();
  SerialPort(const SerialPort&) = delete;
  SerialPort& operator=(const SerialPort&) = delete;

  // Waits up to timeout_ms, then reads what is available into `buffer`; `n` is the count.
  SerialRead read_some(std::span<std::uint8_t> buffer, int timeout_ms, std::size_t& n);
  int fd() const { return fd_; }
  const std::string& device() const { return device_; }

 private:
  std::string device_;
  int fd_ = -1;
};

// The termios speed constant for a baud rate; throws std::invalid_argument if unsupported.
unsigned int baud_constant(int baud);

}  // namespace semap::drivers
