#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "semap/common/messages.hpp"
#include "semap/common/stamp.hpp"
#include "semap/firmware_bridge/gnss_fix_builder.hpp"
#include "semap/firmware_bridge/gnss_framer.h"

namespace semap::firmware_bridge {

struct GnssStreamCounters {
  std::uint64_t bytes = 0;
  std::uint64_t garbage_bytes = 0;
  std::uint64_t nmea_sentences = 0;  // parsed and decoded
  std::uint64_t ubx_frames = 0;      // NAV-PVT decoded
  std::uint64_t rtcm3_frames = 0;    // RTCM3 corrections, CRC-checked and skipped
  std::uint64_t text_lines = 0;      // '#' comments and '{' JSON lines skipped
  std::uint64_t bad_checksum = 0;    // NMEA, UBX and RTCM3
  std::uint64_t too_long = 0;
  std::uint64_t truncated = 0;
  // Well-formed but not decoded: GSV and other sentences, other UBX ids (also those too long to
  // buffer, skipped as they arrive).
  std::uint64_t unknown = 0;
  std::uint64_t bad_field = 0;  // checksum fine, a value malformed
  std::uint64_t fixes = 0;      // GnssFix produced

  GnssStreamCounters& operator+=(const GnssStreamCounters& o);
};

// One serial byte stream (NMEA, UBX, RTCM3 and text lines interleaved) to GnssFix: framer,
// parsers, fix builder and counters of every rejection kind. Not thread-safe; one per device.
class GnssStreamDecoder {
 public:
  explicit GnssStreamDecoder(const GnssFixBuilderConfig& config = {});

  // Feeds bytes read at `stamp`, appending each completed fix to `fixes`.
  void feed(std::span<const std::uint8_t> bytes, common::Stamp stamp,
            std::vector<common::GnssFix>& fixes);

  const GnssStreamCounters& counters() const { return counters_; }

 private:
  void drain(common::Stamp stamp, std::vector<common::GnssFix>& fixes);
  void count(SemapFbStatus status);

  SemapGnssFramer framer_{};
  GnssFixBuilder builder_;
  GnssStreamCounters counters_;
};

}  // namespace semap::firmware_bridge
