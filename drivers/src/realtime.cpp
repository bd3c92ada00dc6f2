#include "semap/drivers/realtime.hpp"

#include <pthread.h>
#include <sched.h>

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

}  // namespace semap::drivers
