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
  std::uint64_t bad_checksum = 0;    // NMEA and UBX
  std::uint64_t too_long = 0;
  std::uint64_t truncated = 0;
  std::uint64_t unknown = 0;    // well-formed but not decoded (GSV, other UBX ids, ...)
  std::uint64_t bad_field = 0;  // checksum fine, a value malformed
  std::uint64_t fixes = 0;      // GnssFix produced
};

// One serial byte stream (NMEA and UBX interleaved) to GnssFix: framer, parsers, fix builder
// and counters of every rejection kind. Not thread-safe; one per device.
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
