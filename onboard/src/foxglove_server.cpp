#include "semap/onboard/foxglove_server.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <thread>

#include "semap/common/logging.hpp"
#include "semap/dds_idl/ros2msg.hpp"

namespace semap::onboard {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using json = nlohmann::json;

namespace {

constexpr std::array<std::string_view, 2> kSubprotocols = {"foxglove.websocket.v1",
                                                           "foxglove.sdk.v1"};
constexpr std::size_t kMaxChannels = 256;
// Messages waiting for the server thread; beyond this droppable ones are dropped (the thread
// only copies and queues, so this is reached only when it gets no CPU at all).
constexpr std::size_t kMaxInbox = 4096;
constexpr std::size_t kMaxRequestBytes = 64 * 1024;

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

void put_le(std::string& out, std::uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xffu));
}

// "?a=1&token=x" -> "x" for "token" (no percent-decoding beyond '+': tokens are plain).
std::optional<std::string> query_param(std::string_view target, std::string_view key) {
  const auto q = target.find('?');
  if (q == std::string_view::npos) return std::nullopt;
  std::string_view rest = target.substr(q + 1);
  while (!rest.empty()) {
    const auto amp = rest.find('&');
    const std::string_view pair = rest.substr(0, amp);
    rest = amp == std::string_view::npos ? std::string_view{} : rest.substr(amp + 1);
    const auto eq = pair.find('=');
    if (pair.substr(0, eq) != key) continue;
    return std::string(eq == std::string_view::npos ? std::string_view{} : pair.substr(eq + 1));
  }
  return std::nullopt;
}

std::string_view content_type(std::string_view path) {
  const auto ends = [&](std::string_view ext) { return path.ends_with(ext); };
  if (ends(".html")) return "text/html; charset=utf-8";
  if (ends(".js") || ends(".mjs")) return "text/javascript; charset=utf-8";
  if (ends(".css")) return "text/css; charset=utf-8";
  if (ends(".json")) return "application/json";
  if (ends(".svg")) return "image/svg+xml";
  if (ends(".png")) return "image/png";
  if (ends(".ico")) return "image/x-icon";
  if (ends(".wasm")) return "application/wasm";
  if (ends(".txt") || ends(".md")) return "text/plain; charset=utf-8";
  return "application/octet-stream";
}

std::int64_t realtime_minus_monotonic_ns() {
  const auto real = std::chrono::duration_cast<std::chrono::nanoseconds>(
                        std::chrono::system_clock::now().time_since_epoch())
                        .count();
  return real - common::Stamp::now().ns;
}

}  // namespace

class FoxgloveServer::Impl {
 public:
  class Client;

  explicit Impl(Options options)
      : options_(std::move(options)), offset_ns_(realtime_minus_monotonic_ns()) {
    for (auto& s : subscribers_) s.store(0);
    session_id_ = std::to_string(common::Stamp::now().ns);
  }

  Options options_;
  std::int64_t offset_ns_;
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
  Client(Impl& server, beast::tcp_stream&& stream, std::string address)
      : server_(server),
        ws_(std::move(stream)),
        address_(std::move(address)),
        connected_(common::Stamp::now()) {}

  void accept(http::request<http::string_body> request, std::string subprotocol) {
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.set_option(websocket::stream_base::decorator([subprotocol](websocket::response_type& r) {
      r.set(http::field::sec_websocket_protocol, subprotocol);
      r.set(http::field::server, "semap-onboard");
    }));
    ws_.read_message_max(1u << 20);
    ws_.async_accept(request, [self = shared_from_this()](beast::error_code ec) {
      if (ec) return self->fail(ec, "accept");
      self->on_open();
    });
  }

  // A message of a channel this client may subscribe to (server thread).
  void deliver(const MessagePtr& m, bool latched) {
    const auto sub = by_channel_.find(m->channel);
    if (sub == by_channel_.end()) return;
    if (queued_bytes_ > server_.options_.client_budget_bytes) {
      if (latched) {
        pending_latched_[m->channel] = m;  // coalesced to the newest
      } else {
        dropped_.fetch_add(1, std::memory_order_relaxed);
      }
      return;
    }
    send_data(sub->second, *m);
  }

