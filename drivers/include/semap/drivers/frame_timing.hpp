#pragma once

#include <cstdint>
#include <span>

#include "semap/common/stamp.hpp"

namespace semap::drivers {

// How steadily a camera delivered: from the driver's stamps and sequence numbers of consecutive
// dequeued frames, against the frame rate the device negotiated.
struct FrameTiming {
  std::size_t frames = 0;
  double fps = 0;               // (frames - 1) / (last stamp - first stamp)
  double mean_interval_ms = 0;  // between consecutive stamps
  double jitter_ms = 0;         // standard deviation of those intervals
  double max_deviation_ms = 0;  // largest |interval - 1000 / nominal_fps|
  std::uint64_t skipped = 0;    // frames the driver's sequence numbers say were never dequeued
};

// `stamps` and `sequences` of the same frames, in dequeue order. `nominal_fps` 0: no nominal
// rate, max_deviation_ms is then from the mean interval.
FrameTiming measure_frame_timing(std::span<const common::Stamp> stamps,
                                 std::span<const std::uint32_t> sequences, double nominal_fps);

}  // namespace semap::drivers
