#pragma once

#include <chrono>
#include <thread>
#include <vector>

#include "semap/dds_idl/message_tap.hpp"
#include "semap/dds_idl/ros2msg.hpp"
#include "semap/dds_idl/topic.hpp"

namespace semap::dds_idl {

// A typed data writer. `write` serialises the sample before returning, so borrowed sequence
// buffers (see borrow_sequence) only need to live for the call.
template <typename T>
class Writer {
 public:
  Writer(const Participant& participant, const Topic<T>& topic, const Qos& qos)
      : topic_name_(topic.name()),
        entity_(check(dds_create_writer(participant.handle(), topic.handle(), qos.get(), nullptr),
                      "dds_create_writer " + topic.name())) {}

  // Writes and sends at once, whether or not the configuration batches writes.
  void write(const T& sample) {
    write_batched(sample);
    flush();
  }

  // With Internal/WriteBatch on in the Cyclone configuration, queues the sample in the writer's
  // packet (sent when it fills, or by flush()), so a burst costs one sendmsg per packet instead
  // of one per sample; without it, sends at once like write().
  void write_batched(const T& sample) {
    // The message is built only on failure: this is the hot path.
    const dds_return_t rc = dds_write(entity_.handle(), &sample);
    if (rc < 0) throw DdsError("dds_write " + topic_name_, rc);
    if (tap_ != nullptr) {
      // The bytes Cyclone sent (serialize_cdr writes them as its serdata does; Cyclone 0.10
      // has no public way to hand a writer bytes of its sertype). One buffer per thread and
      // type, so writers used from several threads stay independent.
      static thread_local std::vector<std::uint8_t> cdr;
      serialize_cdr(sample, cdr);
      tap_->on_message(tap_id_, common::Stamp::now(), cdr);
    }
  }

  // From now on hands every sample written to `tap` too, on a channel named after the topic as
  // ROS 2 sees it, latched when the writer is transient local. Before the threads that write
  // start (the pointer is not synchronised).
  void attach_tap(MessageTap& tap) {
    TapChannel channel{ros2_topic_name(topic_name_),
                       ros2_type_name(TypeDescriptor<T>::get()->m_typename), transient_local()};
    tap_id_ = tap.add_channel(channel);
    tap_ = &tap;
  }
  bool tapped() const { return tap_ != nullptr; }

  // Takes the instance whose key fields `key` holds out of the writer's history: readers keep
  // what they received, late joiners no longer get it. Writing it again registers it again.
  void unregister(const T& key) {
    const dds_return_t rc = dds_unregister_instance(entity_.handle(), &key);
    if (rc < 0) throw DdsError("dds_unregister_instance " + topic_name_, rc);
  }

  // Sends what write_batched queued (Cyclone reports no error here).
  void flush() { dds_write_flush(entity_.handle()); }

  // Number of currently matched readers.
  std::uint32_t matched() const {
    dds_publication_matched_status_t st{};
    check(dds_get_publication_matched_status(entity_.handle(), &st),
          "dds_get_publication_matched_status");
    return st.current_count;
  }

  // Polls until at least `count` readers matched; false on timeout.
  bool wait_for_readers(std::uint32_t count, std::chrono::milliseconds timeout) const {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (matched() < count) {
      if (std::chrono::steady_clock::now() > deadline) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return true;
  }

  dds_entity_t handle() const { return entity_.handle(); }

 private:
  bool transient_local() const {
    dds_qos_t* qos = dds_create_qos();
    dds_durability_kind_t kind = DDS_DURABILITY_VOLATILE;
    if (dds_get_qos(entity_.handle(), qos) >= 0) dds_qget_durability(qos, &kind);
    dds_delete_qos(qos);
    return kind == DDS_DURABILITY_TRANSIENT_LOCAL;
  }

  std::string topic_name_;
  Entity entity_;
  MessageTap* tap_ = nullptr;
  std::uint32_t tap_id_ = 0;
};

}  // namespace semap::dds_idl
