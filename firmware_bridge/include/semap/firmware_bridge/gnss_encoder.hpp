#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "semap/common/messages.hpp"
#include "semap/firmware_bridge/nmea.h"
#include "semap/firmware_bridge/ubx.h"

namespace semap::firmware_bridge {

// Sentences of one NMEA epoch for a fix, in receiver order: RMC, VTG, GST, HDT (when the fix
// has a heading), GGA (each with CR LF). `utc_unix_ms` is the epoch's UTC time. Covariance becomes
// the GST ellipse and sigmas; altitude is written as MSL with zero geoid separation.
std::vector<std::string> encode_nmea_epoch(const common::GnssFix& fix, std::int64_t utc_unix_ms,
                                           SemapNmeaTalker talker);

// NAV-PVT in wire units for a fix (hAcc from the horizontal covariance trace).
SemapUbxNavPvt nav_pvt_from_fix(const common::GnssFix& fix, std::int64_t utc_unix_ms);
// The complete UBX frame of nav_pvt_from_fix.
std::vector<std::uint8_t> encode_ubx_epoch(const common::GnssFix& fix, std::int64_t utc_unix_ms);

}  // namespace semap::firmware_bridge
