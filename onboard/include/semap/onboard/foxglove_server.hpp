#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "semap/dds_idl/health.hpp"
#include "semap/dds_idl/message_tap.hpp"

namespace semap::onboard {

// A Foxglove WebSocket server (protocol v1, subprotocols foxglove.websocket.v1 and
// foxglove.sdk.v1; docs/viewer.md) and, on the same port, plain HTTP GET of a few files (the
// built-in page). Every channel carries CDR (encoding "cdr", schemaEncoding "ros2msg", the
// schema from dds_idl::ros2msg_schema). It is a MessageTap: DDS writers and the viewer hand it
// their messages from any thread; the sockets are served by one thread of its own (asio), so a
// slow or stalled client never slows a writer: on_message copies the bytes and enqueues them.
//
// Each client has a byte budget: while more than `client_budget_bytes` wait to be sent to it,
// messages of droppable channels are dropped for that client (counted), and the newest message
// of each latched channel is kept and sent once the client catches up. The kernel's send
// buffer of each client's socket is set to the budget too (64 KiB to 4 MiB), so a stalled client
// holds at most about twice the budget on the robot. A client subscribing to a latched channel
// gets its newest message at once.
class FoxgloveServer : public dds_idl::MessageTap {
 public:
  struct Options {
    std::string address = "127.0.0.1";
    std::uint16_t port = 8765;  // 0: any free port (port() says which)
    std::string token;          // non-empty: required as ?token= on every request
    std::size_t client_budget_bytes = 8u << 20;
    std::string name = "semap-onboard";
    std::vector<std::pair<std::string, std::string>> metadata;
    // Served over HTTP GET: path relative to "/" ("index.html" is also "/"), contents.
    std::vector<std::pair<std::string_view, std::string_view>> files;
  };

  // Totals since start (the clients' own figures: clients()).
  struct Counters {
    std::uint64_t clients_accepted = 0;
    std::uint64_t clients_refused = 0;       // wrong token, no subprotocol of ours
    std::uint64_t clients_closed_error = 0;  // a read, write or protocol error closed them
    std::uint64_t http_requests = 0;
    std::uint64_t bytes_sent = 0;
    std::uint64_t messages_sent = 0;
    std::uint64_t messages_dropped = 0;  // for slow clients (budget) and a full inbox
    std::uint64_t bad_requests = 0;      // answered with a status message
  };

  explicit FoxgloveServer(Options options);
  ~FoxgloveServer() override;
  FoxgloveServer(const FoxgloveServer&) = delete;
  FoxgloveServer& operator=(const FoxgloveServer&) = delete;

  // Binds and listens (throws std::runtime_error naming the address on failure), then serves
  // on its own thread.
  void start();
  // Closes every client and joins the thread (at most about a second). Idempotent.
  void stop();

  // After start(): the bound port, and "http://ADDRESS:PORT/".
  std::uint16_t port() const;
  std::string url() const;

  // MessageTap: channels may be added before or after start() (clients then get an advertise).
  std::uint32_t add_channel(const dds_idl::TapChannel& channel) override;
  void on_message(std::uint32_t channel, common::Stamp stamp,
                  std::span<const std::uint8_t> cdr) noexcept override;
  // Whether any client subscribes to `channel` now (a producer may skip work otherwise).
  bool subscribed(std::uint32_t channel) const noexcept;

  // The connected clients, for the health report (any thread).
  std::vector<dds_idl::ViewerClientData> clients() const;
  // Every client since start (the last 64 gone, then the connected ones), for the summary.
  std::vector<dds_idl::ViewerClientData> clients_served() const;
  Counters counters() const;

  class Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace semap::onboard
