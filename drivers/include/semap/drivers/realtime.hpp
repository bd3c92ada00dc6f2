#pragma once

#include <string>

namespace semap::drivers {

// A driver thread at SCHED_FIFO reads its device before any normally scheduled thread runs, so
// a busy perception or mapping stage cannot delay the sensor's timestamps or overflow the
// kernel's queues. Priorities 1..99 (0: normal scheduling); needs root, CAP_SYS_NICE or
// RLIMIT_RTPRIO (systemd: LimitRTPRIO=).
inline constexpr int kMaxRealtimePriority = 99;

// Puts the calling thread at SCHED_FIFO `priority`. Returns an empty string, or why the kernel
// refused (the thread then keeps its scheduling).
std::string set_realtime_priority(int priority);

}  // namespace semap::drivers
