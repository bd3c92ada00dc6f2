#include "semap/dds_idl/participant.hpp"

#include "semap/dds_idl/error.hpp"

namespace semap::dds_idl {

Participant::Participant(dds_domainid_t domain, const Qos& qos)
    : domain_(domain),
      entity_(check(dds_create_participant(domain, qos.get(), nullptr), "dds_create_participant")) {
}

}  // namespace semap::dds_idl
