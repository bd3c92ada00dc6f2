#include "semap/onboard/service_notifier.hpp"

#ifdef SEMAP_HAVE_SYSTEMD
#include <systemd/sd-daemon.h>
#endif

namespace semap::onboard {

#ifdef SEMAP_HAVE_SYSTEMD
void ServiceNotifier::ready() const { sd_notify(0, "READY=1"); }
void ServiceNotifier::watchdog() const { sd_notify(0, "WATCHDOG=1"); }
void ServiceNotifier::stopping() const { sd_notify(0, "STOPPING=1"); }
bool ServiceNotifier::watchdog_enabled() const { return sd_watchdog_enabled(0, nullptr) > 0; }
#else
void ServiceNotifier::ready() const {}
void ServiceNotifier::watchdog() const {}
void ServiceNotifier::stopping() const {}
bool ServiceNotifier::watchdog_enabled() const { return false; }
#endif

}  // namespace semap::onboard
