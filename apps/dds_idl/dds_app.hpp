#pragma once

// What the DDS apps share: the dds: config section, CYCLONEDDS_URI, security flags, stopping.
#include <CLI/CLI.hpp>
#include <atomic>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "semap/common/config.hpp"
#include "semap/dds_idl/participant.hpp"

namespace semap::apps {

struct DdsOptions {
  int domain = 0;
  std::string config;  // Cyclone XML; empty keeps CYCLONEDDS_URI as it is
  std::string ns;
  std::string security_dir;
  std::string identity;
  std::string plugin_dir = SEMAP_DDS_SECURITY_PLUGIN_DIR;

  void add_flags(CLI::App& app) {
    app.add_option("--domain", domain, "DDS domain id")->check(CLI::Range(0, 232));
    app.add_option("--dds-config", config, "Cyclone DDS XML (sets CYCLONEDDS_URI)");
    app.add_option("--ns", ns, "topic namespace, e.g. robot1");
    app.add_option("--security", security_dir, "directory made by scripts/dds-security");
    app.add_option("--identity", identity, "identity in --security (robot, planner, ...)");
    app.add_option("--security-plugins", plugin_dir, "directory of libdds_security_*.so");
  }

  // Reads the `dds:` section of a semap YAML (domain, config, namespace); flags given on the
  // command line were applied before and win.
  void read(const common::ConfigSection& dds, const CLI::App& app) {
    const int file_domain = static_cast<int>(dds.get_in_range("domain", domain, 0, 232));
    const std::string file_config = dds.get<std::string>("config", config);
    const std::string file_ns = dds.get<std::string>("namespace", ns);
    if (app.count("--domain") == 0) domain = file_domain;
    if (app.count("--dds-config") == 0) config = file_config;
    if (app.count("--ns") == 0) ns = file_ns;
  }

  // Cyclone reads its network configuration from CYCLONEDDS_URI when the first participant
  // is created; the app, not the library, decides which file that is.
  dds_idl::Participant participant() const {
    if (!config.empty()) {
      const std::string uri = "file://" + std::filesystem::absolute(config).string();
      setenv("CYCLONEDDS_URI", uri.c_str(), 1);
    }
    dds_idl::Qos qos;
    if (!security_dir.empty()) {
      if (identity.empty()) throw std::invalid_argument("--security needs --identity");
      qos.security(dds_idl::SecurityConfig::from_directory(plugin_dir, security_dir, identity));
    }
    return dds_idl::Participant(static_cast<dds_domainid_t>(domain), qos);
  }
};

inline std::atomic<bool>& stop_requested() {
  static std::atomic<bool> stop{false};
  return stop;
}

inline void install_stop_handlers() {
  const auto handler = [](int) { stop_requested() = true; };
  std::signal(SIGINT, handler);
  std::signal(SIGTERM, handler);
}

}  // namespace semap::apps