  void send_text(const json& j) { enqueue(std::make_shared<std::string>(j.dump()), false); }

  void close() {
    if (closing_) return;
    closing_ = true;
    ws_.async_close(websocket::close_code::going_away,
                    [self = shared_from_this()](beast::error_code) {});
  }

  dds_idl::ViewerClientData figures() const {
    return {address_, bytes_.load(std::memory_order_relaxed),
            messages_.load(std::memory_order_relaxed), dropped_.load(std::memory_order_relaxed),
            static_cast<float>(common::seconds_between(common::Stamp::now(), connected_))};
  }

  // Subscriptions: subscription id -> channel, and back.
  std::map<std::uint32_t, std::uint32_t> subscriptions_;
  std::map<std::uint32_t, std::uint32_t> by_channel_;

 private:
  void on_open() {
    open_ = true;
    json info = {{"op", "serverInfo"},
                 {"name", server_.options_.name},
                 {"capabilities", json::array()},
                 {"sessionId", server_.session_id_}};
    json metadata = json::object();
    for (const auto& [k, v] : server_.options_.metadata) metadata[k] = v;
    info["metadata"] = metadata;
    send_text(info);
    std::vector<std::uint32_t> ids;
    {
      std::lock_guard lock(server_.channels_mutex_);
      for (std::uint32_t i = 0; i < server_.channels_.size(); ++i) ids.push_back(i);
    }
    send_text(server_.advertise(ids));
    read();
  }

