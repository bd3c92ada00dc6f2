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
  for (const auto& path : save_paths) pipeline.save_map(path);
}

}  // namespace semap::onboard
