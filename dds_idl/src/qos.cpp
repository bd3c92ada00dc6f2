#include "semap/dds_idl/qos.hpp"

#include <stdexcept>

namespace semap::dds_idl {

namespace {

std::string file_uri(const std::filesystem::path& p) { return "file:" + p.string(); }

}  // namespace

SecurityConfig SecurityConfig::from_directory(const std::filesystem::path& plugin_dir,
                                              const std::filesystem::path& dir,
                                              const std::string& identity) {
  SecurityConfig c;
  c.plugin_dir = plugin_dir;
  c.identity_ca = dir / "ca.pem";
  c.identity_certificate = dir / (identity + ".cert.pem");
  c.private_key = dir / (identity + ".key.pem");
  c.permissions_ca = dir / "ca.pem";
  c.governance = dir / "governance.p7s";
  c.permissions = dir / (identity + "-permissions.p7s");
  return c;
}

Qos::Qos() : qos_(dds_create_qos()) {
  if (!qos_) throw std::bad_alloc();
}

Qos::Qos(const Qos& other) : Qos() { dds_copy_qos(qos_.get(), other.qos_.get()); }

Qos& Qos::operator=(const Qos& other) {
  if (this != &other) dds_copy_qos(qos_.get(), other.qos_.get());
  return *this;
}

Qos& Qos::reliable(std::chrono::milliseconds max_blocking) {
  dds_qset_reliability(qos_.get(), DDS_RELIABILITY_RELIABLE, DDS_MSECS(max_blocking.count()));
  return *this;
}

Qos& Qos::best_effort() {
  dds_qset_reliability(qos_.get(), DDS_RELIABILITY_BEST_EFFORT, 0);
  return *this;
}

Qos& Qos::keep_last(int depth) {
  if (depth < 1) throw std::invalid_argument("Qos::keep_last: depth must be >= 1");
  dds_qset_history(qos_.get(), DDS_HISTORY_KEEP_LAST, depth);
  return *this;
}

Qos& Qos::keep_all() {
  dds_qset_history(qos_.get(), DDS_HISTORY_KEEP_ALL, DDS_LENGTH_UNLIMITED);
  return *this;
}

Qos& Qos::volatile_durability() {
  dds_qset_durability(qos_.get(), DDS_DURABILITY_VOLATILE);
  return *this;
}

Qos& Qos::transient_local() {
  dds_qset_durability(qos_.get(), DDS_DURABILITY_TRANSIENT_LOCAL);
  return *this;
}

Qos& Qos::partition(const std::vector<std::string>& names) {
  std::vector<const char*> ptrs;
  ptrs.reserve(names.size());
  for (const auto& n : names) ptrs.push_back(n.c_str());
  dds_qset_partition(qos_.get(), static_cast<uint32_t>(ptrs.size()), ptrs.data());
  return *this;
}

Qos& Qos::property(const std::string& name, const std::string& value) {
  dds_qset_prop(qos_.get(), name.c_str(), value.c_str());
  return *this;
}

Qos& Qos::security(const SecurityConfig& c) {
  const auto lib = [&](const char* name) { return (c.plugin_dir / name).string(); };
  property("dds.sec.auth.library.path", lib("libdds_security_auth.so"));
  property("dds.sec.auth.library.init", "init_authentication");
  property("dds.sec.auth.library.finalize", "finalize_authentication");
  property("dds.sec.auth.identity_ca", file_uri(c.identity_ca));
  property("dds.sec.auth.identity_certificate", file_uri(c.identity_certificate));
  property("dds.sec.auth.private_key", file_uri(c.private_key));
  property("dds.sec.access.library.path", lib("libdds_security_ac.so"));
  property("dds.sec.access.library.init", "init_access_control");
  property("dds.sec.access.library.finalize", "finalize_access_control");
  property("dds.sec.access.permissions_ca", file_uri(c.permissions_ca));
  property("dds.sec.access.governance", file_uri(c.governance));
  property("dds.sec.access.permissions", file_uri(c.permissions));
  property("dds.sec.crypto.library.path", lib("libdds_security_crypto.so"));
  property("dds.sec.crypto.library.init", "init_crypto");
  property("dds.sec.crypto.library.finalize", "finalize_crypto");
  return *this;
}

}  // namespace semap::dds_idl
