#include "semap/drivers/v4l2_output.hpp"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "semap/drivers/driver_error.hpp"
#include "v4l2_node.hpp"

namespace semap::drivers {

V4l2Output::V4l2Output(const std::string& path) : path_(path) {
  V4l2Node node = open_v4l2_node(path, V4L2_CAP_VIDEO_OUTPUT, "output");
  fd_ = node.fd;
  card_ = std::move(node.card);
}

V4l2Output::~V4l2Output() {
  stop();
  ::close(fd_);
}

int V4l2Output::xioctl(unsigned long request, void* arg, const char* name) const {
  return v4l2_ioctl(fd_, path_, request, arg, name);
}

V4l2Format V4l2Output::set_format(std::uint32_t fourcc, std::uint32_t width, std::uint32_t height) {
  v4l2_format fmt{};
  fmt.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
  fmt.fmt.pix.pixelformat = fourcc;
  fmt.fmt.pix.width = width;
  fmt.fmt.pix.height = height;
  fmt.fmt.pix.field = V4L2_FIELD_NONE;
  xioctl(VIDIOC_S_FMT, &fmt, "VIDIOC_S_FMT");
  if (fmt.fmt.pix.pixelformat != fourcc) {
    throw DriverError(path_ + ": output format " + fourcc_to_string(fourcc) +
                          " not supported (got " + fourcc_to_string(fmt.fmt.pix.pixelformat) + ")",
                      EINVAL);
  }
  format_ = {fmt.fmt.pix.pixelformat, fmt.fmt.pix.width, fmt.fmt.pix.height,
             fmt.fmt.pix.bytesperline, fmt.fmt.pix.sizeimage};
  return format_;
}

void V4l2Output::start(std::uint32_t buffer_count) {
  v4l2_requestbuffers req{};
  req.count = buffer_count;
  req.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
  req.memory = V4L2_MEMORY_MMAP;
  xioctl(VIDIOC_REQBUFS, &req, "VIDIOC_REQBUFS");
  if (req.count < 2) throw DriverError(path_ + ": too few output buffers", ENOMEM);
  buffers_.resize(req.count);
  for (std::uint32_t i = 0; i < req.count; ++i) {
    v4l2_buffer buf{};
    buf.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
    buf.memory = V4L2_MEMORY_MMAP;
    buf.index = i;
    xioctl(VIDIOC_QUERYBUF, &buf, "VIDIOC_QUERYBUF");
    void* p = ::mmap(nullptr, buf.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, buf.m.offset);
    if (p == MAP_FAILED) throw_errno(path_ + ": mmap");
    buffers_[i] = {p, buf.length, false};
  }
  v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
  xioctl(VIDIOC_STREAMON, &type, "VIDIOC_STREAMON");
  streaming_ = true;
}

void V4l2Output::stop() noexcept {
  if (streaming_) {
    v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
    ::ioctl(fd_, VIDIOC_STREAMOFF, &type);  // fails harmlessly on a removed device
    streaming_ = false;
  }
  for (auto& b : buffers_) {
    if (b.start) ::munmap(b.start, b.length);
  }
  if (!buffers_.empty()) {
    v4l2_requestbuffers req{};
    req.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
    req.memory = V4L2_MEMORY_MMAP;
    ::ioctl(fd_, VIDIOC_REQBUFS, &req);
  }
  buffers_.clear();
}

bool V4l2Output::reclaim() {
  v4l2_buffer buf{};
  buf.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
  buf.memory = V4L2_MEMORY_MMAP;
  if (::ioctl(fd_, VIDIOC_DQBUF, &buf) < 0) {
    if (errno == EAGAIN || errno == EINTR) return false;
    throw_errno(path_ + ": VIDIOC_DQBUF");
  }
  buffers_.at(buf.index).queued = false;
  return true;
}

bool V4l2Output::write(std::span<const std::uint8_t> image, std::size_t stride, int timeout_ms) {
  if (!streaming_) throw DriverError(path_ + ": write before start", EINVAL);
  const std::size_t row = std::min<std::size_t>(stride, format_.stride);
  if (format_.height == 0 || image.size() < stride * (format_.height - 1) + row) {
    throw DriverError(path_ + ": a frame of " + std::to_string(image.size()) +
                          " bytes does not fill " + std::to_string(format_.width) + "x" +
                          std::to_string(format_.height),
                      EINVAL);
  }
  const auto queued = [](const Buffer& b) { return b.queued; };
  while (std::any_of(buffers_.begin(), buffers_.end(), queued) && reclaim()) {
  }
  auto free = std::find_if_not(buffers_.begin(), buffers_.end(), queued);
  if (free == buffers_.end()) {
    // Every buffer is with the device: wait until it hands one back.
    pollfd pfd{fd_, POLLOUT, 0};
    if (::poll(&pfd, 1, timeout_ms) < 0 && errno != EINTR) throw_errno(path_ + ": poll");
    if (!reclaim()) return false;
    free = std::find_if_not(buffers_.begin(), buffers_.end(), queued);
  }
  auto* out = static_cast<std::uint8_t*>(free->start);
  for (std::uint32_t v = 0; v < format_.height; ++v) {
    std::memcpy(out + static_cast<std::size_t>(v) * format_.stride, image.data() + v * stride, row);
  }
  v4l2_buffer buf{};
  buf.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
  buf.memory = V4L2_MEMORY_MMAP;
  buf.index = static_cast<std::uint32_t>(free - buffers_.begin());
  buf.bytesused = format_.image_size;
  buf.field = V4L2_FIELD_NONE;
  xioctl(VIDIOC_QBUF, &buf, "VIDIOC_QBUF");
  free->queued = true;
  return true;
}

}  // namespace semap::drivers
