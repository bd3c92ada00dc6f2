#pragma once

#include <string>

#include "semap/common/config.hpp"
#include "semap/dds_idl/map_publisher.hpp"

namespace semap::dds_idl {

// The `dds:` section of a semap configuration:
//   dds: { domain: 0, config: config/cyclonedds-loopback.xml, namespace: robot1, publish_hz: 2,
//          cloud_hz: 0.5, frame_id: map,
//          security: { dir: /etc/semap/dds-security, identity: robot, plugins: /usr/lib/... } }
// `config` is for the application to export as CYCLONEDDS_URI before the first participant.
struct DdsSettings {
  int domain = 0;
  std::string config;
  std::string ns;
  double publish_hz = 2.0;
  double cloud_hz = 0.5;
  std::string frame_id = "map";
  std::string security_dir;  // empty: no DDS Security
  std::string identity;
  std::string security_plugins;

  MapPublisherConfig map_publisher() const { return {ns, frame_id, publish_hz, cloud_hz}; }
  // Participant QoS: DDS Security properties when security_dir is set.
  Qos participant_qos() const;
};

// Reads and checks the section (ranges, namespace syntax, security completeness) and rejects
// unknown keys; throws common::ConfigError naming file, line and key.
DdsSettings read_dds_settings(const common::ConfigSection& dds);

}  // namespace semap::dds_idl
