#pragma once

#include <span>
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

// Pins the calling thread to `cpus` (empty: no change). Keeping a driver on its own core keeps
// other threads' cache and scheduling noise off its wake-ups. Returns an empty string, or why
// the kernel refused (a CPU the machine does not have, a cpuset that excludes it).
std::string set_cpu_affinity(std::span<const int> cpus);

// Locks the process's pages in RAM, now and future (mlockall), so no page fault stalls a
// driver or stage thread on a robot under memory pressure. Returns an empty string, or why it
// was refused (RLIMIT_MEMLOCK too small; systemd: LimitMEMLOCK=infinity), or that the kernel
// locked nothing although mlockall returned success (as under a sanitizer runtime).
std::string lock_memory();

}  // namespace semap::drivers