  void read() {
    ws_.async_read(in_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      if (ec) return self->fail(ec, "read");
      try {
        if (self->ws_.got_text()) {
          self->on_text(beast::buffers_to_string(self->in_.data()));
        } else {
          self->status(2, "binary client messages are not supported (no clientPublish)");
        }
      } catch (const std::exception& e) {
        ++self->server_.bad_requests_;
        self->status(2, std::string("bad request: ") + e.what());
      }
      self->in_.consume(self->in_.size());
      self->read();
    });
  }

  void status(int level, const std::string& message) {
    if (level > 0) ++server_.bad_requests_;
    send_text({{"op", "status"}, {"level", level}, {"message", message}});
  }

  void on_text(const std::string& text) {
    const json j = json::parse(text);
    const std::string op = j.at("op").get<std::string>();
    if (op == "subscribe") {
      for (const auto& s : j.at("subscriptions")) {
        const auto id = s.at("id").get<std::uint32_t>();
        const auto channel = s.at("channelId").get<std::uint32_t>();
        const auto ch = server_.channel(channel);
        if (!ch) {
          status(2, "subscribe: unknown channel id " + std::to_string(channel));
          continue;
        }
        if (subscriptions_.count(id) != 0) {
          status(2, "subscribe: subscription id " + std::to_string(id) + " is in use");
          continue;
        }
        if (by_channel_.count(channel) != 0) {
          status(2, "subscribe: channel " + std::to_string(channel) + " is already subscribed");
          continue;
        }
        subscriptions_[id] = channel;
        by_channel_[channel] = id;
        server_.subscribers_[channel].fetch_add(1);
        // A late joiner gets the latched channel's newest message at once.
        const auto latest = server_.latest_.find(channel);
        if (latest != server_.latest_.end()) deliver(latest->second, true);
      }
    } else if (op == "unsubscribe") {
      for (const auto& s : j.at("subscriptionIds")) {
        const auto id = s.get<std::uint32_t>();
        const auto it = subscriptions_.find(id);
        if (it == subscriptions_.end()) {
          status(1, "unsubscribe: unknown subscription id " + std::to_string(id));
          continue;
        }
        server_.subscribers_[it->second].fetch_sub(1);
        pending_latched_.erase(it->second);
        by_channel_.erase(it->second);
        subscriptions_.erase(it);
      }
    } else {
      status(2, "unsupported op \"" + op + "\"");
    }
  }

 public:
  void release_subscriptions() {
    for (const auto& [id, channel] : subscriptions_) server_.subscribers_[channel].fetch_sub(1);
    subscriptions_.clear();
    by_channel_.clear();
    pending_latched_.clear();
  }

 private:
  void send_data(std::uint32_t subscription, const Message& m) {
    auto frame = std::make_shared<std::string>();
    frame->reserve(13 + m.cdr.size());
    frame->push_back(static_cast<char>(0x01));
    put_le(*frame, subscription, 4);
    put_le(*frame, m.stamp_ns, 8);
    frame->append(reinterpret_cast<const char*>(m.cdr.data()), m.cdr.size());
    enqueue(std::move(frame), true);
  }

  void enqueue(std::shared_ptr<std::string> frame, bool binary) {
    if (closing_) return;
    queued_bytes_ += frame->size();
    queue_.push_back({std::move(frame), binary});
    if (!writing_ && open_) write();
  }

  void write() {
    if (queue_.empty()) {
      writing_ = false;
      return;
    }
    writing_ = true;
    const Out& out = queue_.front();
    ws_.binary(out.binary);
    ws_.async_write(asio::buffer(*out.frame),
                    [self = shared_from_this()](beast::error_code ec, std::size_t n) {
                      if (ec) return self->fail(ec, "write");
                      self->on_written(n);
                    });
  }

  void on_written(std::size_t n) {
    const Out out = std::move(queue_.front());
    queue_.pop_front();
    queued_bytes_ -= out.frame->size();
    bytes_.fetch_add(n, std::memory_order_relaxed);
    if (out.binary) messages_.fetch_add(1, std::memory_order_relaxed);
    // Caught up: what the latched channels hold now goes out.
    if (queued_bytes_ <= server_.options_.client_budget_bytes && !pending_latched_.empty()) {
      auto pending = std::move(pending_latched_);
      pending_latched_.clear();
      for (const auto& [channel, m] : pending) {
        const auto sub = by_channel_.find(channel);
        if (sub != by_channel_.end()) send_data(sub->second, *m);
      }
    }
    write();
  }

  void fail(beast::error_code ec, const char* what) {
    if (failed_) return;
    failed_ = true;
    // A client that went away (closed, or its process ended: reset, end of stream) is a
    // normal end; anything else (a protocol error, a timeout) closed it on an error.
    const bool normal = ec == websocket::error::closed || ec == asio::error::operation_aborted ||
                        ec == asio::error::eof || ec == asio::error::connection_reset ||
                        ec == asio::error::broken_pipe || ec == http::error::end_of_stream ||
                        closing_;
    if (!normal) {
      common::logger("viewer")->info("viewer: client {} closed: {} ({})", address_, ec.message(),
                                     what);
    }
    server_.remove(shared_from_this(), !normal);
  }

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

json FoxgloveServer::Impl::advertise(const std::vector<std::uint32_t>& ids) const {
  json channels = json::array();
  std::lock_guard lock(channels_mutex_);
  for (const std::uint32_t id : ids) {
    const Channel& c = channels_[id];
    channels.push_back({{"id", id},
                        {"topic", c.info.topic},
                        {"encoding", "cdr"},
                        {"schemaName", c.info.type},
                        {"schema", c.schema},
                        {"schemaEncoding", "ros2msg"}});
  }
  return {{"op", "advertise"}, {"channels", channels}};
}

