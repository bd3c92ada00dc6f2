// The Foxglove WebSocket server (foxglove_server.hpp): accepting, the HTTP requests, the channels,
// the fan-out of messages to the clients and the public API. One client's session is
// foxglove_client.cpp; the declarations both share are foxglove_server_impl.hpp.
#include "semap/onboard/foxglove_server.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>

#include "foxglove_server_impl.hpp"
#include "semap/common/logging.hpp"
#include "semap/dds_idl/converters.hpp"
#include "semap/dds_idl/ros2msg.hpp"

namespace semap::onboard {

namespace {

constexpr std::array<std::string_view, 2> kSubprotocols = {"foxglove.websocket.v1",
                                                           "foxglove.sdk.v1"};
// Messages waiting for the server thread; beyond this droppable ones are dropped (the thread
// only copies and queues, so this is reached only when it gets no CPU at all).
constexpr std::size_t kMaxInbox = 4096;
constexpr std::size_t kMaxRequestBytes = 64 * 1024;

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

}  // namespace

FoxgloveServer::Impl::Impl(Options options) : options_(std::move(options)) {
  for (auto& s : subscribers_) s.store(0);
  session_id_ = std::to_string(common::Stamp::now().ns);
}

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
  Impl::Channel c{channel, {}};
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
    auto m = std::make_shared<Impl::Message>();
    m->channel = channel;
    // The time the headers carry (ROS time by default, dds.stamp_clock), so Foxglove's timeline
    // and the messages agree, also across a step of the wall clock.
    const dds_idl::msg::Time time = dds_idl::to_msg_time(stamp);
    m->stamp_ns = static_cast<std::uint64_t>(time.sec_) * 1'000'000'000u + time.nanosec_;
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
