#include "semap/drivers/can_socket.hpp"

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <linux/errqueue.h>
#include <linux/net_tstamp.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <vector>

#include "semap/drivers/driver_error.hpp"
#include "semap/firmware_bridge/linux_can.hpp"

namespace semap::drivers {

bool interface_is_up(const std::string& interface) {
  const int s = ::socket(AF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
  if (s < 0) return false;
  ifreq ifr{};
  std::strncpy(ifr.ifr_name, interface.c_str(), IFNAMSIZ - 1);
  const bool up = ::ioctl(s, SIOCGIFFLAGS, &ifr) == 0 && (ifr.ifr_flags & IFF_UP);
  ::close(s);
  return up;
}

CanSocket::CanSocket(const std::string& interface,
                     std::span<const firmware_bridge::CanIdFilter> filters, bool enable_fd,
                     int receive_buffer)
    : interface_(interface) {
  if (interface.size() >= IFNAMSIZ) throw DriverError("CAN interface name too long", EINVAL);
  const unsigned int index = ::if_nametoindex(interface.c_str());
  if (index == 0) throw_errno("CAN interface " + interface);
  if (!interface_is_up(interface)) throw DriverError(interface + ": interface is down", ENETDOWN);

  fd_ = ::socket(AF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
  if (fd_ < 0) throw_errno("socket(AF_CAN)");
  try {
    std::vector<can_filter> kernel_filters;
    for (const auto& f : filters) {
      can_filter k{};
      k.can_id = f.id | (f.extended ? CAN_EFF_FLAG : 0);
      // Matching on the EFF and RTR bits keeps standard, extended and remote frames apart.
      k.can_mask = f.mask | CAN_EFF_FLAG | CAN_RTR_FLAG;
      kernel_filters.push_back(k);
    }
    if (::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FILTER, kernel_filters.data(),
                     static_cast<socklen_t>(kernel_filters.size() * sizeof(can_filter))) < 0) {
      throw_errno(interface + ": CAN_RAW_FILTER");
    }
    // State changes (warning, passive, active) come as CAN_ERR_CRTL; bus errors are left out:
    // with berr-reporting on they arrive per faulty frame and say nothing the states do not.
    const can_err_mask_t err_mask = CAN_ERR_BUSOFF | CAN_ERR_RESTARTED | CAN_ERR_CRTL;
    if (::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err_mask, sizeof(err_mask)) < 0) {
      throw_errno(interface + ": CAN_RAW_ERR_FILTER");
    }
    if (enable_fd) {
      const int on = 1;
      if (::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &on, sizeof(on)) < 0) {
        throw_errno(interface + ": CAN_RAW_FD_FRAMES");
      }
    }
    // FORCE lifts the rmem_max cap when we are privileged; otherwise take what is allowed.
    if (::setsockopt(fd_, SOL_SOCKET, SO_RCVBUFFORCE, &receive_buffer, sizeof(receive_buffer)) <
        0) {
      ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &receive_buffer, sizeof(receive_buffer));
    }
    const int on = 1;
    if (::setsockopt(fd_, SOL_SOCKET, SO_RXQ_OVFL, &on, sizeof(on)) < 0) {
      throw_errno(interface + ": SO_RXQ_OVFL");
    }
    const int ts_flags = SOF_TIMESTAMPING_RX_SOFTWARE | SOF_TIMESTAMPING_SOFTWARE;
    if (::setsockopt(fd_, SOL_SOCKET, SO_TIMESTAMPING, &ts_flags, sizeof(ts_flags)) < 0) {
      throw_errno(interface + ": SO_TIMESTAMPING");
    }
    sockaddr_can addr{};
    addr.can_family = AF_CAN;
    addr.can_ifindex = static_cast<int>(index);
    if (::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) < 0) {
      throw_errno(interface + ": bind");
    }
  } catch (...) {
    ::close(fd_);
    throw;
  }
}

CanSocket::CanSocket(const std::string& interface, bool enable_fd)
    : CanSocket(interface, {}, enable_fd) {}

CanSocket::~CanSocket() { ::close(fd_); }

CanRead CanSocket::receive(int timeout_ms, CanRxFrame& frame) {
  pollfd pfd{fd_, POLLIN, 0};
  const int r = ::poll(&pfd, 1, timeout_ms);
  if (r < 0) {
    if (errno == EINTR) return CanRead::kTimeout;
    throw_errno(interface_ + ": poll");
  }
  if (r == 0) return CanRead::kTimeout;

  canfd_frame raw{};
  iovec iov{&raw, sizeof(raw)};
  alignas(cmsghdr) char
      control[CMSG_SPACE(sizeof(scm_timestamping)) + CMSG_SPACE(sizeof(std::uint32_t))];
  msghdr msg{};
  msg.msg_iov = &iov;
  msg.msg_iovlen = 1;
  msg.msg_control = control;
  msg.msg_controllen = sizeof(control);
  // The interface going down sets a socket error (ENETDOWN) that recvmsg returns here.
  const ssize_t got = ::recvmsg(fd_, &msg, MSG_DONTWAIT);
  if (got < 0) {
    if (errno == EAGAIN || errno == EINTR) return CanRead::kTimeout;
    throw_errno(interface_ + ": recvmsg");
  }
  if (got != static_cast<ssize_t>(CAN_MTU) && got != static_cast<ssize_t>(CANFD_MTU)) {
    throw DriverError(interface_ + ": short CAN read", EIO);
  }
  CanRead kind = CanRead::kFrame;
  if (raw.can_id & CAN_ERR_FLAG) {
    can_frame error{};
    std::memcpy(&error, &raw, sizeof(error));
    frame.error = classify_error_frame(error);
    frame.frame = SemapCanFrame{};
    frame.frame.id = raw.can_id & CAN_ERR_MASK;
    frame.frame.len = CAN_ERR_DLC;
    std::memcpy(frame.frame.data, raw.data, CAN_ERR_DLC);
    kind = CanRead::kError;
  } else if (!firmware_bridge::from_kernel_frame(&raw, static_cast<std::size_t>(got),
                                                 frame.frame)) {
    return CanRead::kTimeout;  // remote frame: not part of any protocol we decode
  }
  frame.stamp = common::Stamp::now();
  frame.kernel_stamped = false;
  frame.realtime_ns = clock_.to_realtime(frame.stamp);
  for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c; c = CMSG_NXTHDR(&msg, c)) {
    if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMPING) {
      scm_timestamping ts{};
      std::memcpy(&ts, CMSG_DATA(c), sizeof(ts));
      if (ts.ts[0].tv_sec != 0 || ts.ts[0].tv_nsec != 0) {
        frame.realtime_ns = common::Stamp::from_timespec(ts.ts[0]).ns;
        frame.stamp = clock_.to_monotonic(frame.realtime_ns);
        frame.kernel_stamped = true;
      }
    } else if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_RXQ_OVFL) {
      std::memcpy(&frame.kernel_drops, CMSG_DATA(c), sizeof(frame.kernel_drops));
    }
  }
  return kind;
}

}  // namespace semap::drivers
