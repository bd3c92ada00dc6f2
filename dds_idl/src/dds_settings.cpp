#include "semap/dds_idl/dds_settings.hpp"

#include "semap/dds_idl/topic_names.hpp"

namespace semap::dds_idl {

Qos DdsSettings::participant_qos() const {
  Qos q;
  if (!security_dir.empty()) {
    q.security(SecurityConfig::from_directory(security_plugins, security_dir, identity));
  }
  return q;
}

DdsSettings read_dds_settings(const common::ConfigSection& dds) {
  DdsSettings s;
  s.domain = static_cast<int>(dds.get_in_range("domain", 0, 0, 232));
  s.config = dds.get<std::string>("config", "");
  s.ns = dds.get<std::string>("namespace", "");
  s.publish_hz = dds.get_in_range("publish_hz", s.publish_hz, 0.01, 1000.0);
  s.cloud_hz = dds.get_in_range("cloud_hz", s.cloud_hz, 0.0, 100.0);
  s.frame_id = dds.get<std::string>("frame_id", s.frame_id);
  try {
    topic_name(s.ns, SemapTopic::kOdometry);
  } catch (const std::invalid_argument& e) {
    throw common::ConfigError(dds.file() + ": dds.namespace: " + e.what());
  }
  if (dds.has("security")) {
    const auto sec = dds.section("security");
    s.security_dir = sec.get<std::string>("dir");
    s.identity = sec.get<std::string>("identity");
    s.security_plugins = sec.get<std::string>("plugins");
    sec.finish();
  }
  dds.finish();
  return s;
}

}  // namespace semap::dds_idl
