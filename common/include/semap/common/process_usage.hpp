#pragma once

namespace semap::common {

// What this process has used so far (getrusage): CPU time, user + system, in seconds, and the
// largest resident set, in MiB.
double process_cpu_seconds();
double process_peak_rss_mib();
// Seconds since this process started (its start time in /proc/self/stat, 10 ms resolution
// on Linux's usual 100 ticks per second); negative when that cannot be read.
double process_age_seconds();

}  // namespace semap::common
