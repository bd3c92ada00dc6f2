#pragma once

#include <dds/dds.h>

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "semap/dds_idl/security.hpp"

namespace semap::dds_idl {

// Builder over dds_qos_t: `Qos().reliable().transient_local().keep_last(1)`.
class Qos {
 public:
  Qos();
  Qos(const Qos& other);
  Qos& operator=(const Qos& other);
  Qos(Qos&&) noexcept = default;
  Qos& operator=(Qos&&) noexcept = default;
  ~Qos() = default;

  Qos& reliable(std::chrono::milliseconds max_blocking = std::chrono::milliseconds(100));
  Qos& best_effort();
  Qos& keep_last(int depth);
  Qos& keep_all();
  Qos& volatile_durability();
  Qos& transient_local();
  Qos& partition(const std::vector<std::string>& names);
  Qos& property(const std::string& name, const std::string& value);
  // DDS Security plugins and documents of one identity (participant QoS only).
  Qos& security(const SecurityConfig& config);

  const dds_qos_t* get() const { return qos_.get(); }

 private:
  struct Deleter {
    void operator()(dds_qos_t* q) const { dds_delete_qos(q); }
  };
  std::unique_ptr<dds_qos_t, Deleter> qos_;
};

}  // namespace semap::dds_idl