void FoxgloveServer::Impl::do_accept() {
  acceptor_->async_accept(asio::make_strand(io_), [this](beast::error_code ec, tcp::socket s) {
    if (ec == asio::error::operation_aborted || !acceptor_->is_open()) return;
    if (!ec) {
      // Reads the request (WebSocket upgrade or plain GET) with a deadline and a size bound.
      struct Reader : std::enable_shared_from_this<Reader> {
        Impl& server;
        beast::tcp_stream stream;
        beast::flat_buffer buffer;
        http::request_parser<http::string_body> parser;
        Reader(Impl& srv, tcp::socket&& sock) : server(srv), stream(std::move(sock)) {
          parser.body_limit(kMaxRequestBytes);
          parser.header_limit(kMaxRequestBytes);
        }
        void run() {
          stream.expires_after(std::chrono::seconds(30));
          http::async_read(
              stream, buffer, parser,
              [self = shared_from_this()](beast::error_code e, std::size_t) {
                if (e) return;  // the client went or sent garbage: nothing to keep
                self->stream.expires_never();
                try {
                  self->server.on_request(std::move(self->stream), std::move(self->buffer),
                                          self->parser.release());
                } catch (const std::exception& ex) {
                  common::logger("viewer")->warn("viewer: request failed: {}", ex.what());
                }
              });
        }
      };
      // The kernel's send buffer is part of the budget: left to autotune it holds megabytes for
      // a stalled client before the server sees it behind.
      const std::size_t send_buffer =
          std::clamp<std::size_t>(options_.client_budget_bytes, 64u << 10, 4u << 20);
      beast::error_code ignored;
      s.set_option(asio::socket_base::send_buffer_size(static_cast<int>(send_buffer)), ignored);
      std::make_shared<Reader>(*this, std::move(s))->run();
    }
    do_accept();
  });
}

void FoxgloveServer::Impl::on_request(beast::tcp_stream stream, beast::flat_buffer /*buffer*/,
                                      http::request<http::string_body> request) {
  const std::string target(request.target());
  const auto respond = [&](http::status status, std::string_view type, std::string body) {
    auto res = std::make_shared<http::response<http::string_body>>(status, request.version());
    res->set(http::field::server, "semap-onboard");
    res->set(http::field::content_type, std::string(type));
    res->set(http::field::cache_control, "no-cache");
    res->keep_alive(false);
    res->body() = std::move(body);
    res->prepare_payload();
    auto s = std::make_shared<beast::tcp_stream>(std::move(stream));
    s->expires_after(std::chrono::seconds(30));
    http::async_write(*s, *res, [s, res](beast::error_code, std::size_t) {
      beast::error_code ignored;
      s->socket().shutdown(tcp::socket::shutdown_send, ignored);
    });
  };
  const bool upgrade = websocket::is_upgrade(request);
  if (!options_.token.empty() && query_param(target, "token") != options_.token) {
    if (upgrade) ++refused_;
    respond(http::status::unauthorized, "text/plain", "401: ?token= missing or wrong\n");
    return;
  }
  if (upgrade) {
    // The first subprotocol of the client's list that we speak.
    std::string chosen;
    const auto header = request[http::field::sec_websocket_protocol];
    const std::string offered_list(header.data(), header.size());
    std::string_view offered = offered_list;
    while (chosen.empty() && !offered.empty()) {
      const auto comma = offered.find(',');
      std::string_view p = offered.substr(0, comma);
      offered = comma == std::string_view::npos ? std::string_view{} : offered.substr(comma + 1);
      while (!p.empty() && (p.front() == ' ' || p.front() == '\t')) p.remove_prefix(1);
      while (!p.empty() && (p.back() == ' ' || p.back() == '\t')) p.remove_suffix(1);
      for (const auto ours : kSubprotocols) {
        if (p == ours) chosen = std::string(ours);
      }
    }
    if (chosen.empty()) {
      ++refused_;
      respond(http::status::bad_request, "text/plain",
              "400: subprotocol foxglove.websocket.v1 or foxglove.sdk.v1 required\n");
      return;
    }
    beast::error_code ec;
    const auto remote = stream.socket().remote_endpoint(ec);
    const std::string address =
        ec ? std::string("?") : remote.address().to_string() + ":" + std::to_string(remote.port());
    auto client = std::make_shared<Client>(*this, std::move(stream), address);
    {
      std::lock_guard lock(clients_mutex_);
      clients_.push_back(client);
    }
    ++accepted_;
    common::logger("viewer")->info("viewer: client {} connected ({})", address, chosen);
    client->accept(std::move(request), chosen);
    return;
  }
  ++http_requests_;
  if (request.method() != http::verb::get && request.method() != http::verb::head) {
    respond(http::status::method_not_allowed, "text/plain", "405\n");
    return;
  }
  std::string path = target.substr(0, target.find('?'));
  if (path.empty() || path == "/") path = "/index.html";
  path.erase(0, 1);
  for (const auto& [name, contents] : options_.files) {
    if (name == path) {
      respond(http::status::ok, content_type(path),
              request.method() == http::verb::head ? std::string() : std::string(contents));
      return;
    }
  }
  respond(http::status::not_found, "text/plain", "404\n");
}

