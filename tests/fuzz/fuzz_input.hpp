#pragma once
// Reads typed fields from a fuzz input, front to back; past the end every read yields zeros,
// so a target can build a whole message from however many bytes it gets.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <vector>

namespace semap::fuzz {

class FuzzInput {
 public:
  FuzzInput(const std::uint8_t* data, std::size_t size) : bytes_(data, size) {}

  template <typename T>
  T take() {
    T value{};
    const std::size_t n = std::min(sizeof(T), remaining());
    if (n > 0) std::memcpy(&value, bytes_.data() + offset_, n);
    offset_ += n;
    return value;
  }
  // Up to `n` bytes (fewer at the end).
  std::span<const std::uint8_t> take_bytes(std::size_t n) {
    const auto out = bytes_.subspan(offset_, std::min(n, remaining()));
    offset_ += out.size();
    return out;
  }
  // A string of length byte % (max + 1), without NULs (the C strings of a DDS sample).
  std::string take_string(std::size_t max) {
    const auto raw = take_bytes(take<std::uint8_t>() % (max + 1));
    std::string s(raw.begin(), raw.end());
    std::replace(s.begin(), s.end(), '\0', '?');
    return s;
  }
  std::span<const std::uint8_t> rest() { return take_bytes(remaining()); }
  std::size_t remaining() const { return bytes_.size() - offset_; }

 private:
  std::span<const std::uint8_t> bytes_;
  std::size_t offset_ = 0;
};

}  // namespace semap::fuzz
