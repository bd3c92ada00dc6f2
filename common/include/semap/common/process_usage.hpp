#pragma once

namespace semap::common {

// What this process has used so far (getrusage): CPU time, user + system, in seconds, and the
// largest resident set, in MiB.
double process_cpu_seconds();
double process_peak_rss_mib();

}  // namespace semap::common
