#include "semap/drivers/realtime.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>

namespace semap::drivers {

std::string set_realtime_priority(int priority) {
  sched_param param{};
  param.sched_priority = priority;
  const int error = ::pthread_setschedparam(::pthread_self(), SCHED_FIFO, &param);
  if (error == 0) return {};
  return "SCHED_FIFO priority " + std::to_string(priority) + " refused: " + std::strerror(error) +
         (error == EPERM ? " (needs root, CAP_SYS_NICE or LimitRTPRIO=)" : "");
}

std::string set_cpu_affinity(std::span<const int> cpus) {
  if (cpus.empty()) return {};
  cpu_set_t set;
  CPU_ZERO(&set);
  std::string list;
  for (const int cpu : cpus) {
    if (!list.empty()) list += ',';
    list += std::to_string(cpu);
    if (cpu < 0 || cpu >= CPU_SETSIZE)
      return "CPU " + std::to_string(cpu) + " is outside the CPU set";
    CPU_SET(cpu, &set);
  }
  const int error = ::pthread_setaffinity_np(::pthread_self(), sizeof(set), &set);
  if (error == 0) return {};
  return "CPU affinity {" + list + "} refused: " + std::strerror(error) +
         (error == EINVAL ? " (no such CPU online, or outside this process's cpuset)" : "");
}

namespace {

// The kernel's count of this process's locked memory (the VmLck line of /proc/self/status),
// or -1 when it cannot be read.
long locked_kib() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmLck:", 0) == 0) return std::strtol(line.c_str() + 6, nullptr, 10);
  }
  return -1;
}

}  // namespace

std::string lock_memory() {
  if (::mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
    // Sanitizer runtimes intercept mlockall and return success without locking anything.
    if (locked_kib() == 0)
      return "mlockall refused: it returned success but the kernel locked 0 kB";
    return {};
  }
  const int error = errno;
  return std::string("mlockall refused: ") + std::strerror(error) +
         (error == ENOMEM || error == EPERM
              ? " (RLIMIT_MEMLOCK too small: ulimit -l unlimited, systemd LimitMEMLOCK=infinity)"
              : "");
}

}  // namespace semap::drivers
