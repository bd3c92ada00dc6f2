#pragma once

// Internal to semap_onboard: what the Foxglove server (foxglove_server.cpp) and its client
// sessions (foxglove_client.cpp) share: FoxgloveServer::Impl and its Client.

#include <array>
#include <atomic>
#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "semap/common/stamp.hpp"
#include "semap/dds_idl/health.hpp"
#include "semap/dds_idl/message_tap.hpp"
#include "semap/onboard/foxglove_server.hpp"

namespace semap::onboard {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using json = nlohmann::json;

constexpr std::size_t kMaxChannels = 256;

class FoxgloveServer::Impl {
 public:
  class Client;

  struct Message {
    std::uint32_t channel = 0;
    std::uint64_t stamp_ns = 0;  // system clock
    std::vector<std::uint8_t> cdr;
  };
  using MessagePtr = std::shared_ptr<const Message>;

  struct Channel {
    dds_idl::TapChannel info;
    std::string schema;
  };

  explicit Impl(Options options);

  Options options_;
  std::string session_id_;
  asio::io_context io_{1};
  std::optional<tcp::acceptor> acceptor_;
  std::thread thread_;
  std::atomic<bool> running_{false};
  std::uint16_t port_ = 0;

  mutable std::mutex channels_mutex_;
  std::deque<Channel> channels_;
  std::array<std::atomic<int>, kMaxChannels> subscribers_;

  std::mutex inbox_mutex_;
  std::vector<MessagePtr> inbox_;
  bool drain_posted_ = false;
  std::atomic<std::uint64_t> inbox_dropped_{0};

  // The server thread's: the newest message of each latched channel, and the clients.
  std::map<std::uint32_t, MessagePtr> latest_;
  mutable std::mutex clients_mutex_;  // guards the vector for readers on other threads
  std::vector<std::shared_ptr<Client>> clients_;

  std::atomic<std::uint64_t> accepted_{0}, refused_{0}, closed_error_{0}, http_requests_{0},
      bad_requests_{0};
  // Of clients gone (the connected ones add their own).
  std::atomic<std::uint64_t> gone_bytes_{0}, gone_messages_{0}, gone_dropped_{0};
  std::deque<dds_idl::ViewerClientData> gone_;  // under clients_mutex_, the last 64

  void gone(const dds_idl::ViewerClientData& f) {
    gone_bytes_ += f.bytes_sent;
    gone_messages_ += f.messages_sent;
    gone_dropped_ += f.messages_dropped;
    gone_.push_back(f);
    if (gone_.size() > 64) gone_.pop_front();
  }

  void do_accept();
  void on_request(beast::tcp_stream stream, beast::flat_buffer buffer,
                  http::request<http::string_body> request);
  void drain();
  void remove(const std::shared_ptr<Client>& client, bool error);
  json advertise(const std::vector<std::uint32_t>& ids) const;
  std::optional<Channel> channel(std::uint32_t id) const {
    std::lock_guard lock(channels_mutex_);
    if (id >= channels_.size()) return std::nullopt;
    return channels_[id];
  }
};

// One WebSocket client, used only on the server thread (its counters are read elsewhere).
class FoxgloveServer::Impl::Client : public std::enable_shared_from_this<Client> {
 public:
  Client(Impl& server, beast::tcp_stream&& stream, std::string address);

  void accept(http::request<http::string_body> request, std::string subprotocol);
  // A message of a channel this client may subscribe to (server thread).
  void deliver(const MessagePtr& m, bool latched);
  void send_text(const json& j);
  void close();
  dds_idl::ViewerClientData figures() const;
  void release_subscriptions();

  // Subscriptions: subscription id -> channel, and back.
  std::map<std::uint32_t, std::uint32_t> subscriptions_;
  std::map<std::uint32_t, std::uint32_t> by_channel_;

 private:
  void on_open();
  void read();
  void status(int level, const std::string& message);
  void on_text(const std::string& text);
  void send_data(std::uint32_t subscription, const Message& m);
  void enqueue(std::shared_ptr<std::string> frame, bool binary);
  void write();
  void on_written(std::size_t n);
  void fail(beast::error_code ec, const char* what);

  struct Out {
    std::shared_ptr<std::string> frame;
    bool binary = false;
  };

  Impl& server_;
  websocket::stream<beast::tcp_stream> ws_;
  beast::flat_buffer in_;
  std::string address_;
  common::Stamp connected_;
  std::deque<Out> queue_;
  std::size_t queued_bytes_ = 0;
  std::map<std::uint32_t, MessagePtr> pending_latched_;
  bool open_ = false;
  bool writing_ = false;
  bool closing_ = false;
  bool failed_ = false;

 public:
  std::atomic<std::uint64_t> bytes_{0}, messages_{0}, dropped_{0};
};

}  // namespace semap::onboard