void FoxgloveServer::Impl::drain() {
  std::vector<MessagePtr> batch;
  {
    std::lock_guard lock(inbox_mutex_);
    batch.swap(inbox_);
    drain_posted_ = false;
  }
  for (const MessagePtr& m : batch) {
    bool latched = false;
    {
      std::lock_guard lock(channels_mutex_);
      latched = channels_[m->channel].info.latched;
    }
    if (latched) latest_[m->channel] = m;
    for (const auto& client : clients_) client->deliver(m, latched);
  }
}

void FoxgloveServer::Impl::remove(const std::shared_ptr<Client>& client, bool error) {
  if (error) ++closed_error_;
  client->release_subscriptions();
  std::lock_guard lock(clients_mutex_);
  if (std::erase(clients_, client) > 0) gone(client->figures());
}

FoxgloveServer::FoxgloveServer(Options options)
    : impl_(std::make_unique<Impl>(std::move(options))) {}

FoxgloveServer::~FoxgloveServer() { stop(); }

void FoxgloveServer::start() {
  Impl& s = *impl_;
  if (s.running_) return;
  beast::error_code ec;
  const auto address = asio::ip::make_address(s.options_.address, ec);
  if (ec) throw std::runtime_error("viewer.address " + s.options_.address + ": " + ec.message());
  const tcp::endpoint endpoint(address, s.options_.port);
  s.acceptor_.emplace(s.io_);
  const auto check = [&](const char* what) {
    if (ec) {
      throw std::runtime_error(std::string("viewer: ") + what + " " + s.options_.address + ":" +
                               std::to_string(s.options_.port) + ": " + ec.message());
    }
  };
  s.acceptor_->open(endpoint.protocol(), ec);
  check("open");
  s.acceptor_->set_option(asio::socket_base::reuse_address(true), ec);
  check("reuse_address");
  s.acceptor_->bind(endpoint, ec);
  check("bind");
  s.acceptor_->listen(asio::socket_base::max_listen_connections, ec);
  check("listen");
  s.port_ = s.acceptor_->local_endpoint().port();
  s.do_accept();
  s.running_ = true;
  s.thread_ = std::thread([&s] {
    pthread_setname_np(pthread_self(), "viewer");
    // Never throws out of the thread: a handler's exception is logged and the loop goes on.
    for (;;) {
      try {
        s.io_.run();
        break;
      } catch (const std::exception& e) {
        common::logger("viewer")->error("viewer: {}", e.what());
      }
    }
  });
}

