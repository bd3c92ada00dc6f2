#include "semap/drivers/v4l2_device.hpp"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>

#include "semap/drivers/driver_error.hpp"
#include "v4l2_node.hpp"

namespace semap::drivers {

std::string fourcc_to_string(std::uint32_t fourcc) {
  std::string s;
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((fourcc >> (8 * i)) & 0x7f);
    if (c != ' ') s += c;
  }
  // Bit 31 marks the big-endian variant of a format (v4l2_fourcc_be).
  if (fourcc & (1u << 31)) s += "-BE";
  return s;
}

V4l2Device::V4l2Device(const std::string& path) : path_(path) {
  V4l2Node node = open_v4l2_node(path, V4L2_CAP_VIDEO_CAPTURE, "capture");
  fd_ = node.fd;
  card_ = std::move(node.card);
  driver_ = std::move(node.driver);
}

V4l2Device::~V4l2Device() {
  stop();
  ::close(fd_);
}

int V4l2Device::xioctl(unsigned long request, void* arg, const char* name) const {
  return v4l2_ioctl(fd_, path_, request, arg, name);
}

std::vector<V4l2FormatInfo> V4l2Device::formats() const {
  std::vector<V4l2FormatInfo> out;
  for (std::uint32_t index = 0;; ++index) {
    v4l2_fmtdesc desc{};
    desc.index = index;
    desc.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (::ioctl(fd_, VIDIOC_ENUM_FMT, &desc) < 0) {
      if (errno == EINVAL) break;  // end of the list
      throw_errno(path_ + ": VIDIOC_ENUM_FMT");
    }
    out.push_back({desc.pixelformat, reinterpret_cast<const char*>(desc.description)});
  }
  return out;
}

std::vector<V4l2FrameSize> V4l2Device::frame_sizes(std::uint32_t fourcc) const {
  std::vector<V4l2FrameSize> out;
  for (std::uint32_t index = 0;; ++index) {
    v4l2_frmsizeenum size{};
    size.index = index;
    size.pixel_format = fourcc;
    if (::ioctl(fd_, VIDIOC_ENUM_FRAMESIZES, &size) < 0) {
      if (errno == EINVAL || errno == ENOTTY) break;  // end of the list, or not supported
      throw_errno(path_ + ": VIDIOC_ENUM_FRAMESIZES");
    }
    if (size.type == V4L2_FRMSIZE_TYPE_DISCRETE) {
      const auto& d = size.discrete;
      out.push_back({d.width, d.width, 0, d.height, d.height, 0});
    } else {  // stepwise or continuous (steps of 1): one entry, the range
      const auto& s = size.stepwise;
      out.push_back(
          {s.min_width, s.max_width, s.step_width, s.min_height, s.max_height, s.step_height});
      break;
    }
  }
  return out;
}

std::vector<V4l2FrameInterval> V4l2Device::frame_intervals(std::uint32_t fourcc,
                                                           std::uint32_t width,
                                                           std::uint32_t height) const {
  const auto seconds = [](const v4l2_fract& f) {
    return f.denominator ? static_cast<double>(f.numerator) / f.denominator : 0.0;
  };
  std::vector<V4l2FrameInterval> out;
  for (std::uint32_t index = 0;; ++index) {
    v4l2_frmivalenum interval{};
    interval.index = index;
    interval.pixel_format = fourcc;
    interval.width = width;
    interval.height = height;
    if (::ioctl(fd_, VIDIOC_ENUM_FRAMEINTERVALS, &interval) < 0) {
      if (errno == EINVAL || errno == ENOTTY) break;
      throw_errno(path_ + ": VIDIOC_ENUM_FRAMEINTERVALS");
    }
    if (interval.type == V4L2_FRMIVAL_TYPE_DISCRETE) {
      const double s = seconds(interval.discrete);
      out.push_back({s, s, 0.0});
    } else {
      const auto& w = interval.stepwise;
      out.push_back({seconds(w.min), seconds(w.max), seconds(w.step)});
      break;
    }
  }
  return out;
}

V4l2Format V4l2Device::set_format(std::uint32_t fourcc, std::uint32_t width, std::uint32_t height) {
  v4l2_format fmt{};
  fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  fmt.fmt.pix.pixelformat = fourcc;
  fmt.fmt.pix.width = width;
  fmt.fmt.pix.height = height;
  fmt.fmt.pix.field = V4L2_FIELD_NONE;
  xioctl(VIDIOC_S_FMT, &fmt, "VIDIOC_S_FMT");
  if (fmt.fmt.pix.pixelformat != fourcc) {
    throw DriverError(path_ + ": format " + fourcc_to_string(fourcc) + " not supported (got " +
                          fourcc_to_string(fmt.fmt.pix.pixelformat) + ")",
                      EINVAL);
  }
  return {fmt.fmt.pix.pixelformat, fmt.fmt.pix.width, fmt.fmt.pix.height, fmt.fmt.pix.bytesperline,
          fmt.fmt.pix.sizeimage};
}

