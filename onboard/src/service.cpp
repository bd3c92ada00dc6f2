#include "semap/onboard/service.hpp"

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <stop_token>
#include <thread>

#include "semap/common/logging.hpp"
#include "semap/onboard/service_notifier.hpp"

namespace semap::onboard {

void run_service(Pipeline& pipeline, const std::atomic<bool>& stop_requested,
                 const std::vector<std::filesystem::path>& save_paths) {
  const ServiceNotifier service;
  pipeline.start();
  service.ready();
  if (service.watchdog_enabled()) {
    common::logger("onboard")->info("systemd watchdog: pinging every second");
  }
  auto next_ping = std::chrono::steady_clock::now();
  while (!stop_requested.load() && !pipeline.finished()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    pipeline.tick();
    if (const auto now = std::chrono::steady_clock::now(); now >= next_ping) {
      next_ping = now + std::chrono::seconds(1);
      service.watchdog();  // the main loop is alive
    }
  }
  service.stopping();
  std::jthread keepalive([&service](std::stop_token stop) {
    std::mutex mutex;
    std::condition_variable_any woken;
    std::unique_lock lock(mutex);
    while (!stop.stop_requested()) {
      service.watchdog();
      woken.wait_for(lock, stop, std::chrono::milliseconds(500), [] { return false; });
    }
  });
  pipeline.stop();
  for (const auto& path : save_paths) {
    // A full disk fails one save, not the others nor the exit: the summary still comes and
    // the checkpoint log keeps the map up to its last checkpoint (save_failures() has it).
    try {
      pipeline.save_map(path);
    } catch (const std::exception& e) {
      // save_failures() names the map's own path besides the temporary that failed.
      const auto& failures = pipeline.save_failures();
      const auto checkpoint = pipeline.checkpoint_path();
      common::logger("onboard")->error(
          "map not saved: {}{}", failures.empty() ? e.what() : failures.back(),
          checkpoint.empty()
              ? ""
              : "; " + checkpoint.string() + " keeps the map of the last checkpoint (--resume)");
    }
  }
}

}  // namespace semap::onboard