void FoxgloveServer::stop() {
  Impl& s = *impl_;
  if (!s.running_.exchange(false)) return;
  asio::post(s.io_, [&s] {
    beast::error_code ec;
    s.acceptor_->close(ec);
    std::vector<std::shared_ptr<Impl::Client>> clients;
    {
      std::lock_guard lock(s.clients_mutex_);
      clients = s.clients_;
    }
    for (const auto& c : clients) c->close();
  });
  // Clients get a moment to take the close; a stalled one does not hold up the exit.
  std::mutex m;
  std::condition_variable cv;
  bool done = false;
  asio::post(s.io_, [&] {
    std::lock_guard lock(m);
    done = true;
    cv.notify_one();
  });
  {
    std::unique_lock lock(m);
    cv.wait_for(lock, std::chrono::seconds(1), [&] { return done; });
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  s.io_.stop();
  if (s.thread_.joinable()) s.thread_.join();
  {
    std::lock_guard lock(s.clients_mutex_);
    for (const auto& c : s.clients_) s.gone(c->figures());
    s.clients_.clear();
  }
}

std::uint16_t FoxgloveServer::port() const { return impl_->port_; }

std::string FoxgloveServer::url() const {
  return "http://" + impl_->options_.address + ":" + std::to_string(impl_->port_) + "/";
}

std::uint32_t FoxgloveServer::add_channel(const dds_idl::TapChannel& channel) {
  Impl& s = *impl_;
  Channel c{channel, {}};
  try {
    c.schema = dds_idl::ros2msg_schema(channel.type);
  } catch (const std::exception& e) {
    common::logger("viewer")->warn("viewer: {} has no schema: {}", channel.topic, e.what());
  }
  std::uint32_t id = 0;
  {
    std::lock_guard lock(s.channels_mutex_);
    if (s.channels_.size() >= kMaxChannels) {
      throw std::length_error("viewer: more than " + std::to_string(kMaxChannels) + " channels");
    }
    id = static_cast<std::uint32_t>(s.channels_.size());
    s.channels_.push_back(std::move(c));
  }
  if (s.running_) {
    asio::post(s.io_, [&s, id] {
      const json a = s.advertise({id});
      for (const auto& client : s.clients_) client->send_text(a);
    });
  }
  return id;
}

bool FoxgloveServer::subscribed(std::uint32_t channel) const noexcept {
  return channel < kMaxChannels && impl_->subscribers_[channel].load(std::memory_order_relaxed) > 0;
}

void FoxgloveServer::on_message(std::uint32_t channel, common::Stamp stamp,
                                std::span<const std::uint8_t> cdr) noexcept {
  Impl& s = *impl_;
  if (channel >= kMaxChannels) return;
  bool latched = false;
  {
    std::lock_guard lock(s.channels_mutex_);
    if (channel >= s.channels_.size()) return;
    latched = s.channels_[channel].info.latched;
  }
  // Nobody listens and no late joiner needs it: nothing to copy.
  if (!latched && s.subscribers_[channel].load(std::memory_order_relaxed) == 0) return;
  if (!s.running_) {
    if (!latched) return;
  }
  try {
    auto m = std::make_shared<Message>();
    m->channel = channel;
    m->stamp_ns = static_cast<std::uint64_t>(stamp.ns + s.offset_ns_);
    m->cdr.assign(cdr.begin(), cdr.end());
    bool post = false;
    {
      std::lock_guard lock(s.inbox_mutex_);
      if (s.inbox_.size() >= kMaxInbox && !latched) {
        ++s.inbox_dropped_;
        return;
      }
      s.inbox_.push_back(std::move(m));
      post = !s.drain_posted_;
      s.drain_posted_ = true;
    }
    if (post) asio::post(s.io_, [&s] { s.drain(); });
  } catch (...) {
    ++s.inbox_dropped_;  // out of memory: this message is lost, the writer goes on
  }
}

std::vector<dds_idl::ViewerClientData> FoxgloveServer::clients() const {
  std::vector<dds_idl::ViewerClientData> out;
  std::lock_guard lock(impl_->clients_mutex_);
  for (const auto& c : impl_->clients_) out.push_back(c->figures());
  return out;
}

std::vector<dds_idl::ViewerClientData> FoxgloveServer::clients_served() const {
  std::lock_guard lock(impl_->clients_mutex_);
  std::vector<dds_idl::ViewerClientData> out(impl_->gone_.begin(), impl_->gone_.end());
  for (const auto& c : impl_->clients_) out.push_back(c->figures());
  return out;
}

FoxgloveServer::Counters FoxgloveServer::counters() const {
  const Impl& s = *impl_;
  Counters c;
  c.clients_accepted = s.accepted_;
  c.clients_refused = s.refused_;
  c.clients_closed_error = s.closed_error_;
  c.http_requests = s.http_requests_;
  c.bad_requests = s.bad_requests_;
  c.bytes_sent = s.gone_bytes_;
  c.messages_sent = s.gone_messages_;
  c.messages_dropped = s.gone_dropped_ + s.inbox_dropped_;
  std::lock_guard lock(s.clients_mutex_);
  for (const auto& client : s.clients_) {
    const auto f = client->figures();
    c.bytes_sent += f.bytes_sent;
    c.messages_sent += f.messages_sent;
    c.messages_dropped += f.messages_dropped;
  }
  return c;
}

}  // namespace semap::onboard