double V4l2Device::set_frame_rate(double fps) {
  v4l2_streamparm parm{};
  parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  xioctl(VIDIOC_G_PARM, &parm, "VIDIOC_G_PARM");
  if (!(parm.parm.capture.capability & V4L2_CAP_TIMEPERFRAME)) return 0.0;
  // 1/fps as a fraction with a millisecond-level denominator keeps rates like 29.97 exact.
  parm.parm.capture.timeperframe.numerator = 1000;
  parm.parm.capture.timeperframe.denominator = static_cast<std::uint32_t>(std::lround(fps * 1000));
  xioctl(VIDIOC_S_PARM, &parm, "VIDIOC_S_PARM");
  const auto& tpf = parm.parm.capture.timeperframe;
  return tpf.numerator ? static_cast<double>(tpf.denominator) / tpf.numerator : 0.0;
}

void V4l2Device::start(std::uint32_t buffer_count) {
  v4l2_requestbuffers req{};
  req.count = buffer_count;
  req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  req.memory = V4L2_MEMORY_MMAP;
  xioctl(VIDIOC_REQBUFS, &req, "VIDIOC_REQBUFS");
  if (req.count < 2) throw DriverError(path_ + ": too few capture buffers", ENOMEM);
  buffers_.resize(req.count);
  for (std::uint32_t i = 0; i < req.count; ++i) {
    v4l2_buffer buf{};
    buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buf.memory = V4L2_MEMORY_MMAP;
    buf.index = i;
    xioctl(VIDIOC_QUERYBUF, &buf, "VIDIOC_QUERYBUF");
    void* p = ::mmap(nullptr, buf.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, buf.m.offset);
    if (p == MAP_FAILED) throw_errno(path_ + ": mmap");
    buffers_[i] = {p, buf.length};
    xioctl(VIDIOC_QBUF, &buf, "VIDIOC_QBUF");
  }
  v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  xioctl(VIDIOC_STREAMON, &type, "VIDIOC_STREAMON");
  streaming_ = true;
}

void V4l2Device::stop() noexcept {
  if (streaming_) {
    v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    ::ioctl(fd_, VIDIOC_STREAMOFF, &type);  // fails harmlessly on a removed device
    streaming_ = false;
  }
  for (auto& b : buffers_) {
    if (b.start) ::munmap(b.start, b.length);
  }
  if (!buffers_.empty()) {
    v4l2_requestbuffers req{};
    req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    req.memory = V4L2_MEMORY_MMAP;
    ::ioctl(fd_, VIDIOC_REQBUFS, &req);
  }
  buffers_.clear();
  pending_ = -1;
}

void V4l2Device::requeue_pending() {
  if (pending_ < 0) return;
  v4l2_buffer buf{};
  buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  buf.memory = V4L2_MEMORY_MMAP;
  buf.index = static_cast<std::uint32_t>(pending_);
  pending_ = -1;
  xioctl(VIDIOC_QBUF, &buf, "VIDIOC_QBUF");
}

bool V4l2Device::dequeue(int timeout_ms, V4l2Frame& frame) {
  if (!streaming_) throw DriverError(path_ + ": dequeue before start", EINVAL);
  requeue_pending();
  pollfd pfd{fd_, POLLIN, 0};
  const int r = ::poll(&pfd, 1, timeout_ms);
  if (r < 0) {
    if (errno == EINTR) return false;
    throw_errno(path_ + ": poll");
  }
  if (r == 0) return false;
  if (pfd.revents & (POLLERR | POLLHUP | POLLNVAL)) {
    // After unbind the device reports POLLERR; DQBUF gives the precise errno (ENODEV).
    v4l2_buffer probe{};
    probe.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    probe.memory = V4L2_MEMORY_MMAP;
    xioctl(VIDIOC_DQBUF, &probe, "VIDIOC_DQBUF");
    throw DriverError(path_ + ": device reported an error (poll)", EIO);
  }
  v4l2_buffer buf{};
  buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  buf.memory = V4L2_MEMORY_MMAP;
  if (::ioctl(fd_, VIDIOC_DQBUF, &buf) < 0) {
    if (errno == EAGAIN) return false;
    throw_errno(path_ + ": VIDIOC_DQBUF");
  }
  pending_ = static_cast<int>(buf.index);
  const auto& b = buffers_.at(buf.index);
  frame.bytes = {static_cast<const std::uint8_t*>(b.start),
                 std::min<std::size_t>(buf.bytesused, b.length)};
  frame.stamp = common::Stamp::from_timeval(buf.timestamp);
  frame.kernel_stamped = true;
  frame.sequence = buf.sequence;
  frame.error = (buf.flags & V4L2_BUF_FLAG_ERROR) != 0;
  if ((buf.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK) != V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC) {
    // Only monotonic timestamps share the pipeline's clock; fall back to the dequeue time.
    frame.stamp = common::Stamp::now();
    frame.kernel_stamped = false;
  }
  return true;
}

}  // namespace semap::drivers
