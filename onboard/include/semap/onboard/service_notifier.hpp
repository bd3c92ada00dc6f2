#pragma once

namespace semap::onboard {

// Tells systemd how the service is doing (sd_notify, Type=notify in semap-onboard.service):
// ready once the stages run, a watchdog ping from the main loop every second, stopping at
// SIGTERM. Without libsystemd at build time, or outside systemd (no NOTIFY_SOCKET), it does
// nothing.
class ServiceNotifier {
 public:
  void ready() const;
  void watchdog() const;
  void stopping() const;
  // Whether systemd asked for watchdog pings (WatchdogSec=), for the log.
  bool watchdog_enabled() const;
};

}  // namespace semap::onboard
