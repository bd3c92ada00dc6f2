#pragma once

#include <cstdint>

namespace semap::firmware_bridge {

// What a GNSS receiver speaks on its serial port.
enum class GnssProtocol : std::uint8_t { kNmea, kUbx };

}  // namespace semap::firmware_bridge
