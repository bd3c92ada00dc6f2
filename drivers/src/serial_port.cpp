#include "semap/drivers/serial_port.hpp"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <stdexcept>

#include "semap/drivers/driver_error.hpp"

namespace semap::drivers {

unsigned int baud_constant(int baud) {
  switch (baud) {
    case 4800:
      return B4800;
    case 9600:
      return B9600;
    case 19200:
      return B19200;
    case 38400:
      return B38400;
    case 57600:
      return B57600;
    case 115200:
      return B115200;
    case 230400:
      return B230400;
    case 460800:
      return B460800;
    case 921600:
      return B921600;
    default:
      throw std::invalid_argument("unsupported baud rate " + std::to_string(baud));
  }
}

SerialPort::SerialPort(const SerialConfig& config) : device_(config.device) {
  const speed_t speed = baud_constant(config.baud);
  fd_ = ::open(device_.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) throw_errno("open " + device_);
  termios tio{};
  if (::tcgetattr(fd_, &tio) < 0) {
    const int e = errno;
    ::close(fd_);
    errno = e;
    throw_errno(device_ + ": tcgetattr");
  }
  ::cfmakeraw(&tio);  // no echo, no canonical mode, no CR/LF translation, 8 bits
  tio.c_cflag &= ~static_cast<tcflag_t>(PARENB | CSTOPB | CSIZE | CRTSCTS);
  tio.c_cflag |= CS8 | CLOCAL | CREAD;
  tio.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);
  tio.c_cc[VMIN] = static_cast<cc_t>(config.vmin);
  tio.c_cc[VTIME] = static_cast<cc_t>(config.vtime);
  ::cfsetispeed(&tio, speed);
  ::cfsetospeed(&tio, speed);
  if (::tcsetattr(fd_, TCSANOW, &tio) < 0) {
    const int e = errno;
    ::close(fd_);
    errno = e;
    throw_errno(device_ + ": tcsetattr");
  }
  ::tcflush(fd_, TCIFLUSH);  // bytes from before we configured the port are not trustworthy
  // Blocking reads after poll() so that VMIN/VTIME apply.
  ::fcntl(fd_, F_SETFL, ::fcntl(fd_, F_GETFL) & ~O_NONBLOCK);
}

SerialPort::~SerialPort() { ::close(fd_); }

SerialRead SerialPort::read_some(std::span<std::uint8_t> buffer, int timeout_ms, std::size_t& n) {
  n = 0;
  pollfd pfd{fd_, POLLIN, 0};
  const int r = ::poll(&pfd, 1, timeout_ms);
  if (r < 0) {
    if (errno == EINTR) return SerialRead::kTimeout;
    throw_errno(device_ + ": poll");
  }
  if (r == 0) return SerialRead::kTimeout;
  if (pfd.revents & POLLNVAL) throw DriverError(device_ + ": poll: invalid descriptor", EBADF);
  if (pfd.revents & POLLIN) {
    const ssize_t got = ::read(fd_, buffer.data(), buffer.size());
    if (got > 0) {
      n = static_cast<std::size_t>(got);
      return SerialRead::kData;
    }
    if (got < 0 && errno != EAGAIN && errno != EINTR) throw_errno(device_ + ": read");
    if (got < 0) return SerialRead::kTimeout;
  }
  // POLLHUP/POLLERR without data, or a zero-length read: the other end went away.
  throw DriverError(device_ + ": hang-up", EIO);
}

}  // namespace semap::drivers
