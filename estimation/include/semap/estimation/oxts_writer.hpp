#pragma once

// The KITTI raw OXTS format written from navigation states, so a simulated drive can be stored
// the way the dataset stores a real one (read back by oxts_reader.hpp).
#include <string>

#include "semap/common/messages.hpp"
#include "semap/common/stamp.hpp"
#include "semap/estimation/geodesy.hpp"
#include "semap/estimation/nav_state.hpp"
#include "semap/estimation/oxts_reader.hpp"

namespace semap::estimation {

// "YYYY-MM-DD HH:MM:SS.nnnnnnnnn" (UTC) of a stamp in nanoseconds since the epoch: the inverse
// of parse_kitti_timestamp.
std::string format_kitti_timestamp(common::Stamp stamp);

// The 30 values of one OXTS line (dataformat.txt order), enough digits to read back the
// position to well under a millimetre. The level-frame values (vf/vl/vu, af/al/au, wf/wl/wu)
// repeat the body-frame ones: the reader uses only the latter.
std::string format_oxts_line(const OxtsRecord& record);

// The record an OXTS unit would report for `state` (world = ENU at `enu`'s origin, body x
// forward, y left, z up, as the simulator's) with the specific force and rates of `imu`.
OxtsRecord oxts_record_from_state(const NavState& state, const common::ImuSample& imu,
                                  const LocalEnu& enu, double position_accuracy_m = 0.05);

}  // namespace semap::estimation
