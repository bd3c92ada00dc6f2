#pragma once

#include <string>

#include "semap/dds_idl/entity.hpp"
#include "semap/dds_idl/error.hpp"
#include "semap/dds_idl/participant.hpp"
#include "semap/dds_idl/types.hpp"

namespace semap::dds_idl {

// A topic of the generated C type T. Creating the same topic twice in one participant is
// allowed by Cyclone and yields independent handles.
template <typename T>
class Topic {
 public:
  Topic(const Participant& participant, const std::string& name, const Qos& qos = Qos())
      : name_(name),
        entity_(check(dds_create_topic(participant.handle(), TypeDescriptor<T>::get(), name.c_str(),
                                       qos.get(), nullptr),
                      "dds_create_topic " + name)) {}

  dds_entity_t handle() const { return entity_.handle(); }
  const std::string& name() const { return name_; }

 private:
  std::string name_;
  Entity entity_;
};

}  // namespace semap::dds_idl
