#include "semap/drivers/realtime.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>

#include <cerrno>
#include <cstring>

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

std::string lock_memory() {
  if (::mlockall(MCL_CURRENT | MCL_FUTURE) == 0) return {};
  const int error = errno;
  return std::string("mlockall refused: ") + std::strerror(error) +
         (error == ENOMEM || error == EPERM
              ? " (RLIMIT_MEMLOCK too small: ulimit -l unlimited, systemd LimitMEMLOCK=infinity)"
              : "");
}

}  // namespace semap::drivers
