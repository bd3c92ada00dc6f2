#pragma once

#include <dds/ddsi/ddsi_serdata.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <span>

#include "semap/dds_idl/topic.hpp"

namespace semap::dds_idl {

// A typed data reader with a waitset on its data-available state.
template <typename T>
class Reader {
 public:
  // `listener` (optional, copied by Cyclone) runs its callbacks on Cyclone's threads: with
  // on_data_available, the receive thread takes the samples as they arrive, as ddsperf's
  // subscriber does, instead of waking a thread of the application.
  Reader(const Participant& participant, const Topic<T>& topic, const Qos& qos,
         const dds_listener_t* listener = nullptr)
      : topic_name_(topic.name()),
        entity_(check(dds_create_reader(participant.handle(), topic.handle(), qos.get(), listener),
                      "dds_create_reader " + topic.name())),
        condition_(check(dds_create_readcondition(entity_.handle(), DDS_ANY_STATE),
                         "dds_create_readcondition")),
        waitset_(check(dds_create_waitset(participant.handle()), "dds_create_waitset")) {
    check(dds_waitset_attach(waitset_.handle(), condition_.handle(), 0), "dds_waitset_attach");
  }

  // Takes every available sample and calls f(const T&, const dds_sample_info_t&) for those
  // carrying data (not for dispose/unregister notifications). Returns how many had data. The
  // sample is valid only during the call: it lives in storage this reader reuses.
  template <typename F>
  std::size_t take_each(F&& f) {
    std::size_t count = 0;
    for (;;) {
      // Non-null buffers make Cyclone deserialise into the samples of the previous take,
      // reusing their sequence and string buffers, where a loan allocates and frees every
      // sequence of every sample.
      std::array<void*, kBatch> samples;
      for (std::size_t i = 0; i < kBatch; ++i) samples[i] = &(*storage_)[i];
      std::array<dds_sample_info_t, kBatch> infos{};
      const dds_return_t n =
          dds_take(entity_.handle(), samples.data(), infos.data(), kBatch, kBatch);
      if (n < 0) throw DdsError("dds_take " + topic_name_, n);
      if (n == 0) break;
      for (dds_return_t i = 0; i < n; ++i) {
        if (!infos[static_cast<std::size_t>(i)].valid_data) continue;
        f((*storage_)[static_cast<std::size_t>(i)], infos[static_cast<std::size_t>(i)]);
        ++count;
      }
      if (static_cast<std::size_t>(n) < kBatch) break;
    }
    return count;
  }

  // Takes every available sample in its serialised form and calls
  // f(std::span<const std::uint8_t> cdr, const dds_sample_info_t&) for those carrying data; the
  // bytes (encapsulation header first, then the sample's CDR) are valid only during the call.
  // Skips Cyclone's deserialiser and the sample buffers: the caller parses the bytes (for map
  // blocks: read_block_cdr) and must treat them as untrusted input. Returns how many had data.
  template <typename F>
  std::size_t take_each_cdr(F&& f) {
    std::size_t count = 0;
    for (;;) {
      std::array<ddsi_serdata*, kBatch> data{};
      std::array<dds_sample_info_t, kBatch> infos{};
      const dds_return_t n =
          dds_takecdr(entity_.handle(), data.data(), kBatch, infos.data(), DDS_ANY_STATE);
      if (n < 0) throw DdsError("dds_takecdr " + topic_name_, n);
      // Every serdata taken is released, also when f throws.
      const SerdataRelease release{data, n};
      for (dds_return_t i = 0; i < n; ++i) {
        if (!infos[static_cast<std::size_t>(i)].valid_data) continue;
        // The default serdata keeps the sample contiguous: one iovec, no copy.
        ddsi_serdata* d = data[static_cast<std::size_t>(i)];
        ddsrt_iovec_t iov{};
        const SerRef ref{ddsi_serdata_to_ser_ref(d, 0, ddsi_serdata_size(d), &iov), iov};
        f(std::span<const std::uint8_t>(static_cast<const std::uint8_t*>(iov.iov_base),
                                        iov.iov_len),
          infos[static_cast<std::size_t>(i)]);
        ++count;
      }
      if (static_cast<std::size_t>(n) < kBatch) break;
    }
    return count;
  }

  // Blocks until a sample (or state change) is available; false on timeout.
  bool wait(std::chrono::nanoseconds timeout) {
    const dds_return_t rc = dds_waitset_wait(waitset_.handle(), nullptr, 0,
                                             static_cast<dds_duration_t>(timeout.count()));
    return check(rc, "dds_waitset_wait") > 0;
  }

  std::uint32_t matched() const {
    dds_subscription_matched_status_t st{};
    check(dds_get_subscription_matched_status(entity_.handle(), &st),
          "dds_get_subscription_matched_status");
    return st.current_count;
  }

  dds_entity_t handle() const { return entity_.handle(); }

 private:
  static constexpr std::size_t kBatch = 64;
  using Samples = std::array<T, kBatch>;
  // Frees what Cyclone allocated inside the samples; holds at most kBatch samples' worth of
  // buffers, each as large as the largest sample taken into that slot.
  struct FreeSamples {
    void operator()(Samples* s) const {
      for (T& sample : *s) dds_sample_free(&sample, TypeDescriptor<T>::get(), DDS_FREE_CONTENTS);
      delete s;
    }
  };

  struct SerdataRelease {
    std::array<ddsi_serdata*, kBatch>& data;
    dds_return_t n;
    ~SerdataRelease() {
      for (dds_return_t i = 0; i < n; ++i) ddsi_serdata_unref(data[static_cast<std::size_t>(i)]);
    }
  };
  struct SerRef {
    ddsi_serdata* d;
    ddsrt_iovec_t iov;
    ~SerRef() { ddsi_serdata_to_ser_unref(d, &iov); }
  };

  std::string topic_name_;
  Entity entity_;
  Entity condition_;
  Entity waitset_;
  std::unique_ptr<Samples, FreeSamples> storage_{new Samples{}};
};

}  // namespace semap::dds_idl
