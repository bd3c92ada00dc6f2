#pragma once

#include <filesystem>

namespace semap::dds_idl {

// Files of one DDS Security identity, as made by scripts/dds-security. `plugin_dir` holds
// libdds_security_{auth,ac,crypto}.so (Debian: /usr/lib/<triplet>/libddsc0debian).
struct SecurityConfig {
  std::filesystem::path plugin_dir;
  std::filesystem::path identity_ca;
  std::filesystem::path identity_certificate;
  std::filesystem::path private_key;
  std::filesystem::path permissions_ca;
  std::filesystem::path governance;   // signed (S/MIME) governance document
  std::filesystem::path permissions;  // signed (S/MIME) permissions document

  // The layout written by scripts/dds-security: <dir>/ca.pem, <dir>/<identity>.{cert,key}.pem,
  // <dir>/governance.p7s, <dir>/<identity>-permissions.p7s.
  static SecurityConfig from_directory(const std::filesystem::path& plugin_dir,
                                       const std::filesystem::path& dir,
                                       const std::string& identity);
};

}  // namespace semap::dds_idl
