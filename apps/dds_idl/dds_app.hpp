#pragma once

// What the DDS apps share: the dds: config section with command-line overrides,
// CYCLONEDDS_URI, the participant, stopping on SIGINT/SIGTERM.
#include <CLI/CLI.hpp>
#include <atomic>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "semap/common/config.hpp"
#include "semap/dds_idl/dds_settings.hpp"
#include "semap/dds_idl/participant.hpp"

namespace semap::apps {

class DdsOptions {
 public:
  DdsOptions() { s_.security_plugins = SEMAP_DDS_SECURITY_PLUGIN_DIR; }

  void add_flags(CLI::App& app) {
    app.add_option("--domain", s_.domain, "DDS domain id")->check(CLI::Range(0, 232));
    app.add_option("--dds-config", s_.config, "Cyclone DDS XML (sets CYCLONEDDS_URI)");
    app.add_option("--ns", s_.ns, "topic namespace, e.g. robot1");
    app.add_option("--security", s_.security_dir, "directory made by scripts/dds-security");
    app.add_option("--identity", s_.identity, "identity in --security (robot, planner, ...)");
    app.add_option("--security-plugins", s_.security_plugins, "directory of libdds_security_*.so");
  }

  // Takes the `dds:` section of a semap YAML; options given on the command line win.
  void read(const common::ConfigSection& dds, const CLI::App& app) {
    dds_idl::DdsSettings file = dds_idl::read_dds_settings(dds);
    const auto keep = [&](const char* flag, auto& from_file, const auto& from_cli) {
      if (app.count(flag) > 0) from_file = from_cli;
    };
    keep("--domain", file.domain, s_.domain);
    keep("--dds-config", file.config, s_.config);
    keep("--ns", file.ns, s_.ns);
    keep("--security", file.security_dir, s_.security_dir);
    keep("--identity", file.identity, s_.identity);
    if (file.security_plugins.empty() || app.count("--security-plugins") > 0) {
      file.security_plugins = s_.security_plugins;
    }
    s_ = std::move(file);
  }

  const dds_idl::DdsSettings& settings() const { return s_; }

  // Cyclone reads its network configuration from CYCLONEDDS_URI when the first participant
  // is created; the app, not the library, decides which file that is.
  dds_idl::Participant participant() const {
    if (!s_.config.empty()) {
      const std::string uri = "file://" + std::filesystem::absolute(s_.config).string();
      setenv("CYCLONEDDS_URI", uri.c_str(), 1);
    }
    if (!s_.security_dir.empty() && s_.identity.empty()) {
      throw std::invalid_argument("--security needs --identity");
    }
    return dds_idl::Participant(static_cast<dds_domainid_t>(s_.domain), s_.participant_qos());
  }

 private:
  dds_idl::DdsSettings s_;
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
