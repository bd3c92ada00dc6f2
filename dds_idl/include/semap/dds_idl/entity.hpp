#pragma once

#include <dds/dds.h>

#include <utility>

namespace semap::dds_idl {

// Owns one DDS entity handle and deletes it (and its children) on destruction. Deleting a
// child whose parent is already gone fails harmlessly, so member order never matters.
class Entity {
 public:
  Entity() = default;
  explicit Entity(dds_entity_t handle) : handle_(handle) {}
  ~Entity() { reset(); }
  Entity(const Entity&) = delete;
  Entity& operator=(const Entity&) = delete;
  Entity(Entity&& other) noexcept : handle_(std::exchange(other.handle_, 0)) {}
  Entity& operator=(Entity&& other) noexcept {
    if (this != &other) {
      reset();
      handle_ = std::exchange(other.handle_, 0);
    }
    return *this;
  }

  dds_entity_t handle() const { return handle_; }
  explicit operator bool() const { return handle_ > 0; }

  void reset() {
    if (handle_ > 0) dds_delete(handle_);
    handle_ = 0;
  }

 private:
  dds_entity_t handle_ = 0;
};

}  // namespace semap::dds_idl
