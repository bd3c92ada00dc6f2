#pragma once

#include <chrono>
#include <thread>

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
  }

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
  std::string topic_name_;
  Entity entity_;
};

}  // namespace semap::dds_idl
