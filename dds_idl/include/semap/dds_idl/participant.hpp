#pragma once

#include <dds/dds.h>

#include "semap/dds_idl/entity.hpp"
#include "semap/dds_idl/qos.hpp"

namespace semap::dds_idl {

// A domain participant. Cyclone reads its network configuration from CYCLONEDDS_URI, which the
// application (never this library) points at config/cyclonedds-loopback.xml or a real
// network's file.
class Participant {
 public:
  explicit Participant(dds_domainid_t domain = DDS_DOMAIN_DEFAULT, const Qos& qos = Qos());

  dds_entity_t handle() const { return entity_.handle(); }
  dds_domainid_t domain() const { return domain_; }

 private:
  dds_domainid_t domain_;
  Entity entity_;
};

}  // namespace semap::dds_idl
